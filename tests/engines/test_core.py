"""The native step-and-record core: bitwise MuJoCo's own stepping, recording semantics, one error path for every
failure, no mixing between models in concurrent threads, and `mujoco.rollout` over mbsuite's plugin models."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from mujoco import rollout

import mbsuite
from mbsuite import SolverError
from mbsuite.engines import native
from mbsuite.engines.core import Channel, Stepper, map_threads, rows_for
from mbsuite.models.pantograph.equations import PantographConfig
from mbsuite.models.pantograph.modelfiles import mjcf_text
from mbsuite.models.pantograph.mujoco import compiled_model
from mbsuite.models.pantograph.params import PantographParams

PENDULUM = """<mujoco><option timestep="0.002"/><worldbody><body><joint name="j" type="hinge" axis="0 1 0"/>
<geom type="capsule" fromto="0 0 0 0 0 -1" size="0.05" mass="1"/></body></worldbody>
<actuator><motor joint="j"/></actuator></mujoco>"""


def _lab(integrator="rk4"):
    return compiled_model(PantographParams(), PantographConfig(), integrator, 1e-3)


def _start(m):
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    return d


def _ram(n, h, f=4.25):
    return 1.58 + 1.85e-3 * (1 - np.cos(2 * np.pi * f * (np.arange(n) + 0.5) * h))


@pytest.mark.parametrize("integrator", ["euler", "rk4", "implicit", "implicitfast", "discrete"])
def test_bitwise_equal_to_mj_step_and_rollout(integrator):
    """The core calls what mj_step calls: the trajectory of the lab pantograph (engine plugins, friction
    constraints) is bitwise that of a Python mj_step loop and of mujoco.rollout, for every integrator."""
    m = _lab(integrator)
    n = 600
    u = _ram(n, m.opt.timestep)
    d = _start(m)
    tr = Stepper(m, d, [Channel("q", "qpos", 0, 3), Channel("v", "qvel", 0, 3), Channel("P", "act", 0, 1)]).run(
        n, ctrl=u, ctrl_idx=[0])
    d2 = _start(m)
    ref = [np.r_[d2.qpos, d2.qvel, d2.act]]
    for k in range(n):
        d2.ctrl[0] = u[k]
        mujoco.mj_step(m, d2)
        ref.append(np.r_[d2.qpos, d2.qvel, d2.act])
    ref = np.array(ref)
    assert np.array_equal(np.hstack([tr["q"], tr["v"], tr["P"][:, None]]), ref)
    d3 = _start(m)
    x0 = np.zeros(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(m, d3, x0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.tile(d3.ctrl, (1, n, 1))
    ctrl[0, :, 0] = u
    state, _ = rollout.rollout(m, [mujoco.MjData(m) for _ in range(2)], x0[None], ctrl)
    assert np.array_equal(state[0, :, 1:1 + 7], ref[1:])  # rollout: time, qpos, qvel, act


def test_recording_rows_and_times():
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    d = mujoco.MjData(m)
    d.qpos[0] = 0.3
    for n, every in ((10, 1), (10, 3), (9, 3), (0, 5)):
        mujoco.mj_resetData(m, d)
        tr = Stepper(m, d, [Channel("q", "qpos")], every=every).run(n)
        expect = sorted(set(range(0, n + 1, every)) | {n})
        assert tr.t.size == rows_for(n, every) == len(expect)
        assert np.allclose(tr.t, np.array(expect) * m.opt.timestep, rtol=0, atol=1e-15)
        assert tr.steps == n


def test_python_input_between_steps_is_the_same_as_an_array():
    """A Python callable at a sample period (a discrete controller) gives the trajectory of the equivalent array."""
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    n, period = 500, 7
    u = np.repeat(np.sin(np.arange(n // period + 1)), period)[:n]
    d1 = mujoco.MjData(m)
    a = Stepper(m, d1, [Channel("q", "qpos")]).run(n, ctrl=u, ctrl_idx=[0])
    d2 = mujoco.MjData(m)

    def controller(k, data):
        data.ctrl[0] = u[k]

    b = Stepper(m, d2, [Channel("q", "qpos")]).run(n, between=controller, period=period)
    assert np.array_equal(a["q"], b["q"])


def test_non_finite_input_is_an_error_naming_the_time():
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    u = np.zeros(100)
    u[40] = np.nan
    with pytest.raises(SolverError, match=r"pendulum run: MuJoCo diverged \(warning badctrl.*at t = 0\.08"):
        Stepper(m, mujoco.MjData(m), [Channel("q", "qpos")], what="pendulum run", check_every=1).run(
            100, ctrl=u, ctrl_idx=[0])


def test_implausible_value_names_the_channel_and_bound():
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    d = mujoco.MjData(m)
    d.qpos[0] = 1.0
    with pytest.raises(SolverError, match=r"swing = -0\.\d+ is outside its plausible range \[-0\.5, 2\]"):
        Stepper(m, d, [Channel("swing", "qpos", 0, 1, lo=-0.5, hi=2.0)]).run(2000)


def test_plugin_fault_names_the_effect_and_time():
    """A native effect meeting a non-physical state stops the run with the effect's name, the fault and the time."""
    m = compiled_model(PantographParams(), PantographConfig(cylinder="nonlinear"), "rk4", 1e-3)
    d = _start(m)
    d.act[0] = -5.0  # a negative absolute pressure
    with pytest.raises(SolverError, match=r"effect 'cylinder': absolute cylinder pressure became <= 0 .*value -5"):
        Stepper(m, d, [Channel("q", "qpos", 0, 3)]).run(10, ctrl=np.full(10, 1.58), ctrl_idx=[0])


