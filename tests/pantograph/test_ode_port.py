"""The pantograph's hand-derived ODE as a C one-port (`native/ode_port.c`, `ode_port.OdePort`) against its readable
Python twin, `EppingerReference` (`under_wire.py`: one RK4 step of `PantographODE.rhs_with_force` per trial):

- every effect combination `under_wire.config` can produce (gravity, elbow compliant/rigid, B.6/exact kinematics, the
  three cylinders, viscous damping, Coulomb off/smooth): single trials from the static equilibrium and from perturbed
  states, at several force histories and steps, agree to rounding (state and height);
- 2000 steps of trials (several per step, as the catenary's secant iteration makes them) and commits under a varying
  force agree to rounding accumulated over the run;
- failures (non-finite input or state, a diverging step, the elbow without a tangent line, the nonlinear cylinder's
  volume <= 0) return their code and a message naming them; a wrong twin and a wrong struct layout are caught."""

from __future__ import annotations

import ctypes
import itertools
import math

import numpy as np
import pytest

from mbsuite.engines import native
from mbsuite.errors import GeometryError, SolverError
from mbsuite.models.pantograph import ode_port
from mbsuite.models.pantograph.ode_port import OUTPUTS, OdePort
from mbsuite.models.pantograph.under_wire import EppingerReference

#: every effect combination reachable under the wire (`contact` is always bilateral there; coulomb = true is read as
#: "smooth", so False and "smooth" are all there is)
COMBOS = [dict(zip(("gravity", "elbow", "elbow_kinematics", "cylinder", "viscous", "coulomb"), v, strict=True)) for v in
          itertools.product((True, False), ("compliant", "rigid"), ("B6", "exact"), ("constant", "linear", "nonlinear"),
                            (True, False), (False, "smooth"))]
#: (f0, f1) force histories (N; >= 0 presses the head down) and steps (s) of the single trials
FORCES = [(None, None), (None, 30.0), (0.0, 200.0), (-50.0, 150.0)]  # None: the static force (+ offset)
STEPS = (1e-4, 1e-3)
#: single trial, state: max over entries of |C - Python| / max(|Python's new entry|, |its step increment|). Measured
#: over the 96 combinations x 3 states x 4 force histories x 2 steps: 7.5e-15 (a rate, after the 3x3 solve, which is
#: LAPACK's dgesv in numpy and Gaussian elimination in C); the angles 1.9e-16, the cylinder states bit-equal
TOL_TRIAL = 1e-12
#: single trial, height y = y_d - y_op, relative to y_op (y is a mm-sized difference of ~1.6 m terms). Measured: 3.1e-15
TOL_HEIGHT = 3e-13
#: 2000 steps: heights and signals relative to each signal's largest magnitude over the run. Measured: 2.1e-13 (rigid
#: elbow: libm's hypot and Python's math.hypot differ by an ulp now and then, and theta_e reads the fourth-bar length
#: through (lfb - lfb0) / le); the final state 1.5e-13
TOL_RUN = 2e-11


def _id(eff: dict) -> str:
    return "-".join(f"{v}" if not isinstance(v, bool) else (k if v else f"no_{k}") for k, v in eff.items())


def _reference(effects: dict, params: dict | None = None) -> tuple[EppingerReference, float]:
    ref = EppingerReference(params or {}, effects)
    f = ref.static(0.0, 5.0e4)
    return ref, f


def _perturbed(ref: EppingerReference, sign: float) -> np.ndarray:
    """The equilibrium state moved by a few mrad, rates of order 0.1-1 rad/s, the cylinder state off its rest (the
    nonlinear cylinder's pressure by 2 %: out of the orifice's laminar band, on either side of the supply)."""
    ode, x = ref.ode, ref.x.copy()
    nq = ode.nq
    x[:nq] += sign * np.array([3e-3, -2e-3, 4e-3][:nq])
    x[nq:2 * nq] += np.array([0.3, -0.5, 0.8][:nq]) * sign
    if ode.has_P:
        x[-1] = x[-1] * (1.0 + 0.02 * sign) if ode.cfg.cylinder == "nonlinear" else x[-1] + 2e-3 * sign
    return x


