"""Benchmark (not a test): cost per MuJoCo step of every shipped drives and rotational scene against its bare model
stepped in C.

For each scene (`--duration` s simulated, default 1 s or the scene's duration if shorter, on the MuJoCo path):
- bare: the very MjModel the scene's `MujocoRotorSim` compiled (inertias, springs, sources set; locks inactive as in
  the file), same integrator and timestep, stepped `n` times by `mujoco.rollout.rollout(model, data, x0[None],
  zeros((1, n, nu)))` (the C loop, nothing recorded);
- stepping: `MujocoRotorSim.run` (state machine, locks, energy bookkeeping, the controller at its samples, recording)
  per step;
- whole: `mbsuite.run(scene)` (building the system and the model, the run, the result assembly) per step.
Ratios stepping / bare and whole / bare are printed; each time is the median of `--repeats` (>= 5) runs, the three
measurements interleaved round by round. Times are this process's CPU time (`--clock cpu`, the default: on a busy
machine wall time also counts the other processes) or wall time (`--clock wall`).

    python scripts/drives_bench.py [--duration 1] [--repeats 5] [--clock cpu|wall] [scene ...]   (scene: model/name;
    a bare name is a drives scene)
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
from mujoco import rollout

import mbsuite
from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
from mbsuite.models.drives import drive
from mbsuite.models.drives.scene_run import reference_signal
from mbsuite.models.rotational.scene_run import setup as rotational_setup
from mbsuite.paths import mjcf_path
from mbsuite.results import format_table
from mbsuite.scenes import load_scene, shipped_scenes


def setup(scene):
    """(sim, run arguments, make_controller) of a scene on the MuJoCo path, as its model's path builds them (a
    `rotational` scene: its example, no controller)."""
    if scene.model == "rotational":
        s = rotational_setup(scene)
        sim = MujocoRotorSim(s.system, mjcf_path(s.mjcf), timestep=scene.solver.timestep,
                             integrator=scene.solver.integrator)
        return sim, (s.q0, s.w0), lambda: None, s.sample_dt
    eff = dict(scene.effects)
    sv = scene.solver
    mech = eff["mechanism"]
    p = scene.build_params().resolved()
    system = drive.build_system(mech, p, eff)
    ref = reference_signal(dict(scene.input), p["ref"] or 0.0)

    def make():
        c = drive.build_controller(mech, eff["controller"], p, eff, ref=ref)
        if mech == "step_up":
            c.ref = ref
        return c

    sim = MujocoRotorSim(system, mjcf_path(f"drive_{mech}"), timestep=sv.timestep, integrator=sv.integrator)
    return sim, (np.zeros(3), np.zeros(3)), make, sv.sample_dt or 1.0 / p["fs"]


CLOCK = {"cpu": time.process_time, "wall": time.perf_counter}


def timed(fn, clock, arg=None) -> float:
    t0 = clock()
    fn(arg)
    return clock() - t0


def bare_rollout(sim, q0, w0, nstep: int):
    """A function that steps the sim's compiled model nstep times with `mujoco.rollout` from (q0, w0)."""
    m = sim.m
    d = mujoco.MjData(m)
    for i in range(len(q0)):
        d.qpos[sim.qadr[i]] = q0[i]
        d.qvel[sim.dof[i]] = w0[i]
    x0 = np.empty(mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_FULLPHYSICS))
    mujoco.mj_getState(m, d, x0, mujoco.mjtState.mjSTATE_FULLPHYSICS)
    ctrl = np.zeros((1, nstep, m.nu))
    return lambda _: rollout.rollout(m, d, x0[None], ctrl)


HEAD = ["scene", "dt_s", "steps", "bare_us", "stepping_us", "stepping/bare", "whole_us", "whole/bare"]


def bench_scene(name: str, duration: float, repeats: int, clock) -> list:
    sc = load_scene(name if "/" in name else f"drives/{name}")
    dur = min(duration, sc.solver.duration)
    sc = sc.replace(solver={"engine": "mujoco", "duration": dur, "t_settle": min(sc.solver.t_settle, 0.5 * dur)})
    sim, (q0, w0), make, sample_dt = setup(sc)
    nstep = int(round(dur / sc.solver.timestep))
    bare = bare_rollout(sim, q0, w0, nstep)
    bare(None)  # warm-up
    mbsuite.run(sc)  # warm-up (compiles the native library once)
    times: dict[str, list[float]] = {"bare": [], "step": [], "whole": []}
    for _ in range(repeats):
        times["bare"].append(timed(bare, clock))
        times["step"].append(timed(lambda c: sim.run(q0, w0, dur, controller=c, sample_dt=sample_dt), clock, make()))
        times["whole"].append(timed(lambda _: mbsuite.run(sc), clock))
    b, s, w = (float(np.median(times[k])) / nstep for k in ("bare", "step", "whole"))
    return [name, sc.solver.timestep, nstep, 1e6 * b, 1e6 * s, s / b, 1e6 * w, w / b]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--duration", type=float, default=1.0)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--clock", choices=sorted(CLOCK), default="cpu")
    args = ap.parse_args()
    rows = []
    for name in args.scenes or [f"{m}/{n}" for m in ("drives", "rotational") for n in shipped_scenes()[m]]:
        rows.append(bench_scene(name, args.duration, args.repeats, CLOCK[args.clock]))
        print(format_table(HEAD, rows[-1:], ".3g").splitlines()[-1], flush=True)
    print(format_table(HEAD, rows, ".3g"))


if __name__ == "__main__":
    main()
