"""Build the documentation site (mkdocs-material + mkdocstrings, strict: any warning is an error).

The pages are the repository's own documents, gathered into `docs/` at build time so that each exists once: the top
README becomes the home page, each model's README its model page; `docs/gallery.md` shows every figure the suite writes
beside the command that makes it and the CPU time that command took (the figures are made here, by those very
commands, unless `--no-figures`).

    python scripts/build_docs.py               # -> out/site/
    python scripts/build_docs.py --rebuild     # rerun every gallery command: no figure cache, no stored results
    python scripts/build_docs.py --jobs 1      # one gallery command at a time (default: two)
    python scripts/build_docs.py --no-figures  # reuse the figures of an earlier build

`make docs` runs it (`make docs DOCS_FLAGS=--rebuild` for the second form). On a fresh clone it takes about two
minutes on two cores: the long studies are drawn from results committed with the repository, the other commands run,
two at a time (`--jobs`; an entry that reads another's output waits for it). A later build runs only what changed.

What is kept where:

* `out/gallery-cache/<key>/` (not committed): each entry's figures, the command's whole `--out` directory (`out/`,
  which later entries such as `mbsuite compare` read) and `meta.json` (command, key, CPU time -- the user+system time
  of the command's process and those it waited for (`wait4`) --, wall time, date). An entry whose key has a complete
  cache directory is copied from it; any other entry is run, and only it.
* `docs/gallery-stores/<slug>.jsonl` (committed; `<slug>` is the entry's title in lower case, hyphenated): the sweep
  store (`--store`, `mbsuite.analysis.sweep`) of each entry in `STUDIES`, the commands of a minute or more (design
  studies, the MuJoCo frequency sweep): the header and the result records only (claims dropped), ordered by key. Each
  record is one evaluated point and its summary (a few numbers, and the scene it ran: most of a record's kilobyte),
  not a time series; the four stores hold about 0.4 MB. Beside each, `<slug>.json` (committed) names the command
  and the `cache_key` the store was made for, the study's CPU and wall time, its date, record count, size and
  SHA-256.
* `out/gallery-stores/` (not committed): the stores the studies run on (`--store` there: the lock file and the
  claims of a running study stay out of the repository; an interrupted computation resumes from it).

A study entry whose figure is not cached runs its command with `--store` on a copy of its committed store when the
manifest's key is the entry's key and the store's SHA-256 the manifest's: every point is then read, none computed, and
drawing the figure takes seconds; the gallery shows the study's own CPU time and date from the manifest. Otherwise the
store is stale ("entry N: inputs changed, recomputing (about X min)"): it is discarded, the study computed afresh and
its results and manifest written back -- commit them with the change that made them. A cached figure of a study is
reused only while its committed store is valid, so that what is committed always reproduces the figure.

The key (`cache_key`) is the SHA-256 of

* the command line;
* the content of every scene file it names (`model/scene` -> `mbsuite/models/<model>/scenes/<scene>.toml`) and of
  every file such a scene names by a relative path (a line file, say);
* the content of the tracked files (`git ls-files`, read from the work tree, so uncommitted edits count) of each model
  package the command names (`pantograph`, `catenary/...`, `drive` -> drives, ...) and of the model packages those
  import or name (`mbsuite.models.X`, `from ..X`, a string "X": the catenary runs the registry's pantograph), and of
  `mbsuite/analysis` -- but their Markdown (a model's README), which no run reads;
* the keys of the gallery entries whose output it reads (`out/docs-figures/gallery_N` in the command).

Deliberately not in the key: the rest of the package (`mbsuite/engines`, `components`, `cli`, the top-level modules)
and the installed dependencies -- hashing them would rebuild every figure (a quarter of an hour) on any change to the
shared code. After such a change, or a dependency upgrade, build with `--rebuild` (which recomputes the stored
studies too, a quarter of an hour or more on two cores, and rewrites their committed stores). Old cache directories
are not pruned; `rm -rf out/gallery-cache` empties the cache.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import datetime
import hashlib
import json
import os
import re
import resource
import shlex
import shutil
import subprocess
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
MODELS = ("pantograph", "coupler", "drives", "rotational", "catenary", "iftomm")
CACHE = ROOT / "out" / "gallery-cache"
STORES = DOCS / "gallery-stores"  # committed: the stored results of the long studies (`STUDIES`)
WORK_STORES = ROOT / "out" / "gallery-stores"  # the stores those studies run on (lock files, claims, resumption)
ALIASES = {"drive": "drives"}  # command words naming a model package under another name

# (title, command, figure files written into --out, what the figure shows)
GALLERY: list[tuple[str, str, list[str], str]] = [
    ("Pantograph frequency response", "mbsuite freqresp pantograph --methods linear,mujoco",
     ["freqresp.png"], "Response amplitude and phase of F1, F2, HD and y_d per unit ram amplitude, from the "
     "linearisation about the mean ram height and from MuJoCo time simulations, with the thesis' resonances."),
    ("Pantograph time history", "mbsuite run pantograph", ["run.png"],
     "The lab scene's signals over time, one panel per group of signals of one unit and comparable scale."),
    ("EN 50318 passage", "mbsuite catenary catenary/en50318 --speed 250 --quality",
     ["force_uplift_reference2mass_250kmh.png", "quality_reference2mass_250kmh.png"],
     "Contact force, contact-wire height and uplift along the section; the current-collection quality criteria."),
    ("Coupler criteria", "mbsuite coupler criteria --quick",
     ["fig6_phi_difference.png", "fig9_criteria_single.png", "fig10_c5_double.png"],
     "Kinematic errors and criteria c1-c5 of the single and double couplers over a revolution."),
    ("Drives efficiency", "mbsuite drive efficiency drives/step_up_efficiency --loads 0.2,0.4,0.6 --duration 3",
     ["efficiency.png"], "Efficiency and loss breakdown of the step-up drive against load speed."),
    ("Work-precision", "mbsuite workprecision rotational/coupled_clutches --quick --repeats 1", ["workprecision.png"],
     "Error against wall time for every engine and setting; each point labelled with its step or tolerance."),
    ("Two pantographs on one train", "mbsuite catenary catenary/en50318_two_pantographs --speed 300 --quality",
     ["train_force_300kmh.png", "quality_train_300kmh.png"],
     "Both pantographs' contact forces along the section 200 m apart at 300 km/h; their quality criteria."),
    ("A parameter study of an analysis", "mbsuite modes pantograph --vary params.mh=10:16:2", ["study.png"],
     "The pantograph's natural frequencies against its head mass (`--vary` on modes, freqresp, equilibrium, "
     "catenary and the coupler and drive commands)."),
    ("A sweep of time runs", "mbsuite sweep pantograph --vary input.frequency=2,4,6", ["sweep.png"],
     "Each output signal's range over the swept values."),
    ("Coupler dynamics", "mbsuite coupler dynamics coupler/double_lateral", ["run.png"],
     "Input torque, coupler-angle error, closure residual and link forces of the double coupler on MuJoCo."),
    ("Coupler revolution", "mbsuite coupler fpp", ["fpp_single.png"],
     "The single coupler's pose over a revolution of its input (the forward position problem by continuation)."),
    ("Drive run", "mbsuite drive run drives/step_up_pwm", ["run.png"],
     "Speeds, spring twist, energies and clutch/brake commands of the PWM-switched step-up drive."),
    ("Coupled clutches against the Modelica reference", "mbsuite rotational coupled-clutches", ["coupled_clutches.png"],
     "The Modelica Standard Library's CoupledClutches example on both paths against its reference result."),
    ("Drive design tables", "mbsuite drive design tables", ["design_tables.png"],
     "The thesis' Chapter 5 design tables recomputed."),
    ("A stitched line", "mbsuite catenary catenary/en50318_stitched --speed 300 --quality",
     ["force_uplift_reference2mass_300kmh.png", "quality_reference2mass_300kmh.png"],
     "The 2-mass pantograph under the stitched EN 50318 line at 300 km/h: force, wire height and uplift; quality."),
    ("A line of your own", "mbsuite catenary catenary/example_line", ["force_uplift_reference2mass_250kmh.png"],
     "A tension section from a line file: varying spans, stitch wires, masses, presag and a height profile."),
    ("A route through two overlaps", "mbsuite catenary catenary/en50318_route --speed 300",
     ["force_uplift_reference2mass_300kmh.png"],
     "Three EN 50318 tension sections joined by two overlaps at 300 km/h: the head's force and each contact wire's, "
     "the wire it meets, the steady arms' uplift (each section's until the pantograph has left it), overlaps and "
     "anchors marked."),
    ("Sensitivity of the Eppinger pantograph under the wire",
     "mbsuite sensitivity catenary/en50318_eppinger --set solver.engine=mujoco --vary pantograph.params.mh=10:17 "
     "--vary pantograph.params.kh=1500:3000 --vary pantograph.params.bh=5:20 --vary pantograph.params.b2=100:220 "
     "--vary pantograph.params.Pg=6.8e5:7.6e5 --method morris --n 4 --seed 1 --yes", ["sensitivity.png"],
     "Morris elementary effects (mu*, with 95 % intervals) of five pantograph parameters on the EN 50318 statistics."),
    ("The best Eppinger pantograph for the line",
     "mbsuite optimise catenary/en50318_eppinger --set solver.engine=mujoco --vary pantograph.params.kh=1500:3000 "
     "--vary pantograph.params.b2=100:220 --vary pantograph.params.bh=5:20 --start pantograph.params.kh=2250 "
     "--start pantograph.params.b2=157.5 --start pantograph.params.bh=10.8 --objective sigma --band AC --speed 250 "
     "--maxiter 1 --popsize 2 --seed 1 --yes", ["optimise.png"],
     "Differential evolution for the lowest sigma with Fm inside the EN 50367 band: every design evaluated."),
    ("Sigma against the mean force",
     "mbsuite optimise catenary/en50318 --vary params.c2=50:130 --vary params.F0=100:140 --objective sigma "
     "--against Fm --pareto 95,105,115 --band AC --speed 250 --maxiter 3 --popsize 4 --seed 2 --yes",
     ["pareto.png"],
     "The epsilon-constraint front of sigma against Fm at 250 km/h."),
    ("Lumped pantographs fitted to the multibody one", "mbsuite pantograph fit-lumped --stages 3", ["lumped_fit.png"],
     "The Eppinger pantograph's driving-point receptance against its 3-stage lumped and transfer-function fits."),
    ("Two runs compared", "mbsuite compare out/docs-figures/gallery_2 out/docs-figures/gallery_15",
     ["compare_signals.png"], "The 2-mass pantograph at 250 km/h under the EN 50318 line (A: the passage above) and "
     "under the line of your own (B): the statistics side by side with their differences (table, compare.csv), the "
     "signals overlaid along the line; it reads the summary.json files the two gallery commands above wrote."),
]

#: The entries that are long studies (a minute or more): each runs with `--store` on its committed sweep store
#: `docs/gallery-stores/<slug>.jsonl`, valid while its manifest's key is the entry's key (module docstring).
STUDIES = frozenset({
    "Pantograph frequency response",
    "Sensitivity of the Eppinger pantograph under the wire",
    "The best Eppinger pantograph for the line",
    "Sigma against the mean force",
})


def _gather() -> None:
    """Copy the repository's documents into docs/ (generated pages; git-ignored), rewriting their links."""
    text = (ROOT / "README.md").read_text()
    for m in MODELS:
        text = re.sub(rf"\]\(mbsuite/models/{m}/README\.md(#[^)]*)?\)", rf"](models/{m}.md\1)", text)
    text = re.sub(r"\]\(docs/([A-Za-z_]+\.md)\)", r"](\1)", text)  # docs/accuracy.md, docs/stability.md, ...
    (DOCS / "index.md").write_text(text)
    (DOCS / "models").mkdir(exist_ok=True)
    for m in MODELS:
        page = (ROOT / "mbsuite" / "models" / m / "README.md").read_text()
        page = re.sub(r"\]\(\.\./\.\./\.\./docs/([A-Za-z_]+\.md)\)", r"](../\1)", page)
        page = re.sub(r"\]\((\.\./)+([^)]+)\)", r"] (`\2`)", page)  # other repository paths: shown as paths
        (DOCS / "models" / f"{m}.md").write_text(page)