def test_plugin_configuration_fault_is_reported_at_the_first_step():
    native.load()
    text = mjcf_text(PantographParams()).replace('key="le" value="0.082"', 'key="le" value="3.0"')
    m = mujoco.MjModel.from_xml_string(text)
    with pytest.raises(SolverError, match=r"effect 'elbow': elbow chain has no tangent line.*found at load"):
        Stepper(m, _start(m)).run(1)
    text = mjcf_text(PantographParams()).replace('key="ke" value="44640.0"', 'key="ke" value="stiff"')
    m = mujoco.MjModel.from_xml_string(text)
    with pytest.raises(SolverError, match=r"effect 'elbow': a configuration attribute"):
        Stepper(m, _start(m)).run(1)


def test_bad_arguments_are_value_errors():
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    with pytest.raises(ValueError, match="unknown channel field"):
        Channel("x", "qacc_warmstart")
    with pytest.raises(ValueError, match="out of range"):
        Stepper(m, None, [Channel("q", "qpos", 0, 2)])
    with pytest.raises(ValueError, match="ctrl must have shape"):
        Stepper(m).run(10, ctrl=np.zeros(5), ctrl_idx=[0])


def test_map_threads_keeps_order_and_equals_serial():
    m = compiled_model(PantographParams(), PantographConfig(), "rk4", 1e-3)
    freqs = [2.0, 4.25, 8.5, 12.0]

    def point(f):
        d = _start(m)
        return Stepper(m, d, [Channel("q", "qpos", 0, 3)]).run(500, ctrl=_ram(500, 1e-3, f), ctrl_idx=[0])["q"]

    serial = [point(f) for f in freqs]
    threaded = map_threads(point, freqs, workers=2)
    assert all(np.array_equal(a, b) for a, b in zip(serial, threaded, strict=True))
    assert not all(np.array_equal(serial[0], s) for s in serial[1:])  # the inputs really differ
    assert math.isfinite(float(np.sum(threaded[-1])))


def test_divergence_is_reported_with_its_time_even_after_an_earlier_warning():
    """MuJoCo resets a broken state and restarts its warning counters: a data that already counted a warning must not
    hide the next divergence, and the error carries the time of the broken step (not the reset's t = 0)."""
    m = mbsuite.engines.mujoco_engine.load_model(
        PENDULUM.replace('<motor joint="j"/>', '<motor joint="j" gear="1e9"/>'), from_string=True)
    d = mujoco.MjData(m)
    d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number = 1  # counted by an earlier run of this data
    u = np.zeros(100)
    u[50:] = 1e9
    for record in (True, False):
        mujoco.mj_resetData(m, d)
        d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number = 1
        with pytest.raises(SolverError, match=r"diverged .* at t = 0\.1\d* s"):
            Stepper(m, d).run(100, ctrl=u, ctrl_idx=[0], record=record)


def test_configuration_faults_name_the_attribute_and_come_first():
    native.load()
    base = mjcf_text(PantographParams())
    cases = [(base.replace('key="lb" value="0.235"', 'key="lb" value="abc"'), "cylinder", "lb"),
             (base.replace('        <config key="l1" value="1.95"/>\n', ''), "elbow", "l1"),
             (base.replace('key="gamma" value="1.4"', 'key="gamma" value="2.5"'), "cylinder", "gamma")]
    assert all(c[0] != base for c in cases)
    for text, effect, attr in cases:
        m = mujoco.MjModel.from_xml_string(text)
        with pytest.raises(SolverError, match=rf"effect '{effect}': .*attribute '{attr}'.*configuration"):
            Stepper(m, _start(m)).run(5, ctrl=np.full(5, 1.58), ctrl_idx=[0])


