"""The one sweep API: local processes, a Dask LocalCluster, mujoco.rollout, streaming to disk and resume."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import mujoco
import numpy as np
import pytest

from mbsuite import load_scene
from mbsuite.analysis.sweep import (
    SweepStore,
    get_state,
    point_key,
    rollout_sweep,
    run_sweep,
    scene_point,
    sweep_options,
)
from mbsuite.engines.mujoco_engine import callbacks
from mbsuite.errors import SceneError

ROOT = Path(__file__).resolve().parents[2]


def _jobs(n: int = 4) -> list:
    """Short pantograph runs at different frequencies (MuJoCo path with its engine plugins)."""
    sc = load_scene("pantograph").replace(solver={"duration": 0.3, "t_settle": 0.0})
    return [(sc.to_dict(), {"input": {"frequency": 2.0 + 1.5 * i}}) for i in range(n)]


def test_local_pool_equals_serial_and_keeps_order():
    jobs = _jobs()
    serial = run_sweep(scene_point, jobs, workers=1)
    pooled = run_sweep(scene_point, jobs, workers=2)
    assert pooled == serial  # bit-identical, in the order of the points
    f1max = [r["signals"]["F1"]["max"] for r in serial]
    assert len(set(f1max)) == len(f1max)  # the points really differ (no accidental caching)


def test_threads_equal_serial_and_keep_order():
    """The thread executor (native-core runs release the GIL): bit-identical to one worker, in order."""
    jobs = _jobs()
    assert run_sweep(scene_point, jobs, workers=2, executor="threads") == run_sweep(scene_point, jobs, workers=1)


def test_pantograph_frequency_sweep_threads_and_rollout_identical_to_one_thread():
    """The MuJoCo frequency sweep in C threads equals one thread; mujoco.rollout runs the same plugin model with 1 or 2
    threads to identical states."""
    from mbsuite.models.pantograph.analysis import mujoco_sweep
    from mbsuite.models.pantograph.mujoco import MujocoPantograph

    sc = load_scene("pantograph").replace(solver={"duration": 0.6, "t_settle": 0.1})
    freqs = np.array([2.0, 5.0, 9.0, 14.0])
    one, two = mujoco_sweep(sc, freqs, workers=1), mujoco_sweep(sc, freqs, workers=2)
    assert [r["F1"] for r in one] == [r["F1"] for r in two] and len({r["F1"] for r in one}) == 4
    mp = MujocoPantograph(sc.build_params(), None, "rk4", 1e-3)
    mp.set_static(mp.equilibrium(), mp.p.y_op)
    x0 = np.tile(get_state(mp.model, mp.data), (4, 1))
    t = (np.arange(600) + 0.5) * 1e-3
    ctrl = np.zeros((4, 600, mp.model.nu))
    ctrl[:, :, 0] = 1.58 + 1.85e-3 * (1 - np.cos(2 * np.pi * freqs[:, None] * t[None, :]))
    s1, _ = rollout_sweep(mp.model, x0, ctrl, workers=1)
    s2, _ = rollout_sweep(mp.model, x0, ctrl, workers=2)
    assert np.array_equal(s1, s2) and np.all(np.isfinite(s1))


def test_dask_localcluster_identical_to_local(tmp_path):
    distributed = pytest.importorskip("distributed")
    jobs = _jobs()
    local = run_sweep(scene_point, jobs, workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  local_directory=str(tmp_path)) as cluster:
        via_addr = run_sweep(scene_point, jobs, executor="dask", scheduler=cluster.scheduler_address)
        with sweep_options(executor="dask", scheduler=cluster.scheduler_address):
            via_default = run_sweep(scene_point, jobs)  # how the CLI's --executor dask reaches analysis hooks
    assert via_addr == local
    assert via_default == local


def test_dask_executor_needs_a_scheduler_and_unknown_executor_is_an_error():
    with pytest.raises(SceneError, match="scheduler"):
        run_sweep(scene_point, _jobs(1), executor="dask")
    with pytest.raises(SceneError, match="valid"):
        run_sweep(scene_point, _jobs(1), executor="spark")


def _square(x: int) -> int:
    if x == 5:
        raise RuntimeError("point 5 fails")
    return x * x


def _cube(x: int) -> int:
    return x ** 3


def test_store_streams_each_point_and_resume_skips_finished(tmp_path):
    store = tmp_path / "s.jsonl"
    with pytest.raises(RuntimeError, match="point 5"):
        run_sweep(_square, list(range(8)), workers=1, store=store)
    done = SweepStore(store).load()
    assert len(done) == 5  # points 0..4 were streamed before the failure
    lines = [json.loads(x) for x in store.read_text().splitlines()]
    assert [r["result"] for r in lines] == [0, 1, 4, 9, 16] and [r["point"] for r in lines] == [0, 1, 2, 3, 4]
    # a store written for another function is not reused (the key includes the function)
    assert point_key(_square, 3) != point_key(_cube, 3)
    assert run_sweep(_cube, [0, 1, 2, 3], workers=1, store=store) == [0, 1, 8, 27]


def test_pool_failure_keeps_finished_points(tmp_path):
    store = tmp_path / "p.jsonl"
    with pytest.raises(RuntimeError, match="point 5"):
        run_sweep(_square, list(range(8)), workers=2, store=store)
    keys = set(SweepStore(store).load())
    assert point_key(_square, 5) not in keys and len(keys) >= 1


SCRIPT = textwrap.dedent("""
    import os, signal, sys
    from mbsuite.analysis.sweep import run_sweep

    def slow(x):
        with open(os.environ["CALLS"], "a") as fh:
            fh.write(f"{x}\\n")
        if os.environ.get("CRASH") and x == 6:
            os.kill(os.getpid(), signal.SIGKILL)   # a hard crash: no cleanup, no exception handling
        return {"x": x, "y": [x * 0.1, x ** 0.5]}

    res = run_sweep(slow, list(range(10)), workers=1, store=sys.argv[1])
    print(repr(res))
