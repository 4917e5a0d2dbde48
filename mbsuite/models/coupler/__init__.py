"""Single and double 4-link (SS-link) couplers of low-floor tram drives (Maniowski & Czauderna).

Kinematics hand-derived (single.py, double.py, jacobian.py) and in Pinocchio (pinocchio.py), cross-checked;
double-coupler runs on two paths: MuJoCo (mujoco.py) and the rigid kinematic solution (reference.py). See README.md in
this package (its "Files" table says where everything is).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.coupler.spec:SPEC")