#: files no run reads: a package's documentation (its README) is left out of the key
UNREAD_SUFFIXES = (".md",)


def _tracked(root: Path, rel: str) -> list[Path]:
    """The tracked files under `root/rel` (`git ls-files`; every file there when `root` is not a git work tree) but
    its documentation (`UNREAD_SUFFIXES`), which no run reads."""
    try:
        res = subprocess.run(["git", "ls-files", "-z", "--", rel], cwd=root, capture_output=True, check=True)
        names = [n for n in res.stdout.decode().split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = []
    files = ([root / n for n in names] if names else
             [f for f in (root / rel).rglob("*") if f.is_file() and "__pycache__" not in f.parts])
    return sorted(f for f in files if f.suffix not in UNREAD_SUFFIXES)


def _scene_inputs(scene: Path) -> list[Path]:
    """A scene file and every existing file one of its string values names relative to it (a line file, say)."""
    found = [scene]

    def walk(v: object) -> None:
        if isinstance(v, dict):
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)
        elif isinstance(v, str) and v and ("/" in v or "." in v) and (scene.parent / v).is_file():
            found.append((scene.parent / v).resolve())

    try:
        walk(tomllib.loads(scene.read_text()))
    except tomllib.TOMLDecodeError:
        pass  # the command will say so; the file's content is in the key all the same
    return found