def _state_error(xc: np.ndarray, xp: np.ndarray, x0: np.ndarray) -> float:
    scale = np.maximum(np.abs(xp), np.abs(xp - x0))
    scale[scale == 0.0] = 1.0
    return float(np.max(np.abs(xc - xp) / scale))


@pytest.mark.parametrize("effects", COMBOS, ids=_id)
def test_single_trials_equal_the_python_step(effects):
    ref, f_static = _reference(effects)
    op = OdePort(ref)
    x_eq = ref.x.copy()
    worst_x = worst_y = 0.0
    for x0 in (x_eq, _perturbed(ref, 1.0), _perturbed(ref, -1.0)):
        ref.x = x0.copy()
        op.push(ref)
        for (a, b), dt in itertools.product(FORCES, STEPS):
            f0 = f_static if a is None else a
            f1 = f_static + (b or 0.0) if a is None else b
            code, y = op.trial(0.37, dt, f0, f1)
            assert code == 0, op.failure(code)
            yp = ref.trial(0.37, dt, f0, f1)
            worst_x = max(worst_x, _state_error(op.pending(), ref._pending, x0))
            worst_y = max(worst_y, abs(y - yp) / ref.y_op)
            np.testing.assert_array_equal(op.state(), x0)  # a trial leaves the committed state
    assert worst_x <= TOL_TRIAL and worst_y <= TOL_HEIGHT, (worst_x, worst_y)


@pytest.mark.parametrize("effects", [{}, {"elbow": "rigid", "elbow_kinematics": "exact", "cylinder": "nonlinear"},
                                     {"cylinder": "nonlinear", "coulomb": "smooth", "elbow_kinematics": "exact"}],
                         ids=_id)
def test_every_parameter_reaches_the_c_state(effects):
    """Non-default values of every parameter the ODE reads (be > 0, omega_s, the gas constants, ...): the C trial
    still equals the Python one, so no field is dropped or swapped on the way into the struct."""
    params = {"l1": 1.9, "l2": 2.0, "lh": 0.42, "m1": 30.0, "m2": 26.0, "mh": 12.0, "I1": 11.0, "I2": 8.5,
              "Ih": 0.45, "d1": 1.0, "d2": 0.85, "dh": 0.33, "kh": 2400.0, "be": 40.0, "b1": 30.0,
              "b2": 160.0, "bh": 11.0, "c1": 1.2, "c2": 0.5, "ch": 0.4, "xf": 0.11, "yf": 0.18, "le": 0.085,
              "theta_e0": -0.16, "lb": 0.24, "alpha": 1.8, "Ap": 0.0125, "Ao": 3.3e-6, "V0": 0.00098, "Pg": 7.2e5,
              "R_gas": 288.0, "gamma": 1.38, "cd": 0.62, "Pa": 1.0e5, "T": 295.0, "kc": 1.6e5, "bc": 9.2e4,
              "g": 9.81, "y_op": 1.6, "r_laminar": 0.9999, "omega_s": 2e-3}
    if effects.get("elbow") != "rigid":
        params["ke"] = 45000.0
    ref, f = _reference(effects, params)
    op = OdePort(ref)
    x0 = _perturbed(ref, 1.0)
    ref.x = x0.copy()
    op.push(ref)
    code, y = op.trial(0.0, 5e-4, f, f + 20.0)
    assert code == 0, op.failure(code)
    yp = ref.trial(0.0, 5e-4, f, f + 20.0)
    assert _state_error(op.pending(), ref._pending, x0) <= TOL_TRIAL
    assert abs(y - yp) <= TOL_HEIGHT * ref.y_op


