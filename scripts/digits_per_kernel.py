"""How many digits each headline output keeps when OpenBLAS runs another kernel family (the "BLAS kernel" column of
docs/reproducibility.md), measured on this machine for every family its CPU can run.

Every kernel family runs the same public commands (`mbsuite run SCENE --json --out DIR`, `mbsuite catenary`, `mbsuite
modes`, `mbsuite equilibrium`, `mbsuite coupler fpp`) in child processes whose environment is this one plus
`OPENBLAS_CORETYPE=<kernel>` (for 'default' the variable is removed: OpenBLAS picks). `OPENBLAS_VERBOSE=2` makes
scipy-openblas print the core it loaded ('Core: <name>', once for numpy's and once for scipy's library), which is
checked for every run. A family is forced only where /proc/cpuinfo has its instructions: Prescott (sse3, shown as
`pni`; OpenBLAS names this table 'Katmai'), SandyBridge (avx), Haswell (avx2 and fma), SkylakeX (avx512f/bw/dq/vl:
the SkylakeX/Cooperlake/SapphireRapids family of AVX-512 machines); Nehalem (sse4_2) on request.

Every finite JSON number (and, for `mbsuite run`, the window mean and standard deviation over t >= t_settle of each
CSV signal) is flattened to name -> value and compared with the 'default' run (and with Haswell's where 'default'
loaded another core). How to read the table: a cell is digits = floor(-log10(r)) with r in brackets, r the largest
relative change |dy| / max(|y|, s) over the row's outputs, s the largest magnitude of the same quantity in the
baseline run (a signal's min/max/final/mean/std together, a numeric array, an energy book), so that an entry near
zero is measured against its quantity's size; 'bitwise' when every value is the same bits. 'default (repeat)' is a
second default run: it must be bitwise, else the measurement has a noise floor. The events table says whether the
lock/slip/contact-loss sequences and their counts are the same, and how far event times moved.

    .venv/bin/python scripts/digits_per_kernel.py --json-out out/digits_per_kernel.json   # about 5 min on 2 cores
    .venv/bin/python scripts/digits_per_kernel.py --quick --kernels default,SandyBridge
"""

from __future__ import annotations

import argparse
import concurrent.futures
import csv
import hashlib
import importlib.util
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

Values = dict[str, float]


@dataclass(frozen=True)
class Kernel:
    coretype: str | None  # OPENBLAS_CORETYPE value; None: unset (OpenBLAS picks)
    needs: tuple[tuple[str, ...], ...]  # /proc/cpuinfo flags: every group must have one of its names
    prints: tuple[str, ...]  # the names OpenBLAS prints for it ('Core: ...')
    label: str = ""


KERNELS: dict[str, Kernel] = {
    "default": Kernel(None, (), ()),
    "Prescott": Kernel("Prescott", (("pni", "sse3"),), ("Prescott", "Katmai"), "Prescott (SSE3)"),
    "Nehalem": Kernel("Nehalem", (("ssse3",), ("sse4_2",)), ("Nehalem",), "Nehalem (SSE4.2)"),
    "SandyBridge": Kernel("Sandybridge", (("avx",),), ("Sandybridge",), "SandyBridge (AVX)"),
    "Haswell": Kernel("Haswell", (("avx2",), ("fma",)), ("Haswell",), "Haswell (AVX2+FMA)"),
    "SkylakeX": Kernel(
        "SkylakeX",
        (("avx512f",), ("avx512bw",), ("avx512dq",), ("avx512vl",)),
        ("SkylakeX", "Cooperlake", "SapphireRapids"),
        "SkylakeX (AVX-512: SkylakeX/Cooperlake/SapphireRapids family)",
    ),
}
AUTO_KERNELS = ("Prescott", "SandyBridge", "Haswell", "SkylakeX")
REPEAT = "default (repeat)"


@dataclass(frozen=True)
class Command:
    key: str
    label: str
    argv: tuple[str, ...]
    csv: bool = False  # `mbsuite run`: also window statistics of run.csv (--out)
    quick: bool = False


