"""mbsuite's compiled layer: MuJoCo engine plugins (the models' effects) and the step-and-record core, in C.

One documented call makes MuJoCo know mbsuite's plugins, in any script or viewer session:

    >>> import mujoco, mbsuite.native          # the same module as mbsuite.engines.native
    >>> _ = mbsuite.native.load()              # compiles once (cached), registers the plugins with MuJoCo
    >>> m = mujoco.MjModel.from_xml_path(str(mbsuite.model_file("pantograph")))

The sources are `core.c` here, every model package's `native/*.c` and every shared component package's
(`mbsuite/components/*/native/*.c`), in that order, each group sorted. They are compiled with the system
C compiler (`cc`, or `$CC`) against the headers that the installed mujoco wheel ships (`mujoco/include`), linked to
that wheel's `libmujoco`, and cached under `$MBSUITE_NATIVE_DIR` (default `$XDG_CACHE_HOME/mbsuite` or
`~/.cache/mbsuite`) in a folder named by the hash of the sources, the compiler flags and the mujoco version: a new
mujoco or an edited source compiles anew, nothing stale is ever loaded. Compiling against the installed wheel's own
headers (rather than at wheel-build time against whatever mujoco the build environment held) is what keeps the plugin
structs and `mjData` offsets right whatever mujoco 4.x a user has.

Floating point is pinned by the flags (`CFLAGS`): `-ffp-contract=off` forbids the compiler to fuse a*b+c into one
fused multiply-add (GCC fuses by default in its GNU C modes whenever the target has FMA: on aarch64 and ppc64 always,
on x86-64 under `-march=native` or an FMA-capable `-march`; clang fuses within an expression). Every sum is then
computed in the order the source writes it, with one rounding per operation, so the library's arithmetic is the same
on every CPU and for every `-march`. Nothing else needs pinning: `-fno-fast-math` keeps the compiler from reordering
sums (GCC's vectoriser keeps floating-point reductions in order, "fold-left"), and on x86-64 and aarch64 doubles carry
no excess precision. What the flags cannot pin is the C library's `sin`, `cos`, `pow`, `atan2`, ...: glibc picks an
FMA variant at run time on CPUs that have FMA, and its results differ from the other variant's by one ulp for a few
arguments in ten thousand (docs/reproducibility.md has the measurements).

`MBSUITE_NATIVE_EXTRA_CFLAGS` (shell words, e.g. "-march=native") is appended to the flags for checks such as the
determinism tests, which build the library with two `-march` settings and compare the results bit for bit. The extra
flags come last, so they can undo the pinning ("-ffp-contract=fast -mfma" does); they are part of the cache key, so
such a build never replaces the default one. Leave it unset for results that follow docs/reproducibility.md.

Python binds the C in one way (`binding.py`): a `Declaration` per C file (its functions, the ctypes mirrors of its
structs with the C functions returning their sizes, its ABI function and version) and `bind(declaration)`, which loads
the library once under the lock, checks the ABI and every struct size and returns the cached `Binding`. `load()` binds
the core's own declaration (`CORE`) the same way.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from .binding import LOCK as _lock
from .binding import PACKAGE_DIR, Binding, CFunction, CStruct, Declaration, NativeBuildError, bind_with, declare

HERE = Path(__file__).resolve().parent
MODELS_DIR = PACKAGE_DIR / "models"
COMPONENTS_DIR = PACKAGE_DIR / "components"
LIB_NAME = "libmbsuite_native.so"
#: compiler flags; `-fno-fast-math -ffp-contract=off` pin the floating point (module docstring)
CFLAGS = ("-O2", "-fPIC", "-shared", "-std=gnu11", "-Wall", "-Wno-unused-parameter", "-fno-fast-math",
          "-ffp-contract=off")
#: environment variable whose shell words are appended to CFLAGS (checks only; part of the cache key)
EXTRA_CFLAGS_ENV = "MBSUITE_NATIVE_EXTRA_CFLAGS"
ABI_VERSION = 2
_P = ctypes.c_void_p
#: the core's entry points (`core.c`); the mbs_job layout is checked by `mbsuite.engines.core` (`job_size`)
CORE = Declaration("engines/native/core.c", "mbs_abi_version", ABI_VERSION, functions=(
    CFunction("mbs_plugin_overflow", ctypes.c_int), CFunction("mbs_job_size", ctypes.c_int),
    CFunction("mbs_plugin_fault", ctypes.c_int, (_P,) * 7), CFunction("mbs_run", ctypes.c_int, (_P, _P, _P)),
    CFunction("mbs_signal", ctypes.c_double, (_P, ctypes.c_double)),
    CFunction("mbs_fp_contract_probe", ctypes.c_double, (ctypes.c_double,) * 3),
))

__all__ = ["ABI_VERSION", "CORE", "Binding", "CFunction", "CStruct", "Declaration", "NativeBuildError", "bind",
           "build", "build_key", "cache_root", "cflags", "declare", "fuses_multiply_add", "job_size", "library_path",
           "load", "mujoco_dirs", "plugin_names", "sources"]

_lib: ctypes.CDLL | None = None


def _native_files(pattern: str) -> list[Path]:
    """Files matching `pattern` here, then in every model package's `native/`, then in every component package's
    `native/`; each group sorted (an empty group is fine)."""
    return (sorted(HERE.glob(pattern)) + sorted(MODELS_DIR.glob(f"*/native/{pattern}"))
            + sorted(COMPONENTS_DIR.glob(f"*/native/{pattern}")))


def sources() -> list[Path]:
    """The C sources of the library: the core here, then every model package's `native/*.c`, then every component
    package's `native/*.c` (each group sorted)."""
    return _native_files("*.c")


