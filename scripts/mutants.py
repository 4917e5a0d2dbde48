"""Seeded defects: does the default test suite catch realistic physics mistakes with a failing physics assertion?

Each mutation (`scripts/mutations/`, one module per model) is one plausible error in the physics code (a sign flipped
in an equation of motion, an operating point shifted, a regularisation band widened, a loss term dropped, a bound scaled
by 1 %, an event one step late, a Jacobian row swapped...). Mutations run in scratch copies of the committed tree (`git
archive HEAD`; the checkout itself is never edited), `--jobs` at a time (default 2), each copy holding one mutation at a
time. For each mutation:

1. the text edit is applied; its `old` text must occur exactly once in the file, else the check stops naming it;
2. the mutation's own tests (the test folder or file named with it) run as one pytest run: default suite
   (`-m "not slow"`), no `-x`, every failing test recorded;
3. only if that run holds no physics catch, the rest of `tests/` runs as a second, separate run (`--ignore` of the
   folder);
4. the file is restored, also on Ctrl-C or SIGTERM, and its SHA-256 compared with the original's.

Every failing test is classified by a pytest plugin loaded into each run (`-p`), which sees the exception object:
JUnit XML drops the type of a rewritten `assert` and does not say in which file an exception was raised.

- physics: an AssertionError (`assert`, `pytest.approx`, `numpy.testing`) or a pytest failure (`pytest.raises` that
  did not raise, `pytest.fail`) whose innermost frame in the repository is in `tests/`, in a test not on NON_PHYSICS;
- non-physics: a test on NON_PHYSICS (generated model file equal to the shipped file, printed or listed text, CLI
  error text and table layout, documentation), whatever it raised;
- raised: any other exception, or an AssertionError raised inside the package: a crash is not a catch;
- broken: an error at collection or import, or a pytest run that ended without running its tests.

Verdict: `caught` when a physics failure is recorded; else `broken` when a run was broken; else `hung` when a run hit
the timeout; else `NOT CAUGHT`. Before any mutation the unmutated copy runs twice as the same two runs (the chosen
mutations' own tests, then the rest of `tests/`); a failing test in either pass stops the check, naming it (a test that
fails now and then must not pass for a catch).

    python scripts/mutants.py --list                        # the mutations, without running
    python scripts/mutants.py --only NAME[,NAME]            # some of them
    python scripts/mutants.py --doc docs/mutations.md       # all of them (make mutants; an hour or more on 2 cores)

Outcomes are merged by name into `--json` (default out/mutants.json; a mutation not run keeps its earlier outcome
with the commit it ran on); `--doc` renders that file as Markdown. pytest's output of each run is kept in
out/mutants/<mutation>.<run>.log.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

from mutations import GROUPS, MUTATIONS, Mutation

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = "mbsuite_mutant_probe"


# Tests whose failure is not a physics catch, by node id: a test file, or `file::test` (all its parametrisations).
NON_PHYSICS: tuple[tuple[str, str], ...] = (
    ("tests/pantograph/test_model_files.py::test_shipped_files_equal_generator",
     "generated model file equal to the shipped file"),
    ("tests/coupler/test_modelfiles.py::test_shipped_files_equal_generated_baseline",
     "generated model file equal to the shipped file"),
    ("tests/pantograph/test_cli.py::test_freqresp_small", "printed text of a command"),
    ("tests/pantograph/test_cli.py::test_list_json", "listing of models and scenes"),
    ("tests/pantograph/test_cli.py::test_run_writes_csv_with_units_and_summary", "file names, headers and units"),
    ("tests/pantograph/test_cli.py::test_errors_exit_2_with_message", "CLI error text"),
    ("tests/pantograph/test_cli.py::test_pantograph_group_equals_the_top_level_aliases",
     "two spellings of a command print the same"),
    ("tests/coupler/test_cli.py::test_criteria_quick_writes_plots", "table width, file names and headers"),
    ("tests/coupler/test_cli.py::test_fpp_writes_csv_png_summary", "table width and file names"),
    ("tests/coupler/test_cli.py::test_figures_draw_on_given_axes", "figure layout"),
    ("tests/coupler/test_cli.py::test_bad_input_exit_code_2", "CLI error text"),
    ("tests/coupler/test_cli.py::test_dynamics_table_has_units_and_fits", "table width and units"),
    ("tests/suite/test_cli.py::test_hardcases_listing_json", "listing of the hard cases"),
    ("tests/suite/test_cli.py::test_list_shows_each_models_paths_and_groups", "listing of models and paths"),
    ("tests/suite/test_cli.py::test_engine_override_takes_a_path_key_or_label_and_names_the_flag", "CLI error text"),
    ("tests/suite/test_docs.py", "documentation examples run and parse"),
    ("tests/catenary/test_readme_numbers.py", "README tables equal the run they quote"),
    ("tests/suite/test_api_docs.py", "docstrings"),
    ("tests/suite/test_render.py", "rendered images"),
)


# The plugin loaded into every pytest run: it records each failing test with its exception's type, whether it is an
# assertion, and the innermost frame inside the repository; and from where `mbsuite` was imported.
PROBE = '''
import json, os, sys
import pytest

_root = os.path.realpath(os.environ["MBSUITE_MUTANT_ROOT"])
_rows = []


def _origin(excinfo):
    for entry in reversed(excinfo.traceback):
        p = os.path.realpath(str(entry.path))
        if p.startswith(_root + os.sep):
            return os.path.relpath(p, _root)
    return ""


def _last_line(text):
    lines = [x for x in str(text).strip().splitlines() if x.strip()]
    return lines[-1][:300] if lines else ""


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item, call):
    rep = yield
    if rep.failed:
        exc = call.excinfo
        if exc is None:
            _rows.append({"nodeid": rep.nodeid, "when": rep.when, "type": "", "assertion": False, "origin": "",
                          "message": _last_line(rep.longrepr)})
        else:
            assertion = exc.errisinstance(AssertionError) or exc.errisinstance(pytest.fail.Exception)
            msg = " ".join(x.strip() for x in exc.exconly(tryshort=False).splitlines() if x.strip())
            _rows.append({"nodeid": rep.nodeid, "when": rep.when, "type": exc.typename, "assertion": bool(assertion),
                          "origin": _origin(exc), "message": msg[:300]})
    return rep


def pytest_collectreport(report):
    if report.failed:
        _rows.append({"nodeid": report.nodeid, "when": "collect", "type": "", "assertion": False, "origin": "",
                      "message": _last_line(report.longrepr)})


def pytest_sessionfinish(session, exitstatus):
    mod = sys.modules.get("mbsuite")
    with open(os.environ["MBSUITE_MUTANT_RECORD"], "w") as fh:
        json.dump({"rows": _rows, "exitstatus": int(exitstatus), "collected": session.testscollected,
                   "mbsuite": getattr(mod, "__file__", None)}, fh)
'''


@dataclass
class Failure:
    """One failing test (or collection error) of a run, classified."""

    nodeid: str
    when: str
    kind: str  # physics | non-physics | raised | broken
    detail: str


@dataclass
class Run:
    """One pytest run: its paths, how it ended, its failures in the order they happened."""

    label: str
    paths: list[str]
    ignore: list[str]
    status: str  # ok | failed | broken | hung
    exitstatus: int | None
    collected: int
    seconds: float
    log: str
    failures: list[Failure] = field(default_factory=list)

    def physics(self) -> list[Failure]:
        return [f for f in self.failures if f.kind == "physics"]


class CheckError(Exception):
    """The check cannot go on (a mutation does not apply, a file was not restored, the wrong package was tested)."""


def non_physics_reason(nodeid: str) -> str | None:
    """Why a failure of `nodeid` is not a physics catch, or None."""
    for pattern, reason in NON_PHYSICS:
        if nodeid == pattern or nodeid.startswith((pattern + "[", pattern + "::")):
            return reason
    return None


def classify(row: dict) -> Failure:
    """A recorded failure as physics, non-physics, raised or broken (module docstring)."""
    nodeid, when = row["nodeid"], row["when"]
    what = f"{row['type']}: {row['message']}" if row["type"] and not row["message"].startswith(row["type"]) \
        else row["message"]
    if when == "collect":
        return Failure(nodeid, when, "broken", f"collection/import error: {row['message']}")
    reason = non_physics_reason(nodeid)
    if reason:
        return Failure(nodeid, when, "non-physics", f"{reason} ({what})")
    if row["assertion"] and row["origin"].startswith("tests/"):
        return Failure(nodeid, when, "physics", what)
    where = f" in {row['origin']}" if row["origin"] else ""
    return Failure(nodeid, when, "raised", f"{what}{where} (at {when})")


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _scratch_copy(dest: Path) -> str:
    """The committed tree (HEAD) in `dest`, whatever is being edited in the checkout; returns the commit."""
    commit = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                            check=True).stdout.strip()
    archive = subprocess.run(["git", "archive", "--format=tar", commit], cwd=ROOT, capture_output=True, check=True)
    subprocess.run(["tar", "-x", "-C", str(dest)], input=archive.stdout, check=True)
    return commit


def check_applies(root: Path, m: Mutation) -> str:
    """The file's text; CheckError unless `m.old` occurs exactly once in it."""
    path = root / m.path
    if not path.is_file():
        raise CheckError(f"mutation {m.name}: {m.path} does not exist; update the mutation")
    text = path.read_text()
    n = text.count(m.old)
    if n != 1:
        raise CheckError(f"mutation {m.name}: its text occurs {n} times in {m.path} (must be exactly once); "
                         f"the code has moved on: update the mutation. Text:\n{textwrap.indent(m.old, '    ')}")
    return text