COMMANDS: tuple[Command, ...] = (
    Command("drives.pwm.ref", "drives step_up_pwm, reference (DOP853, events)",
            ("run", "drives/step_up_pwm", "--engine", "reference"), csv=True, quick=True),
    Command("drives.pwm.mujoco", "drives step_up_pwm, MuJoCo", ("run", "drives/step_up_pwm", "--engine", "mujoco"),
            csv=True),
    Command("drives.resonant_matched.ref", "drives step_up_resonant_matched, reference",
            ("run", "drives/step_up_resonant_matched", "--engine", "reference"), csv=True, quick=True),
    Command("pantograph.lab.mujoco", "pantograph lab, MuJoCo", ("run", "pantograph/lab", "--engine", "mujoco"),
            csv=True),
    Command("pantograph.lab.ref", "pantograph lab, reference (LSODA)",
            ("run", "pantograph/lab", "--engine", "reference"), csv=True, quick=True),
    Command("pantograph.modes", "pantograph modes", ("modes", "pantograph"), quick=True),
    Command("pantograph.equilibrium", "pantograph equilibrium", ("equilibrium", "pantograph")),
    Command("coupler.double_lateral", "coupler double_lateral, MuJoCo",
            ("run", "coupler/double_lateral", "--engine", "mujoco"), csv=True),
    Command("coupler.fpp", "coupler fpp", ("coupler", "fpp"), quick=True),
    Command("iftomm.fourbar.mujoco", "iftomm fourbar, MuJoCo", ("run", "iftomm/fourbar", "--engine", "mujoco"),
            csv=True),
    Command("iftomm.fourbar.ref", "iftomm fourbar, reference (Pinocchio)",
            ("run", "iftomm/fourbar", "--engine", "reference"), csv=True),
    Command("catenary.en50318", "catenary EN 50318", ("catenary", "catenary/en50318")),
)

# (row label, command key, name patterns): the headline groups of docs/reproducibility.md
_MEANS = (r"^statistics\.mean_(load|motor)_speed$",)
_BOOKS = (r"^signals\.E_in\.final$", r"^stats\.energy_balance\.(input|stored|losses\..+)$")
_FOURBAR = (r"^signals\.(input_angle|input_rate|energy)\.(min|max|final|mean|std)$",)
_DRIFT = (r"^stats\.energy_drift_max$", r"^signals\.energy_drift\.final$")
ROWS: tuple[tuple[str, str, tuple[str, ...]], ...] = (
    ("catenary EN 50318 statistics (Fm, σ, stat. max/min, max, min, uplift)", "catenary.en50318",
     (r"^runs\.[^.]+\.statistics\.",)),
    ("drives step_up_pwm, MuJoCo path: mean load and motor speed", "drives.pwm.mujoco", _MEANS),
    ("same, E_in and energy books (losses, stored)", "drives.pwm.mujoco", _BOOKS),
    ("drives step_up_pwm, reference path (DOP853, events): mean load and motor speed", "drives.pwm.ref", _MEANS),
    ("same, E_in and energy books", "drives.pwm.ref", _BOOKS),
    ("drives step_up_resonant_matched, reference path: mean load and motor speed", "drives.resonant_matched.ref",
     _MEANS),
    ("same, E_in and energy books", "drives.resonant_matched.ref", _BOOKS),
    ("pantograph lab, MuJoCo path: contact force mean, std, max", "pantograph.lab.mujoco",
     (r"^signals\.contact_force\.(mean|std|max)$",)),
    ("same, contact force minimum", "pantograph.lab.mujoco", (r"^signals\.contact_force\.min$",)),
    ("pantograph lab, reference path (LSODA): contact force mean, std", "pantograph.lab.ref",
     (r"^signals\.contact_force\.(mean|std)$",)),
    ("same, contact force max / min", "pantograph.lab.ref", (r"^signals\.contact_force\.(max|min)$",)),
    ("pantograph modes, reference path (f_n, ζ)", "pantograph.modes", (r"^reference\[\d+\]\.",)),
    ("pantograph modes, MuJoCo path (f_n, ζ)", "pantograph.modes", (r"^mujoco\[\d+\]\.",)),
    ("pantograph equilibrium (angles, contact force; three paths)", "pantograph.equilibrium",
     (r"^(reference|mujoco|pinocchio)\.",)),
    ("coupler double_lateral, MuJoCo (input torque mean)", "coupler.double_lateral", (r"^stats\.torque_in_mean$",)),
    ("same, torque ripple, link forces, φ_c error", "coupler.double_lateral",
     (r"^stats\.(torque_in_ripple_pp|torque_in_ripple_rel|link_force_max_abs|link_force_mean\[\d+\]"
      r"|phi_c_err_max|phi_c_err_rms)$",)),
    ("coupler pose over one revolution (`coupler fpp`), c1", "coupler.fpp",
     (r"^(phi_b|x_b|y_b|z_b)\[\d+\]$", r"^c1(_sampled)?$")),
    ("iftomm fourbar, MuJoCo: input angle and rate, energy", "iftomm.fourbar.mujoco", _FOURBAR),
    ("same, energy drift (the integrator's error)", "iftomm.fourbar.mujoco", _DRIFT),
    ("iftomm fourbar, reference path (Pinocchio, DOP853): input angle and rate, energy", "iftomm.fourbar.ref",
     _FOURBAR),
    ("same, energy drift (the integrator's error)", "iftomm.fourbar.ref", _DRIFT),
)

