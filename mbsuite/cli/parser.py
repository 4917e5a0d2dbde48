"""The `mbsuite` argument parser: the generic commands, then each model's own command group (`register(sub,
add_common, emit)` in the model's `cli` module, which returns the group's command name).

A model's `cli` module also declares the top-level commands its `register` adds, `CLI_COMMANDS = {name: help}`, as a
literal read here without importing the model (`declared_commands`): `mbsuite --version`, `--help`, a generic command
and an argument error then build the light parser (`build_parser(models=False)`), which imports no model, engine,
numpy, scipy or matplotlib; only a model's own command builds the whole parser."""

from __future__ import annotations

import argparse
import ast
import importlib
import re
from collections.abc import Callable
from pathlib import Path

from .options import (
    SCENE_HELP,
    add_error_estimate,
    add_progress_options,
    add_scene_options,
    add_speed_option,
    add_sweep_options,
)
from .output import add_common, emit

MODELS_DIR = Path(__file__).resolve().parent.parent / "models"
GENERIC = ("list", "run", "view", "render", "sweep", "sensitivity", "optimise", "workprecision", "perturb",
           "hardcases", "compare")


def deferred(module: str, name: str) -> Callable:
    """A command function imported when the command runs, not when the parser is built."""

    def call(args: argparse.Namespace) -> None:
        return getattr(importlib.import_module(module, __package__), name)(args)

    call.__name__ = call.__qualname__ = name
    return call


def declared_commands() -> dict[str, dict[str, str]] | None:
    """Model package -> the top-level commands its `cli` module declares (`CLI_COMMANDS`, the first is its group),
    read from the source without importing it; None if a model's `cli` module declares none (then only the whole
    parser knows its commands)."""
    out: dict[str, dict[str, str]] = {}
    for folder in sorted(p for p in MODELS_DIR.iterdir() if (p / "__init__.py").is_file()):
        cli = folder / "cli.py"
        if not cli.is_file():
            continue
        value = _literal(cli.read_text(), "CLI_COMMANDS")
        if not value:
            return None
        out[folder.name] = dict(value)
    return out


def _literal(source: str, name: str) -> object:
    """The literal a module-level statement `name = ...` (or `name: T = ...`) of `source` assigns, the last one if
    several (None without one): the statement alone is parsed, not the module (a few lines, not a few hundred)."""
    lines = source.splitlines()
    starts = [i for i, line in enumerate(lines) if re.match(rf"{name}\s*(:[^=]*)?=", line)]
    for i in reversed(starts):
        for j in range(i + 1, len(lines) + 1):  # the statement's lines: the first chunk that parses
            try:
                node = ast.parse("\n".join(lines[i:j])).body[0]
            except SyntaxError:
                continue
            if isinstance(node, ast.Assign | ast.AnnAssign) and node.value is not None:
                return ast.literal_eval(node.value)
            break
    return None


def command_of(argv: list[str]) -> str | None:
    """The command a command line names: its first argument that is not an option (the top level has no option that
    takes a value)."""
    return next((a for a in argv if not a.startswith("-")), None)


class UsageError(Exception):
    """A command line argparse refuses (unknown command or option, a value of the wrong type)."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors: `mbsuite: error: <what>` naming the argument, and where to read the usage."""

    def error(self, message: str) -> None:  # type: ignore[override]
        """A usage error as an exception (exit 2 with the message), not argparse's exit."""
        raise UsageError(f"{message} (usage: {self.prog} --help)")

    def parse_known_args(self, args=None, namespace=None):  # type: ignore[override]
        """argparse's parse, refusing an option that takes one value given twice (argparse keeps the last): the
        command line's overrides compose by one rule (`options.compose`), and a flag repeated is a conflict too."""
        tokens = [a for a in (args if args is not None else []) if isinstance(a, str)]
        if "--" in tokens:
            tokens = tokens[:tokens.index("--")]
        single = (argparse._StoreAction, argparse._StoreConstAction, argparse._StoreTrueAction,
                  argparse._StoreFalseAction)
        for action in self._actions:
            if not isinstance(action, single) or not action.option_strings:
                continue
            given = [t for t in tokens if t in action.option_strings
                     or any(t.startswith(o + "=") for o in action.option_strings if o.startswith("--"))]
            if len(given) > 1:
                self.error(f"{action.option_strings[-1]} given {len(given)} times; it takes one value: give it once")
        return super().parse_known_args(args, namespace)


