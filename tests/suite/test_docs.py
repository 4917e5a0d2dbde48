"""The documentation's code is live: every ```python block of the README and of each model README runs (blocks of one
file in order, sharing a namespace, from a directory that is not the repository root); every TOML scene block is a
valid scene or scene fragment; every `mbsuite ...` command line in the docs is accepted by the command-line parser.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import tomllib
from pathlib import Path

import pytest

import mbsuite
from mbsuite.cli import build_parser

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "mbsuite" / "models").glob("*/README.md")),
        *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
PLACEHOLDER = re.compile(r"[A-Z]{2,}|\[|\.\.\.|\||<")


def _blocks(path: Path, lang: str) -> list[str]:
    return [body for kind, body in FENCE.findall(path.read_text()) if kind == lang]


def _ids(paths: list[Path]) -> list[str]:
    return [str(p.relative_to(ROOT)) for p in paths]


WITH_PYTHON = [p for p in DOCS if _blocks(p, "python")]


@pytest.mark.parametrize("path", WITH_PYTHON, ids=_ids(WITH_PYTHON))
def test_python_blocks_run_outside_the_checkout(path, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    namespace: dict = {"__name__": "__doc_example__"}
    for i, code in enumerate(_blocks(path, "python")):
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(code, f"{path.name}[python block {i}]", "exec"), namespace)  # noqa: S102


def test_there_are_python_examples():
    assert sum(len(_blocks(p, "python")) for p in DOCS) >= 2


def _toml_blocks() -> list[tuple[Path, str]]:
    return [(p, b) for p in DOCS for b in _blocks(p, "toml")]


@pytest.mark.parametrize(("path", "block"), _toml_blocks(), ids=[str(p.relative_to(ROOT)) for p, _ in _toml_blocks()])
def test_toml_blocks_are_valid_scenes_or_fragments(path, block):
    data = tomllib.loads(block)
    if "wires" in data and "model" not in data:  # a catenary line file: read, checked and assembled
        from mbsuite.models.catenary.fe import assemble
        from mbsuite.models.catenary.linefile import line_from_dict
        from mbsuite.models.catenary.params import CatenaryParams

        line = line_from_dict(data, path.parent, str(path))
        assemble(CatenaryParams(line=line, x_end=line.length, window_start=0.0, window_end=line.length))
        return
    if "model" in data:
        mbsuite.scene_from_dict(data)
        return
    # a fragment: it belongs to the model whose README holds it (the top-level README's fragments to the pantograph)
    model = path.parent.name if path.parent.parent.name == "models" else "pantograph"
    base = mbsuite.load_scene(model).to_dict()
    for key, val in data.items():
        if isinstance(val, dict) and isinstance(base.get(key), dict):
            base[key].update(val)
        else:
            base[key] = val
    mbsuite.scene_from_dict(base)


def _command_lines() -> list[tuple[Path, str]]:
    out = []
    for p in DOCS:
        for kind, body in FENCE.findall(p.read_text()):
            if kind not in ("", "bash", "sh", "console"):
                continue
            for line in body.splitlines():
                cmd = line.split("#")[0].strip()
                if cmd.startswith("mbsuite ") and not PLACEHOLDER.search(cmd.replace("--", "")):
                    out.append((p, cmd))
    return out


COMMANDS = _command_lines()


@pytest.mark.parametrize(("path", "cmd"), COMMANDS, ids=[c for _, c in COMMANDS])
def test_command_lines_parse(path, cmd):
    args = build_parser().parse_args(shlex.split(cmd)[1:])
    assert callable(args.func)


def test_there_are_command_examples():
    assert len(COMMANDS) >= 5


@pytest.mark.parametrize("name", sorted(mbsuite.model_specs()))
def test_model_readme_lists_every_parameter_and_input(name):
    """Each model's README names every parameter field and every input key a scene may set (with its default)."""
    import dataclasses

    spec = mbsuite.get_model(name)
    text = (ROOT / "mbsuite" / "models" / name / "README.md").read_text()
    fields = [f.name for f in dataclasses.fields(spec.params_cls)]
    keys = sorted({k for keys in spec.inputs.values() for k in keys})
    missing = [n for n in [*fields, *keys] if f"`{n}`" not in text and f"| {n} |" not in text]
    assert not missing, f"{name} README does not list: {missing}"


@pytest.mark.parametrize("name", ["pantograph", "coupler", "drives", "catenary", "iftomm"])
def test_model_readme_parameter_ranges_are_the_declared_ones(name):
    """Each row `| `param` | default | valid | ...` of a model README's parameter table states the range the loader
    enforces (`Limit.describe()` of the parameter's declaration), so the README cannot drift from the code."""
    import dataclasses

    from mbsuite.limits import limit_of

    spec = mbsuite.get_model(name)
    text = (ROOT / "mbsuite" / "models" / name / "README.md").read_text()
    wrong = []
    for f in dataclasses.fields(spec.params_cls):
        lim = limit_of(spec.params_cls, f.name)
        rows = [ln for ln in text.splitlines() if ln.startswith(f"| `{f.name}` |")]
        if lim is None or not rows:
            continue
        cells = [c.strip() for c in rows[0].strip("|").split("|")]
        core = lim.describe().removesuffix(f" {lim.unit}" if lim.unit else "")  # a table may give units apart
        if len(cells) < 3 or not cells[2].startswith(core):
            wrong.append(f"{f.name}: README {cells[2] if len(cells) > 2 else '?'!r}, declared {lim.describe()!r}")
    assert not wrong, f"{name} README parameter ranges differ from the declarations: {wrong}"


def _docstring_example_modules() -> list[str]:
    """Every mbsuite module whose docstrings hold a `>>>` example."""
    root = Path(mbsuite.__file__).parent
    return sorted(".".join(f.relative_to(root.parent).with_suffix("").parts).removesuffix(".__init__")
                  for f in root.rglob("*.py") if ">>> " in f.read_text())


@pytest.mark.parametrize("module", _docstring_example_modules())
def test_docstring_examples_run(module):
    """Every `>>>` example in a docstring runs (doctest: no exception, and printed output as written)."""
    import doctest
    import importlib

    res = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
                          verbose=False, report=True)
    assert res.attempted > 0 and res.failed == 0, f"{module}: {res.failed} of {res.attempted} examples failed"


README_REF = re.compile(r"README ((?:'[^']+'(?:, )?)+)")


def test_command_help_names_sections_of_its_model_readme():
    """A command's help that points to its model README ("model README 'Lines of your own', 'A line in a file'")
    names a heading (the start of a `#` line) or a bold paragraph title (`**...`) of that README."""
    refs = 0
    for cli in sorted((ROOT / "mbsuite" / "models").glob("*/cli.py")):
        readme = (cli.parent / "README.md").read_text()
        titles = [ln.lstrip("#").strip() for ln in readme.splitlines() if ln.startswith("#")]
        titles += re.findall(r"^\*\*([^*]+)", readme, re.M)
        for group in README_REF.findall(cli.read_text()):
            for name in re.findall(r"'([^']+)'", group):
                refs += 1
                assert any(t.startswith(name) for t in titles), f"{cli.relative_to(ROOT)}: README section {name!r}"
    assert refs
