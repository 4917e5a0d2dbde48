"""The error estimate of a frequency response (`mbsuite.trust.estimate`): the declared tolerances `FR_TOL`, the
`[freqresp]` section that marks a refined copy of one time method's sweep (`validate_section`), its headlines
(amplitude and phase of F1 and HD at every grid frequency, every peak frequency) and their values, and the estimate
of one method (`estimate_method`) with its short summary."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import SceneError
from ...scenes import Scene, scene_from_dict
from ...trust.estimate import ErrorEstimate, Headline
from ...trust.health import judge_estimate
from .freq_grid import FR_SIGNALS, PEAK_SIGNALS, TIME_METHODS, check_grid
from .freq_peaks import Peak
from .freq_sweeps import method_curves
from .inputs import config_of, operating_height
from .linearise import linear_model, linear_response

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
    the scene refined once and twice runs in parallel) and the `INACCURATE:` lines of the estimates past their
    tolerances (`trust.health.judge_estimate`; the caller keeps its report and flags it unless the scene allows
    inaccurate results)."""
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
    warned = judge_estimate(figs, allow_inaccurate=scene.solver.allow_inaccurate,
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
    head = (f"error estimate of the {method} frequency response: {est.describe()}; {len(est.rows)} headlines, "
            f"{len(est.rows) - n_bad - n_free} of {len(est.rows) - n_free} declared within tolerance{free}. Shown: "
            "the peaks and, per curve, signal and quantity, the grid point nearest its tolerance")
    return head + "\n" + fmt(["headline", "unit", "value", "est. error", "tol", "observed order", ""], rows, ".4g")