def _models_named(cmd: str, root: Path) -> set[str]:
    """The model packages a command names (a word `model` or `model/scene`) and, transitively, those they import or
    name in a string (`get_model("pantograph")`: the catenary runs the registry's pantograph under the wire)."""
    models = root / "mbsuite" / "models"
    known = {d.name for d in models.iterdir() if d.is_dir() and (d / "__init__.py").is_file()}
    named = set()
    for tok in shlex.split(cmd)[1:]:
        word = ALIASES.get(tok, tok.split("/")[0])
        if word in known:
            named.add(word)
    todo = list(named)
    while todo:
        for f in (models / todo.pop()).rglob("*.py"):
            text = f.read_text(errors="replace")
            for m in re.findall(r"mbsuite\.models\.(\w+)|from \.\.(\w+)|[\"'](\w+)[\"']", text):
                dep = m[0] or m[1] or m[2]
                if dep in known and dep not in named:
                    named.add(dep)
                    todo.append(dep)
    return named


def cache_key(cmd: str, root: Path = ROOT, deps: dict[int, str] | None = None) -> str:
    """The figure-cache key of a gallery command: see the module docstring for what it covers."""
    h = hashlib.sha256()
    h.update(b"command\0" + cmd.encode() + b"\0")
    files: set[Path] = set()
    for tok in shlex.split(cmd)[1:]:
        if tok.count("/") == 1 and not tok.startswith("out/"):
            model, scene = tok.split("/")
            path = root / "mbsuite" / "models" / ALIASES.get(model, model) / "scenes" / f"{scene}.toml"
            if path.is_file():
                files.update(_scene_inputs(path))
    for model in sorted(_models_named(cmd, root)):
        files.update(_tracked(root, f"mbsuite/models/{model}"))
    files.update(_tracked(root, "mbsuite/analysis"))
    for f in sorted(files):
        rel = f.relative_to(root) if f.is_relative_to(root) else f
        h.update(b"file\0" + str(rel).encode() + b"\0")
        h.update(hashlib.sha256(f.read_bytes()).digest() if f.is_file() else b"missing")
    for n in sorted(int(n) for n in re.findall(r"out/docs-figures/gallery_(\d+)", cmd)):
        h.update(f"entry {n}\0{(deps or {}).get(n, 'unknown')}\0".encode())
    return h.hexdigest()


