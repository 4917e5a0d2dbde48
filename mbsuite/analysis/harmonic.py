"""Fundamental-harmonic projection over whole periods (the thesis' "component at the forcing frequency", Ch. 5.1)."""

from __future__ import annotations

import numpy as np

from ..errors import SolverError


def whole_period_window(t: np.ndarray, f: float, t_settle: float) -> np.ndarray:
    """Boolean mask of the last whole number of periods after `t_settle` (at least one period required)."""
    t_end = t[-1]
    n = int(np.floor((t_end - t_settle) * f + 1e-9))
    if n < 1:
        raise SolverError(f"no whole period of {f} Hz between t_settle = {t_settle} s and t_end = {t_end} s")
    t0 = t_end - n / f
    return t >= t0 - 1e-9 * max(1.0, t_end)


def fundamental(t: np.ndarray, s: np.ndarray, f: float, t_settle: float) -> complex:
    """Complex amplitude c with s(t) ~ a0 + Re(c exp(i 2 pi f t)) over whole periods after t_settle.

    A least-squares fit of (1, cos wt, sin wt) on the samples of the window: exact for a sinusoid whatever the sampling
    grid (a grid that does not divide the period cannot leak the mean into the amplitude, as plain quadrature would),
    and orthogonal to the higher harmonics over whole periods."""
    mask = whole_period_window(t, f, t_settle)
    tt, ss = t[mask], s[mask]
    w = 2 * np.pi * f
    X = np.column_stack([np.ones_like(tt), np.cos(w * tt), np.sin(w * tt)])
    (a0, a, b), *_ = np.linalg.lstsq(X, ss - ss.mean(), rcond=None)
    return complex(a, -b)
