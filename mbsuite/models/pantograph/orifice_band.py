"""Convergence study of the orifice's laminar band (`PantographParams.r_laminar`).

The corrected orifice law (Eppinger 1984, Eq 3.17 with errata 10-14) has an unbounded slope d(mdot)/dP at P = Ps; the
model replaces it by a straight line in dp for Pd/Pu > r_laminar (band width w = 1 - r_laminar). The band is chosen by
convergence: the responses of the nonlinear-cylinder scene with band w and with w/10 must agree, at every frequency of
the sweep (F1, F2, HD fundamental amplitude and phase) and during the start from P = Ps (time histories). The change
from w to w/10 bounds the error of band w against the unregularised law (the changes fall geometrically with w).

Metrics (per frequency, reference path, Coulomb friction as in the scene):
- `amp_rel`: max over F1, F2, HD of | |H_w| / |H_w/10| - 1 |;
- `phase_rad`: max over F1, F2, HD of |arg(H_w / H_w/10)| (rad);
- start: max over t in [0, t_start] and F1, F2, HD of |x_w(t) - x_w/10(t)| / max_t |x_w/10(t) - x_w/10(0)|.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...analysis.harmonic import fundamental
from ...analysis.sweep import run_sweep
from ...errors import SceneError
from ...scenes import Scene, scene_from_dict
from .params import critical_ratio

SIGNALS = ("F1", "F2", "HD")
#: convergence criterion: amplitude and phase (rad) change < 0.1 % when the band width is divided by 10
TOLERANCE = 1e-3


@dataclass(frozen=True)
class BandPoint:
    """Harmonics (complex, relative to the input) of F1, F2, HD at one frequency with one band width."""

    width: float
    f: float
    H: dict[str, complex]
    nfev: int
    wall_s: float


def _scene_with_band(scene: Scene, width: float) -> Scene:
    top = 1.0 - critical_ratio(scene.build_params().gamma)  # the band lies in subsonic flow
    if not 0.0 < width < top:
        raise SceneError(f"laminar band width {width!r} must be in (0, {top:.6g}) (1 - the critical pressure ratio)")
    return scene.replace(params={"r_laminar": 1.0 - width}, effects={"cylinder": "nonlinear"},
                         solver={"engine": "reference"})


def _harmonic_point(job: tuple[dict, float, float]) -> BandPoint:
    from ... import run

    scene_d, width, f = job
    sc = _scene_with_band(scene_from_dict(scene_d), width).replace(input={"type": "sine", "frequency": f},
                                                                   outputs=[*SIGNALS, "y_w"])
    sc = sc.replace(solver={"sample_dt": 1.0 / (64.0 * f)})
    t0 = time.perf_counter()
    res = run(sc)
    wall = time.perf_counter() - t0
    ts = sc.solver.t_settle or 0.5 * sc.solver.duration
    cin = fundamental(res.t, res["y_w"], f, ts)
    return BandPoint(width, f, {s: complex(fundamental(res.t, res[s], f, ts) / cin) for s in SIGNALS},
                     int(res.stats["nfev"]), wall)


def harmonic_changes(a: BandPoint, b: BandPoint) -> tuple[float, float]:
    """(max relative amplitude change, max phase change in rad) over F1, F2, HD from band a to band b."""
    amp = max(abs(abs(a.H[s]) / abs(b.H[s]) - 1.0) for s in SIGNALS)
    ph = max(abs(math.atan2((a.H[s] / b.H[s]).imag, (a.H[s] / b.H[s]).real)) for s in SIGNALS)
    return amp, ph


def sweep(scene: Scene, widths: Sequence[float], freqs: Sequence[float], workers: int = 0) -> list[BandPoint]:
    """Reference runs of `scene` (nonlinear cylinder) for every band width and frequency."""
    jobs = [(scene.to_dict(), float(w), float(f)) for w in widths for f in freqs]
    return run_sweep(_harmonic_point, jobs, workers=workers, progress=False, desc="orifice band")


def start_change(scene: Scene, width: float, t_start: float = 1.0) -> float:
    """The start from P = Ps (the scene's own input): the largest change of F1, F2, HD over [0, t_start] from band
    `width` to `width / 10`, relative to each signal's excursion (module docstring)."""
    from ... import run

    runs = []
    for w in (width, width / 10.0):
        sc = _scene_with_band(scene, w).replace(outputs=list(SIGNALS),
                                                solver={"duration": t_start, "t_settle": 0.0, "sample_dt": 1e-3})
        runs.append(run(sc))
    a, b = runs
    out = 0.0
    for s in SIGNALS:
        scale = float(np.max(np.abs(b[s] - b[s][0])))
        out = max(out, float(np.max(np.abs(a[s] - b[s]))) / scale)
    return out


def study(scene: Scene, widths: Sequence[float], freqs: Sequence[float], workers: int = 0) -> dict:
    """Per band width w (all but the narrowest): the worst amplitude and phase change at the frequencies, the start
    change, and the cost (RHS calls, wall time) of the runs with band w."""
    pts = sweep(scene, widths, freqs, workers)
    by = {(p.width, p.f): p for p in pts}
    rows = []
    for w, w10 in zip(widths[:-1], widths[1:], strict=True):
        if not math.isclose(w10, w / 10.0, rel_tol=1e-9):
            raise SceneError(f"band widths must fall by factors of 10 (got {w} then {w10})")
        ch = [harmonic_changes(by[(w, f)], by[(w10, f)]) for f in freqs]
        amp = [c[0] for c in ch]
        ph = [c[1] for c in ch]
        rows.append({"width": w, "r_laminar": 1.0 - w, "max_amp_rel": max(amp),
                     "at_f_amp": float(freqs[int(np.argmax(amp))]), "max_phase_rad": max(ph),
                     "at_f_phase": float(freqs[int(np.argmax(ph))]), "start": start_change(scene, w),
                     "nfev": sum(by[(w, f)].nfev for f in freqs), "wall_s": sum(by[(w, f)].wall_s for f in freqs)})
    return {"rows": rows, "points": pts}
