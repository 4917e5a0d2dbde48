"""Benchmark (not a test): cost per MuJoCo step of every shipped MuJoCo scene vs its bare model, side by side.

For each scene (1 s simulated on its MuJoCo path, or `--duration`):
- scene: `mbsuite.run(scene)` wall time / number of steps (everything: building the model, callbacks, the model's
  per-step Python logic, recording and post-processing);
- bare loop: the very MjModel the scene compiled, stepped the same number of steps in a tight Python loop with no
  callback installed and nothing recorded;
- bare rollout: the same model and steps through `mujoco.rollout` (the C loop, no Python per step).
Ratios scene / bare loop (the issue's target: <= 1.5) and scene / rollout are printed. Best of `--repeats`.
The steps and the model are captured by counting `mujoco.mj_step`/`mj_RungeKutta` calls in a first, untimed pass.

    python scripts/bench_step_cost.py [--duration 1] [--repeats 5] [--model pantograph]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
from mujoco import rollout

import mbsuite
from mbsuite.results import format_table
from mbsuite.scenes import shipped_scenes


def capture(scene):
    """Run once counting steps; return (model, steps) of the model stepped most."""
    seen: dict[int, list] = {}
    orig_step, orig_rk = mujoco.mj_step, mujoco.mj_RungeKutta

    def step(m, d, *a):
        seen.setdefault(id(m), [m, 0])[1] += 1
        return orig_step(m, d, *a)

    def rk(m, d, n):
        seen.setdefault(id(m), [m, 0])[1] += 1
        return orig_rk(m, d, n)

    mujoco.mj_step, mujoco.mj_RungeKutta = step, rk
    try:
        mbsuite.run(scene)
    finally:
        mujoco.mj_step, mujoco.mj_RungeKutta = orig_step, orig_rk
    if not seen:
        return None, 0
    m, n = max(seen.values(), key=lambda v: v[1])
    return m, n


def best(fn, repeats: int) -> float:
    b = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        b = min(b, time.perf_counter() - t0)
    return b


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--model", action="append", help="only these models (repeatable)")
    a = ap.parse_args()
    rows = []
    for model, scenes in sorted(shipped_scenes().items()):
        if a.model and model not in a.model:
            continue
        for name in scenes:
            sc = mbsuite.load_scene(f"{model}/{name}")
            if "mujoco" not in sc.spec.engines or model == "catenary":
                continue  # the catenary's FE code steps no MuJoCo model of its own size; see its README
            sc = sc.replace(solver={"engine": "mujoco", "duration": a.duration, "t_settle": 0.0})
            m, n = capture(sc)
            if not n:
                continue
            t_scene = best(lambda sc=sc: mbsuite.run(sc), a.repeats) / n
            d = mujoco.MjData(m)

            def loop(m=m, d=d, n=n):
                mujoco.mj_resetData(m, d)
                for _ in range(n):
                    mujoco.mj_step(m, d)

            t_loop = best(loop, a.repeats) / n
            mujoco.mj_resetData(m, d)
            x0 = np.zeros(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
            mujoco.mj_getState(m, d, x0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
            ctrl = np.zeros((1, n, m.nu))
            t_roll = best(lambda m=m, d=d, x0=x0, ctrl=ctrl: rollout.rollout(m, d, x0[None, :], ctrl), a.repeats) / n
            rows.append([f"{model}/{name}", n, t_scene * 1e6, t_loop * 1e6, t_roll * 1e6, t_scene / t_loop,
                         t_scene / t_roll])
            print(f"{model}/{name}: {t_scene * 1e6:.2f} us/step, ratio {t_scene / t_loop:.2f}", flush=True)
    print()
    print(format_table(["scene", "steps", "scene us/step", "bare loop us/step", "rollout us/step",
                        "scene / bare loop", "scene / rollout"], rows, ".3g"))
    print(f"\n{a.duration:g} s simulated per scene, best of {a.repeats}; scene time includes model build and "
          "post-processing")


if __name__ == "__main__":
    main()
