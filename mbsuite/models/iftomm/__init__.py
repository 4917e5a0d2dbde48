"""Two gates of the IFToMM multibody benchmark (A02-type four-bar through its singular positions, A04-type
over-constrained Bricard mechanism) built with mbsuite's MuJoCo and Pinocchio machinery. See README.md."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.iftomm.spec:SPEC")
