"""Peaks of a frequency-response curve not read off the grid: each grid maximum refined by successive three-point
fits (`refine_peaks`, `vertex`) with evaluations of the same method at the frequencies a fit asks for, reported with
the last correction of the search as its resolution (`Peak`); the linearisation's peaks on its exact FRF
(`linear_peaks`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .freq_grid import FR_SIGNALS, PEAK_SIGNALS
from .linearise import linear_response

#: the linearisation's peaks are refined to this resolution whatever `peak_tol` (its FRF costs microseconds)
LINEAR_PEAK_TOL = 1e-6
#: the peak search: each stage that brackets the maximum shrinks the three-point stencil by this factor; at most this
#: many stages (each three evaluations per peak)
STENCIL_SHRINK, MAX_STAGES = 4.0, 12


@dataclass(frozen=True)
class Peak:
    """One resonance peak of an amplitude curve: `f_hz` and its `resolution_hz` (refined: the last correction of the
    search, which converges as the stencil squared, so the remaining error is well below it; not refined: half the
    grid spacing around the grid maximum), the amplitude ratio there, the grid maximum it started from and the
    evaluations the search cost (`converged`: whether it met its tolerance)."""

    f_hz: float
    resolution_hz: float
    amplitude: float
    grid_f_hz: float
    refined: bool
    evaluations: int = 0
    converged: bool = True

    def text(self) -> str:
        """`4.263 ± 0.002` (refined), `4.5 ± 0.25 (grid)`, or `... (search not converged)`."""
        if not self.refined:
            return f"{self.f_hz:g} ± {self.resolution_hz:g} (grid)"
        digits = max(3, min(7, 1 - math.floor(math.log10(max(self.resolution_hz, 1e-9)))))
        return f"{self.f_hz:.{digits}f} ± {self.resolution_hz:.1g}" + ("" if self.converged else
                                                                        " (search not converged)")


def grid_maxima(amp: np.ndarray) -> list[int]:
    """Indices of the interior local maxima of a sampled amplitude curve."""
    return [i for i in range(1, len(amp) - 1) if amp[i] > amp[i - 1] and amp[i] >= amp[i + 1]]


def vertex(f: Sequence[float], amp: Sequence[float]) -> tuple[float, float] | None:
    """The peak (frequency, amplitude) of the curve through three points: the vertex of the parabola in x = f^2
    through y = 1 / amp^2. Exact for a single-degree-of-freedom oscillator, whose |H|^-2 = k^2 ((f_n^2 - f^2)^2 +
    (2 zeta f_n f)^2) / f_n^4 is that parabola, and second order in the spacing for any smooth peak. None if the points
    do not give a maximum (the parabola is not convex, or its vertex is at x <= 0 or y <= 0)."""
    x1, x2, x3 = (float(v) ** 2 for v in f)
    if not all(math.isfinite(a) and a > 0 for a in amp) or len({x1, x2, x3}) < 3:
        return None
    y1, y2, y3 = (1.0 / float(a) ** 2 for a in amp)
    d21, d32 = (y2 - y1) / (x2 - x1), (y3 - y2) / (x3 - x2)
    c2 = (d32 - d21) / (x3 - x1)  # second divided difference: the parabola's curvature
    if not c2 > 0:
        return None
    u = 0.5 * (x1 + x2) - 0.5 * d21 / c2  # where y' = d21 + c2 (2x - x1 - x2) vanishes
    ymin = y1 + d21 * (u - x1) + c2 * (u - x1) * (u - x2)
    if u <= 0 or ymin <= 0:
        return None
    return math.sqrt(u), 1.0 / math.sqrt(ymin)


def refine_peaks(freqs: np.ndarray, amps: dict[str, np.ndarray],
                 evaluate: Callable[[list[float]], list[dict[str, float]]], tol: float,
                 max_stages: int = MAX_STAGES, starts: dict[str, list[float]] | None = None) -> dict[str, list[Peak]]:
    """The peaks of each curve `amps[key]` on the grid `freqs`, each grid maximum refined until the search moves it by
    at most `tol` (Hz).

    A search starts at the vertex through the grid maximum and its neighbours (`vertex`), kept inside the grid bracket
    of the maximum, with a stencil h of a quarter of the grid spacing; or, where `starts[key]` offers a guess inside
    that bracket (the time paths take the linearisation's peaks), at the guess with a sixteenth. Each stage evaluates
    the curve at c - h and c + h around the current estimate c, and at c unless a point evaluated before lies within
    h/2 of it (which then serves as the middle point; `evaluate(frequencies) -> [{key: amplitude}]`, all searches of
    a stage in one call). If the middle point is the largest, the three bracket the maximum: c moves to their vertex
    (stays, if the stencil is too coarse for the fit) and the stencil shrinks by `STENCIL_SHRINK`; the search stops
    when that move is at most `tol` (after two stages at least), and the move is the peak's `resolution_hz` (the error
    left behind it is about STENCIL_SHRINK^2 times smaller). Otherwise c climbs past the larger end point with the
    stencil kept. A search not done after `max_stages` reports its stencil as the resolution and `converged=False`.
    `tol = 0` reports the grid maxima with half the grid spacing, unrefined."""
    df = float(freqs[1] - freqs[0]) if len(freqs) > 1 else 0.0
    out: dict[str, list[Peak]] = {key: [] for key in amps}
    searches = []
    for key, amp in amps.items():
        amp = np.abs(np.asarray(amp, float))
        for i in grid_maxima(amp):
            if tol <= 0:
                out[key].append(Peak(float(freqs[i]), 0.5 * df, float(amp[i]), float(freqs[i]), False))
            else:
                searches.append(_start(key, freqs, amp, i, df, (starts or {}).get(key, [])))
    for _ in range(max_stages):
        todo = [s for s in searches if not s["done"]]
        if not todo:
            break
        asks, plans = [], []
        for s in todo:  # c - h, c + h, and c itself unless a point already evaluated lies in the stencil's middle half
            mid = min(s["pts"], key=lambda q, c=s["c"]: abs(q[0] - c))
            reuse = abs(mid[0] - s["c"]) < 0.5 * s["h"]
            fs = [s["c"] - s["h"], s["c"] + s["h"]] + ([] if reuse else [s["c"]])
            plans.append((len(asks), fs, mid if reuse else None))
            asks += fs
        vals = evaluate(asks)
        for s, (k0, fs, mid) in zip(todo, plans, strict=True):
            new_pts = [(f, float(vals[k0 + j][s["key"]])) for j, f in enumerate(fs)]
            s["pts"] += new_pts
            s["n"] += len(fs)
            s["stages"] += 1
            _advance(s, new_pts + ([mid] if mid else []), tol)
    for s in searches:
        res = s["delta"] if s["done"] else max(s["delta"], s["h"])
        # a fit that lands on its own centre (exact for one mode) claims no better than round-off of the frequency
        out[s["key"]].append(Peak(s["c"], max(res, 1e-12 * s["c"]), s["amp"], s["grid"], True, s["n"], s["done"]))
    for key in out:
        out[key].sort(key=lambda pk: pk.f_hz)
    return out


def _start(key: str, freqs: np.ndarray, amp: np.ndarray, i: int, df: float, guesses: list[float]) -> dict[str, Any]:
    """The search of the grid maximum i of curve `key`: at the vertex through it and its neighbours, kept inside its
    grid bracket, stencil df/4; or at the guess nearest the maximum inside the bracket, stencil df/16."""
    v = vertex(freqs[i - 1:i + 2], amp[i - 1:i + 2])
    lo, hi = float(freqs[i - 1]), float(freqs[i + 1])
    c, h = min(max(v[0] if v else float(freqs[i]), lo), hi), 0.25 * df
    guess = [g for g in guesses if lo < g < hi]
    if guess:
        c, h = min(guess, key=lambda g, f=float(freqs[i]): abs(g - f)), df / 16.0
    return {"key": key, "grid": float(freqs[i]), "lo": lo, "hi": hi, "c": c, "h": h, "amp": float(amp[i]),
            "delta": math.inf, "done": False, "n": 0, "stages": 0,
            "pts": [(float(freqs[j]), float(amp[j])) for j in (i - 1, i, i + 1)]}


def _advance(s: dict[str, Any], pts: list[tuple[float, float]], tol: float) -> None:
    """One stage of search `s` from its three points `pts`: climb past the larger end if they do not bracket the
    maximum, else move to their vertex, shrink the stencil, and stop once the move is at most `tol`."""
    f3, a3 = zip(*sorted(pts), strict=True)
    if a3[1] < max(a3[0], a3[2]):  # no bracket: climb past the larger end (to the fit's vertex if it lies
        j = 0 if a3[0] > a3[2] else 2  # further uphill, at most 4 stencils), inside the grid bracket
        v = vertex(f3, a3)
        new = f3[j]
        if v is not None and (v[0] - f3[j]) * (f3[j] - f3[1]) > 0:
            new = f3[j] + max(-4 * s["h"], min(4 * s["h"], v[0] - f3[j]))
        new = min(max(new, s["lo"]), s["hi"])
        s["delta"], s["c"], s["amp"] = abs(new - s["c"]), new, max(a3)
        return
    v = vertex(f3, a3)
    if v is None:  # bracketed, but too coarse a stencil for the fit: the middle, known to within h
        s["delta"], s["c"], s["amp"] = s["h"], f3[1], a3[1]
    else:
        s["delta"], s["c"], s["amp"] = abs(v[0] - s["c"]), v[0], v[1]
    if s["delta"] <= tol and s["stages"] >= 2:
        s["done"] = True
    else:
        s["h"] /= STENCIL_SHRINK


def linear_peaks(A: np.ndarray, B: np.ndarray, C: np.ndarray, freqs: np.ndarray,
                 curves: dict[str, np.ndarray]) -> dict[str, list[Peak]]:
    """The linearisation's peaks of F1 and HD, refined on its exact FRF to `LINEAR_PEAK_TOL`."""
    idx = [FR_SIGNALS.index(s) for s in PEAK_SIGNALS]

    def evaluate(fs: list[float]) -> list[dict[str, float]]:
        H = np.abs(linear_response(A, B, C, np.asarray(fs)))
        return [{s: float(H[k, i]) for s, i in zip(PEAK_SIGNALS, idx, strict=True)} for k in range(len(fs))]

    return refine_peaks(freqs, {s: np.abs(curves[s]) for s in PEAK_SIGNALS}, evaluate, LINEAR_PEAK_TOL,
                        max_stages=40)
