"""Frequency response: linearisation vs the thesis, MuJoCo vs the reference."""

import math

import numpy as np
import pytest

from mbsuite.analysis.sweep import run_sweep
from mbsuite.models.pantograph.equations import PantographODE
from mbsuite.models.pantograph.freqresp import FR_SIGNALS, _point
from mbsuite.models.pantograph.linearise import linear_response, linearize, modes_from_eigs
from mbsuite.models.pantograph.mujoco import MODES_TIMESTEP, MujocoPantograph, mujoco_modes


@pytest.fixture(scope="module")
def y_lin(params):
    """The lab input y_w = y_op + A (1 - cos wt) oscillates about y_op + A: the linearisation point (closed form;
    `operating_height` is checked by `test_freqresp_linearises_about_the_mean_of_the_input`)."""
    return params.y_op + 1.85e-3


@pytest.fixture(scope="module")
def lin(ode, y_lin):
    return linearize(ode, ode.equilibrium(y_lin), y_lin)


def test_linear_modes_near_thesis(lin):
    """Thesis simulated resonances 4.25 / 8.75 / 19.5 Hz (Ch. 5.1) read off a 0.5 Hz grid, and the cylinder's
    coupled first-order pole at 0.269 Hz (reference erratum 20)."""
    modes = modes_from_eigs(np.linalg.eigvals(lin[0]))
    osc = [m["f_n"] for m in modes if m["kind"] == "oscillatory"]
    first = [m for m in modes if m["kind"] == "first-order"]
    assert len(osc) == 3 and len(first) == 1
    assert osc[0] == pytest.approx(4.25, abs=0.25)
    assert osc[1] == pytest.approx(8.75, abs=0.5)
    assert osc[2] == pytest.approx(19.5, abs=0.5)
    assert first[0]["f_n"] == pytest.approx(0.269, abs=0.002)


def test_mujoco_linearisation_matches_reference(lin, y_lin):
    """MuJoCo's own linearisation (mjd_transitionFD, implicit, h = 1e-4 s) at the same operating point: frequencies
    within 2.5e-4 (measured <= 1.2e-4), damping ratios within 2e-3 (measured <= 5e-4). MuJoCo linearised at y_op
    instead (second mode 8.614 Hz) is 3.5e-4 from the reference at y_op + A (8.611 Hz) and fails."""
    ref = modes_from_eigs(np.linalg.eigvals(lin[0]))
    mp = MujocoPantograph(integrator="implicit", timestep=MODES_TIMESTEP)
    mj = mujoco_modes(mp, mp.equilibrium(y_lin), y_lin)
    for a, b in zip(ref, mj, strict=True):
        assert b["f_n"] == pytest.approx(a["f_n"], rel=2.5e-4)
        assert b["zeta"] == pytest.approx(a["zeta"], rel=2e-3)


def _deviations(res: list[dict], H: np.ndarray) -> tuple[float, float]:
    """Largest amplitude ratio deviation and phase difference (deg) of time-path points from H over all signals."""
    amp = ph = 0.0
    for k, r in enumerate(res):
        for i, s in enumerate(FR_SIGNALS):
            amp = max(amp, abs(r[s][0] / abs(H[k, i]) - 1.0))
            ph = max(ph, abs((r[s][1] - math.degrees(np.angle(H[k, i])) + 180.0) % 360.0 - 180.0))
    return amp, ph


def test_linearisation_matches_both_time_paths_without_friction(lab_scene, lin, ode, params):
    """Coulomb off, A = 1.85 mm: the linear FRF about y_op + A and both time paths (reference LSODA, MuJoCo RK4 1 ms)
    agree within 0.3 % and 0.3 deg at 1, 2, 4.5, 8.5, 10 and 30 Hz (measured: <= 5.8e-4 and 0.10 deg for the
    reference, largest at the first resonance; MuJoCo <= 1.5e-3 at 30 Hz, its step error). The linearisation about
    y_op, which the lab input does not oscillate about, misses HD at 8.5 Hz by 2.7 %: this test fails for it."""
    sc = lab_scene.replace(effects={"coulomb": False})
    freqs = [1.0, 2.0, 4.5, 8.5, 10.0, 30.0]
    H = linear_response(*lin, np.array(freqs))
    jobs = [(sc.to_dict(), f, m) for m in ("reference", "mujoco") for f in freqs]
    res = run_sweep(_point, jobs, workers=0, progress=False)
    for m in ("reference", "mujoco"):
        amp, ph = _deviations([r for r in res if r["method"] == m], H)
        assert amp < 3e-3 and ph < 0.3, m
    wrong = linear_response(*linearize(ode, ode.equilibrium(params.y_op), params.y_op), np.array([8.5]))
    hd = next(r for r in res if r["method"] == "reference" and r["f"] == 8.5)["HD"][0]
    assert abs(hd / abs(wrong[0, 2]) - 1.0) > 0.02


