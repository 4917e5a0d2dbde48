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

The pieces live by concern: the grid and its vocabulary in `freq_grid.py`, the peak search in `freq_peaks.py`, the
time-domain methods in `freq_sweeps.py`, the error estimate in `freq_estimate.py`; this module assembles the study
and its report (and keeps their public names importable from here, where the SPEC and the command line find them).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np

from ...analysis.sweep import SweepOptions
from ...results import Report, SimResult, format_table, write_csv
from ...scenes import Scene
from ...trust.estimate import ErrorEstimate
from ...trust.health import InaccurateResult
from .freq_estimate import (
    FR_TOL,
    SECTION_KEYS,
    estimate_headlines,
    estimate_method,
    estimate_summary,
    estimate_values,
    headline_values,
    validate_section,
)
from .freq_grid import (
    DEFAULTS,
    FR_SIGNALS,
    LIMITS,
    MAX_FREQUENCIES,
    METHODS,
    PEAK_SIGNALS,
    SIGNAL_WORDS,
    THESIS_FREQS,
    THESIS_RESONANCES_MEAS,
    THESIS_RESONANCES_SIM,
    TIME_METHODS,
    check_grid,
)
from .freq_peaks import (
    LINEAR_PEAK_TOL,
    MAX_STAGES,
    STENCIL_SHRINK,
    Peak,
    grid_maxima,
    linear_peaks,
    refine_peaks,
    vertex,
)
from .freq_sweeps import _point, method_curves, mujoco_sweep, sweep_method, time_history_runs, time_peaks
from .inputs import config_of, input_of, operating_height
from .linearise import linear_model, linear_response, modes_from_eigs

__all__ = [
    "DEFAULTS", "FR_SIGNALS", "FR_TOL", "LIMITS", "LINEAR_PEAK_TOL", "MAX_FREQUENCIES", "MAX_STAGES", "METHODS",
    "PEAK_SIGNALS", "SECTION_KEYS", "STENCIL_SHRINK", "THESIS_FREQS", "THESIS_RESONANCES_MEAS",
    "THESIS_RESONANCES_SIM", "TIME_METHODS", "Peak", "_point", "check_grid", "estimate_headlines", "estimate_method",
    "estimate_summary", "estimate_values", "freqresp", "grid_maxima", "headline_values", "linear_peaks",
    "method_curves", "mujoco_sweep", "refine_peaks", "study_curves", "sweep_method", "time_history_runs",
    "time_peaks", "validate_section", "vertex",
]

