"""The command line answers at once: `mbsuite --version`, `--help`, every command's `--help` and argument errors import
no engine, numpy, scipy or matplotlib, and a model's command's help no other model (which modules a command loads is
behaviour; how long it takes is measured by scripts/cli_startup.py, not asserted here)."""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys

import pytest

from mbsuite.cli.output import add_common, emit
from mbsuite.cli.parser import MODELS_DIR, build_parser, declared_commands

HEAVY = ("numpy", "scipy", "matplotlib", "mujoco", "pinocchio", "mbsuite.models.", "mbsuite.engines")

PROBE = """
import contextlib, io, json, sys
from mbsuite.cli import main
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    code = main(sys.argv[1:])
print(json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def _loaded(*argv: str) -> tuple[int, list[str]]:
    """Exit status and the heavy modules loaded by `mbsuite ARGV`, in a fresh interpreter."""
    out = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, check=True).stdout
    data = json.loads(out)
    return data["code"], [m for m in data["modules"] if m.startswith(HEAVY) or m in HEAVY]


@pytest.mark.parametrize("argv", [["--version"], ["run", "--no-such-option"]])
def test_version_and_argument_errors_load_nothing_heavy(argv):
    code, heavy = _loaded(*argv)
    assert code == (0 if argv == ["--version"] else 2)
    assert heavy == [], f"mbsuite {' '.join(argv)} imports {heavy[:8]}"


@pytest.mark.parametrize("argv", [["--help"], ["nosuchcommand"]])
def test_help_and_unknown_command_load_nothing_heavy(argv):
    if declared_commands() is None:
        pytest.skip("a model's cli module declares no CLI_COMMANDS: --help must import the models to list them")
    code, heavy = _loaded(*argv)
    assert code == (0 if argv == ["--help"] else 2) and heavy == [], heavy[:8]


def test_declared_commands_are_the_registered_ones():
    """Each model cli's `CLI_COMMANDS` (what the light parser lists) names exactly the top-level commands its
    `register` adds (the whole parser's), so `--help` and dispatch never disagree."""
    folders = sorted(p.name for p in MODELS_DIR.iterdir() if (p / "cli.py").is_file())
    assert folders, "no model declares a command group"
    for name in folders:
        mod = importlib.import_module(f"mbsuite.models.{name}.cli")
        if not hasattr(mod, "CLI_COMMANDS"):
            continue  # reported by test_help_and_unknown_command_load_nothing_heavy's skip
        sub = argparse.ArgumentParser().add_subparsers()
        group = mod.register(sub, add_common, emit)
        assert set(sub.choices) == set(mod.CLI_COMMANDS), name
        assert next(iter(mod.CLI_COMMANDS)) == group, name


def test_light_and_whole_parser_read_a_generic_command_alike():
    argv = ["sweep", "pantograph", "--vary", "params.mh=10,12", "--json"]
    light = vars(build_parser(models=False).parse_args(argv))
    whole = vars(build_parser().parse_args(argv))
    assert light.pop("func").__name__ == whole.pop("func").__name__ == "cmd_sweep"
    light.pop("cli_groups"), whole.pop("cli_groups")
    assert light == whole


#: what no command's --help may import: the engines, the plotting and numerical stack, numpy itself
ENGINES = ("numpy", "scipy", "matplotlib", "mujoco", "pinocchio", "mbsuite.engines")

#: runs `mbsuite ARGV` for each argv of its JSON argument in a fork of one interpreter that has imported only the
#: command line (each fork starts from the same modules, as a fresh process would), printing what each loaded
FORKED = """
import contextlib, io, json, os, sys
from mbsuite.cli import main
out = {}
for argv in json.loads(sys.argv[1]):
    r, w = os.pipe()
    if os.fork() == 0:
        os.close(r)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            code = main(argv)
        os.write(w, json.dumps({"code": code, "modules": sorted(sys.modules)}).encode())
        os._exit(0)
    os.close(w)
    with os.fdopen(r) as f:
        out[" ".join(argv)] = json.loads(f.read())
    os.wait()
print(json.dumps(out))
"""


def help_commands() -> list[list[str]]:
    """`[command, ..., "--help"]` of every command of the whole parser: each top-level command and each command of
    every group, at every depth (`drive design cadjs`)."""
    out: list[list[str]] = []

    def walk(parser: argparse.ArgumentParser, path: list[str]) -> None:
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, child in action.choices.items():
                    out.append([*path, name, "--help"])
                    walk(child, [*path, name])

    walk(build_parser(), [])
    return out


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="the probe forks")
def test_every_commands_help_loads_no_engine_numpy_or_other_model():
    """Every command's --help (each top-level command, each command of a group at any depth) builds its parser from
    the light parser and, for a model's command, that model's `cli` module alone: it imports no numpy, scipy,
    matplotlib, MuJoCo, Pinocchio or engine, and no module of another model (what it costs: scripts/cli_startup.py)."""
    commands = help_commands()
    assert ["drive", "run", "--help"] in commands and ["coupler", "criteria", "--help"] in commands
    out = subprocess.run([sys.executable, "-c", FORKED, json.dumps(commands)], capture_output=True, text=True,
                         check=True).stdout
    loaded = json.loads(out)
    declared = declared_commands() or {}
    bad = {}
    for argv in commands:
        data = loaded[" ".join(argv)]
        owner = [model for model, names in declared.items() if argv[0] in names]
        heavy = [m for m in data["modules"] if m.startswith(ENGINES)]
        others = [m for m in data["modules"] if m.startswith("mbsuite.models.") and m.split(".")[2] not in owner]
        clis = [m for m in data["modules"] if m.startswith("mbsuite.models.") and m.endswith(".cli")]
        if data["code"] != 0 or heavy or others or clis != [f"mbsuite.models.{m}.cli" for m in owner]:
            bad[" ".join(argv)] = {"exit": data["code"], "heavy": heavy[:6], "other models": others[:6], "cli": clis}
    assert not bad, bad


