"""The two IFToMM benchmark gates' stated geometry: the mechanisms, their bars and loop closures, and the trajectory
both paths return.

- `fourbar` (A02-type): the parallelogram four-bar of `mjcf/iftomm_fourbar.xml`; every half turn of the crank all bars
  are collinear, the closure Jacobian loses rank and the mechanism may switch to the anti-parallelogram branch.
  Branch indicator: the coupler's absolute angle (0 on the parallelogram branch).
- `bricard` (A04-type): the orthogonal Bricard linkage of `mjcf/iftomm_bricard.xml`; 6 closure rows on 5 joint
  coordinates with 1 DOF: the closure Jacobian has rank 4 (two redundant rows: the Bricard's own and the axial
  distance of the two `connect`s that make the sixth hinge).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

MECHANISMS = ("fourbar", "bricard")


@dataclass
class Closure:
    """A point closure: point `a` fixed in Pinocchio joint `ja` equals point `b` fixed in joint `jb` (0 = world)."""

    ja: int
    a: np.ndarray
    jb: int
    b: np.ndarray


@dataclass
class Trajectory:
    """A simulated trajectory: samples t, q, v, energy [J] and closure error [m], plus solver statistics."""
    t: np.ndarray
    q: np.ndarray  # (N, nq)
    v: np.ndarray  # (N, nv)
    energy: np.ndarray
    closure: np.ndarray  # max |closure error| (m) per sample
    stats: dict = field(default_factory=dict)


#: bar length of every benchmark bar [m] (the files' stated geometry)
BAR = 1.0


#: the stated geometry of each file: bodies and joints it must hold and its loop closures, each
#: (connect name, body1, point on body1, body2 or "world", point on body2), points in the bodies' frames [m]
DESIGN: dict[str, dict] = {
    "fourbar": {"bodies": ("crank", "coupler", "rocker"), "joints": ("crank", "coupler", "rocker"),
                # the coupler's far end C meets the rocker's tip: both bars BAR long, ground pivots BAR apart
                "closures": (("C", "coupler", (BAR, 0.0, 0.0), "rocker", (0.0, BAR, 0.0)),)},
    "bricard": {"bodies": ("bar1", "bar2", "bar3", "bar4", "bar5"), "joints": ("j1", "j2", "j3", "j4", "j5"),
                # the sixth hinge (axis x through the cube corner (0, 0, 1)): two points of bar5's end on that axis
                "closures": (("j6a", "bar5", (0.0, -BAR, 0.0), "world", (0.0, 0.0, BAR)),
                             ("j6b", "bar5", (0.5 * BAR, -BAR, 0.0), "world", (0.5 * BAR, 0.0, BAR)))},
}


#: largest closure gap at the initial pose q = 0, relative to the bar length, accepted at load (files rounded to 6
#: digits pass; a moved pivot or a changed bar length fails by orders of magnitude)
CLOSURE_RTOL = 1e-6