def build_parser(models: bool = True, only: str | None = None) -> argparse.ArgumentParser:
    """The `mbsuite` argument parser: the generic commands plus each model's own command group (`models=False`: the
    light parser, whose model commands are declared stubs that parse nothing; `only`: that model's group in full, the
    others' declared stubs). The groups, model -> command name, are the parser's default `cli_groups` (what `mbsuite
    list` shows)."""
    from ..version import __version__

    ap = Parser(
        prog="mbsuite", description="Cross-checked multibody models of railway mechanisms on Pinocchio and MuJoCo: "
        "run scenes, sweeps, frequency responses, work-precision studies and hard cases; `mbsuite list` shows the "
        "models and what each offers.")
    ap.add_argument("--version", action="version", version=f"mbsuite {__version__}")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=Parser)
    add_generic_commands(sub)
    declared = None if models and only is None else (declared_commands() or {})
    if declared is None:
        ap.set_defaults(cli_groups=add_model_groups(sub))
    else:
        full = add_model_groups(sub, only) if only is not None else {}
        for model, commands in declared.items():
            if model in full:
                continue
            for name, helptext in commands.items():
                sub.add_parser(name, help=helptext, add_help=False)
        ap.set_defaults(cli_groups={model: next(iter(commands)) for model, commands in declared.items()})
    return ap


def parser_for(argv: list[str]) -> argparse.ArgumentParser:
    """The light parser when the command line needs no model's commands (`--version`, `--help`, a generic command, an
    unknown command), else the whole one. While a model's `cli` module declares no `CLI_COMMANDS`, only `--version`
    and the generic commands but `list` take the light parser (the others must know that model's commands)."""
    command = command_of(argv)
    declared = declared_commands()
    if declared is None:
        light = command in GENERIC and command != "list" or (command is None and "--version" in argv
                                                                 and not {"-h", "--help"} & set(argv))
        return build_parser(models=not light)
    owner = next((model for model, commands in declared.items() if command in commands), None)
    return build_parser(models=owner is not None, only=owner)  # a model's command: only its module is imported


