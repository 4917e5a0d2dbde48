"""Seeded defects: does the default test suite catch realistic physics mistakes?

Each mutation below is one plausible error in the physics code — a sign flipped in an equation of motion, an operating
point shifted, a regularisation band widened, a loss term dropped, a bound scaled by 1 %, an event one step late, a
Jacobian row swapped... It is applied, one at a time, to a scratch copy of the repository (its committed tree), and the
default suite (`pytest -m "not slow"`) runs against it with `-x`, the mutated model's own tests first. A mutation is
caught when a test fails; the report names the first failing test. Every mutation must be caught.

    python scripts/mutants.py                  # all mutations (tens of minutes on 2 cores)
    python scripts/mutants.py --list           # the mutations, without running
    python scripts/mutants.py --only NAME ...  # some of them
    python scripts/mutants.py --json out/mutants.json
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Mutation:
    """Replace the one occurrence of `old` in `path` by `new`; `tests` run first (then the whole default suite)."""

    name: str
    path: str
    old: str
    new: str
    doc: str
    tests: str


MUTATIONS: tuple[Mutation, ...] = (
    # --- coupler: kinematics -----------------------------------------------------------------------------------------
    Mutation("coupler_jacobian_row_swapped", "mbsuite/models/coupler/jacobian.py",
             "    return np.hstack([lh, np.cross(links_to - o, lh)])",
             "    J = np.hstack([lh, np.cross(links_to - o, lh)])\n    return J[[1, 0, *range(2, len(J))]]",
             "two rows of the mechanism Jacobian swapped (links mislabelled)", "tests/coupler"),
    Mutation("coupler_jacobian_moment_sign", "mbsuite/models/coupler/jacobian.py",
             "    return np.hstack([lh, np.cross(links_to - o, lh)])",
             "    return np.hstack([lh, np.cross(lh, links_to - o)])",
             "the moment part of the Jacobian with the cross product reversed (sign flipped)", "tests/coupler"),
    Mutation("coupler_cond_R_not_squared", "mbsuite/models/coupler/jacobian.py",
             "    s_moment = 2 * p.R * math.cos(math.pi / 4 - p.gamma) * l0 / l",
             "    s_moment = 2 * math.cos(math.pi / 4 - p.gamma) * l0 / l",
             "the closed-form condition number missing a factor R", "tests/coupler"),
    # --- IFToMM ------------------------------------------------------------------------------------------------------
    Mutation("iftomm_mujoco_gravity_sign", "mbsuite/models/iftomm/mujoco.py",
             "    m.opt.gravity[:] = [0.0, -gravity, 0.0]", "    m.opt.gravity[:] = [0.0, gravity, 0.0]",
             "gravity pointing up in the MuJoCo model of the benchmarks (a sign in the equations of motion)",
             "tests/iftomm"),
    # --- drives ------------------------------------------------------------------------------------------------------
    Mutation("drives_breakaway_scaled_1pct", "mbsuite/models/drives/event_exact.py",
             "        return float(self.peaks[e] * el[e])", "        return float(1.01 * self.peaks[e] * el[e])",
             "a clutch's stuck-torque bound (breakaway) scaled by 1.01 on the hand path", "tests/drives"),
    Mutation("drives_lock_impact_dropped", "mbsuite/models/drives/drive.py",
             "    resid = e_in - e_out - sum(d.values()) - stored",
             "    resid = e_in - e_out - sum(v for k, v in d.items() if k != 'lock_impact') - stored",
             "a loss term (the kinetic energy removed by plastic locks) dropped from the energy balance",
             "tests/drives"),
    Mutation("drives_event_one_step_late", "mbsuite/models/drives/native/drives.c",
             "  row[0] = te;", "  row[0] = te + S->dt;",
             "every mode change of the MuJoCo path located one step late", "tests/drives"),
    Mutation("drives_storage_time_truncated", "mbsuite/models/drives/commands.py",
             "        return int(math.floor(x + 0.5))", "        return int(math.floor(x))",
             "durations converted to controller samples by truncation where the thesis means whole samples",
             "tests/drives"),
    Mutation("drives_sliding_torque_scaled_1pct", "mbsuite/models/drives/event_exact.py",
             "            sys.apply(f, e, d * el[e])", "            sys.apply(f, e, 1.01 * d * el[e])",
             "a slipping clutch's torque scaled by 1.01 in the dynamics (its loss bookkeeping unchanged)",
             "tests/drives"),
    Mutation("drives_damper_loss_dropped", "mbsuite/models/drives/event_exact.py",
             "            dE[k0 + i] = s.D * d_w * d_w", "            dE[k0 + i] = 0.0",
             "a spring-damper's dissipation dropped from the energy bookkeeping", "tests/drives"),
    Mutation("iftomm_pinocchio_gravity_scaled", "mbsuite/models/iftomm/pinocchio.py",
             "        self.model.gravity.linear = np.array([0.0, -gravity, 0.0])",
             "        self.model.gravity.linear = np.array([0.0, -0.999 * gravity, 0.0])",
             "gravity 0.1 % weak in the Pinocchio path of the benchmarks", "tests/iftomm"),
    Mutation("coupler_friction_off_in_output_bearing", "mbsuite/models/coupler/mujoco.py",
             "    spec.joint(\"phi_c\").frictionloss = p.joint_friction if effects[\"friction\"] else 0.0",
             "    spec.joint(\"phi_c\").frictionloss = 0.0",
             "the output bearing's friction left out of the MuJoCo coupler", "tests/coupler"),
    # --- pantograph --------------------------------------------------------------------------------------------------
    Mutation("pantograph_eom_centripetal_sign", "mbsuite/models/pantograph/equations.py",
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[2] - t[0]),",
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[0] - t[2]),",
             "a sign flipped in a centripetal term of the hand-derived equations of motion (Eq 3.10)",
             "tests/pantograph"),
    Mutation("pantograph_operating_point_at_y_op", "mbsuite/models/pantograph/inputs.py",
             "        return p.y_op + u.amplitude\n", "        return p.y_op\n",
             "the linearisation point shifted by the input amplitude (y_op instead of the mean input y_op + A)",
             "tests/pantograph"),
    Mutation("pantograph_laminar_band_x10", "mbsuite/models/pantograph/params.py",
             "R_LAMINAR = 0.99999", "R_LAMINAR = 0.9999",
             "the orifice's laminar band widened ten times", "tests/pantograph"),
    Mutation("pantograph_elbow_spring_sign_in_plugin", "mbsuite/models/pantograph/native/pantograph.c",
             "  double Te = e->ke * (te - M_PI + q1 + q2);", "  double Te = -e->ke * (te - M_PI + q1 + q2);",
             "the elbow spring's torque with its sign flipped in the MuJoCo plugin", "tests/pantograph"),
    Mutation("health_stability_figure_under_reads", "mbsuite/health.py",
             'Figure("stability_margin", h * omega_max,', 'Figure("stability_margin", 0.1 * h * omega_max,',
             "the stability-margin figure under-reads ten times (inaccurate timesteps pass quietly)",
             "tests/pantograph"),
    # --- catenary ----------------------------------------------------------------------------------------------------
    Mutation("catenary_droppers_bilateral", "mbsuite/models/catenary/sim.py",
             "        self.slack = dropper_law == \"slack\"", "        self.slack = False",
             "droppers made bilateral (they push as well as pull) in the slack-dropper scenes", "tests/catenary"),
    # --- engine core, signals, scenes, store -------------------------------------------------------------------------
    Mutation("core_input_row_one_step_late", "mbsuite/engines/native/core.c",
             "      const double* row = J->ctrl + k * J->ctrl_ncol;",
             "      const double* row = J->ctrl + (k > 0 ? k - 1 : 0) * J->ctrl_ncol;",
             "the input row applied one step late (each step gets the previous step's input)", "tests/engines"),
    Mutation("signals_c_sine_phase", "mbsuite/engines/native/core.c",
             "s[2] * sin(2.0 * M_PI * s[3] * (t - s[5]) + s[4])",
             "s[2] * sin(2.0 * M_PI * s[3] * (t - s[5]) + 1.001 * s[4])",
             "the C evaluation of a sine input with its phase off by 0.1 %", "tests/engines"),
    Mutation("limits_upper_end_ignored", "mbsuite/limits.py",
             "        if self.hi is not None and (value > self.hi or (self.hi_open and value == self.hi)):",
             "        if False:",
             "every declared upper limit ignored (too large values accepted silently)",
             "tests/suite/test_reliability.py"),
    Mutation("store_checksum_not_verified", "mbsuite/analysis/sweep/store.py",
             "        if digest(body) != rec[\"sha256\"]:\n            self._report(n, offset, \"checksum mismatch",
             "        if False:\n            self._report(n, offset, \"checksum mismatch",
             "the sweep store trusts records whose checksum fails (a forged result comes back)",
             "tests/suite/test_store.py"),
)


def _scratch_copy(dest: Path) -> None:
    """The committed tree (HEAD) in `dest`: a stable snapshot, whatever is being edited in the checkout."""
    archive = subprocess.run(["git", "archive", "--format=tar", "HEAD"], cwd=ROOT, capture_output=True, check=True)
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)


def _apply(root: Path, m: Mutation) -> str:
    path = root / m.path
    text = path.read_text()
    n = text.count(m.old)
    if n != 1:
        raise SystemExit(f"mutation {m.name}: the text to replace occurs {n} times in {m.path} (must be once); the "
                         "code has moved on: update the mutation")
    path.write_text(text.replace(m.old, m.new))
    return text


def _suite(root: Path, first: str, python: str, timeout: float) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(root), "MPLBACKEND": "Agg",
           "MBSUITE_NATIVE_DIR": str(root / ".native-cache")}
    return subprocess.run([python, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", "-m", "not slow", first,
                           "tests"], cwd=root, env=env, capture_output=True, text=True, timeout=timeout)


def run_one(root: Path, m: Mutation, python: str, timeout: float) -> dict:
    """Apply `m` in `root`, run the default suite (`m.tests` first, stop at the first failure), restore."""
    original = _apply(root, m)
    t0 = time.perf_counter()
    try:
        proc = _suite(root, m.tests, python, timeout)
        out = proc.stdout + proc.stderr
        failed = re.findall(r"^(?:FAILED|ERROR) (\S+)", out, re.M)
        caught = proc.returncode != 0
        by = failed[0] if failed else (out.strip().splitlines() or ["?"])[-1]
    except subprocess.TimeoutExpired:
        caught, by = True, f"timeout after {timeout:.0f} s (the suite hung: counted as caught, look at it)"
    finally:
        (root / m.path).write_text(original)
    return {"name": m.name, "caught": caught, "by": by if caught else "",
            "seconds": round(time.perf_counter() - t0, 1), "doc": m.doc}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", help="run only these mutations")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--json", metavar="PATH", help="write the outcomes as JSON")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per mutation (default 1800)")
    ap.add_argument("--no-baseline", action="store_true",
                    help="skip the control run of the unmutated copy (it must pass for the results to mean anything)")
    args = ap.parse_args(argv)
    chosen = [m for m in MUTATIONS if not args.only or m.name in args.only]
    unknown = sorted(set(args.only or ()) - {m.name for m in MUTATIONS})
    if unknown:
        print(f"unknown mutation(s): {unknown}", file=sys.stderr)
        return 2
    if args.list:
        for m in chosen:
            print(f"{m.name:38s} {m.doc}")
        return 0
    rows = []
    with tempfile.TemporaryDirectory(prefix="mbsuite-mutants-") as tmp:
        root = Path(tmp)
        _scratch_copy(root)
        for m in chosen:  # every mutation must apply to the code as it is
            original = _apply(root, m)
            (root / m.path).write_text(original)
        if not args.no_baseline:
            base = _suite(root, "tests", sys.executable, args.timeout)
            if base.returncode != 0:
                tail = (base.stdout + base.stderr).strip().splitlines()[-5:]
                print("the unmutated copy fails its own suite; fix that first:\n" + "\n".join(tail), file=sys.stderr)
                return 2
            print("control: the unmutated copy passes the default suite", flush=True)
        for i, m in enumerate(chosen, 1):
            r = run_one(root, m, sys.executable, args.timeout)
            rows.append(r)
            print(f"[{i}/{len(chosen)}] {m.name}: {'caught by ' + r['by'] if r['caught'] else 'NOT CAUGHT'} "
                  f"({r['seconds']} s)", flush=True)
    missed = [r["name"] for r in rows if not r["caught"]]
    print(f"\n{len(rows) - len(missed)}/{len(rows)} mutations caught" + (f"; missed: {missed}" if missed else ""))
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"mutations": [asdict(m) for m in chosen], "outcomes": rows}, indent=2))
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