def test_a_models_package_loads_its_spec_on_first_use():
    """A model package hands on `SPEC` at its first use (`spec.py`), so importing the package (its `cli`) loads no
    other module of the model; the registry's `SPEC.commands` is the package's `cli`, which the light parser imports
    by that name."""
    probe = ("import json, sys; import mbsuite.models.catenary as m; before = sorted(sys.modules); spec = m.SPEC; "
             "print(json.dumps([before, spec.name, spec.commands]))")
    before, name, commands = json.loads(subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                                                       check=True).stdout)
    assert name == "catenary" and commands == "mbsuite.models.catenary.cli"
    assert [m for m in before if m.startswith("mbsuite.models.catenary.")] == []
    from mbsuite import registry

    for model, spec in registry.models().items():
        if spec.commands is not None:
            assert spec.commands == f"mbsuite.models.{model}.cli", model


def test_fit_defaults_reach_the_command_line_and_the_api():
    """The transfer-function fit's default order is a number on both routes (the command line's default and the
    study's keyword), the one the fit declares."""
    import inspect

    from mbsuite.models.pantograph import lumped_study
    from mbsuite.models.pantograph.fit_defaults import DEFAULT_ORDER

    args = build_parser().parse_args(["pantograph", "fit-lumped"])
    assert args.order == DEFAULT_ORDER == inspect.signature(lumped_study.fit_report).parameters["order"].default == 7


def test_the_startup_benchmark_times_every_top_level_commands_help():
    """scripts/cli_startup.py measures the help of every top-level command the parser lists."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("cli_startup", MODELS_DIR.parents[1] / "scripts" / "cli_startup.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    top = build_parser(models=False)._subparsers._group_actions[0].choices
    assert list(bench.TOP_LEVEL) == list(top)
    assert all([c, "--help"] in bench.COMMANDS.values() for c in top)