def _run(cmd: str, d: Path) -> float:
    """Run one gallery command (`mbsuite ...`) with `--out d`, from the repository root, its messages into `d.log`
    (shown when it fails); the CPU time (user + system) of the command and the processes it waited for."""
    argv = [sys.executable, "-m", "mbsuite.cli", *shlex.split(cmd)[1:], "--out", str(d)]
    log = d.with_name(d.name + ".log")
    log.parent.mkdir(parents=True, exist_ok=True)
    with log.open("wb") as err:
        proc = subprocess.Popen(argv, cwd=ROOT, env={**os.environ, "MPLBACKEND": "Agg"}, stdout=subprocess.DEVNULL,
                                stderr=err)
        try:
            _, status, usage = os.wait4(proc.pid, 0)  # this child's own rusage: other entries run meanwhile
        except BaseException:
            proc.kill()
            proc.wait()
            raise
        proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        sys.stderr.write(log.read_text(errors="replace")[-4000:])
        raise SystemExit(f"gallery: {cmd!r} failed (exit {proc.returncode}); its messages are in {log}")
    return usage.ru_utime + usage.ru_stime


def _cached(cache: Path, key: str, files: list[str]) -> dict | None:
    """The metadata of a complete cache entry for `key` (its meta.json and every figure present), else None."""
    meta = cache / key / "meta.json"
    if not meta.is_file() or not all((cache / key / f).is_file() for f in files):
        return None
    try:
        return json.loads(meta.read_text())
    except (OSError, ValueError):
        return None


