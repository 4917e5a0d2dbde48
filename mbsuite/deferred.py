"""A function named by where it lives, imported at its first call: a model's path table and hooks name their run
functions without importing them, so that listing the models (`mbsuite list`, `--help`) imports no engine code."""

from __future__ import annotations

import importlib
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