""")


def test_killed_sweep_resumes_without_recomputing(tmp_path):
    script = tmp_path / "sweep_script.py"
    script.write_text(SCRIPT)
    store, calls = tmp_path / "store.jsonl", tmp_path / "calls.txt"
    env = {**os.environ, "CALLS": str(calls), "CRASH": "1"}
    p = subprocess.run([sys.executable, str(script), str(store)], env=env, capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == -9  # killed
    assert calls.read_text().split() == [str(i) for i in range(7)]
    with store.open("a") as fh:  # the crash may also leave a torn line behind
        fh.write('{"key": "abc", "pick')
    env.pop("CRASH")
    calls.write_text("")
    p = subprocess.run([sys.executable, str(script), str(store)], env=env, capture_output=True, text=True, cwd=ROOT)
    assert p.returncode == 0, p.stderr
    assert calls.read_text().split() == ["6", "7", "8", "9"]  # only the unfinished points ran
    expect = [{"x": x, "y": [x * 0.1, x ** 0.5]} for x in range(10)]
    assert eval(p.stdout) == expect  # noqa: S307 - our own repr of plain data


PENDULUM = """<mujoco><option timestep="0.002" integrator="RK4"/><worldbody><body><joint name="j" type="hinge"
axis="0 1 0" damping="0.05"/><geom type="capsule" fromto="0 0 0 0 0 -1" size="0.03"/></body></worldbody>
<actuator><motor joint="j"/></actuator></mujoco>"""


def test_rollout_sweep_matches_python_loop_and_refuses_callbacks():
    m = mujoco.MjModel.from_xml_string(PENDULUM)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(1)
    n, steps = 6, 300
    x0 = []
    for q in rng.uniform(-1, 1, n):
        mujoco.mj_resetData(m, d)
        d.qpos[0] = q
        x0.append(get_state(m, d))
    ctrl = rng.uniform(-0.5, 0.5, (n, steps, 1))
    state, _ = rollout_sweep(m, np.array(x0), ctrl, workers=2)
    for b in (0, n - 1):
        mujoco.mj_resetData(m, d)
        mujoco.mj_setState(m, d, x0[b], mujoco.mjtState.mjSTATE_FULLPHYSICS)
        for k in range(steps):
            d.ctrl[0] = ctrl[b, k, 0]
            mujoco.mj_step(m, d)
        assert np.array_equal(state[b, -1], get_state(m, d))  # same C code, same arithmetic
    with callbacks(passive=lambda m, d: None), pytest.raises(SceneError, match="without Python callbacks"):
        rollout_sweep(m, np.array(x0), ctrl)
