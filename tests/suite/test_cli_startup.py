"""The command line answers at once: `mbsuite --version`, `--help` and argument errors import no engine, model,
numpy, scipy or matplotlib (which modules a command loads is behaviour; how long it takes is measured by
scripts/cli_startup.py, not asserted here)."""

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


ENGINES = ("scipy", "matplotlib", "mujoco", "pinocchio", "mbsuite.engines.core", "mbsuite.engines.mujoco_engine",
           "mbsuite.engines.pinocchio_engine", "mbsuite.engines.native")


@pytest.mark.parametrize("argv", [["catenary", "--help"], ["pantograph", "--help"], ["pantograph", "fit-lumped",
                                                                                    "--help"],
                                  ["modes", "--help"], ["coupler", "criteria", "--help"], ["optimise", "--help"],
                                  ["compare", "--help"], ["drive", "run", "--help"], ["rotational", "--help"]])
def test_a_commands_help_loads_its_own_model_only_and_no_engine(argv):
    """A model command's --help builds that model's command group alone (no other model's cli module) and imports
    no engine, scipy or matplotlib."""
    out = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, check=True).stdout
    data = json.loads(out)
    assert data["code"] == 0
    clis = [m for m in data["modules"] if m.startswith("mbsuite.models.") and m.endswith(".cli")]
    declared = declared_commands() or {}
    owner = [f"mbsuite.models.{model}.cli" for model, commands in declared.items() if argv[0] in commands]
    assert clis == owner, clis
    heavy = [m for m in data["modules"] if m.startswith(ENGINES)]
    assert heavy == [], f"mbsuite {' '.join(argv)} imports {heavy[:8]}"


def test_fit_defaults_reach_the_command_line_and_the_api():
    """The transfer-function fit's default order is a number on both routes (the command line's default and the
    study's keyword), the one the fit declares."""
    import inspect

    from mbsuite.models.pantograph import lumped_study
    from mbsuite.models.pantograph.fit_defaults import DEFAULT_ORDER

    args = build_parser().parse_args(["pantograph", "fit-lumped"])
    assert args.order == DEFAULT_ORDER == inspect.signature(lumped_study.fit_report).parameters["order"].default == 7
