"""Pantograph-catenary interaction: a 2-D finite-element catenary (EN 50318:2002 reference scene), the 2-mass reference
pantograph, a consistent coupled integrator and the EN 50318 statistics. The catenary owns the coupling: any pantograph
model of the registry that declares `under_wire` runs under the wire through the protocol of `pantographs.py`. Where
everything is: the Files table of README.md."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...deferred import lazy_names

if TYPE_CHECKING:
    from .spec import SPEC as SPEC

#: `SPEC` (spec.py) imported at its first use: importing the package (its command line's module, for `--help`) loads
#: no other module of the model
__getattr__ = lazy_names(__name__, SPEC="mbsuite.models.catenary.spec:SPEC")
