"""The pantograph's frequency response to the ram y_w = y_op + A (1 - cos w t) (EQSIM's YW): from the linearisation,
from the reference path and from the MuJoCo path (one compiled model, one native-core run per frequency), its peaks
against the thesis' resonances, and the MuJoCo time histories of the thesis' Figs 5-1..5-6.

Amplitudes are ratios of the fundamental of F1, F2, HD, y_d to that of the input; phases are relative to the input's
fundamental (degrees, negative = lag).

Peaks are not read off the grid: each grid maximum is refined by successive three-point fits (`refine_peaks`) with
evaluations of the same method at the frequencies a fit asks for (more time runs for the time paths, the exact FRF of
the linearisation), and reported with the last correction of the search as its resolution (`Peak`). With
`error_estimate=True` every time method also runs refined copies (its step or tolerance, `accuracy.refinement`) and
the amplitudes and phases of F1 and HD at every grid frequency and every peak frequency get an estimated error against
their declared tolerance (`estimate_headlines`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from ...analysis.harmonic import fundamental
from ...analysis.sweep import SweepOptions, run_sweep
from ...errors import SceneError
from ...limits import Limit
from ...results import Report, SimResult, format_table, write_csv
from ...scenes import Scene, scene_from_dict
from ...trust.estimate import ErrorEstimate, Headline
from ...trust.health import judge
from .equations import PantographODE
from .health import step_figures
from .inputs import InputSignal, config_of, input_of, operating_height, start_of
from .linearise import linear_model, linear_response, modes_from_eigs
from .mujoco import MujocoPantograph, run_mujoco, thetas
from .outputs import signals
from .reference import run_reference

FR_SIGNALS = ("F1", "F2", "HD", "y_d")
#: the signals whose peaks are searched and whose response is estimated (the report's table columns)
PEAK_SIGNALS = ("F1", "HD")
THESIS_RESONANCES_SIM = (4.25, 8.75, 19.5)
THESIS_RESONANCES_MEAS = (4.0, 8.25)
#: the forcing frequencies of the thesis' time histories (Figs 5-1..5-6)
THESIS_FREQS = (2.0, 3.5, 4.5, 6.5, 8.5, 10.0)
METHODS = ("linear", "mujoco", "reference")
TIME_METHODS = ("mujoco", "reference")

#: the one default of each frequency-response question, shared by `freqresp(...)` and `mbsuite pantograph freqresp`:
#: the thesis' 1-30 Hz sweep on its 0.5 Hz grid, every method, peaks of the time paths to 0.005 Hz
DEFAULTS: dict[str, Any] = {"f_min": 1.0, "f_max": 30.0, "df": 0.5, "methods": METHODS, "peak_tol": 5e-3}
#: valid ranges of the grid and the peak search (the CLI's flags and the Python arguments alike)
LIMITS = {
    "f_min": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="lowest frequency"),
    "f_max": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="highest frequency"),
    "df": Limit(lo=1e-3, hi=1e3, unit="Hz", doc="frequency step"),
    "peak_tol": Limit(lo=0.0, hi=10.0, unit="Hz",
                      doc="resolution the peak search refines the time paths' peaks to (0: grid maxima, +-df/2)"),
}
MAX_FREQUENCIES = 2000
#: the linearisation's peaks are refined to this resolution whatever `peak_tol` (its FRF costs microseconds)
LINEAR_PEAK_TOL = 1e-6
#: the peak search: each stage that brackets the maximum shrinks the three-point stencil by this factor; at most this
#: many stages (each three evaluations per peak)
STENCIL_SHRINK, MAX_STAGES = 4.0, 12


def check_grid(f_min: float, f_max: float, df: float, peak_tol: float, methods: str | Sequence[str],
               err: type[Exception] = SceneError) -> tuple[np.ndarray, tuple[str, ...]]:
    """The grid `f_min:df:f_max` and the methods, each value checked against `LIMITS` (an `err` naming it)."""
    for k, v in (("f_min", f_min), ("f_max", f_max), ("df", df), ("peak_tol", peak_tol)):
        LIMITS[k].check(k, v, err)
    if f_max < f_min:
        raise err(f"f_max {f_max:g} Hz is below f_min {f_min:g} Hz")
    n = int((f_max - f_min) / df + 1e-9) + 1
    if n > MAX_FREQUENCIES:
        raise err(f"f_min/f_max/df give {n} frequencies; at most {MAX_FREQUENCIES} (enlarge df)")
    if isinstance(methods, str):
        methods = tuple(m.strip() for m in methods.split(",") if m.strip())
    bad = sorted(set(methods) - set(METHODS))
    if bad or not methods:
        raise err(f"unknown frequency-response method(s) {bad or list(methods)}; valid: {list(METHODS)}")
    return np.round(np.arange(f_min, f_max + 0.5 * df, df), 10), tuple(methods)


def _harmonics(t: np.ndarray, sig: dict[str, np.ndarray], f: float, ts: float, method: str) -> dict:
    """Amplitude ratio and phase (deg) of each frequency-response signal relative to the input's fundamental, and
    the contact-force range after t_settle."""
    cin = fundamental(t, sig["y_w"], f, ts)
    out = {"f": f, "method": method}
    for s in FR_SIGNALS:
        H = fundamental(t, sig[s], f, ts) / cin
        out[s] = (abs(H), math.degrees(math.atan2(H.imag, H.real)))
    fc = sig["contact_force"][t >= ts]
    out["contact_force_min"] = float(np.min(fc))
    out["contact_force_max"] = float(np.max(fc))
    return out


def _point(job: tuple[dict, float, str]) -> dict:
    """One frequency with one method, through its path's run (module-level so that it can run in a worker
    process)."""
    scene_d, f, method = job
    scene = scene_from_dict(scene_d).replace(input={"type": "sine", "frequency": f})
    if method == "reference":
        scene = scene.replace(solver={"engine": "reference", "sample_dt": 1.0 / (64.0 * f)})
    elif method == "mujoco_no_coulomb":  # the same sweep without Coulomb friction, to show its effect on the peaks
        scene = scene.replace(solver={"engine": "mujoco"}, effects={"coulomb": False})
    else:
        scene = scene.replace(solver={"engine": "mujoco"})
    run = run_reference if method == "reference" else run_mujoco
    res = run(scene.replace(outputs=[*FR_SIGNALS, "y_w", "contact_force"]))
    out = _harmonics(res.t, res.signals, f, scene.solver.t_settle or 0.5 * scene.solver.duration, method)
    out["cost"] = res.stats
    return out


def mujoco_sweep(scene: Scene, freqs: np.ndarray, *, method: str = "mujoco", workers: int = 0,
                 progress: bool | None = None, options: SweepOptions | None = None) -> list[dict]:
    """The MuJoCo path at every frequency of `freqs` (`method` "mujoco", or "mujoco_no_coulomb" for the same sweep
    without Coulomb friction): one compiled model and one equilibrium, one native-core run per frequency, the runs
    spread over `workers` C threads (0 = all cores; the results do not depend on it). Under the Dask executor every
    point runs through `run_mujoco` on the cluster instead (`options`: where and how sweeps run, `SweepOptions`)."""
    jobs = [(scene.to_dict(), float(f), method) for f in freqs]
    options = options or SweepOptions()
    if options.executor_for(None) == "dask":
        return run_sweep(_point, jobs, workers=workers, progress=progress, desc=f"freqresp {method}", options=options)
    if method == "mujoco_no_coulomb":
        scene = scene.replace(effects={"coulomb": False})
    p = scene.build_params()
    cfg = config_of(scene)
    ode = PantographODE(p, cfg)
    s = scene.solver
    base = input_of(scene.replace(input={"type": "sine"}), p)
    if not s.allow_inaccurate:  # the health figures of the run at the highest frequency, before any step
        judge(step_figures(scene.replace(input={"type": "sine"}), p, cfg,
                           InputSignal("sine", p.y_op, base.amplitude, float(np.max(freqs)))),
              what=f"pantograph frequency sweep up to {float(np.max(freqs)):g} Hz (MuJoCo)")
    mp = MujocoPantograph(p, cfg, s.integrator, s.timestep)
    q0 = mp.start_q(start_of(scene, ode, base), base(0.0))
    ts = s.t_settle or 0.5 * s.duration

    def point(job: tuple[dict, float, str]) -> dict:
        f = job[1]
        u = InputSignal("sine", p.y_op, base.amplitude, f)
        tr = mp.simulate(u, s.duration, q0, data=mujoco.MjData(mp.model),
                         what=f"pantograph frequency sweep at {f:g} Hz (MuJoCo)")
        P = tr["act"].reshape(tr.t.size, -1)[:, 0] if mp.model.na else None
        out = _harmonics(tr.t, signals(ode, thetas(tr["qpos"]), u(tr.t), P), f, ts, method)
        out["cost"] = {"steps": tr.steps, "integrator": s.integrator, "timestep": s.timestep, "warnings": tr.warnings}
        return out

    return run_sweep(point, jobs, workers=workers, progress=progress, desc=f"freqresp {method}", executor="threads",
                     options=options)


def sweep_method(scene: Scene, method: str, freqs: Sequence[float], *, workers: int = 0,
                 progress: bool | None = None, options: SweepOptions | None = None) -> list[dict]:
    """The time path `method` ("reference", "mujoco", "mujoco_no_coulomb") at every frequency of `freqs`."""
    freqs = np.asarray(freqs, float)
    if method == "reference":
        jobs = [(scene.to_dict(), float(f), "reference") for f in freqs]
        return run_sweep(_point, jobs, workers=workers, progress=progress, desc="freqresp reference",
                         options=options)
    return mujoco_sweep(scene, freqs, method=method, workers=workers, progress=progress, options=options)


def _complex_rows(rows: list[dict]) -> dict[str, np.ndarray]:
    """Complex ratios per signal from a sweep's rows."""
    return {s: np.array([r[s][0] * np.exp(1j * math.radians(r[s][1])) for r in rows]) for s in FR_SIGNALS}