@pytest.mark.slow
def test_linearisation_matches_both_time_paths_whole_grid(lab_scene, lin, ode, y_lin):
    """The whole 1-30 Hz grid (0.5 Hz), Coulomb off, both time paths against the linear FRF: 0.3 % and 0.3 deg at every
    frequency outside the third resonance's band 16.5-22 Hz (measured: <= 1.0e-3 reference, 1.5e-3 MuJoCo at 30 Hz;
    <= 0.10 deg). In the band the head swings up to 20 A and the geometric nonlinearity of the time paths reaches
    5.6 % / 4 deg at A = 1.85 mm. There the deviation d(A) = H(A) / H_lin(y_op + A) - 1 falls as A^2 (measured ratio
    4.0-4.3 per halving): its extrapolation (4 d(A/2) - d(A)) / 3 to A -> 0 must be below 3e-3 (complex; measured
    <= 1.2e-3), i.e. the linearisation is the small-amplitude limit of both time paths."""
    sc = lab_scene.replace(effects={"coulomb": False})
    freqs = np.round(np.arange(1.0, 30.25, 0.5), 10)
    H = linear_response(*lin, freqs)
    res = run_sweep(_point, [(sc.to_dict(), float(f), m) for m in ("reference", "mujoco") for f in freqs],
                    workers=0, progress=False)
    band = [f for f in freqs if 16.5 <= f <= 22.0]
    for m in ("reference", "mujoco"):
        rows = [r for r in res if r["method"] == m]
        for k, f in enumerate(freqs):
            if f in band:
                continue
            amp, ph = _deviations([rows[k]], H[k : k + 1])
            assert amp < 3e-3 and ph < 0.3, (m, f)
    half = sc.replace(input={"amplitude": 0.925e-3})
    y_half = y_lin - 1.85e-3 + 0.925e-3
    H_half = linear_response(*linearize(ode, ode.equilibrium(y_half), y_half), np.array(band))
    res_half = run_sweep(_point, [(half.to_dict(), float(f), m) for m in ("reference", "mujoco") for f in band],
                         workers=0, progress=False)
    for m in ("reference", "mujoco"):
        full = {r["f"]: r for r in res if r["method"] == m}
        for k, f in enumerate(band):
            r2 = next(r for r in res_half if r["method"] == m and r["f"] == f)
            for i, s in enumerate(FR_SIGNALS):
                hf = full[f][s][0] * np.exp(1j * math.radians(full[f][s][1]))
                hh = r2[s][0] * np.exp(1j * math.radians(r2[s][1]))
                d_full = hf / H[list(freqs).index(f), i] - 1.0
                d_half = hh / H_half[k, i] - 1.0
                assert abs((4.0 * d_half - d_full) / 3.0) < 3e-3, (m, f, s)


def test_remaining_deviation_grows_with_amplitude_squared(lab_scene, ode, params):
    """About the right operating point what the time path keeps from the linearisation is the geometric
    nonlinearity, which grows as A^2 (a wrong operating point gives a deviation proportional to A). At the first
    resonance (4.25 Hz), Coulomb off, reference path: F1 deviates -3.28e-3 at A = 1.85 mm and -8.20e-4 at 0.925 mm,
    ratio 4.01 (A^2: 4; proportional: 2); the reference's own noise is ~3e-6 (0.4 % of the smaller deviation), the
    tolerance 5 %. (At 8.5 Hz the remaining deviation, 5e-4, is at the level of the start transient left at
    t_settle.)"""
    sc = lab_scene.replace(effects={"coulomb": False})
    dev = []
    jobs = [(sc.replace(input={"amplitude": A}).to_dict(), 4.25, "reference") for A in (1.85e-3, 0.925e-3)]
    for A, r in zip((1.85e-3, 0.925e-3), run_sweep(_point, jobs, workers=0, progress=False), strict=True):
        y = params.y_op + A
        H = linear_response(*linearize(ode, ode.equilibrium(y), y), np.array([4.25]))[0, 0]
        dev.append(r["F1"][0] / abs(H) - 1.0)
    assert abs(dev[0]) > 1e-3  # a resolvable nonlinearity
    assert dev[0] / dev[1] == pytest.approx(4.0, rel=0.05)


