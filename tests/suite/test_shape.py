"""Every model has the one shape the contributor's guide describes, and the layers below the models name none of them.
The test names no model: it walks the registry and the source tree."""

from __future__ import annotations

import ast
import dataclasses
from pathlib import Path

import pytest

import mbsuite
from mbsuite.errors import SceneError
from mbsuite.registry import RunPath, models

ROOT = Path(mbsuite.__file__).parent
MODELS = sorted(models())


@pytest.mark.parametrize("name", MODELS)
def test_path_table(name):
    """One table picks the path: every row runs, says what it is, and its label selects it in a scene."""
    spec = models()[name]
    assert spec.paths, f"{name}: no path"
    assert spec.solver.engine in spec.paths
    scene = mbsuite.load_scene(name)
    for key, path in spec.paths.items():
        assert isinstance(path, RunPath) and callable(path.run) and path.what.strip(), (name, key)
        assert scene.replace(solver={"engine": path.label}).solver.engine == key
        assert scene.replace(solver={"engine": key}).solver.engine == key
    with pytest.raises(SceneError, match=r"solver.engine = .no-such-path. .* is invalid; valid: one of \["):
        scene.replace(solver={"engine": "no-such-path"})


@pytest.mark.parametrize("name", MODELS)
def test_solver_defaults_are_the_scene_defaults(name):
    """A scene that sets no solver key runs on the model's declared defaults."""
    spec = models()[name]
    scene = mbsuite.scene_from_dict({"model": name})
    assert dataclasses.asdict(scene.solver) == dataclasses.asdict(spec.solver)


def _imports(path: Path) -> set[str]:
    """Absolute dotted names of every module a file imports (also inside functions), resolved against its package."""
    pkg = ".".join(path.relative_to(ROOT.parent).with_suffix("").parts[:-1])
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = pkg.split(".")[: len(pkg.split(".")) - node.level + 1] if node.level else []
            mod = ".".join([*base, node.module] if node.module else base)
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
    return out


def test_the_engine_layer_names_no_model():
    """`mbsuite/engines` imports neither a model nor the registry that finds them (models hand it what it needs)."""
    for f in sorted((ROOT / "engines").rglob("*.py")):
        bad = sorted(m for m in _imports(f) if m.startswith(("mbsuite.models", "mbsuite.registry")))
        assert not bad, f"{f.relative_to(ROOT)} imports {bad}"
    for f in sorted((ROOT / "engines").rglob("*.[ch]")):
        text = f.read_text().lower()
        for name in MODELS:
            assert name not in text, f"{f.relative_to(ROOT)} names the model '{name}'"


@pytest.mark.parametrize("name", MODELS)
def test_no_import_circle_inside_a_model(name):
    """No two modules of a model folder import each other, directly or round a longer loop."""
    prefix = f"mbsuite.models.{name}."
    graph = {m: {x for x in deps if x.startswith(prefix)}
             for m, deps in _module_graph().items() if m.startswith(prefix)}

    def reach(a: str) -> set[str]:
        seen, todo = set(), list(graph[a])
        while todo:
            b = todo.pop()
            if b not in seen:
                seen.add(b)
                todo.extend(graph.get(b, ()))
        return seen

    circles = sorted(m for m in graph if m in reach(m))
    assert not circles, f"{name}: modules on an import circle: {circles}"


@pytest.mark.parametrize("name", MODELS)
def test_readme_files_table_names_every_module(name):
    """The README's files table names every module of the folder (a newcomer finds the equations and the run there)."""
    folder = ROOT / "models" / name
    text = (folder / "README.md").read_text()
    assert "## Files" in text, f"{name}: README has no '## Files' table"
    table = text[text.index("## Files"):]
    table = table[: table.find("\n## ", 1)] if "\n## " in table[1:] else table
    missing = [f.name for f in sorted(folder.glob("*.py")) if f.name != "__init__.py" and f"`{f.name}`" not in table]
    assert not missing, f"{name}: README files table does not name {missing}"


def _module_graph() -> dict[str, set[str]]:
    """Module -> the mbsuite modules it imports (at module level or inside functions): `from pkg import name` is an
    import of `pkg.name` when that is a module, else of `pkg`."""
    files = {".".join(f.relative_to(ROOT.parent).with_suffix("").parts).removesuffix(".__init__"): f
             for f in ROOT.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for mod, f in files.items():
        pkg = mod if f.name == "__init__.py" else mod.rpartition(".")[0]
        deps: set[str] = set()
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.Import):
                deps.update(a.name for a in node.names if a.name in files)
            elif isinstance(node, ast.ImportFrom):
                parts = pkg.split(".")
                base = ".".join(parts[: len(parts) - node.level + 1]) if node.level else ""
                src = ".".join(x for x in (base, node.module or "") if x)
                for a in node.names:
                    deps.add(f"{src}.{a.name}" if f"{src}.{a.name}" in files else src)
        graph[mod] = (deps & set(files)) - {mod}
    return graph


def test_no_import_circle_in_the_package():
    """No module of mbsuite reaches itself through imports (Tarjan's strongly connected components; a package's
    `__init__` counts only for what it imports itself)."""
    graph = _module_graph()
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    circles: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                circles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not circles, f"import circles: {circles}"


def test_every_shipped_scene_is_in_its_model_readme():
    """A scene a model ships (`scenes/*.toml`) is named in its README (`name` in backquotes): a user finds it there."""
    missing = []
    for readme in sorted((ROOT / "models").glob("*/README.md")):
        text = readme.read_text(encoding="utf-8")
        for scene in sorted((readme.parent / "scenes").glob("*.toml")):
            if f"`{scene.stem}`" not in text:
                missing.append(f"{readme.parent.name}/{scene.stem}")
    assert not missing, missing