# ---------------------------------------------------------------------------------------------------------------
# peaks
# ---------------------------------------------------------------------------------------------------------------

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
    out: dict[str, list[Peak]] = {}
    searches = []
    for key, amp in amps.items():
        amp = np.abs(np.asarray(amp, float))
        out[key] = []
        for i in grid_maxima(amp):
            if tol <= 0:
                out[key].append(Peak(float(freqs[i]), 0.5 * df, float(amp[i]), float(freqs[i]), False))
                continue
            v = vertex(freqs[i - 1:i + 2], amp[i - 1:i + 2])
            lo, hi = float(freqs[i - 1]), float(freqs[i + 1])
            c, h = min(max(v[0] if v else float(freqs[i]), lo), hi), 0.25 * df
            guess = [g for g in (starts or {}).get(key, []) if lo < g < hi]
            if guess:
                c, h = min(guess, key=lambda g, f=float(freqs[i]): abs(g - f)), df / 16.0
            searches.append({"key": key, "grid": float(freqs[i]), "lo": lo, "hi": hi, "c": c, "h": h,
                             "amp": float(amp[i]), "delta": math.inf, "done": False, "n": 0, "stages": 0,
                             "pts": [(float(freqs[j]), float(amp[j])) for j in (i - 1, i, i + 1)]})
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
            f3, a3 = zip(*sorted(new_pts + ([mid] if mid else [])), strict=True)
            if a3[1] < max(a3[0], a3[2]):  # no bracket: climb past the larger end (to the fit's vertex if it lies
                j = 0 if a3[0] > a3[2] else 2  # further uphill, at most 4 stencils), inside the grid bracket
                v = vertex(f3, a3)
                new = f3[j]
                if v is not None and (v[0] - f3[j]) * (f3[j] - f3[1]) > 0:
                    new = f3[j] + max(-4 * s["h"], min(4 * s["h"], v[0] - f3[j]))
                new = min(max(new, s["lo"]), s["hi"])
                s["delta"], s["c"], s["amp"] = abs(new - s["c"]), new, max(a3)
                continue
            v = vertex(f3, a3)
            if v is None:  # bracketed, but too coarse a stencil for the fit: the middle, known to within h
                s["delta"], s["c"], s["amp"] = s["h"], f3[1], a3[1]
            else:
                s["delta"], s["c"], s["amp"] = abs(v[0] - s["c"]), v[0], v[1]
            if s["delta"] <= tol and s["stages"] >= 2:
                s["done"] = True
            else:
                s["h"] /= STENCIL_SHRINK
    for s in searches:
        res = s["delta"] if s["done"] else max(s["delta"], s["h"])
        # a fit that lands on its own centre (exact for one mode) claims no better than round-off of the frequency
        out[s["key"]].append(Peak(s["c"], max(res, 1e-12 * s["c"]), s["amp"], s["grid"], True, s["n"], s["done"]))
    for key in out:
        out[key].sort(key=lambda pk: pk.f_hz)
    return out