def add_generic_commands(sub: argparse._SubParsersAction) -> None:
    """`list`, `run`, `view`, `render`, `sweep`, `sensitivity`, `optimise`, `workprecision`, `perturb`, `hardcases`,
    `compare`: commands every model's scenes take (the design studies: those declaring headline outputs; `compare`:
    the summaries any of them wrote)."""
    p = sub.add_parser("list", help="models, their paths and their shipped scenes")
    add_common(p)
    p.set_defaults(func=deferred(".commands", "cmd_list"))

    p = sub.add_parser("run", help="time simulation of a scene")
    p.add_argument("scene", help=SCENE_HELP)
    add_common(p)
    add_scene_options(p)
    p.add_argument("--engine", metavar="PATH",
                   help="override the scene's path: a key or label of the model's path table (mbsuite list)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", dest="set_values",
                   help="change one value of the scene, e.g. params.mh=14 (repeatable; a comma list sets a list)")
    add_speed_option(p)
    add_error_estimate(p)
    p.set_defaults(func=deferred(".commands", "cmd_run"))

    p = sub.add_parser("view", help="open MuJoCo's viewer on a scene's model, its effects active")
    p.add_argument("scene", help=SCENE_HELP)
    p.set_defaults(func=deferred(".commands", "cmd_view"))

    p = sub.add_parser("render", help="render a scene's MuJoCo model offscreen to a PNG (headless: MUJOCO_GL=egl)")
    p.add_argument("scene", help=SCENE_HELP)
    p.add_argument("--out", dest="image", metavar="PNG", required=True, help="the image file to write (.png)")
    p.add_argument("--width", type=int, default=640, help="pixels (default 640)")
    p.add_argument("--height", type=int, default=480, help="pixels (default 480)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", dest="set_values",
                   help="change one value of the scene, e.g. params.mh=14 (repeatable)")
    p.add_argument("--json", action="store_true", help="print machine-readable JSON")
    p.set_defaults(func=deferred(".commands", "cmd_render"))

    p = sub.add_parser("sweep", help="parameter study: run a scene over a grid of inputs/parameters/settings")
    p.add_argument("scene", help=SCENE_HELP)
    p.add_argument("--vary", action="append", metavar="SECTION.KEY=VALUES",
                   help="a grid axis: comma list or start:stop:step, e.g. input.frequency=1:30:0.5 (repeatable: "
                        "the grid is the product)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", dest="set_values",
                   help="change one value of the scene at every point, e.g. params.mh=14 (repeatable)")
    p.add_argument("--signals", help="comma list of output signals to tabulate (default: all)")
    add_speed_option(p)
    p.add_argument("--workers", type=int, default=0, help="local processes (0 = all cores)")
    add_error_estimate(p)
    add_sweep_options(p)
    add_scene_options(p)
    add_common(p)
    p.set_defaults(func=deferred(".sweep", "cmd_sweep"))

    add_design_commands(sub)

    p = sub.add_parser("workprecision", help="what accuracy costs: error vs wall time for every engine and method")
    p.add_argument("scene", help=SCENE_HELP)
    p.add_argument("--repeats", type=int, default=5, help="runs per setting; wall time = median (default 5)")
    p.add_argument("--quick", action="store_true", help="a few settings and short runs (smoke test)")
    p.add_argument("--verbose", action="store_true", help="print each setting as it finishes (stderr)")
    add_progress_options(p)
    add_common(p)
    p.set_defaults(func=deferred(".commands", "cmd_workprecision"))

    p = sub.add_parser("perturb", help="stability under perturbation: every parameter, input and initial state "
                                       "changed by a relative eps; invariants, sensitivities, jumps")
    p.add_argument("target", nargs="*", help="scenes (model/scene or TOML path) or models (all their scenes); "
                                             "default: every shipped scene")
    p.add_argument("--eps", default="1e-12,1e-9", help="comma list of relative perturbations (default 1e-12,1e-9)")
    p.add_argument("--draws", type=int, default=2, help="perturbed copies per eps (seeded; default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first draw (default 0)")
    p.add_argument("--duration", type=float, help="shorten longer runs to this many seconds (s)")
    p.add_argument("--hardcases", action="store_true", help="also run the hard cases (of the targets' models)")
    p.add_argument("--hardcases-only", action="store_true", help="only the hard cases")
    p.add_argument("--no-slow", action="store_true", help="leave out the slow hard cases")
    p.add_argument("--verbose", action="store_true", help="print each row as it finishes (stderr)")
    add_common(p)
    p.set_defaults(func=deferred(".commands", "cmd_perturb"))

    p = sub.add_parser("hardcases", help="the hard-case registry: what is hard, the scene, what is asserted")
    p.add_argument("--run", action="store_true", help="run the cases and report each assertion (exit 2 on failure)")
    p.add_argument("--model", help="only this model's cases")
    p.add_argument("--name", action="append", help="only this case (repeatable)")
    p.add_argument("--no-slow", action="store_true", help="leave out the slow cases")
    add_common(p)
    p.set_defaults(func=deferred(".commands", "cmd_hardcases"))

    p = sub.add_parser("compare", help="earlier runs side by side: the headline outputs of their summary.json, the "
                                       "differences to the first, their signals overlaid (--out)")
    p.add_argument("summaries", nargs="+", metavar="SUMMARY",
                   help="a summary.json an earlier command wrote with --out, or its directory (two or more; the "
                        "first is the one the others are compared to)")
    add_common(p)
    p.set_defaults(func=deferred(".compare", "cmd_compare"))