# not outputs: wall times, file names, declared bounds and ranges; events are compared as sequences
EXCLUDE = re.compile(r"(^|\.)timing\.|^files|(^|\.)(loss_)?events\[|\.bound$|\.(low|high)$")
COUNTS = re.compile(
    r"(^|\.)stats\.(events|restarts|lock_trials|segments)$|\.n_cycles$|(^|\.)loss_counts\.|contact_lost_entirely$"
)
WORK = re.compile(r"(^|\.)stats\.(nfev|steps)$")  # solver work: shows changed step-size decisions
ENV_NOTES = ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE", "OPENBLAS_NUM_THREADS", "GLIBC_TUNABLES",
             "NPY_DISABLE_CPU_FEATURES", "MBSUITE_NATIVE_EXTRA_CFLAGS")
PROBE = (
    "import json, platform, numpy, scipy, scipy.linalg, mujoco, mbsuite\n"
    "blas = numpy.__config__.CONFIG.get('Build Dependencies', {}).get('blas', {})\n"
    "print(json.dumps({'numpy': numpy.__version__, 'scipy': scipy.__version__, 'mujoco': mujoco.__version__,"
    " 'openblas': blas.get('version'), 'python': platform.python_version(),"
    " 'libc': ' '.join(platform.libc_ver()), 'mbsuite': mbsuite.__file__}))\n"
)


def cpu_info() -> tuple[str, set[str]]:
    """CPU model name and flags of the first processor in /proc/cpuinfo."""
    name, flags = "unknown", set()
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return name, flags
    for line in text.splitlines():
        key, _, val = line.partition(":")
        key = key.strip()
        if key == "model name" and name == "unknown":
            name = val.strip()
        elif key == "flags" and not flags:
            flags = set(val.split())
    return name, flags


def supported(kernel: str, flags: set[str]) -> bool:
    """Whether this CPU has every instruction set the kernel family uses."""
    return all(any(f in flags for f in group) for group in KERNELS[kernel].needs)


def child_env(kernel: str, code: Path | None = None) -> dict[str, str]:
    """os.environ plus this kernel's OPENBLAS_CORETYPE (removed for 'default'), with OpenBLAS naming its core, and
    the copy of mbsuite in `code` first on the import path."""
    env = dict(os.environ)
    if code is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(code), *filter(None, [os.environ.get("PYTHONPATH")])])
    coretype = KERNELS["default" if kernel == REPEAT else kernel].coretype
    if coretype is None:
        env.pop("OPENBLAS_CORETYPE", None)
    else:
        env["OPENBLAS_CORETYPE"] = coretype
    env["OPENBLAS_VERBOSE"] = "2"
    return env


def cores(stderr: str) -> list[str]:
    """The 'Core: <name>' lines OpenBLAS printed (one per library)."""
    return re.findall(r"^Core: (\S+)", stderr, flags=re.M)


def package_dir() -> Path | None:
    """The directory of the mbsuite package this Python imports (the working tree for an editable install)."""
    spec = importlib.util.find_spec("mbsuite")
    return Path(spec.origin).parent if spec is not None and spec.origin is not None else None