def linear_peaks(A: np.ndarray, B: np.ndarray, C: np.ndarray, freqs: np.ndarray,
                 curves: dict[str, np.ndarray]) -> dict[str, list[Peak]]:
    """The linearisation's peaks of F1 and HD, refined on its exact FRF to `LINEAR_PEAK_TOL`."""
    idx = [FR_SIGNALS.index(s) for s in PEAK_SIGNALS]

    def evaluate(fs: list[float]) -> list[dict[str, float]]:
        H = np.abs(linear_response(A, B, C, np.asarray(fs)))
        return [{s: float(H[k, i]) for s, i in zip(PEAK_SIGNALS, idx, strict=True)} for k in range(len(fs))]

    return refine_peaks(freqs, {s: np.abs(curves[s]) for s in PEAK_SIGNALS}, evaluate, LINEAR_PEAK_TOL,
                        max_stages=40)


def time_peaks(scene: Scene, method: str, freqs: np.ndarray, curves: dict[str, np.ndarray], tol: float, *,
               workers: int = 0, progress: bool | None = None, options: SweepOptions | None = None,
               starts: dict[str, list[float]] | None = None) -> dict[str, list[Peak]]:
    """The peaks of F1 and HD of the time path `method`, refined with more runs of that path (`refine_peaks`; the
    searches start at `starts`, signal -> guesses, where one lies in a grid maximum's bracket)."""

    def evaluate(fs: list[float]) -> list[dict[str, float]]:
        rows = sweep_method(scene, method, fs, workers=workers, progress=progress, options=options)
        return [{s: r[s][0] for s in PEAK_SIGNALS} for r in rows]

    return refine_peaks(freqs, {s: np.abs(curves[s]) for s in PEAK_SIGNALS}, evaluate, tol, starts=starts)


# ---------------------------------------------------------------------------------------------------------------
# the analysis
# ---------------------------------------------------------------------------------------------------------------