def add_design_commands(sub: argparse._SubParsersAction) -> None:
    """`sensitivity` and `optimise`: the design studies of any scene declaring headline outputs (`cli.design`)."""
    p = sub.add_parser("sensitivity", help="which parameters move a scene's headline outputs: Morris screening or "
                                           "Sobol indices over declared ranges (SALib)")
    p.add_argument("scene", help=SCENE_HELP)
    _design_ranges(p)
    p.add_argument("--method", choices=("morris", "sobol"), default="morris",
                   help="morris: elementary effects, n (k + 1) runs; sobol: first-order and total indices, n (k + 2) "
                        "runs (default morris)")
    p.add_argument("--n", type=int, default=8,
                   help="morris: trajectories; sobol: base sample, a power of two (default 8)")
    p.add_argument("--levels", type=int, default=4, help="morris grid levels, even (default 4)")
    p.add_argument("--outputs", help="comma list of headline outputs to analyse (default: all)")
    p.add_argument("--seed", type=int, default=0, help="seed of the sample and the bootstrap (default 0)")
    add_speed_option(p)
    p.add_argument("--workers", type=int, default=0, help="local processes or threads (0 = all cores)")
    add_sweep_options(p)
    add_scene_options(p)
    add_progress_options(p)
    add_common(p)
    p.set_defaults(func=deferred(".design", "cmd_sensitivity"))

    p = sub.add_parser("optimise", help="the design minimising a headline output over declared ranges, subject to "
                                        "bounds (e.g. an output inside a band the model declares), at one or "
                                        "several speeds; or a Pareto front")
    p.add_argument("scene", help=SCENE_HELP)
    _design_ranges(p)
    p.add_argument("--objective", help="the headline output to minimise (default: the one the scene's model declares, "
                                       "`mbsuite list`)")
    p.add_argument("--constraint", action="append", metavar="OUTPUT=LO:HI",
                   help="bounds on a headline output, e.g. Fm=100:130 (an empty side is open: Fm=100:); "
                        "OUTPUT=band[:SYSTEM] is the band the scene's model declares, at each operating point "
                        "(repeatable)")
    p.add_argument("--band", metavar="SYSTEM",
                   help="shortcut for --constraint OUTPUT=band:SYSTEM: the band the scene's model declares on its "
                        "output, for SYSTEM (`mbsuite list` names the bands and their systems)")
    p.add_argument("--speed", metavar="KMH",
                   help="train speed(s), km/h: one value sets input.speed; a comma list makes the robust variant "
                        "(every design at each speed, --aggregate)")
    p.add_argument("--over", action="append", metavar="SECTION.KEY=VALUES",
                   help="operating points of the robust variant (any input/parameter), e.g. input.speed=250,300 "
                        "(repeatable: every combination)")
    p.add_argument("--aggregate", choices=("worst", "mean"), default="worst",
                   help="over several operating points: minimise the worst (default) or the mean")
    p.add_argument("--maxiter", type=int, default=20, help="generations of differential evolution (default 20)")
    p.add_argument("--popsize", type=int, default=5, help="members per factor (scipy's popsize; default 5)")
    p.add_argument("--penalty", type=float, default=10.0,
                   help="objective units per unit of constraint violation (exact penalty; default 10)")
    p.add_argument("--seed", type=int, default=0, help="seed of the optimiser (default 0)")
    p.add_argument("--start", action="append", metavar="SECTION.KEY=VALUE",
                   help="the start design's value of a factor (repeatable; default: the scene's own values, when it "
                        "has them inside the ranges)")
    p.add_argument("--pareto", metavar="LEVELS",
                   help="a Pareto front instead: minimise the objective with --against >= each level (a,b,c or "
                        "start:stop:step; epsilon-constraint)")
    p.add_argument("--against", help="the output the front trades against, maximised (default: the one the scene's "
                                     "model declares)")
    p.add_argument("--error-estimate", action="store_true",
                   help="re-run the optimum at each operating point with its error estimate (refined once and "
                        "twice)")
    p.add_argument("--workers", type=int, default=0, help="local processes or threads (0 = all cores)")
    add_sweep_options(p)
    add_scene_options(p)
    add_progress_options(p)
    add_common(p)
    p.set_defaults(func=deferred(".design", "cmd_optimise"))


def _design_ranges(p: argparse.ArgumentParser) -> None:
    p.add_argument("--vary", action="append", metavar="SECTION.KEY=LO:HI",
                   help="a parameter and its range, e.g. params.m1=5:10 or pantograph.params.Pg=6.5e5:8e5 "
                        "(repeatable)")
    p.add_argument("--set", action="append", metavar="SECTION.KEY=VALUE", dest="set_values",
                   help="change one value of the scene at every point, e.g. params.n_spans=4 (repeatable)")


def add_model_groups(sub: argparse._SubParsersAction, only: str | None = None) -> dict[str, str]:
    """Let each model that declares a command module (`SPEC.commands`; `only`: that model alone, from its package's
    `cli` module, which `declared_commands` read, without the registry: its --help imports no other model module)
    add its command group; returns model -> the group's command name."""
    if only is not None:
        modules = {only: f"{__package__.rpartition('.')[0]}.models.{only}.cli"}
    else:
        from .. import registry

        modules = {name: spec.commands for name, spec in sorted(registry.models().items()) if spec.commands}
    groups: dict[str, str] = {}
    for name, module in modules.items():
        group = importlib.import_module(module).register(sub, add_common, emit)
        if group not in sub.choices:
            raise TypeError(f"{module}.register returned {group!r}, not the command it added")
        groups[name] = group
    return groups
