"""Perturbed copies of a run: inside `perturbed(eps, seed)` every parameter dataclass built (through
`mbsuite.limits.check_fields`, which all of them call), every float of a scene's `[input]` and every initial state a
model hands to `state` is multiplied by (1 + eps z), z a standard normal drawn from the seed, the quantity's name and
its value - so a quantity rebuilt within one copy gets the same value (a value kept inside its declared range: a draw
that would cross a range end is mirrored); integers, words and exact zeros of parameters stay as they are, an initial
state at rest stays at rest. The context is a `ContextVar`: it reaches what the calling thread builds. Outside it
every function here returns its input unchanged. The check that uses these copies is `mbsuite.stability`.
"""


from __future__ import annotations

import contextlib
import dataclasses
import math
import zlib
from collections.abc import Iterator, Sequence
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass
class _Draw:
    eps: float
    seed: int

    def z(self, key: str, x: float) -> float:
        """The standard normal draw of value x under name `key`: the same name and value get the same draw within a
        copy, however often they are built (a check that rebuilds the parameters sees the run's values)."""
        h = zlib.crc32(f"{key}|{x!r}".encode())
        return float(np.random.default_rng((self.seed, h)).standard_normal())


_ACTIVE: ContextVar[_Draw | None] = ContextVar("mbsuite_perturbation", default=None)


@contextlib.contextmanager
def perturbed(eps: float, seed: int) -> Iterator[None]:
    """Inside: parameters, scene inputs and initial states are perturbed by relative `eps` (seeded draw)."""
    if not (math.isfinite(eps) and 0.0 < eps < 1e-3):
        raise ValueError(f"perturbation eps must be in (0, 1e-3), got {eps!r}")
    token = _ACTIVE.set(_Draw(float(eps), int(seed)))
    try:
        yield
    finally:
        _ACTIVE.reset(token)


def active() -> float:
    """The relative perturbation in force (0.0 outside `perturbed`)."""
    d = _ACTIVE.get()
    return d.eps if d is not None else 0.0


def value(x: float, limit: Any = None, key: str = "") -> float:
    """`x` perturbed by the draw in force (unchanged outside `perturbed`, or if x is 0), kept inside `limit`;
    `key` names the quantity (the draw depends on the seed, the key and the value)."""
    d = _ACTIVE.get()
    if d is None or x == 0.0 or not math.isfinite(x):
        return x
    dz = d.eps * d.z(key, x)
    y = x * (1.0 + dz)
    if limit is not None and not _inside(limit, y):
        y = x * (1.0 - dz)
        if not _inside(limit, y):
            return x
    return y


def _inside(limit: Any, y: float) -> bool:
    lo, hi = getattr(limit, "lo", None), getattr(limit, "hi", None)
    if lo is not None and (y < lo or (limit.lo_open and y == lo)):
        return False
    return not (hi is not None and (y > hi or (limit.hi_open and y == hi)))


def fields(obj: Any) -> None:
    """Perturb every float field of a parameter dataclass in place (frozen ones too); called by
    `mbsuite.limits.check_fields` after the check, so it does nothing outside `perturbed`."""
    if _ACTIVE.get() is None:
        return
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        lim = f.metadata.get("limit")
        if isinstance(v, float) and not (lim is not None and (lim.kind is not float or lim.choices is not None)):
            object.__setattr__(obj, f.name, value(v, lim, f"{type(obj).__name__}.{f.name}"))


def state(x: Sequence[float] | np.ndarray, key: str = "state") -> np.ndarray:
    """An initial state perturbed entry by entry, relative (an entry at exactly zero - a rotor at rest - stays there:
    a relative perturbation of zero is zero)."""
    x = np.array(x, dtype=float)
    if _ACTIVE.get() is None:
        return x
    return np.array([value(float(v), key=f"{key}[{i}]") for i, v in enumerate(x.ravel())]).reshape(x.shape)


