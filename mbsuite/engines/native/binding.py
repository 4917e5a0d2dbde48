"""The one way Python binds C in mbsuite's native library: a `Declaration` per C file, bound by
`mbsuite.engines.native.bind` (which is `bind_with` on the package's `load`).

A declaration names the C file, its functions (`CFunction`: name, restype, argtypes), the ctypes mirror of each of
its structs with the C function that returns the struct's `sizeof` (`CStruct`), and its ABI function with the version
Python expects. `bind(declaration)` loads the library (built once, cached) under `LOCK`, checks the ABI and every
struct size, and returns a `Binding` whose attributes are the declared functions, each with its argtypes and restype
set. A mismatch is a `NativeBuildError` naming the C file, the function and both values. Bindings are cached per
declaration, so every thread gets the same one; each binding owns its function objects, so two declarations never
overwrite each other's argtypes on the shared handle.

    CAT = Declaration("models/catenary/native/catenary.c", "mbs_cat_abi", 3,
                      functions=(CFunction("mbs_cat_factor", ctypes.c_int, (ctypes.c_void_p,)), ...),
                      structs=(CStruct(_Job, "mbs_cat_job_size"),))
    lib = bind(CAT)
    lib.mbs_cat_factor(ctypes.byref(job))
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ...errors import MbsuiteError

PACKAGE_DIR = Path(__file__).resolve().parents[2]
#: guards loading the library and binding declarations (reentrant: `bind` calls `load` while holding it)
LOCK = threading.RLock()


class NativeBuildError(MbsuiteError, RuntimeError):
    """The native library could not be compiled or loaded (no C compiler, a compile error, a stale ABI)."""


@dataclass(frozen=True)
class CFunction:
    """A C function of the library: its name, ctypes restype (None for void) and argtypes."""

    name: str
    restype: Any
    argtypes: tuple[Any, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "argtypes", tuple(self.argtypes))


@dataclass(frozen=True)
class CStruct:
    """A ctypes mirror `ctype` of a C struct, and the C function (`int f(void)`) returning the struct's sizeof."""

    ctype: type[ctypes.Structure]
    size_function: str


@dataclass(frozen=True)
class Declaration:
    """What Python expects of one C file of the library: `source` (path under the `mbsuite` package, e.g.
    "models/catenary/native/catenary.c"), its ABI function (`int f(void)`) and the version `abi` it must return,
    its `functions` and its `structs`."""

    source: str
    abi_function: str
    abi: int
    functions: tuple[CFunction, ...] = ()
    structs: tuple[CStruct, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "functions", tuple(self.functions))
        object.__setattr__(self, "structs", tuple(self.structs))


class Binding:
    """The declared functions of one C file on the loaded library, as attributes (`binding.mbs_cat_run(...)`);
    `handle` is the library's ctypes handle, `path` its file, `declaration` what was bound."""

    def __init__(self, handle: ctypes.CDLL, path: Path, declaration: Declaration, functions: dict[str, Any]):
        self.handle = handle
        self.path = path
        self.declaration = declaration
        self.__dict__.update(functions)

    def __getattr__(self, name: str) -> Any:  # only reached for names that are not declared
        raise AttributeError(f"{name} is not declared in the binding of {self.declaration.source}")

    def __repr__(self) -> str:
        return f"<Binding {self.declaration.source} on {self.path}>"


_bindings: dict[Declaration, Binding] = {}


def declare(handle: ctypes.CDLL, path: Path, declaration: Declaration) -> Binding:
    """Declare `declaration`'s functions on `handle` (fresh function objects, the handle's own attributes untouched),
    check its ABI and struct sizes; NativeBuildError on a missing function or a mismatch. Not cached (see `bind`)."""
    d = declaration
    where = f"{d.source} (in {path})"
    sigs = [CFunction(d.abi_function, ctypes.c_int), *(CFunction(s.size_function, ctypes.c_int) for s in d.structs)]
    functions: dict[str, Any] = {}
    for f in (*sigs, *d.functions):
        try:
            fn = handle[f.name]
        except AttributeError:
            raise NativeBuildError(f"{where} has no function {f.name}") from None
        fn.restype, fn.argtypes = f.restype, list(f.argtypes)
        functions[f.name] = fn
    got = functions[d.abi_function]()
    if got != d.abi:
        raise NativeBuildError(f"{where}: {d.abi_function}() returns ABI {got}, Python expects ABI {d.abi}: the C "
                               "file and its declaration disagree")
    for s in d.structs:
        got = functions[s.size_function]()
        want = ctypes.sizeof(s.ctype)
        if got != want:
            raise NativeBuildError(f"{where}: {s.size_function}() returns {got} bytes, the ctypes struct "
                                   f"{s.ctype.__qualname__} is {want} bytes: the C struct and its mirror disagree")
    return Binding(handle, path, d, functions)


def bind_with(declaration: Declaration, load: Callable[[], ctypes.CDLL], sources: Callable[[], list[Path]]) -> Binding:
    """The binding of `declaration` on the library `load()` opens (once, under `LOCK`; `sources()` its C files):
    `mbsuite.engines.native.bind` with the loader passed in. Cached per declaration."""
    b = _bindings.get(declaration)
    if b is not None:
        return b
    with LOCK:
        b = _bindings.get(declaration)
        if b is None:
            if (PACKAGE_DIR / declaration.source).resolve() not in sources():
                raise NativeBuildError(f"{declaration.source} is not a source of mbsuite's native library "
                                       f"(a Declaration's source is a path under {PACKAGE_DIR})")
            handle = load()
            b = _bindings[declaration] = declare(handle, Path(handle._name), declaration)
    return b
