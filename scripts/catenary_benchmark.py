"""CPU time of one EN 50318 reference run (shipped scene: 0.5 m elements, dt 2e-4 s), the readable Python path and
the compiled step core side by side (median of --repeats, alternating), with the cost per step, the banded solve
alone (LAPACK dpbtrs and the core's block sweeps), and the catenary alone against the catenary with the 2-mass
pantograph in the core (same steps, no contact point vs one); with --eppinger also one passage of the Eppinger
pantograph on each engine path (0.5 m, dt 1e-4 s). `--compare` instead times the shipped method (the point-load
correction, `fe.PointCorrection`, at the shipped defaults) against the method before it (the plain Hermite wires at
the same 0.5 m and dt 2e-4 s; with --baseline REV in the code of git revision REV): one single-pantograph EN 50318
passage each, in fresh interpreters, assembly included, alternating, medians and their ratio. Run it on one core:
`taskset -c 0`.

    taskset -c 0 .venv/bin/python scripts/catenary_benchmark.py [--repeats 3] [--speeds 250 300] [--eppinger]
    taskset -c 0 .venv/bin/python scripts/catenary_benchmark.py --compare [--repeats 7] [--baseline REV]
    taskset -c 0 .venv/bin/python scripts/catenary_benchmark.py --lines [--repeats 7]

`--kinds` times whole processes (`mbsuite catenary SCENE --json`, CPU of the child process from the operating
system's accounting) of one EN 50318 passage per pantograph kind, all at one element length and time step (default
0.5 m and 1e-4 s, the Eppinger scene's), alternating, medians with min-max and each median's ratio to the 2-mass
pantograph's; `--error-estimate` adds each kind's run with its error estimate and the ratio to its plain run.

    taskset -c 0 .venv/bin/python scripts/catenary_benchmark.py --kinds [--repeats 3] [--speeds 250] [--error-estimate]

`--lines` times the core's step loop (a whole passage, the 2-mass pantograph, the scene's mesh and step) on the
simple, stitched and compound lines, alternating, and prints the medians per step and per element-step with their
ratio to the simple line's (the compiled core's cost on a line with more wires per node).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.native_core import NativeCore
from mbsuite.models.catenary.pantographs import TwoMassPantograph
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.sim import CHECK_EVERY, CoupledSimulation
from mbsuite.results import format_table

STATS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct")


def _panto(p: CatenaryParams) -> TwoMassPantograph:
    return TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)


def core_loop_cpu(p: CatenaryParams, speed_kmh: float, dt: float, with_pantograph: bool) -> float:
    """CPU seconds of the core's step loop over a whole passage, with the 2-mass pantograph or with no contact point
    (the catenary alone, from the same static state)."""
    fe = assemble(p)
    sim = CoupledSimulation(fe, _panto(p), speed_kmh / 3.6, dt)
    ps = sim.start(p.x_start, p.x_end)
    core = NativeCore(sim, 1, np.array([p.x_start]), np.array([p.x_end]))
    core.u[:], core.q[:], core.p[:] = ps.u, ps.q, ps.p
    core.place(0, p.x_start)
    core.attach([sim.panto.native(dt)])
    if with_pantograph:
        core.present[0], core.active[0] = 1, 1
        core.set_force(0, ps.force)
        core.head[0] = ps.head
    c0 = time.process_time()
    code = core.run(0, ps.nsteps, CHECK_EVERY)
    cpu = time.process_time() - c0
    if code:
        raise RuntimeError(f"core loop failed with code {code}")
    return cpu


#: one passage in a fresh interpreter: CPU seconds (assembly, start, stepping, statistics) and the statistics
PASSAGE = {
    "shipped": ("from mbsuite.models.catenary.analysis import run_scene\n"
                "from mbsuite.scenes import load_scene\n"
                "go = lambda v: run_scene(load_scene('catenary/en50318'), speed_kmh=v)\n"),
    "plain": ("from mbsuite.models.catenary.analysis import simulate\n"
              "from mbsuite.models.catenary.params import CatenaryParams\n"
              "try:\n"
              "    from mbsuite.models.catenary.fe import PointCorrection\n"
              "    from mbsuite.models.catenary.fe import assemble\n"
              "    p = CatenaryParams(element_length=0.5)\n"
              "    go = lambda v: simulate(p, v, 2e-4, fe=assemble(p, point_correction=False))\n"
              "except ImportError:  # code from before the point-load correction: its method\n"
              "    go = lambda v: simulate(CatenaryParams(element_length=0.5), v, 2e-4)\n"),
}
TIMED = ("import json, sys, time\n{setup}"
         "go({speed})\n"  # warm-up: the native layer built and loaded, caches filled
         "c0 = time.process_time()\nrun = go({speed})\ncpu = time.process_time() - c0\n"
         "print(json.dumps({{'cpu': cpu, 'h': run.params.element_length, 'dt': run.dt, 'steps': run.timing['steps'],"
         " 'stats': {{k: run.stats[k] for k in {keys!r}}}}}))\n")


def _passage(kind: str, speed: float, src: Path) -> dict:
    """One timed passage of `kind` ("shipped" or "plain") run by the code under `src` in a fresh interpreter."""
    code = TIMED.format(setup=PASSAGE[kind], speed=speed, keys=STATS)
    env = {**os.environ, "PYTHONPATH": str(src)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=src, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def compare(speeds: list[float], repeats: int, baseline: str | None) -> None:
    """The shipped method at the shipped defaults (`run_scene` of `catenary/en50318`: the parameters' element length,
    the scene's time step, the point-load correction) against the plain Hermite wires at 0.5 m and dt 2e-4 s, each
    passage in its own interpreter (`_passage`), alternating; with `baseline` (a git revision) the plain passage runs
    that revision's code (`git archive` into a temporary folder: the method and the code as they were). CPU seconds
    of the whole passage after a warm-up passage in the same interpreter, medians, min-max and their ratio, and how
    far the two sets of statistics are apart."""
    root = Path(__file__).resolve().parent.parent
    with tempfile.TemporaryDirectory() as tmp:
        old_src = root
        if baseline:
            old_src = Path(tmp)
            archive = subprocess.run(["git", "archive", baseline], cwd=root, capture_output=True, check=True).stdout
            subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        rows = []
        for v in speeds:
            cpu: dict[str, list[float]] = {"plain": [], "shipped": []}
            last: dict[str, dict] = {}
            for r in range(repeats):
                for kind in (("plain", "shipped") if r % 2 == 0 else ("shipped", "plain")):
                    res = _passage(kind, v, old_src if kind == "plain" else root)
                    cpu[kind].append(res["cpu"])
                    last[kind] = res
            old, new = statistics.median(cpu["plain"]), statistics.median(cpu["shipped"])
            d = max(abs(last["shipped"]["stats"][k] - last["plain"]["stats"][k]) for k in STATS if k != "loss_pct")
            sh = last["shipped"]
            rows.append([v, f"{sh['h']:g} m, {sh['dt']:g} s", sh["steps"],
                         f"{old:.3f} ({min(cpu['plain']):.3f}-{max(cpu['plain']):.3f})",
                         f"{new:.3f} ({min(cpu['shipped']):.3f}-{max(cpu['shipped']):.3f})", f"{new / old:.3f}",
                         f"{d:.2f}"])
    what = f"plain Hermite 0.5 m, 2e-4 s ({'code of ' + baseline if baseline else 'this code'})"
    print(format_table(["km/h", "shipped setting", "steps", f"{what}: CPU s (min-max)", "shipped: CPU s (min-max)",
                        "ratio shipped / plain", "max |stat diff| (N, mm)"], rows))


LINE_SCENES = ("catenary/en50318", "catenary/en50318_stitched", "catenary/en50318_compound")


def lines(speeds: list[float], repeats: int) -> None:
    """The core's step loop on each line of LINE_SCENES, alternating; medians per step and per element-step."""
    from mbsuite.scenes import load_scene

    scenes = {name: load_scene(name) for name in LINE_SCENES}
    rows = []
    for v in speeds:
        cpu: dict[str, list[float]] = {name: [] for name in scenes}
        size = {}
        for _ in range(repeats):
            for name, sc in scenes.items():
                p, dt = sc.build_params(), sc.solver.timestep
                cpu[name].append(core_loop_cpu(p, v, dt, True))
                fe = assemble(p)
                size[name] = (fe.n_elements, fe.n, int(np.diff(fe.node_offset).max()),
                              round((p.x_end - p.x_start) / (v / 3.6) / dt))
        base = None
        for name in scenes:
            med = statistics.median(cpu[name])
            ne, n, blk, steps = size[name]
            per = 1e9 * med / (ne * steps)
            base = base or per
            rows.append([v, name.split("/")[1], ne, n, blk, steps, f"{med:.2f}",
                         f"{min(cpu[name]):.2f}-{max(cpu[name]):.2f}", f"{1e6 * med / steps:.1f}", f"{per:.1f}",
                         f"{per / base:.2f}"])
    print(format_table(["km/h", "line", "elements", "DOFs", "node block", "steps", "core loop CPU s (median)",
                        "min-max", "us/step", "ns/element-step", "ratio to simple (per element-step)"], rows))


#: pantograph kind -> scene and the settings that select it (`--kinds`)
KINDS = {
    "2-mass reference": ("catenary/en50318", ()),
    "Eppinger, MuJoCo path": ("catenary/en50318_eppinger", ("solver.engine=mujoco",)),
    "Eppinger, hand-derived path": ("catenary/en50318_eppinger", ("solver.engine=reference",)),
    "lumped 3-stage": ("catenary/en50318_lumped3", ()),
    "transfer function": ("catenary/en50318_transfer", ()),
}


def _child_cpu(cmd: list[str]) -> float:
    """CPU seconds (user + sys) of one whole child process running `cmd` (its output discarded)."""
    import resource

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def kinds(speeds: list[float], repeats: int, h: float, dt: float, error_estimate: bool) -> None:
    """Whole-process CPU of one passage per pantograph kind (KINDS), alternating, medians and ratios (module
    docstring)."""
    exe = [sys.executable, "-m", "mbsuite", "catenary"]
    rows = []
    for v in speeds:
        cmds = {}
        for name, (scene, sets) in KINDS.items():
            base = [*exe, scene, "--json", "--set", f"params.element_length={h}", "--set", f"solver.timestep={dt}",
                    "--set", f"input.speed={v}"]
            for kv in sets:
                base += ["--set", kv]
            cmds[name] = base
            if error_estimate:
                cmds[name + " + error estimate"] = [*base, "--error-estimate", "--allow-inaccurate"]
        cpu: dict[str, list[float]] = {k: [] for k in cmds}
        for r in range(repeats):
            for k in (list(cmds) if r % 2 == 0 else list(reversed(cmds))):
                cpu[k].append(_child_cpu(cmds[k]))
        ref = statistics.median(cpu["2-mass reference"])
        for k, c in cpu.items():
            med = statistics.median(c)
            plain = statistics.median(cpu[k.removesuffix(" + error estimate")])
            rows.append([v, k, f"{med:.2f}", f"{min(c):.2f}-{max(c):.2f}", f"{med / ref:.2f}",
                         f"{med / plain:.2f}" if k.endswith("estimate") else ""])
    print(f"element length {h:g} m, time step {dt:g} s, {repeats} runs each (alternating), whole processes")
    print(format_table(["km/h", "pantograph", "CPU s (median)", "min-max", "ratio to the 2-mass",
                        "ratio to its plain run"], rows))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--speeds", type=float, nargs="+", default=None, help="km/h (default 250 300; --kinds: 250)")
    ap.add_argument("--element-length", type=float, default=0.5)
    ap.add_argument("--timestep", type=float, default=None, help="s (default 2e-4; --kinds: 1e-4)")
    ap.add_argument("--eppinger", action="store_true", help="also time the Eppinger pantograph on both engine paths")
    ap.add_argument("--compare", action="store_true", help="the shipped method against the plain Hermite wires")
    ap.add_argument("--baseline", default=None, help="with --compare: a git revision whose code runs the plain wires")
    ap.add_argument("--lines", action="store_true", help="the core's step loop on the simple, stitched, compound lines")
    ap.add_argument("--kinds", action="store_true", help="whole-process CPU of one passage per pantograph kind")
    ap.add_argument("--error-estimate", action="store_true", help="with --kinds: also each kind with its estimate")
    a = ap.parse_args()
    if a.kinds:
        kinds(a.speeds or [250.0], a.repeats, a.element_length, a.timestep or 1e-4, a.error_estimate)
        return
    a.speeds, a.timestep = a.speeds or [250.0, 300.0], a.timestep or 2e-4
    if a.lines:
        lines(a.speeds, a.repeats)
        return
    if a.compare:
        compare(a.speeds, a.repeats, a.baseline)
        return
    p = CatenaryParams(element_length=a.element_length)
    dt = a.timestep
    fe = assemble(p)
    sim = CoupledSimulation(fe, _panto(p), 70.0, dt)
    core = NativeCore(sim, 1, np.array([0.0]), np.array([p.x_end]))
    b = np.random.default_rng(0).random(fe.n)
    c0 = time.process_time()
    for _ in range(2000):
        sim.lu.solve(b)
    lapack_us = (time.process_time() - c0) / 2000 * 1e6
    c0 = time.process_time()
    for _ in range(2000):
        core.solve(b)
    core_us = (time.process_time() - c0) / 2000 * 1e6
    print(f"banded solve ({fe.n} DOFs, half-bandwidth {sim.lu.bandwidth}): LAPACK dpbtrs {lapack_us:.1f} us, "
          f"core block sweeps {core_us:.1f} us (blocked = {core.blocked})")
    rows, diffs = [], []
    for v in a.speeds:
        cpu = {False: [], True: []}
        stats = {}
        for _ in range(a.repeats):
            for native in (False, True):
                c0 = time.process_time()
                run = simulate(p, v, dt, native=native)
                cpu[native].append(time.process_time() - c0)
                stats[native] = run.stats
                steps = run.timing["steps"]
        py, c = statistics.median(cpu[False]), statistics.median(cpu[True])
        d = max(abs(stats[True][k] - stats[False][k]) for k in STATS)
        diffs.append(d)
        alone = statistics.median(core_loop_cpu(p, v, dt, False) for _ in range(a.repeats))
        coupled = statistics.median(core_loop_cpu(p, v, dt, True) for _ in range(a.repeats))
        rows.append([v, steps, f"{py:.2f}", f"{c:.2f}", f"{py / c:.2f}", f"{1e6 * py / steps:.0f}",
                     f"{1e6 * c / steps:.0f}", f"{alone:.2f}", f"{coupled:.2f}", f"{coupled / alone:.2f}",
                     f"{d:.1e}"])
    print(format_table(["km/h", "steps", "Python CPU (s)", "core CPU (s)", "speed-up", "Python us/step",
                        "core us/step", "catenary alone (s)", "with 2-mass (s)", "ratio", "max |stat diff|"], rows))
    if a.eppinger:
        rows = []
        for engine in ("reference", "mujoco"):
            for v in a.speeds:
                walls, cpus = [], []
                for _ in range(a.repeats):
                    w0, c0 = time.perf_counter(), time.process_time()
                    run = simulate(p, v, 1e-4, pantograph="eppinger", engine=engine)
                    walls.append(time.perf_counter() - w0)
                    cpus.append(time.process_time() - c0)
                steps, trials = run.timing["steps"], run.result.stats["local_solves"]
                cpu_ = statistics.median(cpus)
                rows.append([engine, v, steps, trials, f"{statistics.median(walls):.2f}", f"{cpu_:.2f}",
                             f"{1e6 * cpu_ / steps:.0f}"])
        print()
        print(format_table(["Eppinger path", "km/h", "steps", "trial steps", "wall (s)", "CPU (s)", "CPU us/step"],
                           rows))


if __name__ == "__main__":
    main()
