"""Brecknell-Willis asymmetric pantograph (Eppinger 1984): three cross-checked paths (README "Files").

- `reference` (label `equations`): hand-derived equations (`equations.py`), event-exact stick/slip (`reference.py`);
- `mujoco`: the MJCF of the scene's effects, cylinder and elbow as engine plugins, on the native core (`mujoco.py`);
- Pinocchio (`pinocchio.py`): M(q), gravity, frame Jacobians from the URDF/MJCF, for the equilibrium and cross-checks.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.pantograph.spec:SPEC")