def method_curves(scene: Scene, freqs: np.ndarray, method: str, peak_tol: float, *, workers: int = 0,
                  progress: bool | None = None, options: SweepOptions | None = None
                  ) -> tuple[dict[str, dict[str, np.ndarray]], dict[str, dict[str, list[Peak]]]]:
    """The curves (curve -> signal -> complex ratio; also `contact_force_min`) and refined peaks of one time method:
    "reference", or "mujoco" with its friction-free twin "mujoco_no_coulomb" when the scene has Coulomb friction. The
    peak searches start at the linearisation's peaks (its exact FRF, microseconds per frequency)."""
    names = [method] + (["mujoco_no_coulomb"] if method == "mujoco" and config_of(scene).coulomb else [])
    sc = scene.replace(input={"type": "sine"})
    p = sc.build_params()
    _, A, B, C, _ = linear_model(p, config_of(sc), operating_height(sc, p))
    H = linear_response(A, B, C, freqs)
    starts = {s: [pk.f_hz for pk in v] for s, v in
              linear_peaks(A, B, C, freqs, {s: H[:, i] for i, s in enumerate(FR_SIGNALS)}).items()}
    curves, pks = {}, {}
    for m in names:
        rows = sweep_method(scene, m, freqs, workers=workers, progress=progress, options=options)
        curves[m] = _complex_rows(rows)
        curves[m]["contact_force_min"] = np.array([r["contact_force_min"] for r in rows])
        pks[m] = time_peaks(scene, m, freqs, curves[m], peak_tol, workers=workers, progress=progress,
                            options=options, starts=starts if peak_tol > 0 else None)
    return curves, pks


