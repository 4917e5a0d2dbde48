"""Every public module, function, class and method of the package has a docstring (the API reference is built from
them: `make docs`)."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "mbsuite"


def _undocumented() -> list[str]:
    missing: list[str] = []
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        rel = path.relative_to(PACKAGE.parent)
        if not ast.get_docstring(tree):
            missing.append(f"{rel}: module")

        def visit(node: ast.AST, prefix: str, rel: Path = rel) -> None:
            for ch in ast.iter_child_nodes(node):
                if isinstance(ch, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                    if ch.name.startswith("_"):
                        continue
                    if not ast.get_docstring(ch):
                        missing.append(f"{rel}: {prefix}{ch.name}")
                    if isinstance(ch, ast.ClassDef):
                        visit(ch, f"{prefix}{ch.name}.")

        visit(tree, "")
    return missing


def test_every_public_name_has_a_docstring():
    missing = _undocumented()
    assert not missing, f"{len(missing)} public names without a docstring:\n" + "\n".join(missing)
