"""Friction/clutch machinery: the CoupledClutches reference data, the closed-form early phase and event convergence,
a clutch below and above breakaway (both paths), bad input. CoupledClutches against Dymola on both paths is a hard
case of `mbsuite.models.rotational.cases`, the engagement loss, nested locks and the Coulomb load reversal are hard
cases of `mbsuite.models.drives.cases` (run by `tests/suite/test_hardcases.py`): one source of truth each."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.components.rotational.event_exact import simulate_reference
from mbsuite.components.rotational.interfaces import Friction, Part, RotorSystem, Source, Spring
from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
from mbsuite.errors import ParameterError
from mbsuite.models.rotational import coupled_clutches as cc
from mbsuite.paths import mjcf_path


@pytest.fixture(scope="module")
def ref():
    return cc.load_reference()


@pytest.fixture(scope="module")
def hand():
    return simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)


def test_reference_mode_sequence(ref):
    """The Dymola file itself: the mode sequence we compare against (MSL 4.1.0 CoupledClutches)."""
    ev = cc.reference_events(ref)
    seq = [(e["element"], e["from"], e["to"]) for e in ev]
    assert seq == [("clutch2", 2, -1), ("clutch2", -1, 0), ("clutch1", -1, 0), ("clutch1", 0, -1), ("clutch3", 2, -1),
                   ("clutch1", -1, 0), ("clutch1", 0, -1), ("clutch3", -1, 0), ("clutch1", -1, 2)]


@pytest.mark.literal_inputs("CoupledClutches speeds against the closed form of the literal constants to 2.5e-10 rad/s")
def test_hand_path_closed_form_and_event_precision(hand):
    """t < 0.4 s: only clutch 1 slides, closed form; events converge to <= 1e-9 s under tolerance refinement."""
    m = hand.t < 0.4
    # measured 2.5e-11 rad/s at the default rtol: bound 10x
    assert np.max(np.abs(hand.w[:2, m] - cc.closed_form_early(hand.t[m]))) < 2.5e-10
    fine = simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=1e-2, rtol=1e-12, atol=1e-14)
    t1 = [e["t"] for e in hand.events]
    t2 = [e["t"] for e in fine.events]
    assert len(t1) == len(t2) == 9
    assert max(abs(a - b) for a, b in zip(t1, t2, strict=True)) < 1e-9


def _two_rotors(J1, J2, tau, peak=1.0, drive=0.0, B=0.0):
    return RotorSystem(names=["motor", "spring", "load"], J=np.array([J1, J2, 1.0]), B=np.array([B, B, 0.0]),
                       frictions=[Friction("clutch_a", 0, 1, [Part("ca", tau)], peak=peak)],
                       sources=[Source("motor", 0, drive)])


def test_no_slip_below_breakaway_and_mujoco_creep():
    """A clutch loaded at 90 % of its breakaway torque: no slip (reference), bounded creep (MuJoCo lock). The hand
    path's locked pair moves as one group: its angles differ by rounding only (measured 0 with J0 = J1, 9.1e-13 rad
    over 1 s with J0, J1 moved apart by 1e-10; bound 1e-10 rad, against 0.5 rad in 0.05 s at 0.5 % above
    breakaway, `test_breakaway_threshold_is_sharp`)."""
    tau, peak = 1.0, 1.2
    # rotor 0 driven by 0.9 x breakaway x J0/(J0+J1) share: required clutch torque = 0.9 * peak * tau
    J0, J1 = 1e-3, 1e-3
    drive = 0.9 * peak * tau * (J0 + J1) / J1
    sys_ = _two_rotors(J0, J1, tau, peak=peak, drive=drive)
    res = simulate_reference(sys_, [0, 0, 0], [0, 0, 0], 1.0, sample_dt=1e-3)
    assert res.events == []
    assert np.max(np.abs(res.q[0] - res.q[1])) <= 1e-10  # no slip
    mj = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=1e-4).run([0, 0, 0], [0, 0, 0], 1.0,
                                                                                   sample_dt=1e-3)
    assert mj.events == []
    # soft equality: a constant offset (measured 8.6e-9 rad) and no drift - the offset at 0.5 s equals the one at
    # 1.0 s (measured 8.5e-14 rad, round-off), and the relative speed is zero (measured 1.6e-10 rad/s); a
    # frictionloss "lock" would creep through both. Bounds about 12x the measured values.
    off = mj.q[1] - mj.q[0]
    i05, i10 = int(np.argmin(np.abs(mj.t - 0.5))), mj.t.size - 1
    assert mj.t[i10] == pytest.approx(1.0)
    assert abs(off[i10]) < 1e-7
    assert abs(off[i10] - off[i05]) < 1e-12, (off[i05], off[i10])
    assert np.max(np.abs(mj.w[1, i05:] - mj.w[0, i05:])) < 2e-9
    print(f"MuJoCo lock: offset {off[i10]:.3g} rad, drift 0.5->1 s {off[i10] - off[i05]:.2g} rad, "
          f"max rel. speed {np.max(np.abs(mj.w[1, i05:] - mj.w[0, i05:])):.2g} rad/s")
    # above breakaway it slips at once, at the sliding torque tau: closed form slip q0 - q1 = 1/2 (a0 - a1) t^2 with
    # a0 = (drive - tau)/J0, a1 = tau/J1 (measured 1.1e-14 relative over the record, at its first samples: bound
    # 1e-13, 9x)
    drive2 = 1.1 * peak * tau * (J0 + J1) / J1
    sys2 = _two_rotors(J0, J1, tau, peak=peak, drive=drive2)
    res2 = simulate_reference(sys2, [0, 0, 0], [0, 0, 0], 0.05, sample_dt=1e-3)
    assert res2.events == [] and np.all(res2.modes[0] == -1)  # sliding backward (w_rel = w1 - w0 < 0) from t = 0
    J0, J1 = sys2.J[:2]  # the system the run used (in the perturbed tests: its perturbed coefficients)
    tau, drive2 = sys2.frictions[0].parts[0].level, sys2.sources[0].c0
    slip = 0.5 * ((drive2 - tau) / J0 - tau / J1) * res2.t**2
    np.testing.assert_allclose(res2.q[0] - res2.q[1], slip, rtol=1e-13, atol=0.0)


def test_bad_input():
    with pytest.raises(ParameterError, match="inertia"):
        _two_rotors(-1e-3, 1e-3, 1.0)
    with pytest.raises(ParameterError, match="spring rate"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), springs=[Spring("k", 0, -1, 0.0)])
    with pytest.raises(ParameterError, match="breakaway"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), frictions=[Friction("f", 0, -1, [Part("p", 1)], 0.5)])
    with pytest.raises(ParameterError, match="friction torque"):
        RotorSystem(names=["a"], J=np.ones(1), B=np.zeros(1), frictions=[Friction("f", 0, -1, [Part("p", -1.0)])])


@pytest.mark.parametrize("factor, slips", [(0.995, False), (1.005, True)])
def test_breakaway_threshold_is_sharp(factor, slips):
    """The lock holds up to its breakaway torque peak x tau and not beyond: at 0.5 % below it the hand path never
    slips, at 0.5 % above it slips from t = 0 (a breakaway bound off by 1 % is caught either way)."""
    tau, peak = 1.0, 1.2
    J0, J1 = 1e-3, 1e-3
    drive = factor * peak * tau * (J0 + J1) / J1  # the clutch must carry factor x breakaway to hold
    sys_ = _two_rotors(J0, J1, tau, peak=peak, drive=drive)
    res = simulate_reference(sys_, [0, 0, 0], [0, 0, 0], 0.05, sample_dt=1e-3)
    slip = np.max(np.abs(res.q[0] - res.q[1]))
    if slips:
        # sliding from t = 0 at the sliding torque tau: q0 - q1 = 1/2 (a0 - a1) t^2 (closed form of the system the
        # run used: its inertias, torque and drive; measured 1.1e-14 relative: bound 1e-13, 9x)
        J0, J1 = sys_.J[:2]
        tau, drive = sys_.frictions[0].parts[0].level, sys_.sources[0].c0
        expected = 0.5 * ((drive - tau) / J0 - tau / J1) * res.t**2
        np.testing.assert_allclose(res.q[0] - res.q[1], expected, rtol=1e-13, atol=0.0)
    else:
        assert res.events == [] and slip <= 1e-10  # rounding only (test_no_slip_below_breakaway_and_mujoco_creep)