def freqresp(scene: Scene, f_min: float | None = None, f_max: float | None = None, df: float | None = None,
             methods: str | Sequence[str] | None = None, workers: int = 0, progress: bool | None = None,
             options: SweepOptions | None = None, time_histories: bool = True, *, peak_tol: float | None = None,
             error_estimate: bool = False) -> Report:
    """The `freqresp` hook: frequency response from (i) the linearisation, (ii) the reference time simulation,
    (iii) MuJoCo (with and without Coulomb friction), each curve's refined peaks (`refine_peaks`), and MuJoCo time
    histories at the thesis' frequencies for the writer's figure (`time_histories=False` leaves them out: no figure
    of them is written). Arguments left None take `DEFAULTS` (the command line's defaults too). `options`
    (`SweepOptions`): where and how the sweeps run (executor, store, size guard). `error_estimate`: every time method
    also runs refined copies and each headline (amplitude and phase of F1, HD at every grid frequency, every peak
    frequency) gets its estimated error; an estimate above its tolerance is an `AccuracyError` unless the scene
    allows inaccurate results (then a warning in the report)."""
    f_min, f_max, df, peak_tol = (DEFAULTS[k] if v is None else float(v) for k, v in
                                  (("f_min", f_min), ("f_max", f_max), ("df", df), ("peak_tol", peak_tol)))
    freqs, methods = check_grid(f_min, f_max, df, peak_tol, DEFAULTS["methods"] if methods is None else methods)
    scene = scene.replace(input={"type": "sine"})
    p = scene.build_params()
    cfg = config_of(scene)
    y_lin = operating_height(scene, p)
    _, A, B, C, _ = linear_model(p, cfg, y_lin)
    curves: dict[str, dict[str, np.ndarray]] = {}
    pks: dict[str, dict[str, list[Peak]]] = {}
    if "linear" in methods:
        H = linear_response(A, B, C, freqs)
        curves["linear"] = {s: H[:, i] for i, s in enumerate(FR_SIGNALS)}
        pks["linear"] = linear_peaks(A, B, C, freqs, curves["linear"])
    for m in ("reference", "mujoco"):
        if m in methods:
            c, pk = method_curves(scene, freqs, m, peak_tol, workers=workers, progress=progress, options=options)
            curves.update(c)
            pks.update(pk)
    curves = {m: curves[m] for m in ("linear", "reference", "mujoco", "mujoco_no_coulomb") if m in curves}
    modes = modes_from_eigs(np.linalg.eigvals(A))
    data = {
        "frequencies_hz": freqs,
        "amplitude_input_m": input_of(scene, p).amplitude,
        "linearised_at_height_m": y_lin,
        "modes_linear": modes,
        "peaks_hz": {m: {s: [pk.f_hz for pk in v] for s, v in pks[m].items()} for m in curves},
        "peaks": {m: {s: [asdict(pk) for pk in v] for s, v in pks[m].items()} for m in curves},
        "peak_tol_hz": peak_tol,
        "thesis_resonances_simulated_hz": THESIS_RESONANCES_SIM,
        "thesis_resonances_measured_hz": THESIS_RESONANCES_MEAS,
        "response": {m: {s: {"amplitude": np.abs(c[s]), "phase_deg": np.degrees(np.angle(c[s]))}
                         for s in FR_SIGNALS} for m, c in curves.items()},
    }
    if "mujoco" in curves and "reference" in curves:
        data["mujoco_vs_reference"] = _agreement(freqs, curves["mujoco"], curves["reference"])
    rows = []
    for i, f in enumerate(freqs):
        row = [f]
        for m in curves:
            row += [abs(curves[m]["F1"][i]), abs(curves[m]["HD"][i])]
        rows.append(row)
    headers = ["f (Hz)"] + [f"{m} {s}" for m in curves for s in ("|F1|/A", "|HD|/A")]
    lines = [format_table(headers, rows, ".4g"), "",
             "linearised modes (Coulomb friction excluded) about the static equilibrium at "
             f"y_w = y_op + A = {y_lin:.6g} m (the mean of the input):"]
    for md in modes:
        lines.append(f"  {md['kind']:12s} f_n = {md['f_n']:8.4f} Hz  zeta = {md['zeta']:.4f}")
    how = ("refined by successive three-point fits, ± the search's last correction" if peak_tol > 0
           else f"grid maxima, ± half the {df:g} Hz grid spacing")
    lines.append(f"peaks (Hz; {how}; the linearisation's on its exact FRF):")
    for m in curves:
        lines.append(f"  {m:17s} F1: {', '.join(pk.text() for pk in pks[m]['F1'])};"
                     f"  HD: {', '.join(pk.text() for pk in pks[m]['HD'])}")
    lines.append(f"thesis: simulated {THESIS_RESONANCES_SIM} Hz (0.5 Hz grid), measured {THESIS_RESONANCES_MEAS} Hz")
    if "mujoco_no_coulomb" in curves:
        fr = data["coulomb_effect_on_peaks"] = _peak_heights(pks["mujoco"], pks["mujoco_no_coulomb"])
        lines.append("Coulomb friction on the MuJoCo peaks (|F1|/A, |HD|/A at each refined peak: with -> without):")
        for s, rows_ in fr.items():
            lines.append(f"  {s}: " + "; ".join(f"{r['f_with_hz']:.3f} -> {r['f_without_hz']:.3f} Hz "
                                                 f"{r['with']:.3f} -> {r['without']:.3f}" for r in rows_))
    estimates: dict[str, ErrorEstimate] = {}
    if error_estimate:
        for m in (m for m in TIME_METHODS if m in methods):
            est, warned = estimate_method(scene, m, (f_min, f_max, df), peak_tol, curves, pks, workers=workers)
            estimates[m] = est
            data.setdefault("error_estimate", {})[m] = est.to_dict()
            data.setdefault("warnings", []).extend(warned)
            lines += ["", estimate_summary(est, m), *warned]
        if not estimates:
            lines += ["", "error estimate: no time method asked for (the linearisation's FRF is exact: nothing to "
                          "refine)"]

    histories = time_history_runs(scene) if time_histories else None  # the thesis' Figs 5-1..5-6 for the writer

    def write(out: Path) -> list[Path]:
        cols = [("f", "Hz", freqs)]
        for m, c in curves.items():
            for s in FR_SIGNALS:
                cols.append((f"{m}_{s}_amplitude_ratio", "m/m", np.abs(c[s])))
                cols.append((f"{m}_{s}_phase", "deg", np.degrees(np.angle(c[s]))))
        files = [write_csv(out / "freqresp.csv", cols)]
        prow = [(m, s, pk) for m in curves for s in PEAK_SIGNALS for pk in pks[m][s]]
        files.append(write_csv(out / "freqresp_peaks.csv", [
            ("method", "", np.array([r[0] for r in prow], dtype=object)),
            ("signal", "", np.array([r[1] for r in prow], dtype=object)),
            ("f_peak", "Hz", np.array([r[2].f_hz for r in prow])),
            ("resolution", "Hz", np.array([r[2].resolution_hz for r in prow])),
            ("amplitude_ratio", "m/m", np.array([r[2].amplitude for r in prow])),
            ("grid_maximum", "Hz", np.array([r[2].grid_f_hz for r in prow])),
            ("evaluations", "", np.array([r[2].evaluations for r in prow]))]))
        for method, est in estimates.items():
            files.append(write_csv(out / f"freqresp_error_estimate_{method}.csv", [
                ("headline", "", np.array([r.name for r in est.rows], dtype=object)),
                ("unit", "", np.array([r.unit for r in est.rows], dtype=object)),
                ("value", "", np.array([r.value for r in est.rows])),
                ("estimated_error", "", np.array([r.error for r in est.rows])),
                ("tol", "", np.array([r.tol for r in est.rows])),
                ("observed_order", "", np.array([math.nan if r.order is None else r.order for r in est.rows]))]))
        from ...plotting import save
        from .plots import plot_freqresp, plot_time_histories

        files.append(save(plot_freqresp(freqs, curves), out / "freqresp.png"))
        if histories is not None:
            files.append(save(plot_time_histories(histories), out / "time_histories.png"))
        return files

    return Report(data, "\n".join(lines), write)