def _slug(title: str) -> str:
    """A gallery entry's file name: its title in lower case, words joined by hyphens."""
    return re.sub(r"[^a-z0-9]+", "-", title.lower()).strip("-")


def _manifest(store: Path) -> dict | None:
    """The manifest written next to a committed store (`<slug>.json`), None when absent or unreadable."""
    try:
        man = json.loads(store.with_suffix(".json").read_text())
    except (OSError, ValueError):
        return None
    return man if isinstance(man, dict) else None


def _valid_store(store: Path, key: str) -> dict | None:
    """The manifest of the committed store `store` when it was made for `key` and the store is the file the manifest
    names (its SHA-256); else None."""
    man = _manifest(store)
    if man is None or man.get("key") != key or not store.is_file():
        return None
    if hashlib.sha256(store.read_bytes()).hexdigest() != man.get("sha256"):
        return None
    return man


def _results(store: Path) -> int:
    """The number of result records in a sweep store (0 when there is none)."""
    try:
        return store.read_bytes().count(b'"type":"result"')
    except OSError:
        return 0


def _compact(work: Path, store: Path) -> None:
    """Write the header and the result records of the work store `work` into `store`, byte for byte: the claims,
    torn lines and repeated keys left out, the results ordered by key (a recomputation with equal results writes an
    equal file). Their checksums stay; whoever reads the store checks them."""
    header, results = None, {}
    for line in work.read_bytes().splitlines():
        try:
            body = json.loads(line)["body"]
            kind = body["type"]
        except (ValueError, TypeError, KeyError):
            continue
        if kind == "header" and header is None:
            header = line
        elif kind == "result" and isinstance(body.get("key"), str):
            results.setdefault(body["key"], line)
    if header is None:
        raise SystemExit(f"gallery: {work} is not a sweep store")
    tmp = store.with_name(f".{store.name}.tmp")
    tmp.write_bytes(b"".join(x + b"\n" for x in [header, *(results[k] for k in sorted(results))]))
    tmp.replace(store)


def _prepare_store(store: Path, work: Path, key: str, rebuild: bool, label: str) -> dict | None:
    """Make the work store a study entry runs on: a copy of the committed store when that is valid for `key` (its
    manifest returned), else -- the committed store discarded -- an empty one, or the points of an interrupted
    computation of the same key (None returned)."""
    work.parent.mkdir(parents=True, exist_ok=True)
    man = None if rebuild else _valid_store(store, key)
    if man is not None:
        shutil.copyfile(store, work)
        work.with_suffix(".key").unlink(missing_ok=True)
        return man
    old = _manifest(store)
    if rebuild:
        why = "--rebuild, recomputing its stored results"
    elif old is None or not store.is_file():
        why = "no stored results, computing them"
    elif old.get("key") != key:
        why = "inputs changed, recomputing"
    else:
        why = "stored results damaged, recomputing"
    if old is not None and isinstance(old.get("wall_seconds"), int | float):
        why += f" (about {max(1, round(old['wall_seconds'] / 60))} min)"
    store.unlink(missing_ok=True)
    store.with_suffix(".json").unlink(missing_ok=True)
    mark = work.with_suffix(".key")
    if not rebuild and mark.is_file() and mark.read_text().strip() == key and work.is_file():
        why += f", resuming from the {_results(work)} points of an interrupted run"
    else:
        work.unlink(missing_ok=True)
        mark.write_text(key + "\n")
    print(f"{label}: {why}", file=sys.stderr)
    return None


