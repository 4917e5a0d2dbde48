"""Command line: `mbsuite list | run | view | render | sweep | workprecision | perturb | hardcases | sensitivity |
optimise | compare` plus each model's
command group (`mbsuite pantograph ...`, `mbsuite coupler ...`, ...; `mbsuite list` names them).

Each analysis prints a human table by default, JSON with `--json`, and with `--out DIR` writes CSV (SI units in the
header), PNG plots and `summary.json` (versions, the checkout's commit, the command, the scene as run). A model
package adds its own commands by defining `register(sub, add_common, emit) -> str` in its `cli` module (returning
its group's command name) and declaring there `CLI_COMMANDS = {name: help}`, the top-level commands it adds, which
the parser reads without importing the model (so `mbsuite --version`, `--help` and the generic commands start at
once).

Every command that reads a scene also takes a `summary.json` an earlier command wrote (the scene it ran), and the
model analyses take `--set SECTION.KEY=VALUE` and `--vary SECTION.KEY=VALUES` (a parameter study of the analysis).
Every flag that changes the scene is composed by one rule before the command runs (`options.overrides`): a key set
twice, or a key and a key inside it, is an error naming both flags.

The package: `parser.py` (the parser, the model groups), `commands.py` (the generic commands), `sweep.py` (`mbsuite
sweep`), `study.py` (`--set`/`--vary` on the analyses), `compare.py` (`mbsuite compare`), `options.py` (options several
commands share), `output.py` (tables, JSON, files, one-line errors and warnings). Long work reports its plan, time and
progress through `mbsuite.progress` (`main` opens the command's study).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from .. import progress
from ..errors import MbsuiteError
from ..trust.health import InaccurateResult
from .options import overrides
from .output import check_out, fail, inaccurate, one_line_warnings, quiet_stdout
from .parser import UsageError, build_parser, parser_for

__all__ = ["build_parser", "main"]


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line. Exit status: 0 success, 2 any error (one line naming the input; under --json also a JSON
    object `{"error": {...}}` on stdout), 3 a result printed and written although an error estimate exceeds its
    tolerance (`trust.health.InaccurateResult`: one line on stderr; `--allow-inaccurate` accepts it: 0), 130
    interrupted (Ctrl-C). A closed output pipe ends the command quietly."""
    argv = list(sys.argv[1:] if argv is None else argv)
    ap = parser_for(argv)
    try:
        args = ap.parse_args(argv)
    except UsageError as exc:
        return fail(str(exc), "--json" in argv, "UsageError")
    except SystemExit as exc:  # --help / --version
        return int(exc.code or 0)
    args.argv = argv  # summary.json records the command
    as_json = bool(getattr(args, "json", False))
    try:
        check_out(getattr(args, "out", None))
        overrides(args)  # the one rule over every flag that changes the scene, before anything loads or runs
        with one_line_warnings(), progress.study(
                " ".join(argv[:1]) or "mbsuite", quiet=bool(getattr(args, "quiet", False)), budget=_budget(args),
                confirmed=bool(getattr(args, "yes", False)), out=getattr(args, "out", None),
                store=getattr(args, "store", None)):
            args.func(args)
    except InaccurateResult as exc:
        if not getattr(exc, "shown", False):  # not raised by `emit` after printing the result: nothing was shown
            return fail(str(exc), as_json, type(exc).__name__)
        return inaccurate(str(exc))
    except progress.OverBudget as exc:  # the runs finished before the stop are kept, as on Ctrl-C
        st = progress.last_study()
        kept = st.keep_partial() if st is not None and st.last is not None and st.last.finished else ""
        return fail(f"{exc}{'; ' + kept if kept else ''}", as_json, type(exc).__name__)
    except MbsuiteError as exc:
        return fail(str(exc), as_json, type(exc).__name__)
    except KeyboardInterrupt:
        st = progress.last_study()
        saved = st.keep_partial() if st is not None else "nothing was saved"
        print(f"mbsuite: interrupted; {saved}", file=sys.stderr)
        return 130
    except BrokenPipeError:
        quiet_stdout()
        return 0
    except MemoryError:
        return fail("out of memory: the job is too large for this machine; make it smaller (fewer points, shorter "
                    "run, larger step)", as_json, "MemoryError")
    except OSError as exc:
        name = f" {exc.filename}" if exc.filename else ""
        return fail(f"cannot access{name}: {exc.strerror or exc}", as_json, "OSError")
    except Exception as exc:  # a defect in mbsuite: still one line, the traceback on request
        if os.environ.get("MBSUITE_DEBUG"):
            raise
        return fail(f"internal error ({type(exc).__name__}: {exc}); this is a bug in mbsuite, please report it with "
                    "the command line (MBSUITE_DEBUG=1 prints the traceback)", as_json, "InternalError")
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        quiet_stdout()
    return 0


def _budget(args: object) -> float | None:
    """The command's budget (s): `--budget`, else `progress.BUDGET` where the command takes one; None otherwise."""
    if not hasattr(args, "yes"):
        return None
    from ..limits import Limit

    b = getattr(args, "budget", None)
    return progress.BUDGET if b is None else Limit(lo=0, lo_open=True, unit="s", doc="wall time of a study").check(
        "--budget", b, MbsuiteError)
