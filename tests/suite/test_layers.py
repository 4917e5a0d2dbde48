"""The import graph of the package: no circles, no import running up the layers, no shared layer naming a model, no
model importing another. Read from the source's import statements (module level and inside functions alike), so a
lazy import counts as much as a top-level one.

The layers, bottom up (`LAYERS`): the foundation (errors, limits, schema, settings, results, the trust vocabulary);
engines and shared components; the registry and scenes; the studies (`analysis`); the models; the command line; the
models' command groups (`models/<model>/cli.py`, plugged into the command line through `SPEC.commands`). A module may
import its own layer or a lower one. `docs/CONTRIBUTING_MODELS.md` ("Where a module goes") describes the same order.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2] / "mbsuite"

#: (layer, the modules in it: a dotted name covers the module and everything below it; "=name" the module alone; the
#: package's face `mbsuite/__init__.py` lazily hands on `run`, `load_scene`, ...: it sits with `simulate`)
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("foundation", ("mbsuite.errors", "mbsuite.version", "mbsuite.limits", "mbsuite.schema", "mbsuite.deferred",
                    "mbsuite.paths", "mbsuite.overrides", "mbsuite.plotting", "mbsuite.modeltext",
                    "mbsuite.stepping", "mbsuite.results", "mbsuite.progress", "mbsuite.settings", "mbsuite.statistics",
                    "mbsuite.trust.health", "mbsuite.trust.perturbation", "mbsuite.trust.estimate", "mbsuite.trust")),
    ("engines and components", ("mbsuite.engines", "mbsuite.components", "mbsuite.native")),
    ("registry and scenes", ("mbsuite.registry", "mbsuite.scenes", "mbsuite.scene_schema", "mbsuite.modelfiles",
                             "mbsuite.hardcases", "mbsuite.pathrun")),
    ("studies", ("mbsuite.analysis", "mbsuite.simulate", "mbsuite.trust.robustness", "=mbsuite")),
    ("models", ("mbsuite.models",)),
    ("command line", ("mbsuite.cli", "mbsuite.__main__")),
    ("model command groups", ()),  # mbsuite.models.<model>.cli
)
#: layers that name no model
SHARED = ("foundation", "engines and components", "registry and scenes", "studies", "command line")


@cache
def modules() -> dict[str, Path]:
    out = {}
    for p in ROOT.rglob("*.py"):
        parts = list(p.relative_to(ROOT.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = p
    return out


def _targets(name: str, path: Path, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The package modules an import statement names (an imported name that is a module counts as that module)."""
    mods = modules()
    if isinstance(node, ast.Import):
        found = [a.name for a in node.names]
    else:
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        if node.level:
            base = package.split(".")[: len(package.split(".")) - node.level + 1]
            stem = ".".join(base + ([node.module] if node.module else []))
        else:
            stem = node.module or ""
        found = [f"{stem}.{a.name}" if f"{stem}.{a.name}" in mods else stem for a in node.names]
    out = []
    for t in found:
        while t and t not in mods:
            t = t.rpartition(".")[0]
        if t.startswith("mbsuite"):
            out.append(t)
    return out


@cache
def graph() -> dict[str, frozenset[str]]:
    edges: dict[str, set[str]] = defaultdict(set)
    for name, path in modules().items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import | ast.ImportFrom):
                edges[name].update(t for t in _targets(name, path, node) if t != name)
    return {k: frozenset(v) for k, v in edges.items()}


def layer(name: str) -> int:
    """The layer index of a module (the longest matching prefix wins; a model's cli.py is a command group)."""
    parts = name.split(".")
    if len(parts) >= 4 and parts[1] == "models" and parts[3] == "cli":
        return len(LAYERS) - 1
    best, length = None, -1
    for i, (_, prefixes) in enumerate(LAYERS):
        for pre in prefixes:
            if pre.startswith("="):
                if name == pre[1:]:
                    return i
                continue
            if (name == pre or name.startswith(pre + ".")) and len(pre) > length:
                best, length = i, len(pre)
    assert best is not None, f"module {name} is in no layer: add it to LAYERS (and to CONTRIBUTING_MODELS.md)"
    return best


def model_of(name: str) -> str | None:
    parts = name.split(".")
    return parts[2] if len(parts) >= 3 and parts[1] == "models" else None


def circles() -> list[list[str]]:
    """The modules that import each other in a loop: the strongly connected components of more than one module
    (`scipy.sparse.csgraph.connected_components`)."""
    import numpy as np
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    g, names = graph(), sorted(modules())
    at = {n: i for i, n in enumerate(names)}
    rows = [(at[a], at[b]) for a, targets in g.items() for b in targets]
    r, c = (np.array(x, dtype=int) for x in zip(*rows, strict=True)) if rows else (np.zeros(0, int),) * 2
    _, label = connected_components(coo_matrix((np.ones(r.size), (r, c)), shape=(len(names),) * 2),
                                    directed=True, connection="strong")
    groups: dict[int, list[str]] = defaultdict(list)
    for name, k in zip(names, label, strict=True):
        groups[int(k)].append(name)
    return sorted(sorted(v) for v in groups.values() if len(v) > 1)


def test_every_module_is_in_a_layer():
    for name in modules():
        layer(name)


def test_no_import_circles():
    assert circles() == []


def test_no_import_runs_up_the_layers():
    up = sorted(f"{a} ({LAYERS[layer(a)][0]}) -> {b} ({LAYERS[layer(b)][0]})"
                for a, targets in graph().items() for b in targets if layer(b) > layer(a))
    assert up == []


def test_shared_layers_import_no_model():
    bad = sorted(f"{a} -> {b}" for a, targets in graph().items() for b in targets
                 if LAYERS[layer(a)][0] in SHARED and model_of(b) is not None)
    assert bad == []


def test_no_model_imports_another():
    bad = sorted(f"{a} -> {b}" for a, targets in graph().items() for b in targets
                 if model_of(a) and model_of(b) and model_of(a) != model_of(b))
    assert bad == []


@pytest.mark.parametrize("case", ["up", "model", "circle"])
def test_the_checks_see_a_violation(case, monkeypatch):
    """Each check fails on a graph with the fault planted (the checks can fail)."""
    g = dict(graph())
    if case == "up":
        g["mbsuite.errors"] = g.get("mbsuite.errors", frozenset()) | {"mbsuite.analysis.optimise"}
    elif case == "model":
        g["mbsuite.analysis.optimise"] = g["mbsuite.analysis.optimise"] | {"mbsuite.models.catenary.quality"}
    else:
        g["mbsuite.limits"] = g["mbsuite.limits"] | {"mbsuite.schema"}
    monkeypatch.setitem(globals(), "graph", lambda: g)
    check = {"up": test_no_import_runs_up_the_layers, "model": test_shared_layers_import_no_model,
             "circle": test_no_import_circles}[case]
    with pytest.raises(AssertionError):
        check()
