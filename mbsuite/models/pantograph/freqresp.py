"""The pantograph's frequency response to the ram y_w = y_op + A (1 - cos w t) (EQSIM's YW): from the linearisation,
from the reference path and from the MuJoCo path (one compiled model, one native-core run per frequency), its peaks
against the thesis' resonances, and the MuJoCo time histories of the thesis' Figs 5-1..5-6.

Amplitudes are ratios of the fundamental of F1, F2, HD, y_d to that of the input; phases are relative to the input's
fundamental (degrees, negative = lag).
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from ...analysis.harmonic import fundamental
from ...analysis.sweep import SweepOptions, run_sweep
from ...errors import SceneError
from ...health import judge
from ...results import Report, SimResult, format_table, write_csv
from ...scenes import Scene, scene_from_dict
from .equations import PantographODE
from .health import step_figures
from .inputs import InputSignal, config_of, input_of, operating_height, start_of
from .linearise import linear_model, linear_response, modes_from_eigs
from .mujoco import MujocoPantograph, run_mujoco, thetas
from .outputs import signals
from .reference import run_reference

FR_SIGNALS = ("F1", "F2", "HD", "y_d")
THESIS_RESONANCES_SIM = (4.25, 8.75, 19.5)
THESIS_RESONANCES_MEAS = (4.0, 8.25)
#: the forcing frequencies of the thesis' time histories (Figs 5-1..5-6)
THESIS_FREQS = (2.0, 3.5, 4.5, 6.5, 8.5, 10.0)


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


def peaks(freqs: np.ndarray, amp: np.ndarray) -> list[float]:
    """Local maxima of an amplitude curve, refined by a parabola through the three points around each."""
    out = []
    for i in range(1, len(freqs) - 1):
        if amp[i] > amp[i - 1] and amp[i] >= amp[i + 1]:
            y0, y1, y2 = amp[i - 1], amp[i], amp[i + 1]
            den = y0 - 2 * y1 + y2
            off = 0.5 * (y0 - y2) / den if den != 0 else 0.0
            out.append(float(freqs[i] + off * (freqs[i + 1] - freqs[i])))
    return out


def freqresp(scene: Scene, f_min: float = 1.0, f_max: float = 30.0, df: float = 0.5,
             methods: str | tuple[str, ...] = ("linear", "mujoco", "reference"), workers: int = 0,
             progress: bool | None = None, options: SweepOptions | None = None,
             time_histories: bool = True) -> Report:
    """The `freqresp` hook: frequency response from (i) the linearisation, (ii) the reference time simulation,
    (iii) MuJoCo (with and without Coulomb friction), and MuJoCo time histories at the thesis' frequencies for the
    writer's figure (`time_histories=False` leaves them out: no figure of them is written). `options`
    (`SweepOptions`): where and how the sweeps run (executor, store, size guard)."""
    if isinstance(methods, str):
        methods = tuple(m.strip() for m in methods.split(",") if m.strip())
    bad = sorted(set(methods) - {"linear", "mujoco", "reference"})
    if bad:
        raise SceneError(f"unknown frequency-response method(s) {bad}; valid: ['linear', 'mujoco', 'reference']")
    if not (0 < f_min <= f_max and df > 0):
        raise SceneError(f"need 0 < f_min <= f_max and df > 0 (got {f_min}, {f_max}, {df})")
    freqs = np.round(np.arange(f_min, f_max + 0.5 * df, df), 10)
    scene = scene.replace(input={"type": "sine"})
    p = scene.build_params()
    cfg = config_of(scene)
    y_lin = operating_height(scene, p)
    _, A, B, C, _ = linear_model(p, cfg, y_lin)
    curves: dict[str, dict[str, np.ndarray]] = {}
    if "linear" in methods:
        H = linear_response(A, B, C, freqs)
        curves["linear"] = {s: H[:, i] for i, s in enumerate(FR_SIGNALS)}
    sim_methods = [m for m in methods if m != "linear"]
    if "mujoco" in sim_methods and cfg.coulomb:
        sim_methods.append("mujoco_no_coulomb")
    results = []
    if "reference" in sim_methods:
        jobs = [(scene.to_dict(), float(f), "reference") for f in freqs]
        results += run_sweep(_point, jobs, workers=workers, progress=progress, desc="freqresp reference",
                             options=options)
    for m in ("mujoco", "mujoco_no_coulomb"):
        if m in sim_methods:
            results += mujoco_sweep(scene, freqs, method=m, workers=workers, progress=progress, options=options)
    for m in sim_methods:
        rows = [r for r in results if r["method"] == m]
        curves[m] = {s: np.array([r[s][0] * np.exp(1j * math.radians(r[s][1])) for r in rows]) for s in FR_SIGNALS}
        curves[m]["contact_force_min"] = np.array([r["contact_force_min"] for r in rows])
    modes = modes_from_eigs(np.linalg.eigvals(A))
    res_peaks = {m: {s: peaks(freqs, np.abs(c[s])) for s in ("F1", "HD")} for m, c in curves.items()}
    data = {
        "frequencies_hz": freqs,
        "amplitude_input_m": input_of(scene, p).amplitude,
        "linearised_at_height_m": y_lin,
        "modes_linear": modes,
        "peaks_hz": res_peaks,
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
    for m, pk in res_peaks.items():
        lines.append(f"peaks {m:9s} F1: {', '.join(f'{v:.3f}' for v in pk['F1'])} Hz;"
                     f"  HD: {', '.join(f'{v:.3f}' for v in pk['HD'])} Hz")
    lines.append(f"thesis: simulated {THESIS_RESONANCES_SIM} Hz, measured {THESIS_RESONANCES_MEAS} Hz")
    if "mujoco_no_coulomb" in curves:
        fr = data["coulomb_effect_on_peaks"] = _peak_heights(freqs, curves["mujoco"], curves["mujoco_no_coulomb"])
        lines.append("Coulomb friction on the MuJoCo peaks (|F1|/A, |HD|/A at each F1/HD peak: with -> without):")
        for s, rows_ in fr.items():
            lines.append(f"  {s}: " + "; ".join(f"{r['f_hz']:.2f} Hz {r['with']:.3f} -> {r['without']:.3f}"
                                                 for r in rows_))

    histories = time_history_runs(scene) if time_histories else None  # the thesis' Figs 5-1..5-6 for the writer

    def write(out: Path) -> list[Path]:
        cols = [("f", "Hz", freqs)]
        for m, c in curves.items():
            for s in FR_SIGNALS:
                cols.append((f"{m}_{s}_amplitude_ratio", "m/m", np.abs(c[s])))
                cols.append((f"{m}_{s}_phase", "deg", np.degrees(np.angle(c[s]))))
        files = [write_csv(out / "freqresp.csv", cols)]
        from ...plotting import save
        from .plots import plot_freqresp, plot_time_histories

        files.append(save(plot_freqresp(freqs, curves), out / "freqresp.png"))
        if histories is not None:
            files.append(save(plot_time_histories(histories), out / "time_histories.png"))
        return files

    return Report(data, "\n".join(lines), write)


def _peak_heights(freqs: np.ndarray, on: dict, off: dict) -> dict:
    """Amplitude at the grid peaks of the friction-free curve, with and without Coulomb friction."""
    out = {}
    for s in ("F1", "HD"):
        a_off, a_on = np.abs(off[s]), np.abs(on[s])
        idx = [i for i in range(1, len(freqs) - 1) if a_off[i] > a_off[i - 1] and a_off[i] >= a_off[i + 1]]
        out[s] = [{"f_hz": float(freqs[i]), "with": float(a_on[i]), "without": float(a_off[i])} for i in idx]
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
