"""The time-domain frequency-response methods: the reference path and the MuJoCo path (one compiled model, one
native-core run per frequency) under the ram y_w = y_op + A (1 - cos w t) (EQSIM's YW), the amplitude ratios and
phases of each signal's fundamental to the input's, their refined peaks (`time_peaks`, starting at the
linearisation's), and the MuJoCo time histories of the thesis' Figs 5-1..5-6."""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np

from ...analysis.harmonic import fundamental
from ...analysis.sweep import SweepOptions, run_sweep
from ...results import SimResult
from ...scenes import Scene, scene_from_dict
from ...trust.health import judge
from .equations import PantographODE
from .freq_grid import FR_SIGNALS, PEAK_SIGNALS, THESIS_FREQS
from .freq_peaks import Peak, linear_peaks, refine_peaks
from .health import step_figures
from .inputs import InputSignal, config_of, input_of, operating_height, start_of
from .linearise import linear_model, linear_response
from .mujoco import MujocoPantograph, run_mujoco, thetas
from .outputs import signals
from .reference import run_reference


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



def time_peaks(scene: Scene, method: str, freqs: np.ndarray, curves: dict[str, np.ndarray], tol: float, *,
               workers: int = 0, progress: bool | None = None, options: SweepOptions | None = None,
               starts: dict[str, list[float]] | None = None) -> dict[str, list[Peak]]:
    """The peaks of F1 and HD of the time path `method`, refined with more runs of that path (`refine_peaks`; the
    searches start at `starts`, signal -> guesses, where one lies in a grid maximum's bracket)."""

    def evaluate(fs: list[float]) -> list[dict[str, float]]:
        rows = sweep_method(scene, method, fs, workers=workers, progress=progress, options=options)
        return [{s: r[s][0] for s in PEAK_SIGNALS} for r in rows]

    return refine_peaks(freqs, {s: np.abs(curves[s]) for s in PEAK_SIGNALS}, evaluate, tol, starts=starts)



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


def time_history_runs(scene: Scene, freqs: tuple[float, ...] = THESIS_FREQS) -> dict[float, SimResult]:
    """MuJoCo runs of `scene` under a sine ram at each frequency (outputs y_w, HD, F2, F1) for
    `plots.plot_time_histories`."""
    return {f: run_mujoco(scene.replace(input={"type": "sine", "frequency": f}, solver={"engine": "mujoco"},
                                        outputs=["y_w", "HD", "F2", "F1"])) for f in freqs}

