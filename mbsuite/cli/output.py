"""What the command line writes: a report as a table or JSON (and its files under `--out`), one-line errors, the
checks and clean-ups around them."""

from __future__ import annotations

import argparse
import json
import os
import sys
import textwrap
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MbsuiteError

if TYPE_CHECKING:
    from ..results import Report


def add_common(p: argparse.ArgumentParser) -> None:
    """`--json`, `--out DIR` and `--quiet`, which every command that reports takes."""
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.add_argument("--out", metavar="DIR", help="write CSV/PNG/summary.json into DIR")
    p.add_argument("--quiet", action="store_true",
                   help="no progress: neither the plan of a long study, its time estimate nor the bar (stderr)")


def emit(report: Report, args: argparse.Namespace, scene_dict: dict | None) -> None:
    """Print `report` (its table, or its data as JSON under `--json`) and write its files under `--out`; then, for a
    report flagged inaccurate (`Report.flag_inaccurate`), raise `InaccurateResult` (`main`: exit status 3)."""
    from ..results import to_jsonable

    files = report.save(args.out, scene_dict, command_record(args)) if getattr(args, "out", None) else []
    if args.json:
        payload = dict(report.data)
        if files:
            payload["files"] = [str(f) for f in files]
        print(json.dumps(to_jsonable(payload), indent=2))
    else:
        print(report.table)
        for f in files:
            print(f"wrote {f}")
    if report.inaccurate:
        from ..trust.health import InaccurateResult

        exc = InaccurateResult(report.inaccurate, report)
        exc.shown = True  # `main`: the result is out, exit 3
        raise exc


def command_record(args: argparse.Namespace) -> dict:
    """What summary.json records of the command: its argv (as typed, when `main` ran it) and every option's value."""
    options = {k: v for k, v in vars(args).items()
               if k not in ("func", "cli_groups", "argv") and (v is None or isinstance(v, str | int | float | list))}
    return {"argv": getattr(args, "argv", None), "options": options}


def wrap(text: str, width: int = 100, indent: str = "  ") -> str:
    """`text` filled to `width` columns, later lines indented two more."""
    return textwrap.fill(text, width=width, initial_indent=indent, subsequent_indent=indent + "  ")


def inaccurate(message: str) -> int:
    """The verdict on a result printed although an error estimate exceeds its tolerance: one line on stderr (the
    result, under --json its JSON with `"inaccurate"`, is on stdout); exit status 3 (`EXIT_INACCURATE`)."""
    from ..trust.health import EXIT_INACCURATE

    message = " ".join(message.split())
    print(f"mbsuite: inaccurate: {message}", file=sys.stderr)
    return EXIT_INACCURATE


def fail(message: str, as_json: bool, kind: str) -> int:
    """One line on stderr (and, under --json, a JSON object on stdout); exit status 2."""
    message = " ".join(message.split())  # messages quoting a solver's text may hold line breaks
    if as_json:
        print(json.dumps({"error": {"type": kind, "message": message}}))
    print(f"mbsuite: error: {message}", file=sys.stderr)
    return 2


def check_out(out: str | None) -> None:
    """`--out DIR` must be a directory we can write, checked before any work is done."""
    if not out:
        return
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise MbsuiteError(f"--out {out}: exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".mbsuite-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise MbsuiteError(f"--out {out}: cannot write there ({exc.strerror or exc})") from exc


def quiet_stdout() -> None:
    """After a closed pipe: send the rest of stdout to /dev/null so the interpreter's final flush stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


@contextmanager
def one_line_warnings() -> Iterator[None]:
    """Warnings as one line each on stderr, `mbsuite: <Category>: <message>`, without the package's source line, and
    each text once per command (the format of Python's own display: a caller recording warnings still gets them)."""
    seen: set[str] = set()
    before = warnings.formatwarning

    def fmt(message: Warning | str, category: type[Warning], filename: str, lineno: int,
            line: str | None = None) -> str:
        text = f"mbsuite: {category.__name__}: {' '.join(str(message).split())}"
        if text in seen:
            return ""
        seen.add(text)
        return text + "\n"

    warnings.formatwarning = fmt
    try:
        yield
    finally:
        warnings.formatwarning = before
