"""Where the model files live.

The repository keeps `mjcf/` and `models_urdf/` at its top level (the user's layout). With an editable install the
package
finds them next to itself; `MBSUITE_MODELS_DIR` overrides the root (a directory holding `mjcf/` and `models_urdf/`).
"""

from __future__ import annotations

import os
from pathlib import Path

from .errors import ModelFileError

PACKAGE_DIR = Path(__file__).resolve().parent


def models_root() -> Path:
    env = os.environ.get("MBSUITE_MODELS_DIR")
    candidates = [Path(env)] if env else []
    candidates.append(PACKAGE_DIR.parent)
    for root in candidates:
        if (root / "mjcf").is_dir() and (root / "models_urdf").is_dir():
            return root
    raise ModelFileError(
        "cannot find the model files (mjcf/ and models_urdf/); looked in "
        + ", ".join(str(c) for c in candidates)
        + ". Install mbsuite editable from its repository (pip install -e .) or set MBSUITE_MODELS_DIR."
    )


def mjcf_path(name: str) -> Path:
    """Path of `mjcf/<name>.xml`; raises ModelFileError naming the file if it is missing."""
    p = models_root() / "mjcf" / f"{name}.xml"
    if not p.is_file():
        raise ModelFileError(f"MJCF file not found: {p}")
    return p


def urdf_path(name: str) -> Path:
    """Path of `models_urdf/<name>.urdf`; raises ModelFileError naming the file if it is missing."""
    p = models_root() / "models_urdf" / f"{name}.urdf"
    if not p.is_file():
        raise ModelFileError(f"URDF file not found: {p}")
    return p
