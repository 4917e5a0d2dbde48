"""Benchmark (not a test): what every shipped MuJoCo scene costs against its model stepped bare in C.

For each scene (its own duration, or `--duration`), measured side by side in one process, A B A B ..., medians of
`--repeats` (>= 5):
- whole run: `mbsuite.run(scene)` (building the model, the equilibrium or assembly, the native core's loop with its
  native effects, steppers and checks, recording, post-processing and statistics);
- stepping: the time spent inside the native core (`Stepper.run`) per step;
- bare: the very compiled model the scene ran, from the same initial state with the same input array, stepped by
  `mujoco.rollout` (MuJoCo's own C loop: nothing recorded but the state, nothing checked).
Ratios: stepping / bare per step, and whole run / (bare per step x steps). A second table shows what the native
effects themselves cost: the pantograph with its engine plugins against the same model without them (constant
cylinder force law, no elbow spring), both bare.

    python scripts/bench_core.py [--repeats 5] [--duration D] [--model M ...] [--scene model/scene ...]
"""

from __future__ import annotations

import argparse
import statistics
import time

import mujoco
import numpy as np
from mujoco import rollout

import mbsuite
from mbsuite.engines import core
from mbsuite.results import format_table
from mbsuite.scenes import shipped_scenes


class Capture:
    """Wraps `core.Stepper.run` to note the model, initial state, input and time of the longest run of a scene."""

    def __init__(self) -> None:
        self.runs: list[dict] = []
        self._orig = core.Stepper.run

    def __enter__(self) -> Capture:
        cap = self

        def run(stepper, nstep, **kw):
            m, d = stepper.model, stepper.data
            x0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
            mujoco.mj_getState(m, d, x0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
            ctrl0 = d.ctrl.copy()
            t0 = time.perf_counter()
            out = cap._orig(stepper, nstep, **kw)
            cap.runs.append({"model": m, "x0": x0, "ctrl0": ctrl0, "nstep": int(nstep), "ctrl": kw.get("ctrl"),
                             "idx": kw.get("ctrl_idx"), "seconds": time.perf_counter() - t0})
            return out

        core.Stepper.run = run
        return self

    def __exit__(self, *exc: object) -> None:
        core.Stepper.run = self._orig

    def main(self) -> dict:
        return max(self.runs, key=lambda r: r["nstep"])

    def stepping_seconds(self) -> float:
        return sum(r["seconds"] for r in self.runs)


def bare_rollout(run: dict, data: mujoco.MjData) -> float:
    """Seconds for `mujoco.rollout` of the captured run's model, state and inputs."""
    m, n = run["model"], run["nstep"]
    ctrl = np.tile(run["ctrl0"], (1, n, 1))
    if run["ctrl"] is not None:
        idx = np.arange(m.nu) if run["idx"] is None else np.asarray(run["idx"])
        ctrl[0, :, idx] = np.asarray(run["ctrl"]).reshape(-1, len(idx))[:n].T
    t0 = time.perf_counter()
    rollout.rollout(m, data, run["x0"][None], ctrl)
    return time.perf_counter() - t0


def bench_scene(ref: str, repeats: int, duration: float | None) -> list:
    sc = mbsuite.load_scene(ref)
    sc = sc.replace(solver={"engine": "mujoco", **({"duration": duration, "t_settle": 0.0} if duration else {})})
    mbsuite.run(sc)  # warm-up: compile the native library, caches
    whole, stepping, bare = [], [], []
    steps = 0
    for _ in range(repeats):
        with Capture() as cap:
            t0 = time.perf_counter()
            mbsuite.run(sc)
            whole.append(time.perf_counter() - t0)
        main = cap.main()
        if main["nstep"] < 100:
            # one step per call of an outer loop (a pantograph under the FE catenary): measured by that loop's own
            # benchmark (scripts/catenary_benchmark.py), not against a bare rollout
            raise mbsuite.MbsuiteError("co-simulated one step at a time by an outer loop")
        steps = sum(r["nstep"] for r in cap.runs)
        stepping.append(cap.stepping_seconds())
        bare.append(bare_rollout(main, mujoco.MjData(main["model"])) / main["nstep"])
    w, s, b = statistics.median(whole), statistics.median(stepping), statistics.median(bare)
    return [ref, steps, b * 1e6, s / steps * 1e6, (s / steps) / b, w, w / (b * steps)]


def plugin_cost(repeats: int) -> list:
    from mbsuite.models.pantograph.equations import PantographConfig
    from mbsuite.models.pantograph.mujoco import compiled_model
    from mbsuite.models.pantograph.params import PantographParams

    rows = []
    for cfg in (PantographConfig(), PantographConfig(cylinder="nonlinear")):
        runs = {}
        for plugins in (True, False):
            m = compiled_model(PantographParams(), cfg, "rk4", 1e-3, plugins)
            d = mujoco.MjData(m)
            mujoco.mj_resetDataKeyframe(m, d, 0)
            x0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
            mujoco.mj_getState(m, d, x0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
            n = 10_000
            u = 1.58 + 1.85e-3 * (1 - np.cos(2 * np.pi * 4.25 * (np.arange(n) + 0.5) * 1e-3))
            runs[plugins] = {"model": m, "x0": x0, "ctrl0": d.ctrl.copy(), "nstep": n, "ctrl": u, "idx": [0]}
        t = {True: [], False: []}
        for _ in range(repeats):
            for plugins in (True, False):
                r = runs[plugins]
                t[plugins].append(bare_rollout(r, mujoco.MjData(r["model"])) / r["nstep"])
        a, b = statistics.median(t[True]), statistics.median(t[False])
        rows.append([f"cylinder {cfg.cylinder}, elbow {cfg.elbow}", a * 1e6, b * 1e6, a / b])
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--duration", type=float, default=None, help="simulated seconds (default: each scene's own)")
    ap.add_argument("--model", action="append", help="only these models (repeatable)")
    ap.add_argument("--scene", action="append", help="only these scenes, model/scene (repeatable)")
    a = ap.parse_args()
    refs = a.scene or [f"{m}/{s}" for m, ss in sorted(shipped_scenes().items()) for s in ss
                       if (not a.model or m in a.model) and "mujoco" in mbsuite.get_model(m).engines]
    rows = []
    for ref in refs:
        try:
            row = bench_scene(ref, a.repeats, a.duration)
        except mbsuite.MbsuiteError as exc:  # e.g. a catenary scene whose pantograph has no MuJoCo path
            print(f"{ref}: skipped ({exc})", flush=True)
            continue
        rows.append(row)
        print(f"{ref}: stepping {row[4]:.2f}x bare, whole run {row[6]:.2f}x", flush=True)
    print()
    print(format_table(["scene", "steps", "bare us/step", "core us/step", "stepping / bare", "whole run s",
                        "whole / bare"], rows, ".3g"))
    print(f"\nmedians of {a.repeats} runs, interleaved with the bare rollout; bare = mujoco.rollout of the scene's own "
          "compiled model, state and input")
    print()
    print(format_table(["pantograph model (RK4, 1 ms, 4.25 Hz ram)", "with plugins us/step",
                        "without us/step", "ratio"], plugin_cost(a.repeats), ".3g"))


if __name__ == "__main__":
    main()
