"""`mbsuite compare A B [C ...] [--out DIR] [--json]`: the headline outputs of earlier runs side by side, read from
the summary.json each wrote with `--out` (`mbsuite.analysis.compare`), with their differences to the first and, with
`--out`, their signals overlaid."""

from __future__ import annotations

import argparse
import importlib
from collections.abc import Mapping
from pathlib import Path

from ..errors import MbsuiteError


def model_units(model: str) -> Mapping[str, str]:
    """The units table of a model's command group (`UNITS` in its `cli` module: the units of the numbers its
    analyses report, by name), empty when it has none."""
    from ..registry import models

    spec = models().get(model)
    if spec is None or not spec.commands:
        return {}
    table = getattr(importlib.import_module(spec.commands), "UNITS", None)
    return dict(table) if isinstance(table, Mapping) else {}


def cmd_compare(args: argparse.Namespace) -> None:
    """Compare the summaries given; `--out` may not be the directory of one of them (its summary.json would be
    overwritten)."""
    from ..analysis.compare import compare, summary_file
    from .output import emit

    if args.out:
        out = Path(args.out).resolve()
        for a in args.summaries:
            if summary_file(a).resolve().parent == out:
                raise MbsuiteError(f"--out {args.out} holds the summary.json of {a}: writing there would overwrite "
                                   "it; give another directory")
    emit(compare(args.summaries, units_for=model_units), args, None)