def snapshot(dest: Path) -> Path | None:
    """Copy mbsuite and its model files (mjcf/, models_urdf/) into `dest`: every run imports the same code even if
    the working tree is edited meanwhile. Returns the directory to put on PYTHONPATH."""
    pkg = package_dir()
    if pkg is None:
        return None
    shutil.copytree(pkg, dest / pkg.name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for folder in ("mjcf", "models_urdf"):
        if (pkg.parent / folder).is_dir():
            shutil.copytree(pkg.parent / folder, dest / folder)
    return dest


def source_fingerprint() -> dict[str, str]:
    """Hash of every file of mbsuite's package and models: a concurrent edit between runs changes it."""
    pkg = package_dir()
    if pkg is None:
        return {}
    out: dict[str, str] = {}
    for root in (pkg, pkg.parent / "mjcf", pkg.parent / "models_urdf"):
        if root.is_dir():
            for p in sorted(root.rglob("*")):
                if p.is_file() and "__pycache__" not in p.parts and p.suffix not in (".so", ".pyc"):
                    out[str(p.relative_to(pkg.parent))] = hashlib.sha256(p.read_bytes()).hexdigest()[:12]
    return out


def flatten(obj: object) -> tuple[Values, dict[str, str]]:
    """Finite numbers of a JSON object as name -> value, and name -> quantity (the group its scale comes from: a
    signal's statistics, a numeric array, an energy book; else the number itself)."""
    values: Values = {}
    quantity: dict[str, str] = {}

    def walk(o: object, name: str, group: str | None) -> None:
        if isinstance(o, bool) or not isinstance(o, (int, float, dict, list)):
            return
        if isinstance(o, (int, float)):
            if math.isfinite(o) and not EXCLUDE.search(name):
                values[name] = float(o)
                quantity[name] = group or name
        elif isinstance(o, dict):
            for k, v in o.items():
                sub = f"{name}.{k}" if name else str(k)
                if group is None and re.search(r"(^|\.)signals\.[^.]+$", name):
                    walk(v, sub, name)
                elif group is None and name.endswith("energy_balance") and k != "relative":
                    walk(v, sub, name)
                else:
                    walk(v, sub, group)
        else:
            numeric = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in o)
            for i, v in enumerate(o):
                tag = v["name"] if isinstance(v, dict) and isinstance(v.get("name"), str) else str(i)
                walk(v, f"{name}[{tag}]", group or (f"{name}[]" if numeric else None))

    walk(obj, "", None)
    return values, quantity


def event_lists(obj: object, name: str = "") -> dict[str, list]:
    """Every list of events in a JSON object ('events', 'loss_events'), by its name."""
    found: dict[str, list] = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            sub = f"{name}.{k}" if name else k
            if isinstance(v, list) and (k == "events" or k.endswith("_events")):
                found[sub] = v
            else:
                found.update(event_lists(v, sub))
    return found


def window_stats(csv_path: Path, t_settle: float) -> Values:
    """Mean and (population) standard deviation of every CSV signal over t >= t_settle, exactly summed."""
    with csv_path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    names = [h.split(" [")[0].strip() for h in rows[0]]
    data = [[float(x) for x in r] for r in rows[1:] if r and float(r[0]) >= t_settle]
    out: Values = {}
    if not data:
        return out
    for j, n in enumerate(names[1:], start=1):
        col = [r[j] for r in data]
        mean = math.fsum(col) / len(col)
        out[f"signals.{n}.mean"] = mean
        out[f"signals.{n}.std"] = math.sqrt(math.fsum((x - mean) ** 2 for x in col) / len(col))
    return out


def run_command(mbsuite: str, cmd: Command, kernel: str, timeout: float, code: Path | None = None) -> dict:
    """One command under one kernel: flattened numbers, quantities, event lists, cores loaded, wall time."""
    env = child_env(kernel, code)
    with tempfile.TemporaryDirectory(prefix="digits_per_kernel_") as tmp:
        argv = [mbsuite, *cmd.argv, "--json"] + (["--out", tmp] if cmd.csv else [])
        t0 = time.perf_counter()
        try:
            p = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout, check=False)
        except subprocess.TimeoutExpired:
            return {"argv": argv[1:], "error": f"timeout after {timeout:.0f} s", "wall_s": timeout}
        wall = time.perf_counter() - t0
        rec: dict = {"argv": argv[1:], "wall_s": round(wall, 2), "cores": sorted(set(cores(p.stderr)))}
        if p.returncode != 0:
            rec["error"] = f"exit {p.returncode}: {p.stderr.strip()[-400:]}"
            return rec
        try:
            doc = json.loads(p.stdout)
        except json.JSONDecodeError as exc:
            rec["error"] = f"no JSON on stdout ({exc})"
            return rec
        values, quantity = flatten(doc)
        if cmd.csv and (Path(tmp) / "run.csv").is_file():
            t_settle = float(doc.get("solver", {}).get("t_settle") or 0.0)
            for name, v in window_stats(Path(tmp) / "run.csv", t_settle).items():
                if math.isfinite(v):
                    values[name] = v
                    quantity[name] = name.rsplit(".", 1)[0]
        rec.update(values=values, quantity=quantity, events=event_lists(doc),
                   counts={k: v for k, v in values.items() if COUNTS.search(k)},
                   work={k: v for k, v in values.items() if WORK.search(k)}, t_end=doc.get("t_end"))
        return rec