def _peak_heights(on: dict[str, list[Peak]], off: dict[str, list[Peak]]) -> dict:
    """Each refined friction-free peak beside the nearest refined peak with Coulomb friction: frequencies and
    amplitude ratios."""
    out = {}
    for s in PEAK_SIGNALS:
        rows = []
        for pk in off[s]:
            if not on[s]:
                continue
            w = min(on[s], key=lambda q, f=pk.f_hz: abs(q.f_hz - f))
            rows.append({"f_with_hz": w.f_hz, "f_without_hz": pk.f_hz, "with": w.amplitude, "without": pk.amplitude})
        out[s] = rows
    return out


def _agreement(freqs: np.ndarray, a: dict, b: dict) -> dict:
    """Max amplitude relative difference and phase difference (deg) per signal, over all frequencies."""
    out = {}
    for s in FR_SIGNALS:
        ra = np.abs(np.abs(a[s]) / np.abs(b[s]) - 1.0)
        dph = np.abs(np.degrees(np.angle(a[s] / b[s])))
        out[s] = {"max_amplitude_rel": float(np.max(ra)), "max_phase_deg": float(np.max(dph)),
                  "at_f_amp": float(freqs[int(np.argmax(ra))]), "at_f_phase": float(freqs[int(np.argmax(dph))])}
    return out


def time_history_runs(scene: Scene, freqs: tuple[float, ...] = THESIS_FREQS) -> dict[float, SimResult]:
    """MuJoCo runs of `scene` under a sine ram at each frequency (outputs y_w, HD, F2, F1) for
    `plots.plot_time_histories`."""
    return {f: run_mujoco(scene.replace(input={"type": "sine", "frequency": f}, solver={"engine": "mujoco"},
                                        outputs=["y_w", "HD", "F2", "F1"])) for f in freqs}


# ---------------------------------------------------------------------------------------------------------------
# the error estimate of a frequency response (mbsuite.trust.estimate)
# ---------------------------------------------------------------------------------------------------------------

#: declared tolerances of the frequency response at the shipped settings (MuJoCo RK4 1 ms, the default grid and peak
#: search): amplitude ratios `amp_rel` of the linearised FRF's amplitude at the same frequency plus `amp_floor` (in
#: ratio units: 0.2 % of the ram amplitude), phases in degrees, peak frequencies in Hz; 3.4-5.4x the largest estimate
#: measured on the shipped scenes (`mbsuite pantograph freqresp pantograph/<scene> --methods linear,mujoco
#: --error-estimate`, README "Declared accuracy"): amplitude 2.0e-3 (nonlinear_cylinder F1 at 9.5 Hz, 3.4x), phase
#: 0.40 deg (HD at 8.5 Hz, 3.8x), peak 1.8e-3 Hz (5.4x), all with Coulomb friction (MuJoCo's regularised friction
#: converges at order 1); without it 0.19 % of the amplitude (at 30 Hz) and 0.09 deg.
FR_TOL = {"amp_rel": 2e-2, "amp_floor": 2e-3, "phase_deg": 1.5, "peak_hz": 0.01}
#: keys of the `[freqresp]` section that marks a frequency-response job (`estimate_method`)
SECTION_KEYS = ("f_min", "f_max", "df", "method", "peak_tol", "peaks", "lost")


def validate_section(value: Any) -> dict[str, Any]:
    """Validator of the `[freqresp]` scene section (`ModelSpec.sections`): it marks a scene as one time method's
    frequency response (what `freqresp(..., error_estimate=True)` hands its refined copies): the grid `f_min`, `f_max`,
    `df` (Hz), the `method` ("mujoco" or "reference"), `peak_tol` (Hz), `peaks` (curve.signal -> the peak
    frequencies found at the scene's own settings, which name the peak headlines) and `lost` (curve -> the grid
    frequencies at which the scene's own run lost contact)."""
    if not isinstance(value, dict):
        raise SceneError(f"[freqresp] must be a table with keys {list(SECTION_KEYS)}, got {value!r}")
    bad = sorted(set(value) - set(SECTION_KEYS))
    missing = sorted(set(SECTION_KEYS) - set(value))
    if bad or missing:
        raise SceneError(f"[freqresp] keys: unknown {bad}, missing {missing}; valid keys: {list(SECTION_KEYS)}")
    if value["method"] not in TIME_METHODS:
        raise SceneError(f"[freqresp] method {value['method']!r}: one of {list(TIME_METHODS)}")
    try:
        check_grid(*(float(value[k]) for k in ("f_min", "f_max", "df", "peak_tol")), (value["method"],))
    except (TypeError, ValueError) as exc:
        raise SceneError(f"[freqresp] f_min, f_max, df, peak_tol must be numbers (Hz): {exc}") from None
    for key in ("peaks", "lost"):
        v = value[key]
        if not isinstance(v, dict) or not all(
                isinstance(x, list) and all(isinstance(y, int | float) and math.isfinite(y) for y in x)
                for x in v.values()):
            raise SceneError(f"[freqresp] {key} must map names to lists of frequencies (Hz), got {v!r}")
    return {**{k: float(value[k]) for k in ("f_min", "f_max", "df", "peak_tol")}, "method": value["method"],
            **{key: {str(k): [float(x) for x in v] for k, v in value[key].items()} for key in ("peaks", "lost")}}


