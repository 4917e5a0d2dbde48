"""MuJoCo plumbing shared by all models: loading with clear errors (mbsuite's engine plugins registered first),
integrators, warning counters, the joint-space inertia, and scoped Python callbacks.

mbsuite's shipped scenes install no Python callback: their effects are engine plugins (`native/`). `callbacks(...)`
remains for the Python twins of those plugins (the readable reference the tests compare against) and for users'
own experiments: MuJoCo's Python callbacks (`mujoco.set_mjcb_*`) are process-global and hold the GIL, so they are
installed only for the duration of a `with` block and always removed.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path

import mujoco
import numpy as np

from ..errors import ModelFileError, SceneError
from . import native

INTEGRATOR = {
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE,
}

_CALLBACK_SETTERS = {
    "act_dyn": mujoco.set_mjcb_act_dyn,
    "act_gain": mujoco.set_mjcb_act_gain,
    "act_bias": mujoco.set_mjcb_act_bias,
    "passive": mujoco.set_mjcb_passive,
    "control": mujoco.set_mjcb_control,
}
_active: dict[str, Callable] = {}


def read_model_text(path: Path) -> str:
    """The text of a model file, refused (ModelFileError naming the file) if it is not UTF-8 or declares XML entities
    (a DTD: entity expansion is a denial-of-service vector and no model file needs one)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ModelFileError(f"cannot read model file {path}: {exc.strerror or exc}") from exc
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ModelFileError(f"model file {path} is not UTF-8 text (byte {exc.start})") from exc
    if "<!DOCTYPE" in text or "<!ENTITY" in text:
        raise ModelFileError(f"model file {path} declares a DTD or XML entities; model files may not")
    return text


def one_line(text: object) -> str:
    """A parser's message on one line (MuJoCo and Pinocchio report over several)."""
    return " ".join(str(text).split())


def check_compiled(model: mujoco.MjModel, name: str) -> None:
    """Checks of a compiled model that MuJoCo's compiler leaves to the user: a positive, finite timestep."""
    h = float(model.opt.timestep)
    if not (np.isfinite(h) and h > 0):
        raise ModelFileError(f"{name}: option timestep = {h!r} must be a positive finite number")


FileCheck = Callable[[Path, str, object], None]


def load_model(source: str | Path | mujoco.MjSpec, *, from_string: bool = False,
               check: FileCheck | None = None) -> mujoco.MjModel:
    """Compile an MJCF file/string/MjSpec (mbsuite's engine plugins registered first); any parse or compile error is
    re-raised as ModelFileError naming the source, on one line. `check(path, "mujoco", model)`, the checks a model
    hands in for its own file (e.g. loop closures against the stated link lengths), runs on a loaded file."""
    native.load()
    name = "<string>" if from_string else ("<MjSpec>" if isinstance(source, mujoco.MjSpec) else str(source))
    try:
        if isinstance(source, mujoco.MjSpec):
            m = source.compile()
        elif from_string:
            m = mujoco.MjModel.from_xml_string(str(source))
        else:
            p = Path(source)
            if not p.is_file():
                raise ModelFileError(f"MJCF file not found: {p}")
            read_model_text(p)
            m = mujoco.MjModel.from_xml_path(str(p))
    except ModelFileError:
        raise
    except Exception as exc:  # mujoco raises ValueError with the parser message
        raise ModelFileError(f"MuJoCo cannot load {name}: {one_line(exc)}") from exc
    check_compiled(m, name)
    if check is not None and not from_string and not isinstance(source, mujoco.MjSpec):
        check(Path(source), "mujoco", m)
    return m


def set_integrator(model: mujoco.MjModel, integrator: str, timestep: float) -> None:
    """Set a model's integrator (by name) and timestep; an unknown name is a SceneError listing the valid ones."""
    if integrator not in INTEGRATOR:
        raise SceneError(f"unknown integrator {integrator!r}; valid: {list(INTEGRATOR)}")
    model.opt.integrator = INTEGRATOR[integrator]
    model.opt.timestep = float(timestep)


def active_callbacks() -> dict[str, Callable]:
    """The mbsuite callbacks currently installed (empty outside a `callbacks()` block)."""
    return dict(_active)


@contextlib.contextmanager
def callbacks(**cbs: Callable | None) -> Iterator[None]:
    """Install MuJoCo callbacks (`act_dyn`, `act_gain`, `act_bias`, `passive`, `control`) for a block; None = not
    installed.

    Nesting the same callback is an error (they are process-global)."""
    wanted = {k: v for k, v in cbs.items() if v is not None}
    bad = sorted(set(wanted) - set(_CALLBACK_SETTERS))
    if bad:
        raise ValueError(f"unknown MuJoCo callback(s) {bad}; valid: {sorted(_CALLBACK_SETTERS)}")
    clash = sorted(set(wanted) & set(_active))
    if clash:
        raise RuntimeError(f"MuJoCo callback(s) {clash} already installed by another simulation in this process")
    try:
        for k, fn in wanted.items():
            _CALLBACK_SETTERS[k](fn)
            _active[k] = fn
        yield
    finally:
        for k in wanted:
            _CALLBACK_SETTERS[k](None)
            _active.pop(k, None)


def warnings_raised(data: mujoco.MjData) -> dict[str, int]:
    """Non-zero MuJoCo warning counters by name."""
    counts = data.warning.number  # one array: iterating the struct list costs ~100 us
    return {mujoco.mjtWarning(int(i)).name: int(counts[i]) for i in np.flatnonzero(counts)}


def full_inertia(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Dense joint-space inertia M(q) (mujoco 4: `mj_fullM(m, d, dst)` reads `d.M`); call after mj_forward."""
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return M