def test_a_wrong_twin_is_caught():
    """The comparison can fail: the elbow stiffness or the head spring of the C state off by 1e-7 (relative), the
    orifice's gas constant by 1e-5 (it moves the pressure, 8e5 Pa, by little in a step), moves a single trial beyond
    10 TOL_TRIAL (measured: 9.5e-9, 7.0e-10, 1.4e-8)."""
    for name, rel, effects in (("ke", 1e-7, {}), ("gas", 1e-5, {"cylinder": "nonlinear"}),
                               ("kh", 1e-7, {"elbow": "rigid"})):
        ref, f = _reference(effects)
        x0 = _perturbed(ref, 1.0)
        ref.x = x0.copy()
        op = OdePort(ref)
        setattr(op._s, name, getattr(op._s, name) * (1.0 + rel))
        code, _ = op.trial(0.0, 1e-3, f, f + 20.0)
        assert code == 0
        ref.trial(0.0, 1e-3, f, f + 20.0)
        assert _state_error(op.pending(), ref._pending, x0) > 10 * TOL_TRIAL, name


RUN_COMBOS = [
    {},  # the lab scene's effects under the wire (Coulomb as the smooth law)
    {"elbow": "rigid", "elbow_kinematics": "exact", "cylinder": "nonlinear"},
    {"elbow_kinematics": "exact", "cylinder": "nonlinear", "coulomb": False},
    {"gravity": False, "viscous": False, "coulomb": False, "cylinder": "constant"},
    {"elbow": "rigid", "cylinder": "linear", "viscous": False},
]


@pytest.mark.parametrize("effects", RUN_COMBOS, ids=_id)
def test_two_thousand_steps_of_trials_and_commits_equal_the_python(effects):
    """2000 steps of 1e-4 s under f = 120 + 40 sin(2 pi 7 t) N, three trials per step (the secant iteration's f1
    guesses: 5 % high, 3 % low, then the force itself) before the commit; every height and the signals of every
    committed state against the Python adapter."""
    ref, _ = _reference(effects)
    op = OdePort(ref)
    dt, n = 1e-4, 2000

    def force(t: float) -> float:
        return 120.0 + 40.0 * math.sin(2.0 * math.pi * 7.0 * t)

    y_c, y_p, rows, sig = [], [], [], {k: [] for k in OUTPUTS}
    for k in range(n):
        t = k * dt
        f0, f1 = force(t), force(t + dt)
        for g in (1.05 * f1, 0.97 * f1, f1):
            code, y = op.trial(t, dt, f0, g)
            assert code == 0, op.failure(code)
            y_c.append(y)
            y_p.append(ref.trial(t, dt, f0, g))
        op.commit()
        ref.commit()
        rows.append(op.outputs())
        for key, v in ref.signals().items():
            sig[key].append(v)
    y_c, y_p = np.array(y_c), np.array(y_p)
    assert np.max(np.abs(y_c - y_p)) <= TOL_RUN * np.max(np.abs(y_p))
    got = op.signals(np.array(rows))
    assert set(got) == set(sig)
    for key in OUTPUTS:
        want = np.array(sig[key])
        assert got[key].shape == (n,)
        assert np.max(np.abs(got[key] - want)) <= TOL_RUN * np.max(np.abs(want)), key
    # the state moved (the comparison is not of a pantograph at rest) and pull() hands it back
    assert np.ptp(y_p) > 1e-3
    x_c = op.state()
    assert _state_error(x_c, ref.x, np.zeros_like(x_c)) <= TOL_RUN
    back = EppingerReference({}, effects)
    op.pull(back)
    np.testing.assert_array_equal(back.x, x_c)


def test_a_non_finite_force_fails_naming_it_and_the_commit_after_it_changes_nothing():
    ref, f = _reference({})
    op = OdePort(ref)
    x0 = op.state()
    assert op.trial(0.0, 1e-4, f, f)[0] == 0
    code, _ = op.trial(0.0, 1e-4, f, float("nan"))
    assert code == ode_port.FAIL_INPUT
    msg = op.failure(code)
    assert "non-finite force f1 = nan" in msg
    assert op.pending() is None
    op.commit()
    np.testing.assert_array_equal(op.state(), x0)
    code, _ = op.trial(0.0, float("inf"), f, f)
    assert code == ode_port.FAIL_INPUT and "time step dt = inf" in op.failure(code)