def _grid_of(grid: tuple[float, float, float]) -> np.ndarray:
    return check_grid(grid[0], grid[1], grid[2], 0.0, ("linear",))[0]


def _grid(sec: dict) -> np.ndarray:
    return check_grid(sec["f_min"], sec["f_max"], sec["df"], sec["peak_tol"], (sec["method"],))[0]


def _curve_names(scene: Scene, method: str) -> tuple[str, ...]:
    return (method, "mujoco_no_coulomb") if method == "mujoco" and config_of(scene).coulomb else (method,)


def _linear_at(scene: Scene, freqs: np.ndarray) -> np.ndarray:
    """The linearised FRF (nf, 4) of the scene at `freqs` (the tolerances' scale and the phases' branch)."""
    sc = scene.replace(input={"type": "sine"})
    p = sc.build_params()
    _, A, B, C, _ = linear_model(p, config_of(sc), operating_height(sc, p))
    return linear_response(A, B, C, freqs)


def _fmt_f(f: float) -> str:
    return f"{f:g}"


def estimate_headlines(scene: Scene) -> tuple[Headline, ...]:
    """The headlines of a frequency-response job (`[freqresp]` section): per curve of its method and signal F1, HD,
    the amplitude ratio `{curve}.{signal}.amp@{f}Hz` (tolerance `FR_TOL["amp_rel"]` times the linearised FRF's
    amplitude there plus `FR_TOL["amp_floor"]`: relative where the signal responds, absolute near its
    antiresonances), the phase `{curve}.{signal}.phase@{f}Hz` (deg) at every grid frequency, and
    every peak frequency `{curve}.{signal}.peak{k}` (Hz, k = 1, 2, ... in the order of the peaks the scene's own run
    found). Where the scene's own run lost contact (push-only contact; `lost`), and for a peak within a grid spacing
    of such a frequency, the headline carries no tolerance: the fundamental of a bouncing head is a describing-function
    value that converges where the losses are regular and not where they are irregular, so its estimate is reported
    and not judged."""
    sec = scene.sections["freqresp"]
    freqs = _grid(sec)
    H = np.abs(_linear_at(scene, freqs))
    out = []
    for c in _curve_names(scene, sec["method"]):
        lost = set(sec["lost"].get(c, []))
        for s in PEAK_SIGNALS:
            i = FR_SIGNALS.index(s)
            floor = FR_TOL["amp_floor"]
            for k, f in enumerate(freqs):
                gone = float(f) in lost
                why = "; contact lost: not declared" if gone else ""
                out.append(Headline(f"{c}.{s}.amp@{_fmt_f(f)}Hz", "m/m",
                                    None if gone else FR_TOL["amp_rel"] * float(H[k, i]) + floor,
                                    f"|{s}|/A at {f:g} Hz ({c}){why}"))
                out.append(Headline(f"{c}.{s}.phase@{_fmt_f(f)}Hz", "deg", None if gone else FR_TOL["phase_deg"],
                                    f"phase of {s} relative to the ram at {f:g} Hz ({c}){why}"))
            for k, f in enumerate(sec["peaks"].get(f"{c}.{s}", []), start=1):
                gone = any(abs(f - g) <= sec["df"] for g in lost)
                out.append(Headline(f"{c}.{s}.peak{k}", "Hz", None if gone else FR_TOL["peak_hz"],
                                    f"peak {k} of |{s}| ({c}), {f:.3f} Hz at the scene's settings"
                                    + ("; contact lost nearby: not declared" if gone else "")))
    return tuple(out)


def headline_values(scene: Scene, curves: dict[str, dict[str, np.ndarray]],
                    pks: dict[str, dict[str, list[Peak]]]) -> dict[str, float]:
    """The headline values of a frequency-response job from its curves and refined peaks. Phases (deg) are taken on
    the branch within 180 deg of the linearised FRF's phase at the same frequency (every level on the same branch);
    a peak is the refined peak nearest the one the scene's own run found, NaN if none lies within a grid spacing."""
    sec = scene.sections["freqresp"]
    freqs = _grid(sec)
    H = _linear_at(scene, freqs)
    out: dict[str, float] = {}
    for c in _curve_names(scene, sec["method"]):
        for s in PEAK_SIGNALS:
            i = FR_SIGNALS.index(s)
            ph_lin = np.degrees(np.angle(H[:, i]))
            for k, f in enumerate(freqs):
                z = curves[c][s][k]
                out[f"{c}.{s}.amp@{_fmt_f(f)}Hz"] = float(abs(z))
                d = (math.degrees(np.angle(z)) - ph_lin[k] + 180.0) % 360.0 - 180.0
                out[f"{c}.{s}.phase@{_fmt_f(f)}Hz"] = float(ph_lin[k] + d)
            found = [pk.f_hz for pk in pks[c][s]]
            for k, f0 in enumerate(sec["peaks"].get(f"{c}.{s}", []), start=1):
                near = min(found, key=lambda x, f0=f0: abs(x - f0)) if found else math.nan
                out[f"{c}.{s}.peak{k}"] = float(near) if abs(near - f0) <= sec["df"] else math.nan
    return out


