"""The one sweep API: local processes, a Dask LocalCluster, mujoco.rollout, streaming to disk and resume."""

from __future__ import annotations

import functools
import itertools
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
    SweepOptions,
    SweepStore,
    check_grid,
    get_state,
    parse_values,
    point_key,
    rollout_sweep,
    run_sweep,
    scene_point,
)
from mbsuite.engines.mujoco_engine import callbacks
from mbsuite.errors import SceneError

ROOT = Path(__file__).resolve().parents[2]


def _jobs(n: int = 4) -> list:
    """Short pantograph runs at different frequencies (MuJoCo path with its engine plugins)."""
    sc = load_scene("pantograph").replace(solver={"duration": 0.3, "t_settle": 0.0})
    return [(sc.to_dict(), {"input": {"frequency": 2.0 + 1.5 * i}}) for i in range(n)]


def _logged_scene_point(calls: str, job: tuple[dict, dict]) -> dict:
    """`scene_point` that first appends the point's frequency to the file `calls` (one line per evaluation, from any
    process): the count of points a sweep really computed."""
    with open(calls, "a") as fh:
        fh.write(f"{job[1]['input']['frequency']}\n")
    return scene_point(job)


def _computed(calls: Path) -> list[float]:
    return sorted(float(x) for x in calls.read_text().split()) if calls.exists() else []


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
    from mbsuite.models.pantograph.freqresp import mujoco_sweep
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
    """The cluster's results equal the local pool's; with a store the cluster's workers (other processes) compute
    each point once, counted in a file each computation appends to, and a resumed sweep computes none."""
    distributed = pytest.importorskip("distributed")
    jobs = _jobs()
    local = run_sweep(scene_point, jobs, workers=2)
    calls, freqs = tmp_path / "calls.txt", sorted(job[1]["input"]["frequency"] for job in jobs)
    path = str(calls)

    def logged(job):
        """`_logged_scene_point` as a closure naming nothing of this module: Dask ships it by value (cloudpickle),
        as the workers cannot import the tests."""
        with open(path, "a") as fh:
            fh.write(f"{job[1]['input']['frequency']}\n")
        return scene_point(job)

    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  local_directory=str(tmp_path)) as cluster:
        store = tmp_path / "dask.jsonl"  # a store works with the cluster too: claims, results, resume
        via_addr = run_sweep(logged, jobs, executor="dask", scheduler=cluster.scheduler_address, store=store)
        assert _computed(calls) == freqs  # each point computed once, by the workers
        assert run_sweep(logged, jobs, executor="dask", scheduler=cluster.scheduler_address, store=store) == via_addr
        assert _computed(calls) == freqs  # the resumed sweep: every result from the store
        cli_options = SweepOptions(executor="dask", scheduler=cluster.scheduler_address)
        via_default = run_sweep(scene_point, jobs, options=cli_options)  # how the CLI's --executor dask reaches hooks
    assert via_addr == local
    assert via_default == local


def test_dask_executor_needs_a_scheduler_and_unknown_executor_is_an_error():
    with pytest.raises(SceneError, match="scheduler"):
        run_sweep(scene_point, _jobs(1), executor="dask")
    with pytest.raises(SceneError, match="valid"):
        run_sweep(scene_point, _jobs(1), executor="spark")


def test_sweep_options_are_checked_once_and_keyword_only():
    with pytest.raises(SceneError, match="scheduler"):
        SweepOptions(executor="dask")
    with pytest.raises(SceneError, match="valid"):
        SweepOptions(executor="spark")
    with pytest.raises(SceneError, match="max_points = 0 is invalid"):
        SweepOptions(max_points=0)
    with pytest.raises(TypeError):
        SweepOptions("local")  # the fields are keyword-only
    # a caller's preference wins, except that a preferred "threads" yields to a cluster the options ask for
    dask = SweepOptions(executor="dask", scheduler="tcp://127.0.0.1:8786")
    assert dask.executor_for(None) == "dask" and dask.executor_for("threads") == "dask"
    assert dask.executor_for("local") == "local"
    assert SweepOptions().executor_for(None) == "local"
    assert SweepOptions(executor="threads").executor_for(None) == "threads"


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
    lines = [json.loads(x)["body"] for x in store.read_text().splitlines()]
    assert lines[0] == {"type": "header", "format": "mbsuite-sweep-store", "version": 1}
    res = [r for r in lines if r["type"] == "result"]
    assert [r["result"] for r in res] == [0, 1, 4, 9, 16] and [r["point"] for r in res] == [0, 1, 2, 3, 4]
    assert [r["key"] for r in lines if r["type"] == "claim"] == [point_key(_square, x) for x in range(6)]
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


