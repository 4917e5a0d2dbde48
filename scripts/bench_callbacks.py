"""Benchmark (not a test): per-step cost of pantograph scenes vs the bare MuJoCo model, measured side by side.

- bare: the shipped mjcf/pantograph.xml compiled directly, no Python callback installed;
- lab scene: elbow (passive) + linear cylinder (act_dyn) callbacks;
- effects off: cylinder = constant, elbow = rigid -> no callback: should cost what the bare model costs (ratio ~1).
Each variant steps the same number of steps in the same Python loop (ctrl written each step), best of R repeats;
`mujoco.rollout` of the bare model shows the C-loop cost without Python per-step overhead.

    python scripts/bench_callbacks.py [--steps 20000] [--repeats 7]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
from mujoco import rollout

from mbsuite.engines.mujoco_engine import step_cost
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.reference import PantographConfig
from mbsuite.paths import mjcf_path
from mbsuite.results import format_table


def loop_cost(model, cbs: dict, q0: np.ndarray, steps: int, repeats: int) -> float:
    ctrl = 1.58 + 1.85e-3 * (1 - np.cos(2 * np.pi * 4.25 * np.arange(steps) * model.opt.timestep))
    return step_cost(model, cbs, q0, steps, repeats, ctrl)


def rollout_cost(model, q0: np.ndarray, steps: int, repeats: int) -> float:
    d = mujoco.MjData(model)
    d.qpos[:] = q0
    state = np.zeros(mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(model, d, state, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.zeros((1, steps, model.nu))
    ctrl[0, :, 0] = 1.58 + 1.85e-3 * (1 - np.cos(2 * np.pi * 4.25 * np.arange(steps) * model.opt.timestep))
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        rollout.rollout(model, d, state[None, :], ctrl)
        best = min(best, time.perf_counter() - t0)
    return best / steps


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=7)
    a = ap.parse_args()
    bare = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    lab = MujocoPantograph(config=PantographConfig())
    off = MujocoPantograph(config=PantographConfig(cylinder="constant", elbow="rigid"))
    q0 = lab.equilibrium()
    rows = []
    c_bare = loop_cost(bare, {}, q0, a.steps, a.repeats)
    c_lab = loop_cost(lab.model, lab.callback_set(), q0, a.steps, a.repeats)
    c_off = loop_cost(off.model, off.callback_set(), off.equilibrium(), a.steps, a.repeats)
    c_roll = rollout_cost(bare, q0, a.steps, a.repeats)
    rows.append(["bare MJCF, no callback (Python loop)", c_bare * 1e6, 1.0])
    rows.append(["lab scene: elbow + cylinder callbacks", c_lab * 1e6, c_lab / c_bare])
    rows.append(["effects off (constant cylinder, rigid elbow)", c_off * 1e6, c_off / c_bare])
    rows.append(["bare MJCF via mujoco.rollout (C loop)", c_roll * 1e6, c_roll / c_bare])
    print(format_table(["variant", "us / step", "ratio to bare"], rows, ".3g"))
    print(f"\n{a.steps} steps, best of {a.repeats}; callback overhead per step = {(c_lab - c_bare) * 1e6:.2f} us")


if __name__ == "__main__":
    main()
