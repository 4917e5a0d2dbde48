"""Friction/clutch machinery: CoupledClutches vs the Modelica reference, analytic checks, hard cases (both paths)."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.errors import ParameterError
from mbsuite.models.drives import coupled_clutches as cc
from mbsuite.models.drives.friction import Friction, Part, RotorSystem, Source, Spring, simulate_reference
from mbsuite.models.drives.mujoco_path import MujocoRotorSim
from mbsuite.paths import mjcf_path

DT_MJ = 1e-4


@pytest.fixture(scope="module")
def ref():
    return cc.load_reference()


@pytest.fixture(scope="module")
def hand():
    return simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)


@pytest.fixture(scope="module")
def mj():
    sim = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=DT_MJ)
    return sim.run(cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)


def _rows(res, ref):
    return cc.match_events(cc.events_as_codes(res.events), cc.reference_events(ref))


def test_reference_mode_sequence(ref):
    """The Dymola file itself: the mode sequence we compare against (MSL 4.1.0 CoupledClutches)."""
    ev = cc.reference_events(ref)
    seq = [(e["element"], e["from"], e["to"]) for e in ev]
    assert seq == [("clutch2", 2, -1), ("clutch2", -1, 0), ("clutch1", -1, 0), ("clutch1", 0, -1), ("clutch3", 2, -1),
                   ("clutch1", -1, 0), ("clutch1", 0, -1), ("clutch3", -1, 0), ("clutch1", -1, 2)]


def test_hand_path_matches_dymola(hand, ref):
    rows = _rows(hand, ref)
    assert all(r["t"] is not None and r["t_ref"] is not None for r in rows), rows  # identical mode sequence
    dt = max(abs(r["t"] - r["t_ref"]) for r in rows)
    assert dt < 1e-5  # README: "a few microseconds in lock times" (DASSL tol 1e-6); we see <= 4.1e-6 s
    grid = np.round(np.arange(0, 1.5 + 1e-9, 0.1), 10)
    for tt in grid:
        i = int(np.argmin(np.abs(hand.t - tt)))
        j = int(np.nonzero(np.isclose(ref["t"], tt))[0][-1])
        assert np.max(np.abs(hand.w[:, i] - ref["w"][:, j])) < 1e-4  # reference accuracy ~1e-5 .. 6e-5


def test_hand_path_closed_form_and_event_precision(hand):
    """t < 0.4 s: only clutch 1 slides, closed form; events converge to <= 1e-9 s under tolerance refinement."""
    m = hand.t < 0.4
    assert np.max(np.abs(hand.w[:2, m] - cc.closed_form_early(hand.t[m]))) < 1e-8
    fine = simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=1e-2, rtol=1e-12, atol=1e-14)
    t1 = [e["t"] for e in hand.events]
    t2 = [e["t"] for e in fine.events]
    assert len(t1) == len(t2) == 9
    assert max(abs(a - b) for a, b in zip(t1, t2, strict=True)) < 1e-9


def test_mujoco_path_matches(mj, hand, ref):
    rows = _rows(mj, ref)
    assert all(r["t"] is not None and r["t_ref"] is not None for r in rows), rows
    # event times (interpolated within the step) within one timestep of the event-exact solution
    for a, b in zip(mj.events, hand.events, strict=True):
        assert (a["element"], a["from"], a["to"]) == (b["element"], b["from"], b["to"])
        assert abs(a["t"] - b["t"]) < DT_MJ
        assert abs(a["t_step"] - b["t"]) < 2 * DT_MJ  # the step at which the lock/release is applied
    i = [int(np.argmin(np.abs(hand.t - tt))) for tt in np.arange(0, 1.5 + 1e-9, 0.1)]
    assert np.max(np.abs(mj.w[:, i] - hand.w[:, i])) < 5e-4
    assert not mj.stats["warnings"]


def _two_rotors(J1, J2, tau, peak=1.0, drive=0.0, B=0.0):
    return RotorSystem(names=["motor", "spring", "load"], J=np.array([J1, J2, 1.0]), B=np.array([B, B, 0.0]),
                       frictions=[Friction("clutch_a", 0, 1, [Part("ca", tau)], peak=peak)],
                       sources=[Source("motor", 0, drive)])


@pytest.mark.parametrize("engine", ["reference", "mujoco"])
def test_engagement_dissipation_analytic(engine):
    """Free two-inertia engagement: slip loss = 1/2 J1 J2/(J1+J2) dw^2 (within 1 %), common speed by momentum."""
    J1, J2, dw = 2e-3, 5e-4, 50.0
    sys_ = _two_rotors(J1, J2, 0.5)
    w0 = [dw, 0.0, 0.0]
    if engine == "reference":
        res = simulate_reference(sys_, [0, 0, 0], w0, 0.2, sample_dt=1e-3)
        reset = res.stats["reset_energy"]
    else:
        res = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-5).run([0, 0, 0], w0, 0.2,
                                                                                        sample_dt=1e-3)
        reset = res.stats["reset_energy"]
    expected = 0.5 * J1 * J2 / (J1 + J2) * dw**2
    lost = res.energy["ca"][-1] + reset
    assert abs(lost - expected) < 0.01 * expected
    if engine == "reference":
        assert abs(lost - expected) < 1e-9 * expected  # event-exact: 4e-11 relative (README)
    assert np.allclose(res.w[:2, -1], J1 * dw / (J1 + J2), rtol=1e-4)
    assert [e["to"] for e in res.events] == ["stuck"]


def test_no_slip_below_breakaway_and_mujoco_creep():
    """A clutch loaded at 90 % of its breakaway torque: zero slip (reference), bounded creep (MuJoCo lock)."""
    tau, peak = 1.0, 1.2
    # rotor 0 driven by 0.9 x breakaway x J0/(J0+J1) share: required clutch torque = 0.9 * peak * tau
    J0, J1 = 1e-3, 1e-3
    drive = 0.9 * peak * tau * (J0 + J1) / J1
    sys_ = _two_rotors(J0, J1, tau, peak=peak, drive=drive)
    res = simulate_reference(sys_, [0, 0, 0], [0, 0, 0], 1.0, sample_dt=1e-3)
    assert res.events == []
    assert np.max(np.abs(res.q[0] - res.q[1])) == 0.0  # exactly no slip
    mj = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-4).run([0, 0, 0], [0, 0, 0], 1.0,
                                                                                   sample_dt=1e-3)
    assert mj.events == []
    # soft equality: a constant offset ~ torque x timeconst^2 / J (README: 8.6e-9 rad) and no drift - the offset at
    # 0.5 s equals the one at 1.0 s, and the relative speed is zero (a frictionloss "lock" would creep through both)
    off = mj.q[1] - mj.q[0]
    i05, i10 = int(np.argmin(np.abs(mj.t - 0.5))), mj.t.size - 1
    assert mj.t[i10] == pytest.approx(1.0)
    assert abs(off[i10]) < 1e-7
    assert abs(off[i10] - off[i05]) < 1e-10, (off[i05], off[i10])
    assert np.max(np.abs(mj.w[1, i05:] - mj.w[0, i05:])) < 1e-5
    print(f"MuJoCo lock: offset {off[i10]:.3g} rad, drift 0.5->1 s {off[i10] - off[i05]:.2g} rad, "
          f"max rel. speed {np.max(np.abs(mj.w[1, i05:] - mj.w[0, i05:])):.2g} rad/s")
    # above breakaway it slips at once
    sys2 = _two_rotors(J0, J1, tau, peak=peak, drive=1.1 * peak * tau * (J0 + J1) / J1)
    res2 = simulate_reference(sys2, [0, 0, 0], [0, 0, 0], 0.05, sample_dt=1e-3)
    assert res2.modes[0, 1] in (-1, 1) and abs(res2.q[1, -1] - res2.q[0, -1]) > 1e-3


def test_nested_locks_three_rotors():
    """Both clutches lock (three rotors one rigid group), then the brake holds the group: nested locks."""
    sys_ = RotorSystem(
        names=["motor", "spring", "load"], J=np.array([1e-3, 2e-3, 3e-3]), B=np.zeros(3),
        frictions=[Friction("clutch_a", 0, 1, [Part("ca", 0.5)]), Friction("clutch_b", 1, 2, [Part("cb", 0.5)]),
                   Friction("spring_ground", 1, -1, [Part("brake", 0.3, schedule=lambda t: 1.0 if t >= 0.3 else 0.0)])],
        breaks=[0.3])
    w0 = [30.0, 10.0, 0.0]
    res = simulate_reference(sys_, [0, 0, 0], w0, 1.0, sample_dt=1e-3)
    stuck_a = [e["t"] for e in res.events if e["element"] == "clutch_a" and e["to"] == "stuck"]
    stuck_b = [e["t"] for e in res.events if e["element"] == "clutch_b" and e["to"] == "stuck"]
    assert stuck_a and stuck_b
    t_all = max(stuck_a[0], stuck_b[0])
    i = int(np.searchsorted(res.t, t_all + 1e-3))
    p0 = float(np.dot(sys_.J, w0))
    assert np.allclose(res.w[:, i], p0 / sys_.J.sum(), rtol=1e-9)  # one rigid group, momentum conserved
    # the brake (0.3 N m) decelerates the whole group at 0.3/6e-3 and holds it at rest: nested stuck set
    assert res.modes[:, -1].tolist() == [0, 0, 0]
    assert np.allclose(res.w[:, -1], 0.0, atol=1e-12)
    mj = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-4).run([0, 0, 0], w0, 1.0, sample_dt=1e-3)
    assert mj.modes[:, -1].tolist() == [0, 0, 0]
    assert np.all(np.abs(mj.w[:, -1]) < 1e-6)
    for el in ("clutch_a", "clutch_b", "spring_ground"):
        t_r = [e["t"] for e in res.events if e["element"] == el]
        t_m = [e["t"] for e in mj.events if e["element"] == el]
        assert len(t_r) == len(t_m)
        assert np.allclose(t_r, t_m, atol=1e-4)


def test_coulomb_load_reversal_no_chatter_no_stall():
    """A load on a spring under Coulomb friction reverses direction repeatedly: one event per reversal, it sticks
    for good once the spring torque falls below the friction level, and the integrator does not stall."""
    sys_ = RotorSystem(names=["motor", "spring", "load"], J=np.array([1.0, 1.0, 1e-3]), B=np.zeros(3),
                       springs=[Spring("k", 2, -1, 1.0)],
                       frictions=[Friction("load_ground", 2, -1, [Part("load", 0.05, output=True)])])
    res = simulate_reference(sys_, [0, 0, 1.0], [0, 0, 0], 2.0, sample_dt=1e-3)
    kinds = [(e["from"], e["to"]) for e in res.events]
    # amplitude drops by 2 C/K = 0.1 rad per half cycle: 1.0 -> 0.9 -> ... -> stuck when |theta| < C/K = 0.05
    assert kinds[-1][1] == "stuck"
    n_rev = sum(1 for k in kinds if "stuck" not in k)
    assert n_rev == 9  # 1.0 -> 0.05 in 10 half cycles with 9 direction reversals, no chatter
    assert abs(res.q[2, -1]) <= 0.05 + 1e-12
    assert res.stats["nfev"] < 20000


def test_bad_input():
    with pytest.raises(ParameterError, match="inertia"):
        _two_rotors(-1e-3, 1e-3, 1.0)
    with pytest.raises(ParameterError, match="spring rate"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), springs=[Spring("k", 0, -1, 0.0)])
    with pytest.raises(ParameterError, match="breakaway"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), frictions=[Friction("f", 0, -1, [Part("p", 1)], 0.5)])
    with pytest.raises(ParameterError, match="friction torque"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), frictions=[Friction("f", 0, -1, [Part("p", -1.0)])])