def _kill_group(proc: subprocess.Popen) -> None:
    """End the pytest process and everything it started (it runs in a session of its own)."""
    for sig, wait in ((signal.SIGTERM, 10.0), (signal.SIGKILL, 30.0)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
            return
        except subprocess.TimeoutExpired:
            continue


def pytest_run(root: Path, probe_dir: Path, label: str, paths: list[str], ignore: list[str], timeout: float,
               log_dir: Path) -> Run:
    """One pytest run of `paths` (minus `ignore`) in the scratch copy, every failing test recorded and classified."""
    record = probe_dir / f"{label}.json"
    record.unlink(missing_ok=True)
    log = log_dir / f"{label}.log"
    env = {**os.environ, "PYTHONPATH": f"{root}{os.pathsep}{probe_dir}", "MPLBACKEND": "Agg",
           "MBSUITE_NATIVE_DIR": str(root / ".native-cache"), "PYTHONDONTWRITEBYTECODE": "1",
           "MBSUITE_MUTANT_ROOT": str(root), "MBSUITE_MUTANT_RECORD": str(record)}
    cmd = [sys.executable, "-m", "pytest", "-q", "-rA", "-p", "no:cacheprovider", "-p", PLUGIN, "-m", "not slow",
           "--continue-on-collection-errors", *paths, *(f"--ignore={p}" for p in ignore)]
    t0 = time.perf_counter()
    with open(log, "w") as out:
        out.write(" ".join(cmd) + "\n\n")
        out.flush()
        proc = subprocess.Popen(cmd, cwd=root, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        try:
            exitstatus: int | None = proc.wait(timeout=timeout)
            hung = False
        except subprocess.TimeoutExpired:
            _kill_group(proc)
            exitstatus, hung = None, True
        except BaseException:
            _kill_group(proc)
            raise
    seconds = round(time.perf_counter() - t0, 1)
    data = json.loads(record.read_text()) if record.is_file() else {"rows": [], "collected": 0, "mbsuite": None}
    imported = data.get("mbsuite")
    if imported and not Path(imported).resolve().is_relative_to(root.resolve()):
        raise CheckError(f"run {label}: the tests imported mbsuite from {imported}, not from the scratch copy {root}")
    failures = [classify(r) for r in data["rows"]]
    if hung:
        status = "hung"
    elif exitstatus not in (0, 1) or not record.is_file():
        status = "broken"
        failures.append(Failure(label, "session", "broken", f"pytest exit status {exitstatus} (see {log})"))
    else:
        status = "ok" if exitstatus == 0 and not failures else "failed"
    return Run(label, paths, ignore, status, exitstatus, int(data.get("collected", 0)), seconds, str(log), failures)


def _without_nested(paths: list[str]) -> list[str]:
    """The paths, each once, none inside another (pytest merges overlapping path arguments)."""
    uniq = sorted(set(paths))
    return [p for p in uniq if not any(p != q and p.startswith(q.rstrip("/") + "/") for q in uniq)]


def run_mutation(root: Path, probe_dir: Path, m: Mutation, timeout: float, log_dir: Path,
                 own_only: bool = False) -> list[Run]:
    """Apply `m`, run its own tests and, without a physics catch there, the rest; restore and verify the file."""
    path = root / m.path
    text = check_applies(root, m)
    original, digest = path.read_bytes(), _sha256(path)
    runs: list[Run] = []
    try:
        path.write_text(text.replace(m.old, m.new, 1))
        runs.append(pytest_run(root, probe_dir, f"{m.name}.own", [m.tests], [], timeout, log_dir))
        if not runs[0].physics() and not own_only:
            runs.append(pytest_run(root, probe_dir, f"{m.name}.rest", ["tests"], [m.tests], timeout, log_dir))
    finally:
        path.write_bytes(original)
        if _sha256(path) != digest:
            raise CheckError(f"{m.path} was not restored: its SHA-256 differs from the original's")
    return runs


def verdict(runs: list[Run]) -> str:
    """caught | broken | hung | NOT CAUGHT (module docstring)."""
    if any(r.physics() for r in runs):
        return "caught"
    for status, name in (("broken", "broken"), ("hung", "hung")):
        if any(r.status == status or any(f.kind == status for f in r.failures) for r in runs):
            return name
    return "NOT CAUGHT"


def outcome(m: Mutation, runs: list[Run], commit: str) -> dict:
    """A mutation's outcome as stored in the JSON file and rendered in the Markdown."""
    failures = [f for r in runs for f in r.failures if f.when != "session"]
    physics = [f for f in failures if f.kind == "physics"]
    return {"name": m.name, "path": m.path, "doc": m.doc, "tests": m.tests, "commit": commit,
            "date": time.strftime("%Y-%m-%d"), "verdict": verdict(runs),
            "first_physics": physics[0].nodeid if physics else "", "n_failing": len(failures),
            "n_physics": len(physics), "runs": [asdict(r) for r in runs]}


def _md(text: str) -> str:
    return text.replace("|", "\\|")


def _short(text: str, n: int = 200) -> str:
    """`text` cut to `n` characters (the whole message stays in the JSON file and the run's log)."""
    return text if len(text) <= n else text[: n - 3] + "..."


def render(outcomes: dict[str, dict], mutations: tuple[Mutation, ...] = ()) -> str:
    """docs/mutations.md from the outcomes, one row per mutation of the list (`not run` where none is stored)."""
    mutations = mutations or MUTATIONS
    lines = ["# Mutation check", "", *textwrap.wrap(
             "Generated by `scripts/mutants.py` (`make mutants`; a subset: `python scripts/mutants.py --only NAME "
             "--doc docs/mutations.md`). Each mutation seeds one physics defect into a scratch copy of the committed "
             "tree, runs its model's own tests, and, when none of them fails with a physics assertion, the rest of "
             "`tests/`. A catch is a failing assertion (`assert`, `pytest.approx`, `numpy.testing`, `pytest.raises` "
             "that did not raise) raised in a test that does not only compare generated files with shipped files, "
             "printed text or documentation (the list below); an exception inside the package, a collection or "
             "import error, or a timeout is not a catch. The unmutated copy passes the same runs first.", 120), "",
             "| mutation | file | what it breaks | verdict | first physics catch | failing tests (physics / all) "
             "| commit |", "|---|---|---|---|---|---|---|"]
    counts: dict[str, int] = {}
    for m in mutations:
        o = outcomes.get(m.name)
        v = o["verdict"] if o else "not run"
        counts[v] = counts.get(v, 0) + 1
        catch = f"`{o['first_physics']}`" if o and o["first_physics"] else "—"
        tally = f"{o['n_physics']} / {o['n_failing']}" if o else "—"
        lines.append(f"| `{m.name}` | `{m.path}` | {_md(m.doc)} | {'**' + v + '**' if v != 'caught' else v} | "
                     f"{_md(catch)} | {tally} | {o['commit'] if o else '—'} |")
    order = ("caught", "NOT CAUGHT", "broken", "hung", "not run")
    lines += ["", "Totals: " + ", ".join(f"{k} {counts[k]}" for k in order if k in counts)
              + f" (of {len(mutations)} mutations).", "", "| model or layer | mutations | caught |", "|---|---|---|"]
    for group, members in GROUPS.items():
        here = [m for m in members if m in mutations]
        if here:
            caught = sum(1 for m in here if outcomes.get(m.name, {}).get("verdict") == "caught")
            lines.append(f"| {group} | {len(here)} | {caught} |")
    lines += ["", "## Failures that are not catches", "", *textwrap.wrap(
              "Per mutation, the failing tests that do not count, each with its reason: a test on the non-physics "
              "list, an exception that is not an assertion (raised), or an error at collection or import (broken).",
              120), ""]
    none = True
    for m in mutations:
        o = outcomes.get(m.name)
        other = [f for r in (o["runs"] if o else []) for f in r["failures"] if f["kind"] != "physics"]
        if other:
            none = False
            lines.append(f"- `{m.name}`:")
            lines += [f"    - {f['kind']}: `{f['nodeid']}`: {_md(_short(f['detail']))}" for f in other]
    if none:
        lines.append("None.")
    lines += ["", "## Tests whose failure is not a physics catch", "",
              "A test file, or a test with all its parametrisations (`NON_PHYSICS` in `scripts/mutants.py`):", ""]
    lines += [f"- `{p}`: {reason}" for p, reason in NON_PHYSICS]
    return "\n".join(lines) + "\n"


def _load(path: Path) -> dict[str, dict]:
    if not path.is_file():
        return {}
    return {o["name"]: o for o in json.loads(path.read_text()).get("outcomes", [])}


def _on_sigterm(signum: int, frame: object) -> None:
    raise KeyboardInterrupt


def _baseline(root: Path, probe_dir: Path, own: list[str], n: int, timeout: float, log_dir: Path) -> list[Run]:
    """The unmutated copy's two runs (the chosen mutations' own tests, then the rest), labelled with pass `n`."""
    runs = []
    for label, paths, ignore in ((f"baseline{n}.own", own, []), (f"baseline{n}.rest", ["tests"], own)):
        runs.append(pytest_run(root, probe_dir, label, paths, ignore, timeout, log_dir))
        if runs[-1].status != "ok":
            break
    return runs


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", action="append", metavar="NAME[,NAME]", help="run only these mutations")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--jobs", type=int, default=2,
                    help="mutations at a time, each in a scratch copy of its own (default 2)")
    ap.add_argument("--json", metavar="PATH", default=str(ROOT / "out" / "mutants.json"),
                    help="outcomes, merged by mutation name (default out/mutants.json)")
    ap.add_argument("--doc", metavar="PATH", help="write the outcomes in --json as Markdown (docs/mutations.md)")
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per pytest run (default 3600)")
    ap.add_argument("--try", dest="trial", action="store_true",
                    help="while writing a mutation and its test: no baseline, only the mutation's own tests, outcomes "
                         "printed and not stored (the docs table comes from a full run)")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error(f"--jobs must be at least 1, got {args.jobs}")
    names = [n.strip() for group in args.only or () for n in group.split(",") if n.strip()]
    unknown = sorted(set(names) - {m.name for m in MUTATIONS})
    if unknown:
        ap.error(f"unknown mutation(s): {', '.join(unknown)} (see --list)")
    chosen = [m for m in MUTATIONS if not names or m.name in names]
    if args.list:
        for m in chosen:
            print(f"{m.name:40s} {m.path:44s} {m.tests}\n{'':40s} {m.doc}")
        return 0
    signal.signal(signal.SIGTERM, _on_sigterm)
    log_dir = ROOT / "out" / "mutants"
    log_dir.mkdir(parents=True, exist_ok=True)
    store = Path(args.json)
    outcomes = _load(store)
    rows: list[dict] = []
    lock = threading.Lock()
    try:
        with tempfile.TemporaryDirectory(prefix="mbsuite-mutants-") as tmp:
            probe_dir = Path(tmp) / "probe"
            probe_dir.mkdir()
            (probe_dir / f"{PLUGIN}.py").write_text(PROBE)
            jobs = min(args.jobs, len(chosen)) or 1
            roots = [Path(tmp) / f"tree{i}" for i in range(jobs)]
            commits = set()
            for root in roots:
                root.mkdir()
                commits.add(_scratch_copy(root))
            if len(commits) != 1:
                raise CheckError(f"HEAD moved while the scratch copies were made ({', '.join(sorted(commits))})")
            commit = commits.pop()
            for m in chosen:  # every mutation must apply to the code as it is, before anything runs
                check_applies(roots[0], m)
            own = _without_nested([m.tests for m in chosen])
            if not args.trial:
                print(f"commit {commit}: the unmutated copy twice, {', '.join(own)} and then the rest of tests/",
                      flush=True)
            # Twice, so that a test that fails now and then is found before it can pass for a catch; with two copies
            # both passes run at once, and each copy builds its native code before any mutation.
            passes = [] if args.trial else [(roots[0], 1), (roots[1 % len(roots)], 2)]
            with ThreadPoolExecutor(max_workers=len(roots)) as pool:
                if len(roots) > 1 and passes:
                    results = list(pool.map(lambda rn: _baseline(rn[0], probe_dir, own, rn[1], args.timeout,
                                                                 log_dir), passes))
                else:
                    results = [_baseline(root, probe_dir, own, n, args.timeout, log_dir) for root, n in passes]
            for runs in results:
                for run in runs:
                    if run.status != "ok":
                        print(f"the unmutated copy does not pass {run.label} ({run.status}, exit status "
                              f"{run.exitstatus}); fix that first (log: {run.log}):", file=sys.stderr)
                        for f in run.failures:
                            print(f"    {f.kind}: {f.nodeid}: {f.detail}", file=sys.stderr)
                        return 2
                    print(f"    {run.label}: {run.collected} tests pass ({run.seconds} s)", flush=True)
            queue = list(reversed(chosen))

            def worker(root: Path) -> None:
                while True:
                    with lock:
                        if not queue:
                            return
                        m = queue.pop()
                    t0 = time.perf_counter()
                    runs = run_mutation(root, probe_dir, m, args.timeout, log_dir, own_only=args.trial)
                    o = outcome(m, runs, commit)
                    with lock:
                        rows.append(o)
                        outcomes[m.name] = o
                        other = o["n_failing"] - o["n_physics"]
                        by = f" by {o['first_physics']}" if o["first_physics"] else ""
                        print(f"[{len(rows)}/{len(chosen)}] {m.name}: {o['verdict']}{by}; {o['n_physics']} physics "
                              f"failures, {other} others; runs: "
                              f"{', '.join(r.label.split('.')[-1] + '=' + r.status for r in runs)} "
                              f"({time.perf_counter() - t0:.0f} s; restored, hash verified)", flush=True)

            with ThreadPoolExecutor(max_workers=jobs) as pool:
                for f in [pool.submit(worker, root) for root in roots[:jobs]]:
                    f.result()
    except CheckError as e:
        print(f"mutation check stopped: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted; a mutated file was restored (hash verified); the outcomes so far are kept", file=sys.stderr)
        return 130
    finally:
        if rows and args.trial:
            for o in rows:
                for r in o["runs"]:
                    for f in r["failures"]:
                        print(f"    {o['name']}: {f['kind']}: {f['nodeid']}: {_short(f['detail'], 160)}")
        elif rows:
            store.parent.mkdir(parents=True, exist_ok=True)
            order = {m.name: i for i, m in enumerate(MUTATIONS)}
            ordered = sorted(outcomes.values(), key=lambda o: order.get(o["name"], len(order)))
            store.write_text(json.dumps({"outcomes": ordered}, indent=1) + "\n")
            if args.doc:
                Path(args.doc).write_text(render(outcomes))
    missed = [o["name"] for o in rows if o["verdict"] != "caught"]
    print(f"\n{len(rows) - len(missed)}/{len(rows)} mutations caught by a physics assertion"
          + (f"; not caught: {', '.join(missed)}" if missed else ""))
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
