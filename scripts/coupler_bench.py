"""Benchmark (not a test): cost per MuJoCo step of every shipped coupler scene against its bare model stepped in C, and
the batched kinematic reference against the per-sample continuation.

For each scene (its own duration, or `--duration`):
- bare: the very MjModel the scene compiles (`mujoco.build`: design, effects, misalignment, integrator, timestep), from
  the same initial state with the same ramped input, stepped by `mujoco.rollout.rollout(model, data, x0[None], ctrl)`
  (the C loop; it records the state, nothing else);
- stepping: the scene's `core.Stepper` run (all channels, plausibility bounds, checks) per step;
- whole: `mbsuite.run(scene)` per step (building and assembling the model, the run, the batched kinematic reference,
  the signals, the statistics and the result).
The three are measured one after another in every repetition (interleaved, so that a busy machine slows them alike);
times are medians over `--repeats` (>= 5) repetitions, ratios are medians of the per-repetition ratios.
Then, on the default scene's recorded samples: `kinematic_output` (Gauss-Newton per sample, continuation) against
`kinematic_pose` (all samples at once), their largest difference and the speed-up.

    python scripts/coupler_bench.py [--repeats 7] [--duration 2] [scene ...]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
from mujoco import rollout

import mbsuite
from mbsuite.engines import core
from mbsuite.models.coupler import SPEC
from mbsuite.models.coupler import mujoco as cm
from mbsuite.models.coupler.reference import kinematic_output, kinematic_pose
from mbsuite.models.coupler.scenario import scene_inputs
from mbsuite.results import format_table
from mbsuite.scenes import load_scene

STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS


def _timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def measure(scene, repeats: int) -> dict:
    """Median seconds per step of the bare rollout, the stepping and the whole run of one scene, and their ratios."""
    sv = scene.solver
    p, inp = scene.build_params(), scene_inputs(scene)
    m, d, _ = cm.build(p, dict(scene.effects), inp, sv.timestep, sv.integrator)
    n = int(round(sv.duration / sv.timestep))
    every = max(1, int(round(sv.sample_dt / sv.timestep))) if sv.sample_dt > 0 else 1
    x0 = np.empty(mujoco.mj_stateSize(m, STATE))
    mujoco.mj_getState(m, d, x0, STATE)
    ctrl = cm.ramp_input(inp, n, sv.timestep)
    d_bare = mujoco.MjData(m)
    chans = cm.channels(m, p, inp)

    def stepping() -> None:
        mujoco.mj_setState(m, d, x0, STATE)
        core.Stepper(m, d, chans, every=every).run(n, ctrl=ctrl, ctrl_idx=[0, 1])

    mbsuite.run(scene)  # warm-up (the native library is compiled once per mujoco version)
    rows = []
    for _ in range(repeats):
        rows.append([_timed(lambda: rollout.rollout(m, d_bare, x0[None], ctrl[None])), _timed(stepping),
                     _timed(lambda: mbsuite.run(scene))])
    a = np.array(rows) / n
    return {"steps": n, "bare": float(np.median(a[:, 0])), "stepping": float(np.median(a[:, 1])),
            "whole": float(np.median(a[:, 2])), "stepping_ratio": float(np.median(a[:, 1] / a[:, 0])),
            "whole_ratio": float(np.median(a[:, 2] / a[:, 0]))}


def fpp_speedup(scene, repeats: int) -> dict:
    """Per-sample continuation vs the batched FPP on the samples of a MuJoCo run of the scene."""
    sv = scene.solver
    p, inp = scene.build_params(), scene_inputs(scene)
    m, d, info = cm.build(p, dict(scene.effects), inp, sv.timestep, sv.integrator)
    n = int(round(sv.duration / sv.timestep))
    every = max(1, int(round(sv.sample_dt / sv.timestep)))
    tr = core.Stepper(m, d, cm.channels(m, p, inp), every=every).run(n, ctrl=cm.ramp_input(inp, n, sv.timestep),
                                                                     ctrl_idx=[0, 1])
    guess = cm.simulated_pose(p, tr)
    seq = [_timed(lambda: kinematic_output(p, inp, tr["phi_a"], info["u0"])) for _ in range(max(1, repeats // 3))]
    bat = [_timed(lambda: kinematic_pose(p, inp, tr["phi_a"], guess, tr.t)) for _ in range(repeats)]
    diff = np.max(np.abs(kinematic_output(p, inp, tr["phi_a"], info["u0"])
                         - kinematic_pose(p, inp, tr["phi_a"], guess, tr.t)[:, 0]))
    return {"samples": tr.t.size, "per_sample_s": float(np.median(seq)), "batched_s": float(np.median(bat)),
            "speedup": float(np.median(seq) / np.median(bat)), "max_diff_rad": float(diff)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--duration", type=float, default=0.0, help="simulated seconds (default: the scene's own)")
    ap.add_argument("scenes", nargs="*", help="scene names (default: every shipped coupler scene)")
    a = ap.parse_args()
    repeats = max(5, a.repeats)
    rows = []
    for name in a.scenes or sorted(SPEC.scene_files()):
        sc = load_scene(f"coupler/{name}")
        if a.duration > 0:
            sc = sc.replace(solver={"duration": a.duration, "t_settle": min(sc.solver.t_settle, a.duration / 2)})
        r = measure(sc, repeats)
        rows.append([name, r["steps"], 1e6 * r["bare"], 1e6 * r["stepping"], r["stepping_ratio"], 1e6 * r["whole"],
                     r["whole_ratio"]])
    print(format_table(["scene", "steps", "bare us/step", "stepping us/step", "stepping/bare", "whole us/step",
                        "whole/bare"], rows, ".3g"))
    print(f"medians of {repeats} interleaved repetitions")
    f = fpp_speedup(load_scene("coupler"), repeats)
    print(f"\nkinematic reference on {f['samples']} samples: per-sample continuation {1e3 * f['per_sample_s']:.1f} ms, "
          f"batched {1e3 * f['batched_s']:.2f} ms (x{f['speedup']:.0f}), max |difference| {f['max_diff_rad']:.1e} rad")


if __name__ == "__main__":
    main()