def _headers() -> list[Path]:
    return _native_files("*.h")


def mujoco_dirs() -> tuple[Path, Path]:
    """(include directory, libmujoco shared object) of the installed mujoco wheel."""
    import mujoco

    root = Path(mujoco.__file__).resolve().parent
    inc = root / "include"
    libs = sorted(root.glob("libmujoco.so*")) or sorted(root.glob("libmujoco*.dylib"))
    if not (inc / "mujoco" / "mujoco.h").is_file() or not libs:
        raise NativeBuildError(f"the mujoco wheel at {root} ships no headers or no libmujoco; mbsuite's native layer "
                               "needs both (mujoco >= 4 from PyPI has them)")
    return inc, libs[0]


def cflags() -> tuple[str, ...]:
    """The flags the library is compiled with: `CFLAGS`, then the words of $MBSUITE_NATIVE_EXTRA_CFLAGS (if set)."""
    return CFLAGS + tuple(shlex.split(os.environ.get(EXTRA_CFLAGS_ENV, "")))


def _compiler() -> list[str]:
    """The C compiler command: $CC (may carry arguments, e.g. "ccache gcc"), else cc, gcc or clang."""
    cc = shlex.split(os.environ.get("CC", "")) or [shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
                                                   or ""]
    if not cc[0]:
        raise NativeBuildError("mbsuite's native layer needs a C compiler (cc, gcc or clang, or $CC) to compile its "
                               "MuJoCo plugins once per mujoco version; install one (e.g. apt install gcc)")
    return cc