def _entry(cmd: str, files: list[str], d: Path, key: str, cache: Path = CACHE, rebuild: bool = False,
           run: Callable[[str, Path], float | None] = _run, store: Path | None = None, label: str = "gallery entry",
           work: Path | None = None) -> dict:
    """Make one gallery entry's figures in cache/<key>/ (or reuse them) and its output directory `d`; its metadata.

    A reused entry's output directory is restored from the cache when absent, for later entries that read it. A study
    entry (`store`: its committed sweep store) runs with `--store` on the work store `work` (default
    `cache/../gallery-stores/<store's name>`), made from the committed store while that is valid for `key`; a
    computed study's results are written back into `store` and its manifest. Its metadata carries the study's CPU
    time, not that of drawing a figure from its stored results."""
    meta = None if rebuild else _cached(cache, key, files)
    if meta is not None and store is not None and _valid_store(store, key) is None:
        meta = None  # the committed store must hold what the figure shows: a fresh clone draws it from there
    if meta is not None:
        if not d.is_dir() and (cache / key / "out").is_dir():
            shutil.copytree(cache / key / "out", d)
        return {**meta, "reused": True}
    if d.exists():
        shutil.rmtree(d)
    man = None
    if store is not None:
        work = work or cache.parent / "gallery-stores" / store.name
        man = _prepare_store(store, work, key, rebuild, label)
        before = _results(work)
        cmd_run = f"{cmd} --store {shlex.quote(str(work))}"
    else:
        cmd_run = cmd
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    used = run(cmd_run, d)
    wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = used if used is not None else (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    tmp = cache / f"{key}.tmp"
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    for f in files:
        hits = sorted(d.rglob(f))
        if not hits:
            raise SystemExit(f"gallery: {cmd!r} wrote no {f} into {d}")
        shutil.copy2(hits[0], tmp / f)
    shutil.copytree(d, tmp / "out")
    now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
    meta = {"command": cmd, "key": key, "cpu_seconds": round(cpu, 3), "wall_seconds": round(wall, 3), "date": now}
    if store is not None and work is not None:
        rel = str(store.relative_to(ROOT)) if store.is_relative_to(ROOT) else str(store)
        if man is not None:  # drawn from the committed results: the study's own times and date
            meta = {**meta, "cpu_seconds": man["cpu_seconds"], "wall_seconds": man["wall_seconds"],
                    "date": man["date"], "store": rel, "drawn_cpu_seconds": round(cpu, 3)}
            if _results(work) > before:
                print(f"{label}: its stored results lacked {_results(work) - before} of this run's points, computed "
                      f"now (another machine's rounding?); {rel} is kept as it is (--rebuild refreshes it)",
                      file=sys.stderr)
        else:
            _compact(work, store)
            body = store.read_bytes()
            man = {"command": cmd, "key": key, "cpu_seconds": meta["cpu_seconds"], "wall_seconds": meta["wall_seconds"],
                   "date": now, "records": _results(store), "bytes": len(body),
                   "sha256": hashlib.sha256(body).hexdigest()}
            store.with_suffix(".json").write_text(json.dumps(man, indent=2) + "\n")  # last: the store is now valid
            work.with_suffix(".key").unlink(missing_ok=True)
            meta = {**meta, "store": rel}
    (tmp / "meta.json").write_text(json.dumps(meta, indent=2) + "\n")  # written last: an entry is complete or absent
    if (cache / key).exists():
        shutil.rmtree(cache / key)
    tmp.rename(cache / key)
    return {**meta, "reused": False}


def _keys() -> list[str]:
    """Every gallery entry's cache key, in order (an entry reading an earlier one's output depends on its key)."""
    keys: list[str] = []
    for _title, cmd, _files, _what in GALLERY:
        keys.append(cache_key(cmd, ROOT, dict(enumerate(keys))))
    return keys


def _prepare_native() -> None:
    """Compile mbsuite's native layer once before the entries run side by side (each would compile it otherwise)."""
    subprocess.run([sys.executable, "-c", "from mbsuite.engines import native; native.load()"], cwd=ROOT, check=True)


def _figures(out: Path, rebuild: bool = False, jobs: int = 2) -> list[dict]:
    """Make (or take from the cache) every gallery entry's figures and copy them into docs/gallery/; their metadata.

    Up to `jobs` commands run at a time; an entry that reads another's output waits for it."""
    dest = DOCS / "gallery"
    dest.mkdir(exist_ok=True)
    keys = _keys()
    if any(rebuild or _cached(CACHE, key, files) is None for key, (_, _, files, _) in zip(keys, GALLERY, strict=True)):
        _prepare_native()

    def one(i: int) -> dict:
        title, cmd, files, _what = GALLERY[i]
        for n in sorted({int(n) for n in re.findall(r"out/docs-figures/gallery_(\d+)", cmd)}):
            done[n].result()  # an earlier entry (submitted before this one): its output directory first
        store = STORES / f"{_slug(title)}.jsonl" if title in STUDIES else None
        meta = _entry(cmd, files, out / f"gallery_{i}", keys[i], CACHE, rebuild, store=store, label=f"entry {i}",
                      work=WORK_STORES / f"{_slug(title)}.jsonl")
        if meta["reused"]:
            how = "cached"
        elif "drawn_cpu_seconds" in meta:
            how = f"drawn from {meta['store']} in {meta['drawn_cpu_seconds']:.1f} s CPU"
        else:
            how = f"ran in {meta['wall_seconds']:.1f} s"
        print(f"gallery {i:2d} {how}: {cmd}", file=sys.stderr)
        for f in files:
            shutil.copy2(CACHE / keys[i] / f, dest / _name(i, f))
        return meta

    done: dict[int, concurrent.futures.Future] = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        try:
            for i in range(len(GALLERY)):
                done[i] = pool.submit(one, i)
            return [done[i].result() for i in range(len(GALLERY))]
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)
            raise