def probe(kernel: str, code: Path | None = None) -> dict:
    """Versions, the mbsuite imported and the cores OpenBLAS loads under this kernel's environment."""
    p = subprocess.run([sys.executable, "-P", "-c", PROBE], env=child_env(kernel, code), capture_output=True, text=True,
                       check=False)
    info = json.loads(p.stdout) if p.returncode == 0 and p.stdout.strip() else {"error": p.stderr.strip()[-400:]}
    info["cores"] = cores(p.stderr)
    return info


def relative_changes(base: dict, other: dict) -> tuple[dict[str, float], list[str]]:
    """Per name |dy| / max(|y|, s), s the largest magnitude of its quantity in base; names present in one run only."""
    bv, ov, q = base["values"], other["values"], base["quantity"]
    scale: dict[str, float] = {}
    for n, v in bv.items():
        scale[q[n]] = max(scale.get(q[n], 0.0), abs(v))
    rel: dict[str, float] = {}
    for n, y in bv.items():
        if n not in ov:
            continue
        dy = abs(ov[n] - y)
        den = max(abs(y), scale[q[n]])
        rel[n] = 0.0 if dy == 0 else (dy / den if den > 0 else math.inf)
    missing = sorted(set(bv) ^ set(ov))
    return rel, missing


def compare_events(base: dict, other: dict) -> str:
    """Whether the event sequences and counts are the same; how far event times moved."""
    parts: list[str] = []
    for name, be in base["events"].items():
        oe = other["events"].get(name, [])

        def sig(e: object) -> tuple:
            if not isinstance(e, dict):
                return (repr(e),)
            return tuple(sorted((k, v) for k, v in e.items() if not isinstance(v, float)))

        bs, os_ = [sig(e) for e in be], [sig(e) for e in oe]
        if bs != os_:
            i = next((k for k, (a, b) in enumerate(zip(bs, os_, strict=False)) if a != b), min(len(bs), len(os_)))
            parts.append(f"{name}: **differ** ({len(be)} vs {len(oe)}, first at #{i})")
            continue
        dt = max((abs(a[k] - b[k]) for a, b in zip(be, oe, strict=True) if isinstance(a, dict)
                  for k in a if isinstance(a[k], float)), default=0.0)
        parts.append(f"{name}: same ({len(be)})" + (f", max Δt {dt:.1e} s" if dt else (", same t" if be else "")))
    changed = [f"{k.rsplit('.', 1)[-1]} {base['counts'][k]:g}→{other['counts'].get(k, math.nan):g}"
               for k in base["counts"] if other["counts"].get(k) != base["counts"][k]]
    if changed:
        parts.append("counts **differ**: " + ", ".join(changed))
    elif base["counts"]:
        parts.append("counts same")
    work = [f"{k.rsplit('.', 1)[-1]} {base['work'][k]:g}→{other['work'].get(k, math.nan):g}"
            for k in base.get("work", {}) if other.get("work", {}).get(k) != base["work"][k]]
    if work:
        parts.append("solver work differs (" + ", ".join(work) + ")")
    return "; ".join(parts)


def cell(rel: float | None) -> str:
    """digits (relative change), 'bitwise', or 'n/a'."""
    if rel is None:
        return "n/a"
    if rel == 0:
        return "bitwise"
    if not math.isfinite(rel):
        return "0 (inf)"
    return f"{max(0, math.floor(-math.log10(rel)))} ({rel:.1e})"


def worst(rels: list[float | None]) -> float | None:
    """The largest relative change, None when nothing was compared."""
    got = [r for r in rels if r is not None]
    return max(got) if got else None