def estimate_values(scene_d: dict) -> dict[str, float]:
    """The headline values of one level of a frequency-response job `scene_d` (a `Scene.to_dict()` with a
    `[freqresp]` section): its method's sweep and peak search at the scene's settings (module-level: it runs in a
    worker process; its MuJoCo points in one thread there, the levels in parallel)."""
    scene = scene_from_dict(scene_d)
    sec = scene.sections["freqresp"]
    curves, pks = method_curves(scene, _grid(sec), sec["method"], sec["peak_tol"], workers=1, progress=False)
    return headline_values(scene, curves, pks)


def estimate_method(scene: Scene, method: str, grid: tuple[float, float, float], peak_tol: float,
                    curves: dict[str, dict[str, np.ndarray]], pks: dict[str, dict[str, list[Peak]]], *,
                    workers: int = 0) -> tuple[ErrorEstimate, list[str]]:
    """The error estimate of one time method's frequency response (the scene's own curves and peaks are level 0;
    the scene refined once and twice runs in parallel) and the warnings of the estimates past their tolerances (an
    `AccuracyError` instead unless the scene allows inaccurate results)."""
    from ...analysis.errorestimate import error_estimate

    names = _curve_names(scene, method)
    # the job's headlines are the frequency response's: the scene's [accuracy] (the time run's) does not apply
    job = scene_from_dict({**scene.to_dict(), "accuracy": {}, "freqresp": {
        "f_min": grid[0], "f_max": grid[1], "df": grid[2], "method": method, "peak_tol": peak_tol,
        "peaks": {f"{c}.{s}": [pk.f_hz for pk in pks[c][s]] for c in names for s in PEAK_SIGNALS},
        "lost": {c: [float(f) for f, fc in zip(_grid_of(grid), curves[c]["contact_force_min"], strict=True)
                     if fc <= 0.0] if config_of(scene).contact == "unilateral" else [] for c in names}}},
        source=scene.source)
    base = headline_values(job, curves, pks)
    est = error_estimate(job, base=base, evaluate=estimate_values, workers=workers)
    # a scene's [accuracy] names the time run's headlines: these tolerances are FR_TOL's
    figs = [replace(f, fix=f.fix.split(" (or set accuracy.")[0] + " (the frequency response's tolerances are "
                    "mbsuite.models.pantograph.freqresp.FR_TOL)") for f in est.figures()]
    warned = judge(figs, allow_inaccurate=scene.solver.allow_inaccurate,
                   what=f"pantograph frequency response ({method}) of {scene.name or scene.source or 'the scene'}")
    return est, warned


def estimate_summary(est: ErrorEstimate, method: str) -> str:
    """The estimate in short: every peak frequency's row, and per curve, signal and quantity the declared row nearest
    its tolerance and the undeclared row (contact lost) with the largest estimate (the whole table is in the JSON and
    `freqresp_error_estimate_<method>.csv`)."""
    from ...results import format_table as fmt

    worst: dict[str, Any] = {}
    show = []
    for r in est.rows:
        curve, sig, what = r.name.split(".", 2)
        if what.startswith("peak"):
            show.append(r)
            continue
        key = f"{curve}.{sig}.{what.split('@')[0]}" + (" (not declared)" if r.tol is None else "")
        ratio = r.error if r.tol is None else r.error / r.tol
        if key not in worst or ratio > worst[key][0]:
            worst[key] = (ratio, r)
    show = [w[1] for w in worst.values()] + show
    n_bad = sum(1 for r in est.rows if r.tol is not None and not r.ok)
    n_free = sum(1 for r in est.rows if r.tol is None)
    rows = [[r.name, r.unit, r.value, r.error, "-" if r.tol is None else r.tol,
             "-" if r.order is None else f"{r.order:.2f}",
             "not declared" if r.tol is None else ("ok" if r.ok else "EXCEEDED")] for r in show]
    free = (f" ({n_free} not declared: contact lost at the scene's settings, the estimate reported, not judged)"
            if n_free else "")
    head = (f"error estimate of the {method} frequency response: {est.setting} refined by {est.factor:g} twice "
            f"(nominal order {est.nominal_order:g}; levels: {'; '.join(est.settings)}); {len(est.rows)} headlines, "
            f"{len(est.rows) - n_bad - n_free} of {len(est.rows) - n_free} declared within tolerance{free}. Shown: "
            "the peaks and, per curve, signal and quantity, the grid point nearest its tolerance")
    return head + "\n" + fmt(["headline", "unit", "value", "est. error", "tol", "observed order", ""], rows, ".4g")