def cache_root() -> Path:
    """Where the native library is built and cached: $MBSUITE_NATIVE_DIR, else ~/.cache/mbsuite."""
    env = os.environ.get("MBSUITE_NATIVE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "mbsuite"


def build_key() -> str:
    """Hash of everything the binary depends on: sources, headers, flags, compiler, mujoco version and library."""
    import mujoco

    inc, lib = mujoco_dirs()
    h = hashlib.sha256()
    for p in sources() + _headers():  # every file's place in the package and its whole content
        data = p.read_bytes()
        h.update(f"{os.path.relpath(p, PACKAGE_DIR)}\0{len(data)}\0".encode())
        h.update(data)
    h.update(" ".join(cflags()).encode())
    cc = _compiler()
    h.update(" ".join(cc).encode())
    h.update(subprocess.run([*cc, "--version"], capture_output=True, text=True, check=False).stdout.encode())
    h.update(mujoco.__version__.encode())
    h.update(str(lib).encode())
    for header in sorted((inc / "mujoco").glob("*.h")):
        h.update(header.read_bytes())
    h.update(sys.platform.encode())
    return h.hexdigest()[:20]


def library_path() -> Path:
    """Where the library for the installed mujoco and the current sources lives (it may not be built yet)."""
    return cache_root() / f"native-{build_key()}" / LIB_NAME


def build(force: bool = False) -> Path:
    """Compile the library if it is not cached (or `force`); returns its path. Atomic: concurrent builders never see a
    half-written file."""
    out = library_path()
    if out.is_file() and not force:
        return out
    inc, lib = mujoco_dirs()
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
    except OSError:  # an unwritable home: the system's temporary directory, per user
        out = Path(tempfile.gettempdir()) / f"mbsuite-{os.getuid()}" / out.parent.name / LIB_NAME
        if out.is_file() and not force:
            return out
        out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".build-", suffix=".so", dir=out.parent)
    os.close(fd)
    cmd = [*_compiler(), *cflags(), f"-I{inc}", f"-I{HERE}", *map(str, sources()), "-o", tmp, str(lib),
           f"-Wl,-rpath,{lib.parent}", "-lm"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        if proc.returncode != 0:
            raise NativeBuildError(f"compiling mbsuite's native layer failed ({cmd[0]}):\n{proc.stderr.strip()}")
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return out


def load() -> ctypes.CDLL:
    """Build (once, cached) and load the library; registers mbsuite's engine plugins with MuJoCo. Idempotent and
    thread-safe. Returns the ctypes handle of the library, with the core's entry points (`CORE`) declared on it."""
    global _lib
    if _lib is not None:
        return _lib
    with _lock:
        if _lib is not None:
            return _lib
        import mujoco

        path = build()
        mujoco.mj_loadPluginLibrary(str(path))  # dlopen: its constructors register the plugins
        lib = ctypes.CDLL(str(path))  # the same handle (dlopen is reference counted)
        core = declare(lib, path, CORE)
        if core.mbs_plugin_overflow():
            raise NativeBuildError("more engine plugins registered than the native core tracks (MBS_MAX_PLUGINS)")
        for name in (CORE.abi_function, *(f.name for f in CORE.functions)):  # as the handle's attributes
            setattr(lib, name, getattr(core, name))
        _lib = lib
        return lib


def bind(declaration: Declaration) -> Binding:
    """The binding of one C file of the library (`binding.py`): loads the library once (thread-safe), declares the
    functions, checks the ABI and every struct size (NativeBuildError naming the C file, the function and both values on
    a mismatch). Cached per declaration: every call and every thread gets the same `Binding`."""
    return bind_with(declaration, load, sources)


def fuses_multiply_add() -> bool:
    """True if the loaded library fuses a*b+c into one rounding (an FMA): never with `CFLAGS`; a build whose
    $MBSUITE_NATIVE_EXTRA_CFLAGS re-enable contraction on an FMA target does."""
    a, b = 1.0 + 2.0**-30, 1.0 - 2.0**-30  # a*b = 1 - 2^-60: rounds to 1 unless fused with the -1
    return load().mbs_fp_contract_probe(a, b, -1.0) != 0.0


def job_size() -> int:
    """sizeof(mbs_job) of the loaded library (checked against the ctypes layout)."""
    return int(load().mbs_job_size())


def plugin_names() -> list[str]:
    """Names of mbsuite's registered MuJoCo plugins (after `load()`)."""
    import re

    load()
    names = []
    for p in sources():
        names += re.findall(r'\.name\s*=\s*"(mbsuite\.[^"]+)"', p.read_text())
    return sorted(names)