def test_copying_data_keeps_plugin_state_without_leaking():
    m = _lab()
    src, dst = _start(m), mujoco.MjData(m)
    mujoco.mj_step(m, src)

    def rss() -> int:
        with open("/proc/self/statm") as fh:
            return int(fh.read().split()[1]) * 4096

    for _ in range(50_000):  # warm-up: the first copies grow the allocator's arenas once
        mujoco.mj_copyData(dst, m, src)
    before = rss()
    for _ in range(50_000):
        mujoco.mj_copyData(dst, m, src)
    assert rss() - before < 4e6  # measured 0; a copy that leaks its plugin blocks grows by ~17 MB here
    a = Stepper(m, src, [Channel("q", "qpos", 0, 3)]).run(50, ctrl=np.full(50, 1.58), ctrl_idx=[0])
    b = Stepper(m, dst, [Channel("q", "qpos", 0, 3)]).run(50, ctrl=np.full(50, 1.58), ctrl_idx=[0])
    assert np.array_equal(a["q"], b["q"])


def test_a_python_callback_in_the_process_is_refused():
    from mbsuite.engines.mujoco_engine import callbacks

    m = _lab()
    with callbacks(passive=lambda m_, d_: None), pytest.raises(SolverError, match="process-global"):
        Stepper(m, _start(m)).run(10, ctrl=np.full(10, 1.58), ctrl_idx=[0])


def test_rollout_reports_a_plugin_fault():
    from mbsuite.analysis.sweep import get_state, rollout_sweep

    m = compiled_model(PantographParams(), PantographConfig(cylinder="nonlinear"), "rk4", 1e-3)
    d = _start(m)
    d.act[0] = -5.0
    x0 = get_state(m, d)
    with pytest.raises(SolverError, match=r"effect 'cylinder': absolute cylinder pressure"):
        rollout_sweep(m, x0[None], np.full((1, 10, m.nu), 1.58), workers=1)


def test_recorded_times_are_exactly_the_step_grid():
    """Row times are t0 + k h exactly: MuJoCo's running sum of h drifts off the grid (by ~1e-13 s after 10^4 steps)
    and would move samples across a window boundary such as t >= t_settle."""
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    d = mujoco.MjData(m)
    tr = Stepper(m, d, [Channel("q", "qpos")]).run(20_000)
    assert np.array_equal(tr.t, np.arange(20_001) * m.opt.timestep)
    assert np.sum(tr.t >= 40.0) == 1 and np.sum(tr.t >= 20.0) == 10_001  # h = 2 ms


def test_a_run_longer_than_one_c_call_is_one_run(monkeypatch):
    """A long run is stepped in pieces (so Ctrl-C is honoured between C calls); the pieces make exactly the run of
    one call: same rows, same times, bitwise."""
    from mbsuite.engines import core

    m = _lab()
    n = 1000
    u = _ram(n, m.opt.timestep)
    chans = [Channel("q", "qpos", 0, 3), Channel("P", "act", 0, 1)]
    whole = Stepper(m, _start(m), chans, every=7).run(n, ctrl=u, ctrl_idx=[0])
    monkeypatch.setattr(core, "INTERRUPT_STEPS", 97)  # 11 pieces, none aligned with the recording period
    pieces = Stepper(m, _start(m), chans, every=7).run(n, ctrl=u, ctrl_idx=[0])
    assert np.array_equal(whole.t, pieces.t) and np.array_equal(whole["q"], pieces["q"])
    assert np.array_equal(whole["P"], pieces["P"]) and whole.steps == pieces.steps == n


@pytest.mark.parametrize("n, every", [(10, 3), (9, 3), (7, 1), (5, 8)])
def test_decimated_rows_hold_the_state_of_their_step(n, every):
    """Row j of a run recorded every `every` steps holds the state after k_j = j every steps (and the final state),
    each channel in its own columns: bitwise equal to a Python mj_step loop read at the same steps (the time column
    is the core's, never a channel's)."""
    m = mbsuite.engines.mujoco_engine.load_model(PENDULUM, from_string=True)
    d = mujoco.MjData(m)
    d.qpos[0], d.qvel[0] = 0.3, -1.2
    tr = Stepper(m, d, [Channel("q", "qpos"), Channel("v", "qvel"), Channel("u", "ctrl")], every=every).run(
        n, ctrl=np.linspace(0.5, 1.5, n), ctrl_idx=[0])
    d2 = mujoco.MjData(m)
    d2.qpos[0], d2.qvel[0] = 0.3, -1.2
    u = np.linspace(0.5, 1.5, n)
    rows = [(d2.qpos[0], d2.qvel[0], d2.ctrl[0])]
    for k in range(n):
        d2.ctrl[0] = u[k]
        mujoco.mj_step(m, d2)
        rows.append((d2.qpos[0], d2.qvel[0], d2.ctrl[0]))
    steps = sorted(set(range(0, n + 1, every)) | {n})
    want = np.array(rows)[steps]
    # the control recorded at step k is the input of step k (the final row keeps the last one applied)
    want[:-1, 2] = [u[k] for k in steps[:-1]]
    assert np.array_equal(tr["q"], want[:, 0]) and np.array_equal(tr["v"], want[:, 1])
    assert np.array_equal(tr["u"], want[:, 2])
    assert np.array_equal(tr.t, np.array(steps) * m.opt.timestep)