def test_mujoco_vs_reference_at_default_timestep(lab_scene):
    """Amplitudes within 1 % and phases within 2 deg at the first two resonances and at 2 and 10 Hz, lab
    scene (Coulomb friction on: event-exact in the reference, frictionloss in MuJoCo)."""
    freqs = [2.0, 4.25, 8.5, 10.0]
    jobs = [(lab_scene.to_dict(), f, m) for f in freqs for m in ("mujoco", "reference")]
    res = run_sweep(_point, jobs, workers=0, progress=False)
    for f in freqs:
        mj = next(r for r in res if r["f"] == f and r["method"] == "mujoco")
        rf = next(r for r in res if r["f"] == f and r["method"] == "reference")
        for s in ("F1", "F2", "y_d") + (("HD",) if f > 2.0 else ()):
            assert mj[s][0] == pytest.approx(rf[s][0], rel=0.01), (f, s)
            assert abs(mj[s][1] - rf[s][1]) < 2.0, (f, s)
        # HD at 2 Hz is the smallest, stick-slip dominated signal (0.15 A): 1 % of it is 3 um
        assert mj["HD"][0] == pytest.approx(rf["HD"][0], rel=0.03)


def test_coulomb_friction_lowers_resonance_peaks(lab_scene):
    """The thesis' small Coulomb friction removes 7.6 % of the F1 peak at the first resonance (4.25 Hz). MuJoCo's
    frictionloss against a different method, the event-exact stick/slip reference: F1 on/off 0.92371 vs 0.92390,
    the reductions differ by 0.25 % of themselves; bound 2 % (8x)."""
    jobs = [(lab_scene.replace(effects={"coulomb": c}).to_dict(), 4.25, m)
            for m in ("mujoco", "reference") for c in (True, False)]
    mj_on, mj_off, ref_on, ref_off = (r["F1"][0] for r in run_sweep(_point, jobs, workers=0, progress=False))
    drop_mj, drop_ref = 1.0 - mj_on / mj_off, 1.0 - ref_on / ref_off
    assert drop_ref > 0.05  # friction matters at the resonance: the comparison is not of two zeros
    assert drop_mj == pytest.approx(drop_ref, rel=0.02)


def test_exact_chain_wrap_changes_statics_little():
    """Erratum 22: the exact chain wrap moves the equilibrium by 6.4e-3 rad (theta_1). A different method predicts the
    shift: one Newton step of the exact model's static residual from the B.6 equilibrium, -J^-1 r (first order in
    the 0.016 rad theta_e difference). Measured: the prediction is off by 0.9 % of the shift (second-order terms);
    bound 5 %."""
    b6 = PantographODE()
    exact = PantographODE(elbow_kinematics="exact")
    a, b = b6.equilibrium(), exact.equilibrium()
    shift = b[:3] - a[:3]
    q, y, h = a[:3], b6.p.y_op, 1e-7
    J = np.column_stack([(exact.static_residual(q + h * e, y) - exact.static_residual(q - h * e, y)) / (2 * h)
                         for e in np.eye(3)])
    predicted = np.linalg.solve(J, -exact.static_residual(q, y))
    assert np.max(np.abs(predicted - shift)) < 0.05 * np.max(np.abs(shift))
    assert np.max(np.abs(shift)) > 1e-3  # the two kinematics do differ (resolvable shift)


def test_freqresp_linearises_about_the_mean_of_the_input(lab_scene):
    """The `freqresp` analysis as the user runs it (Coulomb off, 8.5 Hz, linear and MuJoCo): the linear FRF about the
    height `operating_height` chooses and the MuJoCo time path (RK4 1 ms) give the same HD ratio: measured 2.0414 vs
    2.0423 (4.0e-4), bound 2e-3 (5x). About y_op instead of the mean y_op + A of the input the linear HD ratio is
    2.7 % low (README "Linearisation")."""
    from mbsuite.models.pantograph.freqresp import freqresp

    sc = lab_scene.replace(effects={"coulomb": False})
    data = freqresp(sc, 8.5, 8.5, 0.5, methods=("linear", "mujoco"), workers=1, progress=False,
                    time_histories=False).data
    lin, mj = (data["response"][m]["HD"]["amplitude"][0] for m in ("linear", "mujoco"))
    assert lin == pytest.approx(mj, rel=2e-3)
