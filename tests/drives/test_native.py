"""The MuJoCo path's native stepper (`native/rotors.c` in the native core) against its Python twin and the event-exact
hand path; threads; a chattering state machine; bad input; the step objects of both paths."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.components.rotational.event_exact import ReferenceSimulator, simulate_reference
from mbsuite.components.rotational.interfaces import Friction, Part, RotorSystem, Source
from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
from mbsuite.engines.inputs import Pulse, Step
from mbsuite.errors import ParameterError, SceneError, SolverError
from mbsuite.models.drives import drive
from mbsuite.models.drives.analysis import simulate_scene
from mbsuite.models.rotational import coupled_clutches as cc
from mbsuite.paths import mjcf_path
from mbsuite.scenes import load_scene

DT = 1e-4


def _cc(stepper="native"):
    sim = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=DT)
    return sim.run(cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4, stepper=stepper)


def _rotors(frictions, J, sources=(), springs=()):
    return RotorSystem(names=["motor", "spring", "load"], J=np.asarray(J, float), B=np.zeros(3),
                       frictions=list(frictions), sources=list(sources), springs=list(springs))


def _same(a, b, t_tol=1e-12, w_tol=1e-9):
    """Same event sequence (times within t_tol), same recorded grid, states and energy terms within w_tol."""
    assert [(e["element"], e["from"], e["to"]) for e in a.events] == [(e["element"], e["from"], e["to"])
                                                                      for e in b.events]
    for x, y in zip(a.events, b.events, strict=True):
        assert abs(x["t"] - y["t"]) <= t_tol and x["t_step"] == y["t_step"], (x, y)
    assert np.array_equal(a.t, b.t) and np.array_equal(a.modes, b.modes)
    np.testing.assert_allclose(a.w, b.w, rtol=0, atol=w_tol)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=w_tol)
    for k in a.energy:
        np.testing.assert_allclose(a.energy[k], b.energy[k], rtol=1e-9, atol=1e-12, err_msg=k)
    assert a.stats["lock_trials"] == b.stats["lock_trials"]


@pytest.fixture(scope="module")
def cc_native():
    return _cc()


def test_native_events_against_the_hand_path_on_coupled_clutches(cc_native):
    """The mode changes of the native stepper against the event-exact hand path (DOP853, events by root finding): the
    same sequence, every change within one MuJoCo step (measured max 4.7e-5 s, a break, detected at the step after
    the lock torque passes breakaway; locks interpolated within the step 2.1e-5 s, the one after that late break;
    bound 1e-4 s, 2.1x); and the energy balance over the run: source work = slip losses + lock impact + kinetic
    energy (measured 1.2e-11 of the turnover; bound 1e-10, 8.1x)."""
    hand = simulate_reference(cc.build_system(), cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    seq = [(e["element"], e["from"], e["to"]) for e in cc_native.events]
    assert len(seq) == 9 and seq == [(e["element"], e["from"], e["to"]) for e in hand.events]
    for e, h in zip(cc_native.events, hand.events, strict=True):
        assert abs(e["t"] - h["t"]) < DT, (e, h)
        assert 0.0 <= e["t_step"] - e["t"] <= DT  # interpolated within the step at which the change is applied
    bal = drive.energy_balance(cc.build_system(), cc_native)
    assert abs(bal.relative) < 1e-10, bal
    assert cc_native.stats["warnings"] == {} and cc_native.stats["steps"] == 15000


def test_native_equals_python_twin_coupled_clutches(cc_native):
    _same(cc_native, _cc("python"))


def test_native_equals_python_twin_drive_with_controller():
    """A step-up drive with its PWM controller (brake, clutch, bearings, the command queue): both steppers."""
    sc = load_scene("drives/step_up_pwm")
    p = sc.build_params().resolved("table_4_2")
    eff = dict(sc.effects)
    system = drive.build_system("step_up", p, eff)
    out = {}
    for stepper in ("native", "python"):
        ctrl = drive.build_controller("step_up", "pwm", p, eff, ref=287.0)
        sim = MujocoRotorSim(system, mjcf_path("drive_step_up"), timestep=DT)
        out[stepper] = sim.run(np.zeros(3), np.zeros(3), 0.5, controller=ctrl, sample_dt=2e-3, stepper=stepper)
    a, b = out["native"], out["python"]
    _same(a, b)
    assert len(a.events) >= 10 and a.stats["lock_trials"] >= 5
    assert abs(drive.energy_balance(system, a).relative) < 2e-7  # measured 2.2e-8: 9x
    for c in a.u:
        assert np.array_equal(a.u[c], b.u[c])


class _Toggle:
    """A controller engaging a clutch at every other sample (period `dt`), for a period longer than a core chunk."""

    def __init__(self, dt):
        self.dt = dt
        self.log = []

    def __call__(self, k, t, q, w):
        self.log.append((k, t))
        return {"ca": 1 - k % 2}


def test_long_controller_period_in_chunks():
    """A controller period of 5000 steps (more than a chunk of the core): sampled at the right steps, the native
    stepper equal to the twin; a clutch engaging on a driven motor every other 0.5 s."""
    sys_ = _rotors([Friction("clutch_a", 0, 1, [Part("ca", 0.2, command="ca")])], [1e-3, 2e-3, 1.0],
                   sources=[Source("motor", 0, 0.1, -1e-3)])
    out = {}
    for stepper in ("native", "python"):
        ctrl = _Toggle(0.5)
        out[stepper] = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT).run(
            [0, 0, 0], [0, 0, 0], 2.0, controller=ctrl, sample_dt=1e-2, stepper=stepper)
        assert [k for k, _ in ctrl.log] == [0, 1, 2, 3]
    _same(out["native"], out["python"])
    ev = [(e["element"], e["to"]) for e in out["native"].events]
    assert ("clutch_a", "stuck") in ev and ("clutch_a", "free") in ev
    assert np.array_equal(out["native"].u["ca"][::50], [1, 0, 1, 0, 0])  # no sample at t_end (as the hand path)


def test_callable_schedule_is_tabulated_on_the_half_step_grid():
    """An arbitrary callable (here the brake step of the nested-locks case) gives the results of the equal signal:
    the table holds its values at every instant the state machine evaluates it."""

    def brake(t: float) -> float:
        return 1.0 if t >= 0.3 else 0.0

    res = {}
    for name, sched in (("callable", brake), ("signal", Step(height=1.0, t0=0.3))):
        sys_ = _rotors([Friction("clutch_a", 0, 1, [Part("ca", 0.5)]), Friction("clutch_b", 1, 2, [Part("cb", 0.5)]),
                        Friction("spring_ground", 1, -1, [Part("brake", 0.3, schedule=sched)])], [1e-3, 2e-3, 3e-3])
        res[name] = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT).run(
            [0, 0, 0], [30.0, 10.0, 0.0], 0.6, sample_dt=1e-3)
    _same(res["callable"], res["signal"], t_tol=0.0, w_tol=0.0)
    assert res["signal"].modes[:, -1].tolist() == [0, 0, 0]


def test_output_grid_as_before():
    """Rows at every `sample_dt` from 0 with t = step x dt; a final state off the grid is not recorded."""
    for stepper in ("native", "python"):
        sim = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=DT)
        r = sim.run(cc.Q0, cc.W0, 0.1005, sample_dt=1e-3, stepper=stepper)
        assert r.t.size == 101 and np.array_equal(r.t, np.arange(101) * 10 * DT)
        assert r.w.shape == (4, 101) and all(v.size == 101 for v in r.energy.values())


@pytest.mark.parametrize("stepper", ["native", "python"])
def test_chattering_state_machine_is_a_clear_error(stepper):
    """A source torque reversing every two steps above the breakaway torque: the bearing locks and breaks at the step
    rate; the run stops with a SolverError naming the element and the time (not NaN, not a silent result)."""
    sys_ = _rotors([Friction("motor_ground", 0, -1, [Part("bearing", 0.5)])], [1e-3, 1.0, 1.0],
                   sources=[Source("motor", 0, 1.0, shape=Pulse(amplitude=2.0, offset=-1.0, width=0.5,
                                                                period=4 * DT))])
    sim = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT)
    with pytest.raises(SolverError, match=r"does not settle: friction element 'motor_ground'.*at t = 0\.0035 s"):
        sim.run([0, 0, 0], [0, 0, 0], 0.05, sample_dt=1e-3, stepper=stepper)
    # the same torque reversing every 10 steps is resolved (stick/slip at the forcing rate, no error)
    sys_.sources[0].shape = Pulse(amplitude=2.0, offset=-1.0, width=0.5, period=20 * DT)
    r = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT).run([0, 0, 0], [0, 0, 0], 0.05,
                                                                              sample_dt=1e-3, stepper=stepper)
    assert len(r.events) > 40 and np.all(np.isfinite(r.w))


def test_bad_input_named():
    sys_ = _rotors([Friction("clutch_a", 0, 1, [Part("ca", 0.5, schedule=lambda t: np.nan if t > 0.01 else 1.0)])],
                   [1e-3, 1e-3, 1.0])
    sim = MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT)
    with pytest.raises(ParameterError, match=r"schedule of friction part 'ca' is not finite at t = 0\.01"):
        sim.run([0, 0, 0], [1, 0, 0], 0.05)
    sys_.frictions[0].parts[0].schedule = "on"
    with pytest.raises(ParameterError, match="schedule of friction part 'ca' must be a signal"):
        sim.run([0, 0, 0], [1, 0, 0], 0.05)
    sys_.frictions[0].parts[0].schedule = None
    sys_.sources.append(Source("motor", 0, 1.0, shape=lambda t: float("inf")))
    with pytest.raises(ParameterError, match="shape of torque source 'motor' is not finite"):
        MujocoRotorSim(sys_, mjcf_path("drive_step_up_down"), timestep=DT).run([0, 0, 0], [1, 0, 0], 0.05)
    sys_.sources.pop()
    with pytest.raises(ParameterError, match="initial speeds w0 must be 3 finite numbers"):
        sim.run([0, 0, 0], [1, np.nan, 0], 0.05)
    with pytest.raises(ParameterError, match="initial positions q0 must be 3"):
        sim.run([0, 0], [1, 0, 0], 0.05)
    with pytest.raises(SceneError, match="duration"):
        sim.run([0, 0, 0], [1, 0, 0], -1.0)
    with pytest.raises(ValueError, match="unknown stepper"):
        sim.run([0, 0, 0], [1, 0, 0], 0.05, stepper="fortran")
    with pytest.raises(SceneError, match="must divide"):
        simulate_scene(load_scene("drives/step_up_pwm").replace(solver={"engine": "mujoco", "timestep": 3e-4}))


def test_rotor_stepper_step_and_advance():
    """The Python twin as a step object: advancing in pieces (and single steps) is the run in one go."""
    from mbsuite.components.rotational.rotor_run import RotorRun
    from mbsuite.components.rotational.stepper import RotorStepper

    sim = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=DT)
    whole = sim.run(cc.Q0, cc.W0, 0.8, sample_dt=1e-3, stepper="python")
    st = RotorStepper(RotorRun(sim, cc.Q0, cc.W0, 0.8, sample_dt=1e-3))
    st.run(0.3)
    assert st.k == 3000
    st.step()
    st.run(0.71)
    res = st.run(0.8).result()
    _same(res, whole, t_tol=0.0, w_tol=0.0)


def test_reference_simulator_step_object():
    """The hand path's step object: one solver step at a time / run in pieces = simulate_reference."""
    sys_ = cc.build_system()
    whole = simulate_reference(sys_, cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    sim = ReferenceSimulator(sys_, cc.Q0, cc.W0, cc.T_END, sample_dt=5e-4)
    for _ in range(5):
        sim.step()
    assert 0.0 < sim.t < 0.4 and sim.solver is not None
    sim.run(0.75)
    assert 0.75 <= sim.t and [e["to"] for e in sim.events] == ["backward", "stuck", "stuck"][:len(sim.events)]
    res = sim.run(cc.T_END).result()
    assert sim.done and res.events == whole.events and np.array_equal(res.w, whole.w)
    assert res.stats == whole.stats


def test_step_objects_meet_the_protocol():
    """The hand path's `ReferenceSimulator` and the Python twin `RotorStepper` are `mbsuite.stepping.StepObject`s;
    `run(t_end)` steps to t_end and `status` says when the run is finished."""
    from mbsuite.components.rotational.rotor_run import RotorRun
    from mbsuite.components.rotational.stepper import RotorStepper
    from mbsuite.stepping import StepObject

    ref = ReferenceSimulator(cc.build_system(), cc.Q0, cc.W0, 0.2, sample_dt=5e-4)
    sim = MujocoRotorSim(cc.build_system(), mjcf_path("coupled_clutches"), timestep=DT)
    twin = RotorStepper(RotorRun(sim, cc.Q0, cc.W0, 0.2, sample_dt=1e-3))
    for obj in (ref, twin):
        assert isinstance(obj, StepObject)
        assert obj.status == "running" and obj.t == 0.0
        obj.run(0.1)
        assert obj.t >= 0.1 - 1e-12 and obj.status == "running"
        obj.run(0.2)
        assert obj.status == "finished"