Curves = dict[str, dict[str, np.ndarray]]
Peaks = dict[str, dict[str, list[Peak]]]


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
    frequency) gets its estimated error; an estimate above its tolerance keeps the report, with a warning in it, and
    unless the scene allows inaccurate results raises `InaccurateResult` carrying it (the command line prints it,
    writes its files and exits 3)."""
    f_min, f_max, df, peak_tol = (DEFAULTS[k] if v is None else float(v) for k, v in
                                  (("f_min", f_min), ("f_max", f_max), ("df", df), ("peak_tol", peak_tol)))
    freqs, methods = check_grid(f_min, f_max, df, peak_tol, DEFAULTS["methods"] if methods is None else methods)
    scene = scene.replace(input={"type": "sine"})
    p = scene.build_params()
    y_lin = operating_height(scene, p)
    _, A, B, C, _ = linear_model(p, config_of(scene), y_lin)
    curves, pks = _curves(scene, freqs, methods, peak_tol, (A, B, C), workers=workers, progress=progress,
                          options=options)
    modes = modes_from_eigs(np.linalg.eigvals(A))
    data = _data(freqs, curves, pks, peak_tol, input_of(scene, p).amplitude, y_lin, modes)
    lines = _summary(freqs, curves, pks, data, df, peak_tol, y_lin, modes)
    estimates: dict[str, ErrorEstimate] = {}
    if error_estimate:
        estimates = _estimates(scene, methods, (f_min, f_max, df), peak_tol, curves, pks, data, lines, workers)
    histories = time_history_runs(scene) if time_histories else None  # the thesis' Figs 5-1..5-6 for the writer
    rep = Report(data, "\n".join(lines), _writer(freqs, curves, pks, estimates, histories))
    warned = [w for w in data.get("warnings", []) if w.startswith("INACCURATE: ")]
    if warned and not scene.solver.allow_inaccurate:
        raise InaccurateResult(warned, rep)
    return rep


def study_curves(data: dict[str, Any]) -> tuple[list[dict[str, Any]], tuple[str, ...]]:
    """The curves of a `freqresp` report's data, for a `--vary` study (`mbsuite.cli.study`): one per method and
    signal, the amplitude ratio of the signal's fundamental to the ram's (m/m) and its phase relative to the ram's
    (deg, negative = lag; the report's own values, unchanged) against the forcing frequency (Hz); and the data keys
    that hold them (`frequencies_hz`, `response`)."""
    from .outputs import UNITS

    freqs = data["frequencies_hz"]
    curves = []
    for method, signals in data["response"].items():
        for s in FR_SIGNALS:
            words = SIGNAL_WORDS[s]
            curves.append({
                "output": s, "title": f"{words}: response to the ram input", "method": method,
                "x": {"name": "frequency", "unit": "Hz", "label": "forcing frequency", "values": freqs},
                "y": [{"name": "amplitude", "unit": f"{UNITS[s]}/{UNITS['y_w']}", "scale": "log",
                       "label": f"{words.split(' = ')[0]} per unit ram amplitude",
                       "values": signals[s]["amplitude"]},
                      {"name": "phase", "unit": "deg", "period": 360.0,
                       "label": f"phase of {s} relative to the ram input", "values": signals[s]["phase_deg"]}]})
    return curves, ("frequencies_hz", "response")


def _curves(scene: Scene, freqs: np.ndarray, methods: tuple[str, ...], peak_tol: float,
            abc: tuple[np.ndarray, np.ndarray, np.ndarray], *, workers: int, progress: bool | None,
            options: SweepOptions | None) -> tuple[Curves, Peaks]:
    """The curves (method -> signal -> complex ratio) and refined peaks of every method asked for: the linearisation
    on its exact FRF (`abc`: its A, B, C), then the reference and MuJoCo sweeps, in the report's order."""
    curves: Curves = {}
    pks: Peaks = {}
    if "linear" in methods:
        H = linear_response(*abc, freqs)
        curves["linear"] = {s: H[:, i] for i, s in enumerate(FR_SIGNALS)}
        pks["linear"] = linear_peaks(*abc, freqs, curves["linear"])
    for m in ("reference", "mujoco"):
        if m in methods:
            c, pk = method_curves(scene, freqs, m, peak_tol, workers=workers, progress=progress, options=options)
            curves.update(c)
            pks.update(pk)
    return {m: curves[m] for m in ("linear", "reference", "mujoco", "mujoco_no_coulomb") if m in curves}, pks


def _data(freqs: np.ndarray, curves: Curves, pks: Peaks, peak_tol: float, amplitude: float, y_lin: float,
          modes: list[dict]) -> dict[str, Any]:
    """The report's data: grid, input, linearised modes, peaks, responses, and the comparisons MuJoCo vs reference
    and with vs without Coulomb friction where both curves are there."""
    data = {
        "frequencies_hz": freqs,
        "amplitude_input_m": amplitude,
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
    if "mujoco_no_coulomb" in curves:
        data["coulomb_effect_on_peaks"] = _peak_heights(pks["mujoco"], pks["mujoco_no_coulomb"])
    return data


def _summary(freqs: np.ndarray, curves: Curves, pks: Peaks, data: dict[str, Any], df: float, peak_tol: float,
             y_lin: float, modes: list[dict]) -> list[str]:
    """The report's text: |F1|/A and |HD|/A per frequency and method, the linearised modes, the peaks beside the
    thesis' resonances, and the effect of Coulomb friction on the MuJoCo peaks."""
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
    if "coulomb_effect_on_peaks" in data:
        lines.append("Coulomb friction on the MuJoCo peaks (|F1|/A, |HD|/A at each refined peak: with -> without):")
        for s, rows_ in data["coulomb_effect_on_peaks"].items():
            lines.append(f"  {s}: " + "; ".join(f"{r['f_with_hz']:.3f} -> {r['f_without_hz']:.3f} Hz "
                                                 f"{r['with']:.3f} -> {r['without']:.3f}" for r in rows_))
    return lines


def _estimates(scene: Scene, methods: tuple[str, ...], grid: tuple[float, float, float], peak_tol: float,
               curves: Curves, pks: Peaks, data: dict[str, Any], lines: list[str],
               workers: int) -> dict[str, ErrorEstimate]:
    """The error estimate of every time method asked for (`estimate_method`), added to `data` and `lines`."""
    estimates: dict[str, ErrorEstimate] = {}
    for m in (m for m in TIME_METHODS if m in methods):
        est, warned = estimate_method(scene, m, grid, peak_tol, curves, pks, workers=workers)
        estimates[m] = est
        data.setdefault("error_estimate", {})[m] = est.to_dict()
        data.setdefault("warnings", []).extend(warned)
        lines += ["", estimate_summary(est, m), *warned]
    if not estimates:
        lines += ["", "error estimate: no time method asked for (the linearisation's FRF is exact: nothing to "
                      "refine)"]
    return estimates


def _writer(freqs: np.ndarray, curves: Curves, pks: Peaks, estimates: dict[str, ErrorEstimate],
            histories: dict[float, SimResult] | None) -> Callable[[Path], list[Path]]:
    """The report's writer: the curves, the peaks and each error estimate as CSV, the FRF figure and (with
    `histories`) the thesis' time histories."""

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

    return write


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