def table(header: list[str], rows: list[list[str]]) -> str:
    """A Markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kernels", help="comma list of kernel families to run (default: 'default' and every one of "
                    f"{', '.join(AUTO_KERNELS)} this CPU supports); choices: {', '.join(KERNELS)}")
    ap.add_argument("--quick", action="store_true",
                    help="only the BLAS-sensitive commands (" + ", ".join(c.key for c in COMMANDS if c.quick)
                    + "), no repeat of 'default'")
    ap.add_argument("--repeat-default", action=argparse.BooleanOptionalAction, default=None,
                    help="run 'default' a second time as a control (default: on, off with --quick)")
    ap.add_argument("--json-out", type=Path, help="write the raw results (every flattened number) here")
    ap.add_argument("--md-out", type=Path, help="also write the printed Markdown here")
    ap.add_argument("--jobs", type=int, default=1, help="commands run at once (default 1; results do not depend "
                    "on it, wall times do)")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds one command may take (default 900)")
    ap.add_argument("--mbsuite", default=None, help="the mbsuite executable (default: next to this Python)")
    ap.add_argument("--snapshot", action=argparse.BooleanOptionalAction, default=True,
                    help="run every command on a copy of mbsuite taken at start, so that edits of the working tree "
                    "made meanwhile cannot enter one kernel's runs and not another's (default: on)")
    args = ap.parse_args()

    t_start = time.perf_counter()
    cpu, flags = cpu_info()
    if args.kernels:
        wanted = [k.strip() for k in args.kernels.split(",") if k.strip()]
        unknown = [k for k in wanted if k not in KERNELS]
        if unknown:
            ap.error(f"unknown kernel(s) {unknown}; choices: {', '.join(KERNELS)}")
        wanted = ["default"] + [k for k in wanted if k != "default"]
    else:
        wanted = ["default", *AUTO_KERNELS]
    skipped = {k: "CPU lacks " + " + ".join("/".join(g) for g in KERNELS[k].needs if not any(f in flags for f in g))
               for k in wanted if not supported(k, flags)}
    kernels = [k for k in wanted if k not in skipped]
    if args.repeat_default if args.repeat_default is not None else not args.quick:
        kernels.append(REPEAT)
    commands = [c for c in COMMANDS if c.quick or not args.quick]
    mbsuite = args.mbsuite or str(Path(sys.executable).with_name("mbsuite"))
    if not Path(mbsuite).is_file():
        mbsuite = shutil.which("mbsuite") or ap.error("no mbsuite executable found; pass --mbsuite")

    def log(msg: str) -> None:
        print(f"[{time.perf_counter() - t_start:6.0f} s] {msg}", file=sys.stderr, flush=True)

    fingerprints: dict[str, dict[str, str]] = {"start": source_fingerprint()}
    tmp_code = tempfile.TemporaryDirectory(prefix="digits_per_kernel_code_")
    code = snapshot(Path(tmp_code.name)) if args.snapshot else None
    probes: dict[str, dict] = {}
    results: dict[str, dict[str, dict]] = {}
    for k in kernels:
        probes[k] = probe(k, code)
        log(f"{k}: OpenBLAS loads {', '.join(probes[k]['cores']) or '?'}; mbsuite from {probes[k].get('mbsuite')}")
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            futs = {c.key: pool.submit(run_command, mbsuite, c, k, args.timeout, code) for c in commands}
            results[k] = {}
            for c in commands:
                rec = futs[c.key].result()
                results[k][c.key] = rec
                log(f"  {k:18s} {c.key:30s} {rec.get('wall_s', 0):7.1f} s  {rec.get('error', '')}")
        fingerprints[f"after {k}"] = source_fingerprint()
    tmp_code.cleanup()

    # which core each run loaded, and whether the forced one took
    core_of = {k: sorted({c for rec in results[k].values() for c in rec.get("cores", [])}) for k in kernels}
    notes: list[str] = []
    for k in kernels:
        kern = KERNELS["default" if k == REPEAT else k]
        if kern.coretype and not set(core_of[k]) <= set(kern.prints):
            notes.append(f"forced {k} but OpenBLAS loaded {core_of[k]}")
        if len(core_of[k]) > 1 and not kern.coretype:
            notes.append(f"{k}: the runs loaded different cores {core_of[k]}")
    default_core = ", ".join(core_of["default"]) or "?"
    baselines = ["default"]
    if "Haswell" in kernels and core_of["default"] != core_of["Haswell"]:
        baselines.append("Haswell")

    # comparisons
    comp: dict[str, dict[str, dict]] = {}
    for b in baselines:
        comp[b] = {}
        for k in kernels:
            if k == b:
                continue
            per: dict[str, dict] = {}
            for c in commands:
                base, other = results[b][c.key], results[k][c.key]
                if "values" not in base or "values" not in other:
                    per[c.key] = {"error": base.get("error") or other.get("error")}
                    continue
                rel, missing = relative_changes(base, other)
                top = sorted(rel.items(), key=lambda kv: -kv[1])[:5]
                per[c.key] = {"rel": rel, "missing": missing, "events": compare_events(base, other),
                              "worst": [[n, r, base["values"][n]] for n, r in top if r > 0]}
            comp[b][k] = per

    def row_rel(b: str, k: str, key: str, pats: tuple[str, ...]) -> float | None:
        per = comp[b][k].get(key, {})
        if "rel" not in per:
            return None
        got = [r for n, r in per["rel"].items() if any(re.search(p, n) for p in pats)]
        return max(got) if got else None

    def row_own(b: str, k: str, key: str, pats: tuple[str, ...]) -> tuple[str, float] | None:
        """The row's least-kept output and its change relative to its own value, |dy| / |y|."""
        per = comp[b][k].get(key, {})
        got = [(r, n) for n, r in per.get("rel", {}).items() if r > 0 and any(re.search(p, n) for p in pats)]
        if not got:
            return None
        n = max(got)[1]
        y, yo = results[b][key]["values"][n], results[k][key]["values"][n]
        return n, abs(yo - y) / abs(y) if y else math.inf

    def head(k: str) -> str:
        return k if k == REPEAT or not core_of[k] else f"{k} [{'/'.join(core_of[k])}]"

    versions = {k: v for k, v in probes["default"].items() if k != "cores"}
    labels = {c.key: c.label for c in commands}
    out: list[str] = ["# Digits per OpenBLAS kernel family", ""]
    out.append(f"- CPU: {cpu}; flags: " + ", ".join(
        f for f in ("pni", "ssse3", "sse4_2", "avx", "avx2", "fma", "avx512f", "avx512bw", "avx512dq", "avx512vl")
        if f in flags) + " (pni = SSE3)")
    out.append(f"- numpy {versions.get('numpy')}, scipy {versions.get('scipy')}, mujoco {versions.get('mujoco')}, "
               f"OpenBLAS {versions.get('openblas')}, Python {versions.get('python')}, {versions.get('libc')}")
    out.append(f"- 'default' (no OPENBLAS_CORETYPE): OpenBLAS picked **{default_core}** (numpy's and scipy's library)")
    out.append("- kernels run: " + "; ".join(
        f"{k} → {'/'.join(core_of[k]) or '?'}" for k in kernels) + " (OpenBLAS prints its Prescott table as Katmai)")
    for k, why in skipped.items():
        out.append(f"- {KERNELS[k].label or k}: **not run**, {why} (never forced on a CPU without its instructions)")
    machine = {v: os.environ[v] for v in ENV_NOTES if v in os.environ}
    if machine:
        out.append("- this machine's environment sets " + ", ".join(f"{k}={v}" for k, v in machine.items())
                   + " (OPENBLAS_CORETYPE replaced per kernel, removed for 'default'; the others kept in every run)")
    else:
        out.append("- the environment sets none of " + ", ".join(ENV_NOTES))
    out.append("- durations: the scenes' defaults, nothing shortened"
               + (f"; --quick: only {', '.join(c.key for c in commands)}" if args.quick else ""))
    edits: dict[str, list[str]] = {}
    prev = fingerprints["start"]
    for when, fp in fingerprints.items():
        changed = sorted(n for n in set(fp) | set(prev) if fp.get(n) != prev.get(n))
        if changed:
            edits[when] = changed
        prev = fp
    code_id = hashlib.sha256(json.dumps(fingerprints["start"], sort_keys=True).encode()).hexdigest()[:12]
    if code is not None:
        out.append(f"- code: every run imported one copy of mbsuite and its model files, taken at start from "
                   f"{package_dir()} ({len(fingerprints['start'])} files, content hash {code_id})")
    else:
        out.append(f"- code: the working tree {package_dir()} (content hash at start {code_id}; --no-snapshot)")
    if edits:
        out.append("- mbsuite's working tree changed while this ran: "
                   + "; ".join(f"{when}: {', '.join(ch[:8])}{' ...' if len(ch) > 8 else ''}"
                               for when, ch in edits.items())
                   + (" (not used: the runs imported the copy taken at start)" if code is not None else
                      " — **the runs imported the edited files**: a kernel's differences may come from the edit; "
                      "'default (repeat)' shows whether they did"))
    for n in notes:
        out.append(f"- **{n}**")

    for b in baselines:
        cols = [k for k in kernels if k != b]
        out += ["", f"## Headline outputs against {head(b)}", ""]
        rows, own_notes = [], []
        for label, key, pats in ROWS:
            if key not in {c.key for c in commands}:
                continue
            rels = [row_rel(b, k, key, pats) for k in cols]
            forced = [r for k, r in zip(cols, rels, strict=True) if k != REPEAT]
            rows.append([label, *[cell(r) for r in rels], cell(worst(forced))])
            for k, r in zip(cols, rels, strict=True):
                own = row_own(b, k, key, pats)
                if own and r and cell(own[1]).split()[0] != cell(r).split()[0]:
                    own_notes.append(f"{labels[key]}, {k}: `{own[0]}` changed by {own[1]:.1e} of its own value "
                                     f"({cell(own[1]).split()[0]} digits that way)")
        out.append(table(["headline output", *[head(k) for k in cols], "agree to (forced kernels)"], rows))
        if own_notes:
            out += ["", "Relative to the output's own value |y| (the convention of docs/reproducibility.md) instead of "
                    "its quantity's largest magnitude:", ""] + [f"- {n}" for n in own_notes]

        out += ["", f"## Every finite number of each command's JSON (and CSV window mean/std) against {head(b)}", ""]
        rows = []
        for c in commands:
            rels: list[float | None] = []
            least, least_rel = "–", 0.0
            for k in cols:
                per = comp[b][k][c.key]
                r = max(per["rel"].values(), default=0.0) if "rel" in per else None
                rels.append(r)
                if per.get("worst") and k != REPEAT and r is not None and r > least_rel:
                    least, least_rel = f"`{per['worst'][0][0]}` ({k})", r
                if per.get("missing"):
                    notes.append(f"{c.key}, {k} vs {b}: names in one run only: {per['missing'][:5]}")
            rows.append([c.label, *[cell(r) for r in rels], least])
        out.append(table(["command", *[head(k) for k in cols], "least-kept number"], rows))

        ev_rows = []
        for c in commands:
            if not (results[b][c.key].get("events") or results[b][c.key].get("counts")):
                continue
            ev_rows.append([c.label, *[comp[b][k][c.key].get("events", "n/a") for k in cols]])
        if ev_rows:
            out += ["", f"## Event sequences and counts against {head(b)}", ""]
            out.append(table(["command", *[head(k) for k in cols]], ev_rows))

    errors = [f"{k} {c}: {r['error']}" for k in kernels for c, r in results[k].items() if "error" in r]
    extra = [n for n in notes if "names in one run only" in n] + errors
    if extra:
        out += ["", "## Notes", ""] + [f"- {n}" for n in extra]
    walls = {c.key: [results[k][c.key].get("wall_s", math.nan) for k in kernels] for c in commands}
    out += ["", "## Runs", ""]
    out.append(table(["command", "argv", "t_end [s]", "wall per kernel [s]"],
                     [[c.key, "`mbsuite " + " ".join(c.argv) + " --json" + (" --out DIR`" if c.csv else "`"),
                       str(results["default"][c.key].get("t_end") or "–"),
                       " / ".join(f"{w:.0f}" for w in walls[c.key])] for c in commands]))
    total = time.perf_counter() - t_start
    out += ["", f"Total wall time {total:.0f} s for {len(kernels)} kernel runs of {len(commands)} commands "
            f"(--jobs {args.jobs})."]
    text = "\n".join(out)
    print(text)
    if args.md_out:
        args.md_out.write_text(text + "\n")
    if args.json_out:
        payload = {
            "cpu": cpu, "flags": sorted(flags), "versions": versions, "probes": probes, "core_of": core_of,
            "skipped": skipped, "machine_env": machine, "code_hash": code_id, "source_edits": edits,
            "total_wall_s": round(total, 1),
            "rows": [{"label": lab, "command": key, "patterns": list(p)} for lab, key, p in ROWS],
            "results": results, "comparisons": comp,
        }
        args.json_out.write_text(json.dumps(payload, indent=1, default=str) + "\n")


if __name__ == "__main__":
    main()
