"""Perturbed copies of a run: inside `perturbed(eps, seed)` every parameter dataclass built (through
`mbsuite.limits.check_fields`, which all of them call), every float of a scene's `[input]` and every initial state a
model hands to `state` is multiplied by (1 + eps z), z a standard normal drawn from the seed, the quantity's name and
its value (or, given a range [eps, eps_max], by (1 + e z) with e drawn log-uniform in the range for each quantity: the
rounding of a stranger's machine, emulated) - so a quantity rebuilt within one copy gets the same value (a value kept
inside its declared range: a draw that would cross a range end is mirrored); integers, words and exact zeros of
parameters stay as they are, an initial state at rest stays at rest. The context is a `ContextVar`: it reaches what the
calling thread builds. Outside it every function here returns its input unchanged. The check that uses these copies is
`mbsuite.trust.robustness`.
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
    eps_max: float | None = None
    outer: _Draw | None = None  # the draw in force when this one was entered (nested copies compose)
    made: set[float] = dataclasses.field(default_factory=set)  # the values this copy produced

    def rel(self, key: str, x: float) -> float:
        """The relative change eps z of value x under name `key`, z a standard normal: the same name and value get
        the same draw within a copy, however often they are built (a check that rebuilds the parameters sees the
        run's values). With a range, eps is drawn log-uniform in [eps, eps_max] after z (so z is the same draw)."""
        rng = np.random.default_rng((self.seed, zlib.crc32(f"{key}|{x!r}".encode())))
        z = float(rng.standard_normal())
        if self.eps_max is None:
            return self.eps * z
        return self.eps * (self.eps_max / self.eps) ** float(rng.uniform()) * z

    def apply(self, x: float, limit: Any, key: str) -> float:
        """x perturbed by the outer draws, then by this one; a value this copy produced stays as it is (an object
        rebuilt from another's fields, a rotor inertia taken from a perturbed parameter)."""
        if x in self.made:
            return x
        if self.outer is not None:
            x = self.outer.apply(x, limit, key)
        dz = self.rel(key, x)
        y = x * (1.0 + dz)
        if limit is not None and not _inside(limit, y):
            y = x * (1.0 - dz)
            if not _inside(limit, y):
                return x
        self.made.add(y)
        return y


#: the draw key shared by coordinates along a line (supports, droppers, clamps, wire ends): equal stays equal
POSITION = "position"

_ACTIVE: ContextVar[_Draw | None] = ContextVar("mbsuite_perturbation", default=None)


@contextlib.contextmanager
def perturbed(eps: float, seed: int, eps_max: float | None = None) -> Iterator[None]:
    """Inside: parameters, scene inputs and initial states are perturbed by relative `eps` (seeded draw), or by a
    relative size drawn per quantity in [eps, eps_max]. Inside another `perturbed`, on top of its draws (a stability
    check made in the perturbed tests compares its copies with the run as the outer draws made it)."""
    if not (math.isfinite(eps) and 0.0 < eps < 1e-3):
        raise ValueError(f"perturbation eps must be in (0, 1e-3), got {eps!r}")
    if eps_max is not None and not (math.isfinite(eps_max) and eps <= eps_max < 1e-3):
        raise ValueError(f"perturbation eps_max must be in [eps, 1e-3) = [{eps!r}, 1e-3), got {eps_max!r}")
    token = _ACTIVE.set(_Draw(float(eps), int(seed), None if eps_max is None else float(eps_max), _ACTIVE.get()))
    try:
        yield
    finally:
        _ACTIVE.reset(token)


def active() -> float:
    """The (smallest) relative perturbation in force (0.0 outside `perturbed`)."""
    d = _ACTIVE.get()
    return d.eps if d is not None else 0.0


def size() -> float:
    """The largest relative size of a draw in force (eps_max, or eps; 0.0 outside `perturbed`): a value compared
    with a closed form of unperturbed constants may differ by a few times this."""
    d = _ACTIVE.get()
    return 0.0 if d is None else (d.eps_max if d.eps_max is not None else d.eps)


def value(x: float, limit: Any = None, key: str = "") -> float:
    """`x` perturbed by the draw in force (unchanged outside `perturbed`, or if x is 0), kept inside `limit`;
    `key` names the quantity (the draw depends on the seed, the key and the value)."""
    d = _ACTIVE.get()
    if d is None or x == 0.0 or not math.isfinite(x):
        return x
    return d.apply(x, limit, key)


def _inside(limit: Any, y: float) -> bool:
    lo, hi = getattr(limit, "lo", None), getattr(limit, "hi", None)
    if lo is not None and (y < lo or (limit.lo_open and y == lo)):
        return False
    return not (hi is not None and (y > hi or (limit.hi_open and y == hi)))


def fields(obj: Any) -> None:
    """Perturb every float field of a parameter dataclass in place (frozen ones too); called by
    `mbsuite.limits.check_fields` after the check, so it does nothing outside `perturbed`. A field's draw is keyed by
    `<class>.<field>`, or by the shared key in its metadata `draw` (positions along a line: `POSITION`), so that equal
    coordinates of different objects (a wire's end and the last support) stay equal."""
    if _ACTIVE.get() is None:
        return
    for f in dataclasses.fields(obj):
        v = getattr(obj, f.name)
        lim = f.metadata.get("limit")
        if isinstance(v, float) and not (lim is not None and (lim.kind is not float or lim.choices is not None)):
            object.__setattr__(obj, f.name, value(v, lim, f.metadata.get("draw") or f"{type(obj).__name__}.{f.name}"))


def state(x: Sequence[float] | np.ndarray, key: str = "state") -> np.ndarray:
    """An initial state perturbed entry by entry, relative (an entry at exactly zero - a rotor at rest - stays there:
    a relative perturbation of zero is zero)."""
    x = np.array(x, dtype=float)
    if _ACTIVE.get() is None:
        return x
    return np.array([value(float(v), key=f"{key}[{i}]") for i, v in enumerate(x.ravel())]).reshape(x.shape)


