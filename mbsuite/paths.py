"""Where the model files live, and the one call that gives a model file's path.

The repository keeps `mjcf/` and `models_urdf/` at its top level (the source of truth); a built wheel carries a copy
inside the package (`mbsuite/_modelfiles/`). `models_root()` looks, in order, in `MBSUITE_MODELS_DIR` (a directory
holding `mjcf/` and `models_urdf/`), in the installed package, and next to the package (an editable install).

    >>> import mujoco, mbsuite
    >>> _ = mbsuite.native.load()            # the model files' effects are mbsuite's engine plugins
    >>> model = mujoco.MjModel.from_xml_path(str(mbsuite.model_file("pantograph")))        # mjcf/pantograph.xml
    >>> urdf = mbsuite.model_file("coupler_double", "urdf")                                 # models_urdf/...urdf
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from .errors import ModelFileError

PACKAGE_DIR = Path(__file__).resolve().parent
KINDS = {"mjcf": ("mjcf", ".xml"), "urdf": ("models_urdf", ".urdf")}


def _candidates() -> list[Path]:
    env = os.environ.get("MBSUITE_MODELS_DIR")
    out = [Path(env)] if env else []
    out.append(Path(str(resources.files("mbsuite").joinpath("_modelfiles"))))
    out.append(PACKAGE_DIR.parent)
    return out


def models_root() -> Path:
    """The directory holding `mjcf/` and `models_urdf/`. `MBSUITE_MODELS_DIR`, when set, must hold at least one of
    them (a file asked for in a missing one is then an error naming it): never a silent fall-back to the shipped
    files."""
    env = os.environ.get("MBSUITE_MODELS_DIR")
    if env:
        root = Path(env)
        if not ((root / "mjcf").is_dir() or (root / "models_urdf").is_dir()):
            raise ModelFileError(f"MBSUITE_MODELS_DIR={env} holds neither mjcf/ nor models_urdf/; unset it to use "
                                 "the shipped model files")
        return root
    candidates = _candidates()
    for root in candidates:
        if (root / "mjcf").is_dir() and (root / "models_urdf").is_dir():
            return root
    raise ModelFileError(
        "cannot find the model files (mjcf/ and models_urdf/); looked in "
        + ", ".join(str(c) for c in candidates)
        + ". Reinstall mbsuite, or set MBSUITE_MODELS_DIR to a directory holding mjcf/ and models_urdf/."
    )


def model_file(name: str, kind: str = "mjcf") -> Path:
    """Path of a shipped model file: `kind="mjcf"` -> `mjcf/<name>.xml`, `kind="urdf"` -> `models_urdf/<name>.urdf`.
    Raises ModelFileError naming the file (and the shipped ones) if it is missing."""
    if kind not in KINDS:
        raise ModelFileError(f"model file kind {kind!r} is unknown; valid kinds: {list(KINDS)}")
    folder, suffix = KINDS[kind]
    d = models_root() / folder
    p = d / f"{name}{suffix}"
    if not p.is_file():
        shipped = sorted(q.stem for q in d.glob(f"*{suffix}"))
        raise ModelFileError(f"{kind.upper()} file not found: {p}; shipped {kind} models: {shipped}")
    return p


def model_files(kind: str = "mjcf") -> dict[str, Path]:
    """Every shipped model file of `kind`, by name."""
    if kind not in KINDS:
        raise ModelFileError(f"model file kind {kind!r} is unknown; valid kinds: {list(KINDS)}")
    folder, suffix = KINDS[kind]
    return {p.stem: p for p in sorted((models_root() / folder).glob(f"*{suffix}"))}


def mjcf_path(name: str) -> Path:
    """Path of `mjcf/<name>.xml` (same as `model_file(name, "mjcf")`)."""
    return model_file(name, "mjcf")


def urdf_path(name: str) -> Path:
    """Path of `models_urdf/<name>.urdf` (same as `model_file(name, "urdf")`)."""
    return model_file(name, "urdf")
