"""A function named by where it lives, imported at its first call: a model's path table and hooks name their run
functions without importing them, so that listing the models (`mbsuite list`, `--help`) imports no engine code. And a
package's names imported at their first use (`lazy_names`): a model package hands on its `SPEC` so, and importing the
package (its command-line module, for `mbsuite catenary --help`) loads no other module of the model."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable
from typing import Any


class Deferred:
    """Stands for the function `target` = `"package.module:name"`; the module is imported at the first call. Pickles
    by its target (a worker process imports the function itself)."""

    def __init__(self, target: str):
        module, sep, name = target.partition(":")
        if not (module and sep and name):
            raise ValueError(f"a deferred function is named 'package.module:name', got {target!r}")
        self.target = target
        self._fn: Callable[..., Any] | None = None

    def resolve(self) -> Callable[..., Any]:
        """The function itself (imported now if it was not yet)."""
        if self._fn is None:
            module, _, name = self.target.partition(":")
            self._fn = getattr(importlib.import_module(module), name)
        return self._fn

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.resolve()(*args, **kwargs)

    def __reduce__(self) -> tuple[type, tuple[str]]:
        return (Deferred, (self.target,))

    def __repr__(self) -> str:
        return f"Deferred({self.target!r})"


def lazy_names(module: str, **targets: str) -> Callable[[str], Any]:
    """The module-level `__getattr__` (PEP 562) of module `module`: each name of `targets` (name ->
    `"package.module:name"`) imported at its first use and then kept in the module (the next use is a plain lookup)."""

    def __getattr__(name: str) -> Any:
        if name not in targets:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        try:
            value = Deferred(targets[name]).resolve()
        except AttributeError as exc:  # not an absent name: `getattr(module, name, None)` must not hide the defect
            raise ImportError(f"{module}.{name} ({targets[name]}): {exc}") from exc
        setattr(sys.modules[module], name, value)
        return value

    return __getattr__