def _name(i: int, f: str) -> str:
    """A gallery figure's file: its command's index and the name the command gave it (several write `run.png`)."""
    return f"{i:02d}_{f}"


def _gallery_page(metas: list[dict | None]) -> None:
    lines = ["# Gallery", "", "Every figure below is written by the command above it (`--out DIR`); the same "
             "directory also holds the CSV files (SI units in the header) and `summary.json`. The CPU time is the "
             "command's (user plus system) on the machine and the day its figures were made: the build reuses a "
             "figure whose command and inputs are unchanged, and draws a long study's figure from the study's "
             "results stored with the repository while they are valid for its inputs (`scripts/build_docs.py`).", ""]
    for i, ((title, cmd, files, what), meta) in enumerate(zip(GALLERY, metas, strict=True)):
        lines += [f"## {title}", "", f"```\n{cmd} --out DIR\n```", ""]
        if meta is not None and meta.get("store"):
            lines += [f"CPU time: {meta['cpu_seconds']:.1f} s (computed {meta['date'][:10]}; the figure is drawn from "
                      f"the study's stored results, `{meta['store']}`).", ""]
        elif meta is not None:
            lines += [f"CPU time: {meta['cpu_seconds']:.1f} s (made {meta['date'][:10]}).", ""]
        lines += [what, ""]
        lines += [f"![{title}](gallery/{_name(i, f)})" for f in files] + [""]
    (DOCS / "gallery.md").write_text("\n".join(lines))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-figures", action="store_true", help="do not remake the gallery's figures")
    ap.add_argument("--rebuild", action="store_true",
                    help="rerun every gallery command, ignoring the figure cache and the studies' stored results")
    ap.add_argument("--jobs", type=int, default=2, metavar="N", help="gallery commands run at a time (default 2)")
    args = ap.parse_args(argv)
    _gather()
    t0 = time.perf_counter()
    if args.no_figures:
        metas: list[dict | None] = [_cached(CACHE, key, files) for key, (_, _, files, _) in zip(_keys(), GALLERY,
                                                                                               strict=True)]
    else:
        metas = list(_figures(ROOT / "out" / "docs-figures", args.rebuild, args.jobs))
    _gallery_page(metas)
    missing = [_name(i, f) for i, (_, _, files, _) in enumerate(GALLERY) for f in files
               if not (DOCS / "gallery" / _name(i, f)).is_file()]
    if missing:
        print(f"gallery figures missing: {missing}; run without --no-figures", file=sys.stderr)
        return 2
    t1 = time.perf_counter()
    print(f"gallery: {t1 - t0:.1f} s", file=sys.stderr)
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    code = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(ROOT / "mkdocs.yml")],
                          cwd=ROOT, env=env).returncode
    print(f"mkdocs: {time.perf_counter() - t1:.1f} s", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