def test_a_non_finite_state_and_a_diverging_step_fail_naming_them():
    ref, f = _reference({"cylinder": "nonlinear"})
    op = OdePort(ref)
    # forces so large that the rates overflow: the stage and the rate are named
    code, _ = op.trial(0.0, 1e-4, 1.5e308, 1.5e308)
    assert code == ode_port.FAIL_RATE
    msg = op.failure(code)
    assert "non-finite state rate" in msg and "RK4 stage 1" in msg and "diverged" in msg
    ref.x[2] = np.nan
    op.push(ref)
    code, _ = op.trial(0.0, 1e-4, f, f)
    assert code == ode_port.FAIL_STATE and "non-finite committed state x[2] = nan" in op.failure(code)


def test_the_elbow_without_a_tangent_fails_as_the_python_raises():
    """A chain base point (xf, -yf) within the pinion radius of the elbow's circle at theta_1 = -0.54 rad: the Python
    raises GeometryError, the C trial returns its code and names the geometry."""
    params = {"l1": 1.2, "d1": 1.0, "xf": 1.0, "yf": 0.6}
    for elbow in ("compliant", "rigid"):
        ref = EppingerReference(params, {"elbow": elbow})
        nq = ref.ode.nq
        x = np.zeros(ref.ode.n)
        x[:nq] = [-0.54, 0.5, 0.0][:nq] if nq == 3 else [-0.54, 0.0]
        x[-1] = ref.ode.cylinder_lever(-0.54)[0]
        ref.x = x
        _fails_alike(ref, GeometryError, "no tangent line", ode_port.FAIL_ELBOW, "no tangent line at theta_1 = -0.54",
                     "RK4 stage 1")


def test_a_non_positive_cylinder_volume_fails_as_the_python_raises():
    ref, _ = _reference({"cylinder": "nonlinear"})
    ref.x[0] = -0.3  # x_p = lb cos(alpha + 0.3) < -V0 / Ap
    _fails_alike(ref, SolverError, "volume became non-positive", ode_port.FAIL_VOLUME,
                 "volume became non-positive (V = -", "theta_1 = -0.3")


def _fails_alike(ref, error: type, match: str, code: int, *said: str) -> None:
    """The Python trial raises `error` (matching `match`); the C trial from the same state returns `code`, and its
    failure text holds every piece of `said`."""
    with pytest.raises(error, match=match):
        ref.trial(0.0, 1e-4, 100.0, 100.0)
    op = OdePort(ref)
    got, _ = op.trial(0.0, 1e-4, 100.0, 100.0)
    assert got == code
    msg = op.failure(got)
    assert all(s in msg for s in said), msg


def test_the_port_is_filled_and_event_exact_coulomb_is_refused():
    ref, _ = _reference({})
    op = OdePort(ref)
    p = op.port
    assert p.self == ctypes.addressof(op._s) and p.affine == 0 and p.nout == len(OUTPUTS) == 4
    assert p.map is None and p.trial and p.commit and p.outputs
    out = op.outputs()
    sig = ref.signals()
    assert out.tolist() == [sig[k] for k in OUTPUTS]
    ref.cfg = ref.ode.cfg = type(ref.cfg)(**{**ref.cfg.__dict__, "coulomb": True})
    with pytest.raises(ValueError, match="coulomb = True"):
        OdePort(ref)


def test_a_struct_layout_mismatch_is_refused():
    class Longer(ode_port._State):
        _fields_ = [("extra", ctypes.c_double)]

    size = ctypes.sizeof(ode_port._State)
    decl = native.Declaration(ode_port.DECLARATION.source, "mbs_panto_ode_abi", ode_port.ABI,
                              structs=(native.CStruct(Longer, "mbs_panto_ode_size"),))
    with pytest.raises(native.NativeBuildError, match=f"returns {size} bytes.*is {size + 8} bytes"):
        native.bind(decl)
    with pytest.raises(native.NativeBuildError, match=f"returns ABI {ode_port.ABI}"):
        native.bind(native.Declaration(ode_port.DECLARATION.source, "mbs_panto_ode_abi", ode_port.ABI + 1))