# ------------------------------------------------------------------------------------------------ sizes and values
def test_parse_values_lists_and_ranges_stop_included():
    assert parse_values("1:30:0.5") == [1.0 + 0.5 * i for i in range(59)]  # 1, 1.5, ..., 30
    assert parse_values("0:0.3:0.1") == [0.0, 0.1, 0.2, 0.3]  # stop reached up to rounding, printed decimals
    assert parse_values("2:2:1") == [2.0]
    assert parse_values("1e5, 2e5,true,linear") == [1e5, 2e5, True, "linear"]
    assert parse_values("1:3:1,10") == [1.0, 2.0, 3.0, 10.0]


@pytest.mark.parametrize(("text", "match"), [
    ("a:b:c", "range start 'a' is not a number"),
    ("1:b:1", "range stop 'b' is not a number"),
    ("1:2:0", "step 0 must be > 0"),
    ("1:2:-0.5", "step -0.5 must be > 0"),
    ("3:1:1", "stop 1 is below start 3"),
    ("1:inf:1", "not finite"),
    ("nan", "not finite"),
    ("1,-inf", "not finite"),
    ("1:2", "a range reads start:stop:step"),
    ("1,,2", "empty item"),
    ("", "empty"),
])
def test_parse_values_errors_name_the_text(text, match):
    with pytest.raises(SceneError, match=match) as err:
        parse_values(text)
    assert repr(text) in str(err.value)


def test_too_many_points_fail_before_anything_is_built():
    with pytest.raises(SceneError, match="1,000,000,000 points exceed the limit of 10,000"):
        parse_values("1:1e9:1")  # what once exhausted the memory
    with pytest.raises(SceneError, match="exceed the limit"):
        parse_values("0:1:1e-300")  # the count overflows a float
    with pytest.raises(SceneError, match="1,000,000 points exceed"):
        check_grid([100, 100, 100])
    with pytest.raises(SceneError, match="exceed the limit of 10,000"):
        run_sweep(_cube, range(10**12), workers=1)
    with pytest.raises(SceneError, match="more than 10,000"):
        run_sweep(_cube, itertools.count(), workers=1)  # an endless generator is read only up to the limit
    assert len(parse_values("1:20000:1", max_points=20_000)) == 20_000  # the limit can be raised
    assert check_grid([100, 100], max_points=10_000) == 10_000
    with pytest.raises(SceneError, match="6 points exceed the limit of 5"):
        run_sweep(_cube, range(6), workers=1, options=SweepOptions(max_points=5))
    with pytest.raises(SceneError, match="max_points = 0 is invalid"):
        run_sweep(_cube, [1], max_points=0)


def test_scene_points_resume_from_the_store_identical(tmp_path):
    """Real scene results (nested dicts of numpy-derived numbers) come back from the store equal to a fresh run, and
    the resumed sweep computes none of them again."""
    jobs = _jobs(2)
    store, calls = tmp_path / "scene.jsonl", tmp_path / "calls.txt"
    logged = functools.partial(_logged_scene_point, str(calls))
    stored = run_sweep(logged, jobs, workers=1, store=store)
    freqs = sorted(job[1]["input"]["frequency"] for job in jobs)
    assert _computed(calls) == freqs
    assert run_sweep(logged, jobs, workers=1, store=store) == stored == run_sweep(scene_point, jobs, workers=1)
    assert _computed(calls) == freqs  # served from the store: no point computed twice
