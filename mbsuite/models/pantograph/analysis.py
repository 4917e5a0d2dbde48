"""Pantograph analyses: time runs (both engines), equilibrium (three paths), linearised modes, frequency response.

Outputs follow the thesis (Ch. 5.1): F1 = l1 sin t1, F2 = l2 sin t2, HD = lh sin th, y_d = F1 + F2 + HD, against the
input
y_w = y_op + A (1 - cos w t) (EQSIM's YW). Amplitudes are ratios to the input amplitude A; phases are relative to the
input's fundamental (degrees, negative = lag).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from ...analysis.harmonic import fundamental
from ...analysis.sweep import run_sweep
from ...errors import SceneError
from ...health import Figure, judge, nyquist_ratio, stability_margin
from ...limits import Limit
from ...results import Report, SimResult, assemble, format_table, write_csv
from ...scenes import Scene, scene_from_dict
from .elbow import theta_e_array
from .modelfiles import q_to_theta, theta_to_q
from .mujoco import MujocoPantograph, thetas
from .params import PantographParams
from .reference import PantographConfig, PantographODE, simulate

UNITS = {
    "F1": "m", "F2": "m", "HD": "m", "y_d": "m", "y_w": "m", "theta1": "rad", "theta2": "rad", "thetah": "rad",
    "theta_e": "rad", "elbow_windup": "rad", "contact_force": "N", "cylinder_force": "N", "cylinder_state": "m or Pa",
}
FR_SIGNALS = ("F1", "F2", "HD", "y_d")
THESIS_RESONANCES_SIM = (4.25, 8.75, 19.5)
THESIS_RESONANCES_MEAS = (4.0, 8.25)
MODES_TIMESTEP = 1e-4  # MuJoCo's discrete-time linearisation is mapped to continuous time by log(mu)/h

_INITIAL = Limit(kind=str, choices=("equilibrium", "fortran"), default="equilibrium",
                 doc="'equilibrium' (static equilibrium at y_w(0)) or 'fortran' (the thesis' start: no equilibrium)")
#: the scene input keys of each input type, with their valid ranges and defaults (`ModelSpec.inputs`)
INPUTS: dict[str, dict[str, Limit]] = {
    "sine": {
        "amplitude": Limit(lo=0.0, hi=0.2, unit="m", default=1.85e-3,
                           doc="half peak-to-peak A of y_w = y_op + A (1 - cos 2 pi f t); thesis 1.85 mm"),
        "frequency": Limit(lo=0.0, lo_open=True, hi=100.0, unit="Hz", default=2.0,
                           doc="ram frequency; the thesis sweeps 1-30 Hz, its rigid links are not valid far above"),
        "initial": _INITIAL,
    },
    "static": {"initial": _INITIAL},
    "step": {
        "height": Limit(lo=-0.5, hi=0.5, unit="m", default=1e-3, doc="step of the ram height at t_step"),
        "t_step": Limit(lo=0.0, unit="s", default=0.1, doc="time of the step"),
        "initial": _INITIAL,
    },
}


def config_of(scene: Scene) -> PantographConfig:
    """The scene's effects as a `PantographConfig`."""
    return PantographConfig(**dict(scene.effects))


@dataclass(frozen=True)
class InputSignal:
    """The ram height y_w(t) (m): sine y_op + A (1 - cos 2 pi f t), step y_op + h (t >= t_step), or static y_op.
    Accepts a float or an array of times."""

    kind: str
    y_op: float
    amplitude: float = 0.0
    frequency: float = 0.0
    t_step: float = 0.0

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if self.kind == "sine":
            y = self.y_op + self.amplitude * (1.0 - np.cos(2.0 * math.pi * self.frequency * t))
        elif self.kind == "step":
            y = self.y_op + np.where(t >= self.t_step, self.amplitude, 0.0)
        else:
            y = np.full_like(t, self.y_op)
        return float(y) if y.ndim == 0 else y


def input_of(scene: Scene, p: PantographParams) -> InputSignal:
    """The scene's ram input; its keys were checked against `INPUTS` by the scene loader (defaults filled in)."""
    inp = scene.input
    kind = inp.get("type", "sine")
    if kind == "sine":
        d = INPUTS["sine"]
        return InputSignal("sine", p.y_op, float(inp.get("amplitude", d["amplitude"].default)),
                           float(inp.get("frequency", d["frequency"].default)))
    if kind == "step":
        d = INPUTS["step"]
        return InputSignal("step", p.y_op, float(inp.get("height", d["height"].default)), 0.0,
                           float(inp.get("t_step", d["t_step"].default)))
    return InputSignal("static", p.y_op)


def operating_height(scene: Scene, p: PantographParams) -> float:
    """The ram height the motion takes place about, where `freqresp` and `modes` linearise: the mean of the input.
    Sine y_op + A (1 - cos wt): y_op + A; step: its final level y_op + height; static: y_op. (Linearising at y_op
    instead shifts the 8.5 Hz HD ratio by -2.7 % at A = 1.85 mm: the operating point moves with A.)"""
    u = input_of(scene, p)
    if u.kind in ("sine", "step"):
        return p.y_op + u.amplitude
    return p.y_op


def initial_theta(scene: Scene, ode: PantographODE, u: InputSignal) -> np.ndarray:
    """Initial state: the static equilibrium (default) or the thesis' FORTRAN start (erratum 18; not an equilibrium)."""
    x0 = ode.equilibrium(u(0.0))
    if scene.input.get("initial", "equilibrium") == "fortran":
        if ode.nq != 3:
            raise SceneError("initial = 'fortran' needs the compliant elbow")
        p = ode.p
        t1 = math.asin((p.y_op + u.amplitude) / (2.0 * p.l1))
        x0[:3] = [t1, t1, 0.0]
        if ode.cfg.cylinder == "linear":
            x0[-1] = ode.cylinder_lever(t1)[0]
    return x0


def signals(ode: PantographODE, theta: np.ndarray, y_w: np.ndarray, P: np.ndarray | None) -> dict[str, np.ndarray]:
    """Output signals from absolute angles theta (N, 3), ram height and cylinder state (shared by both engines;
    vectorised)."""
    p = ode.p
    F1, F2, HD = p.l1 * np.sin(theta[:, 0]), p.l2 * np.sin(theta[:, 1]), p.lh * np.sin(theta[:, 2])
    y_d = F1 + F2 + HD
    fc = p.ks * (y_d - y_w)
    if ode.cfg.contact == "unilateral":
        fc = np.maximum(fc, 0.0)
    te, _ = theta_e_array(p, theta[:, 0], ode.cfg.elbow_kinematics == "exact")
    if ode.cfg.cylinder == "constant" or P is None:
        cyl = np.full_like(F1, p.Pg * p.Ap)
    elif ode.cfg.cylinder == "linear":
        cyl = p.Pg * p.Ap + p.kc * (P - p.lb * np.cos(p.alpha - theta[:, 0]))  # 3.26
    else:
        cyl = (P - p.Pa) * p.Ap  # 3.22
    out = {"F1": F1, "F2": F2, "HD": HD, "y_d": y_d, "y_w": y_w, "theta1": theta[:, 0], "theta2": theta[:, 1],
           "thetah": theta[:, 2], "theta_e": te, "elbow_windup": te - theta[:, 1], "contact_force": fc,
           "cylinder_force": cyl}
    if P is not None:
        out["cylinder_state"] = P
    return out


def _contact_losses(t: np.ndarray, fc: np.ndarray) -> list[dict]:
    """Contact-loss intervals from a sampled contact force (MuJoCo path)."""
    lost = fc <= 0.0
    ev, start = [], None
    for k in range(len(t)):
        if lost[k] and start is None:
            start = t[k]
        elif not lost[k] and start is not None:
            ev.append({"kind": "contact_loss", "t_start": float(start), "duration": float(t[k] - start)})
            start = None
    if start is not None:
        ev.append({"kind": "contact_loss", "t_start": float(start), "duration": None})
    return ev


#: bound on h * omega_max per MuJoCo integrator as a fraction of its stability limit (`mbsuite.health`): rk4 1.4,
#: the Euler family 0.1, discrete 0.01. Chosen from the error measured against the reference (lab scene, Coulomb off,
#: 2 / 4.25 / 8.5 Hz; README "Health figures"): near each bound the physics error is about 1 % (rk4 0.61-0.78 % at
#: h omega = 1.22, 2.4-27 % at 1.46-2.44; Euler family ~0.1 h omega: 0.61-0.89 % at 0.061, 4.4 % at 0.49; discrete
#: ~1.4 h omega: 0.99-1.2 % at 0.0098, 5.9-7.4 % at 0.061). First-order methods damp or detune the fastest mode by
#: O(h omega), hence their tighter bounds.
STABILITY_FRACTION = {"rk4": 0.5, "euler": 0.05, "implicit": 0.1, "implicitfast": 0.1, "discrete": 0.005}
#: the geometric working range of the absolute link angles (the range `PantographODE.equilibrium` accepts)
WORKING_RANGE = ((0.0, 0.5 * math.pi), (0.0, 0.5 * math.pi), (-0.5 * math.pi, 0.5 * math.pi))


def step_figures(scene: Scene, p: PantographParams, cfg: PantographConfig, u: InputSignal) -> list[Figure]:
    """The health figures of a MuJoCo run known before it steps: `stability_margin` (h times the highest natural
    frequency of the linearisation at the operating height) and, for a sine ram, `nyquist_ratio`."""
    s = scene.solver
    w = omega_max(p, cfg, operating_height(scene, p))
    figs = [stability_margin(s.timestep, w, s.integrator, fraction=STABILITY_FRACTION.get(s.integrator, 0.5))]
    if u.kind == "sine":
        figs.append(nyquist_ratio(s.timestep, u.frequency))
    return figs


def excursion(theta: np.ndarray, theta0: np.ndarray) -> Figure:
    """Plausibility: the largest excursion of a link angle from the equilibrium, relative to the distance from the
    equilibrium to the edge of the working range (0 < theta_1, theta_2 < pi/2, |theta_h| < pi/2). Above 1 the linkage
    has folded or passed the vertical: the result is not a pantograph's motion."""
    val = 0.0
    for i, (lo, hi) in enumerate(WORKING_RANGE):
        room = min(theta0[i] - lo, hi - theta0[i])
        dev = np.abs(theta[:, i] - theta0[i])
        val = max(val, float(np.max(dev)) / room if np.all(np.isfinite(dev)) else math.inf)
    return Figure("excursion", val, 1.0, "", "largest link-angle excursion / room to the edge of the working range",
                  "reduce the input amplitude or solver.timestep; check the parameters")


def run(scene: Scene) -> SimResult:
    """The `run` hook: time simulation with the scene's engine ("mujoco" or "reference") under the ram of the
    thesis' lab (input sine/step/static). Under a finite-element catenary the pantograph runs as a catenary scene
    (`under_wire.py` implements the catenary's protocol).

    Health figures (`mbsuite.health`): MuJoCo runs report `stability_margin`, `nyquist_ratio` (sine input) and
    `excursion`, the reference path `excursion`. Figures known before stepping are judged first: a setting past its
    bound raises `AccuracyError` without running, unless `solver.allow_inaccurate`."""
    p = scene.build_params()
    cfg = config_of(scene)
    ode = PantographODE(p, cfg)
    u = input_of(scene, p)
    s = scene.solver
    x0 = initial_theta(scene, ode, u)
    at_rest = scene.input.get("initial", "equilibrium") == "equilibrium"
    th0 = ode.theta((x0 if at_rest else ode.equilibrium(u(0.0)))[: ode.nq])  # the excursion's origin
    if s.engine == "reference":
        dt_out = s.sample_dt or s.timestep
        t_eval = np.arange(0.0, s.duration + 0.5 * dt_out, dt_out)
        max_step = s.max_step or (1.0 / (16.0 * u.frequency) if u.kind == "sine" else 0.0)
        sol = simulate(ode, u, s.duration, x0, method=s.method, rtol=s.rtol, atol=s.atol, max_step=max_step,
                       t_eval=t_eval)
        th = np.array([ode.theta(sol.x[: ode.nq, k]) for k in range(sol.t.size)])
        P = sol.x[-1] if ode.has_P else None
        return assemble(scene, sol.t, signals(ode, th, u(sol.t), P), engine="reference", events=sol.events,
                        stats={"nfev": sol.nfev, "segments": sol.nsegments, "method": s.method, "rtol": s.rtol},
                        health=[excursion(th, th0)])
    else:
        what = f"pantograph scene {scene.name or '(unnamed)'} (MuJoCo)"
        pre = step_figures(scene, p, cfg, u)
        if not s.allow_inaccurate:
            judge(pre, what=what)  # raises AccuracyError before any step is taken
        mp = MujocoPantograph(p, cfg, s.integrator, s.timestep)
        q0 = None if scene.input.get("initial", "equilibrium") == "equilibrium" else theta_to_q(x0[:3])
        every = max(int(round((s.sample_dt or s.timestep) / s.timestep)), 1)
        tr = mp.simulate(u, s.duration, q0, every=every, what=what, guess=theta_to_q(ode.theta(x0[:ode.nq])))
        P = tr["act"].reshape(tr.t.size, -1)[:, 0] if mp.model.na else None
        th = thetas(tr["qpos"])
        sig = signals(ode, th, u(tr.t), P)
        ev = _contact_losses(tr.t, sig["contact_force"]) if cfg.contact == "unilateral" else []
        return assemble(scene, tr.t, sig, engine="mujoco", events=ev,
                        stats={"steps": tr.steps, "integrator": s.integrator, "timestep": s.timestep,
                               "warnings": tr.warnings}, health=[*pre, excursion(th, th0)])


def mujoco_model(scene: Scene) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The `mujoco_model` hook (`mbsuite view`): the compiled MuJoCo model of exactly the scene's effects (engine
    plugins for the cylinder and the compliant elbow, `mujoco.py`) with the scene's integrator and timestep, and its
    data in the state a MuJoCo run starts from: the static equilibrium at the ram height y_w(0) (or the scene's
    `initial = "fortran"` start), at rest, cylinder at rest, ctrl[catenary] = y_w(0), after mj_forward."""
    p = scene.build_params()
    cfg = config_of(scene)
    ode = PantographODE(p, cfg)
    u = input_of(scene, p)
    s = scene.solver
    x0 = initial_theta(scene, ode, u)
    mp = MujocoPantograph(p, cfg, s.integrator, s.timestep)
    y0 = float(np.asarray(u(np.zeros(1))).ravel()[0])
    if scene.input.get("initial", "equilibrium") == "equilibrium":
        q0 = mp.equilibrium(y0, theta_to_q(ode.theta(x0[:ode.nq])))
    else:
        q0 = theta_to_q(x0[:3])
    mp.set_static(q0, y0)
    mp.data.time = 0.0
    return mp.model, mp.data


# ------------------------------------------------------------------------------------------------ linearisation
def linearize(ode: PantographODE, x0: np.ndarray, y_w0: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A = df/dx, B = df/dy_w at the equilibrium (central differences), C for (F1, F2, HD, y_d).

    Coulomb friction is not linearisable and is left out (the modes are those of the viscous model); the contact is
    taken as closed (bilateral)."""
    lin = PantographODE(ode.p, PantographConfig(**{**ode.cfg.__dict__, "coulomb": False, "contact": "bilateral"}))
    n = lin.n
    A = np.zeros((n, n))
    for i in range(n):
        h = 1e-6 * max(1.0, abs(x0[i]))
        e = np.zeros(n)
        e[i] = h
        A[:, i] = (lin.rhs(0.0, x0 + e, y_w0) - lin.rhs(0.0, x0 - e, y_w0)) / (2 * h)
    h = 1e-7
    B = (lin.rhs(0.0, x0, y_w0 + h) - lin.rhs(0.0, x0, y_w0 - h)) / (2 * h)
    p = ode.p
    J, _ = lin.theta_jacobian(x0[: lin.nq])
    th = lin.theta(x0[: lin.nq])
    Ct = np.diag([p.l1 * math.cos(th[0]), p.l2 * math.cos(th[1]), p.lh * math.cos(th[2])]) @ J
    C = np.zeros((4, n))
    C[:3, : lin.nq] = Ct
    C[3, : lin.nq] = Ct.sum(axis=0)
    return A, B, C


def _linear_config(cfg: PantographConfig) -> PantographConfig:
    """The effects the linearisation keeps (Coulomb friction excluded, contact closed): one cache entry for all."""
    return PantographConfig(**{**cfg.__dict__, "coulomb": False, "contact": "bilateral"})


@functools.lru_cache(maxsize=256)
def _linear_cached(p: PantographParams, cfg: PantographConfig, y_w: float) -> tuple[np.ndarray, ...]:
    ode = PantographODE(p, cfg)
    x0 = ode.equilibrium(y_w)
    A, B, C = linearize(ode, x0, y_w)
    lam = np.linalg.eigvals(A)
    for a in (x0, A, B, C, lam):
        a.flags.writeable = False
    return x0, A, B, C, lam


def linear_model(p: PantographParams, cfg: PantographConfig, y_w: float) -> tuple[np.ndarray, ...]:
    """(x0, A, B, C, eigenvalues of A) about the static equilibrium at ram height y_w; cached per parameter set,
    effects and height (read-only arrays; one equilibrium and 2n + 2 right-hand sides, ~10 ms, on a miss)."""
    return _linear_cached(p, _linear_config(cfg), float(y_w))


def omega_max(p: PantographParams, cfg: PantographConfig, y_w: float) -> float:
    """The largest |eigenvalue| of the linearised model (rad/s): the fastest mode a fixed step must resolve (lab
    scene: the 19.4 Hz head mode, 121.9 rad/s; the nonlinear cylinder adds its real pole, 163 rad/s with the default
    laminar band)."""
    return float(np.max(np.abs(linear_model(p, cfg, y_w)[4])))


def stiffest_pole(p: PantographParams, cfg: PantographConfig, y_w: float) -> float:
    """The largest |real eigenvalue| of the linearised model (1/s): the cylinder's pole (0 if it has none)."""
    lam = linear_model(p, cfg, y_w)[4]
    real = np.abs(lam[np.abs(lam.imag) <= 1e-9 * np.maximum(np.abs(lam), 1.0)])
    return float(np.max(real)) if real.size else 0.0


def modes_from_eigs(lam: np.ndarray) -> list[dict]:
    """Natural frequency (Hz) and damping ratio of each complex pair; time constant of each real pole."""
    out = []
    for v in sorted(lam, key=lambda z: abs(z)):
        if v.imag < -1e-9:
            continue
        wn = abs(v)
        if abs(v.imag) > 1e-9:
            out.append({"kind": "oscillatory", "f_n": wn / (2 * math.pi), "zeta": -v.real / wn,
                        "f_d": v.imag / (2 * math.pi)})
        elif wn > 0:
            out.append({"kind": "first-order", "f_n": wn / (2 * math.pi), "tau": -1.0 / v.real, "zeta": 1.0})
    return out


def linear_response(A: np.ndarray, B: np.ndarray, C: np.ndarray, freqs: np.ndarray) -> np.ndarray:
    """H(j w) = C (j w I - A)^-1 B per frequency, (nf, 4) complex, relative to the input y_w."""
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(1j * 2 * math.pi * f * np.eye(n) - A, B) for f in freqs])


def mujoco_modes(mp: MujocoPantograph, q0: np.ndarray, y_w: float) -> list[dict]:
    """Modes from MuJoCo's own finite-difference linearisation (mjd_transitionFD) at rest at joint positions q0 under
    ram height y_w, mapped to continuous time."""
    import mujoco

    m, d = mp.model, mp.data  # the MujocoPantograph's own copy of the model: edited here, restored after
    if m.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4:  # mjd_transitionFD does not support RK4
        raise SceneError("MuJoCo modes: mjd_transitionFD does not support the rk4 integrator; use another integrator")
    nx = 2 * m.nv + m.na
    A = np.zeros((nx, nx))
    saved = m.dof_frictionloss.copy()
    m.dof_frictionloss[:] = 0.0  # Coulomb friction is not linearisable: excluded, as in the reference linearisation
    try:
        mp.set_static(q0, y_w)
        mujoco.mjd_transitionFD(m, d, 1e-7, True, A, None, None, None)
    finally:
        m.dof_frictionloss[:] = saved
    mu = np.linalg.eigvals(A)
    lam = np.log(mu.astype(complex)) / m.opt.timestep
    return modes_from_eigs(lam)


# ------------------------------------------------------------------------------------------------ frequency response
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
    """One frequency with one method, through `run` (module-level so that it can run in a worker process)."""
    scene_d, f, method = job
    scene = scene_from_dict(scene_d).replace(input={"type": "sine", "frequency": f})
    if method == "reference":
        scene = scene.replace(solver={"engine": "reference", "sample_dt": 1.0 / (64.0 * f)})
    elif method == "mujoco_no_coulomb":  # the same sweep without Coulomb friction, to show its effect on the peaks
        scene = scene.replace(solver={"engine": "mujoco"}, effects={"coulomb": False})
    else:
        scene = scene.replace(solver={"engine": "mujoco"})
    res = run(scene.replace(outputs=[*FR_SIGNALS, "y_w", "contact_force"]))
    out = _harmonics(res.t, res.signals, f, scene.solver.t_settle or 0.5 * scene.solver.duration, method)
    out["cost"] = res.stats
    return out


def mujoco_sweep(scene: Scene, freqs: np.ndarray, *, method: str = "mujoco", workers: int = 0,
                 progress: bool | None = None) -> list[dict]:
    """The MuJoCo path at every frequency of `freqs` (`method` "mujoco", or "mujoco_no_coulomb" for the same sweep
    without Coulomb friction): one compiled model and one equilibrium, one native-core run per frequency, the runs
    spread over `workers` C threads (0 = all cores; the results do not depend on it). Under the Dask executor every
    point runs through `run` on the cluster instead."""
    import mujoco

    from ...analysis.sweep import current_executor

    jobs = [(scene.to_dict(), float(f), method) for f in freqs]
    if current_executor() == "dask":
        return run_sweep(_point, jobs, workers=workers, progress=progress, desc=f"freqresp {method}")
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
    x0 = initial_theta(scene, ode, base)
    q0 = mp.equilibrium(base(0.0), theta_to_q(ode.theta(x0[:ode.nq]))) \
        if scene.input.get("initial", "equilibrium") == "equilibrium" else theta_to_q(x0[:3])
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

    return run_sweep(point, jobs, workers=workers, progress=progress, desc=f"freqresp {method}", executor="threads")


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
             progress: bool | None = None) -> Report:
    """Frequency response from (i) the linearisation, (ii) the reference time simulation, (iii) MuJoCo."""
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
        results += run_sweep(_point, jobs, workers=workers, progress=progress, desc="freqresp reference")
    for m in ("mujoco", "mujoco_no_coulomb"):
        if m in sim_methods:
            results += mujoco_sweep(scene, freqs, method=m, workers=workers, progress=progress)
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

    def write(out: Path) -> list[Path]:
        cols = [("f", "Hz", freqs)]
        for m, c in curves.items():
            for s in FR_SIGNALS:
                cols.append((f"{m}_{s}_amplitude_ratio", "m/m", np.abs(c[s])))
                cols.append((f"{m}_{s}_phase", "deg", np.degrees(np.angle(c[s]))))
        files = [write_csv(out / "freqresp.csv", cols)]
        from ...plotting import save
        from .plots import plot_freqresp, plot_time_histories, time_history_runs

        files.append(save(plot_freqresp(freqs, curves), out / "freqresp.png"))
        files.append(save(plot_time_histories(time_history_runs(scene)), out / "time_histories.png"))
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


# ------------------------------------------------------------------------------------------------ equilibrium, modes
def equilibrium_all_paths(scene: Scene) -> dict:
    """Equilibrium at y_op from the hand-derived path, Pinocchio and MuJoCo."""
    from .pinocchio import PinocchioPantograph

    p = scene.build_params()
    cfg = config_of(scene)
    ode = PantographODE(p, cfg)
    x0 = ode.equilibrium()
    th_ref = ode.theta(x0[: ode.nq])
    out = {"reference": th_ref}
    mp = MujocoPantograph(p, cfg, scene.solver.integrator, scene.solver.timestep)
    out["mujoco"] = q_to_theta(mp.equilibrium())
    if cfg.elbow == "compliant" and p == PantographParams():
        out["pinocchio"] = q_to_theta(PinocchioPantograph(p, cfg).equilibrium())
    return out


def equilibrium_report(scene: Scene) -> Report:
    """The `equilibrium` hook: the static equilibrium at the operating height from the reference, Pinocchio and
    MuJoCo, side by side."""
    p = scene.build_params()
    ode = PantographODE(p, config_of(scene))
    paths = equilibrium_all_paths(scene)
    rows, data = [], {}
    for name, th in paths.items():
        y_d = p.l1 * math.sin(th[0]) + p.l2 * math.sin(th[1]) + p.lh * math.sin(th[2])
        te = ode.elbow(th[0]).theta_e
        d = {"theta1": th[0], "theta2": th[1], "thetah": th[2], "y_d": y_d, "contact_force": p.ks * (y_d - p.y_op),
             "elbow_windup": te - th[1], "theta_e": te, "dtheta_e_dtheta1": ode.elbow(th[0]).dtheta_e}
        data[name] = d
        rows.append([name, *[d[k] for k in ("theta1", "theta2", "thetah", "contact_force", "elbow_windup")]])
    ref = paths["reference"]
    data["max_difference_rad"] = {k: float(np.max(np.abs(v - ref))) for k, v in paths.items() if k != "reference"}
    table = format_table(["path", "theta1 (rad)", "theta2 (rad)", "thetah (rad)", "contact force (N)",
                          "elbow wind-up (rad)"], rows, ".10g")
    table += "\nmax |theta - theta_ref| (rad): " + ", ".join(f"{k} {v:.2e}" for k, v in
                                                               data["max_difference_rad"].items())
    keys = [("theta1", "rad"), ("theta2", "rad"), ("thetah", "rad"), ("y_d", "m"), ("contact_force", "N"),
            ("elbow_windup", "rad"), ("theta_e", "rad"), ("dtheta_e_dtheta1", "-")]

    def write(out: Path) -> list[Path]:
        return [write_csv(Path(out) / "equilibrium.csv", [("path", "", list(paths))]
                          + [(k, u, [data[n][k] for n in paths]) for k, u in keys])]

    return Report(data, table, write)


def modes_report(scene: Scene, height: float | None = None) -> Report:
    """Linearised modes about the static equilibrium at `height` (m; default: the mean of the scene's input,
    `operating_height`), from the hand-derived equations and from MuJoCo's own linearisation."""
    p = scene.build_params()
    cfg = config_of(scene)
    if height is None:
        y_lin = operating_height(scene, p)
    else:
        reach = p.l1 + p.l2
        y_lin = Limit(lo=0.0, hi=reach, lo_open=True, hi_open=True, unit="m").check("height", height, SceneError)
    ref = modes_from_eigs(linear_model(p, cfg, y_lin)[4])
    mp = MujocoPantograph(p, cfg, "implicit", MODES_TIMESTEP)  # mjd_transitionFD: no RK4; small h for log(mu)/h
    mj = mujoco_modes(mp, mp.equilibrium(y_lin), y_lin)
    rows = []
    for i, md in enumerate(ref):
        m2 = mj[i] if i < len(mj) else {"f_n": float("nan"), "zeta": float("nan")}
        rows.append([md["kind"], md["f_n"], md["zeta"], m2["f_n"], m2["zeta"]])
    table = format_table(["mode", "f_n ref (Hz)", "zeta ref", "f_n MuJoCo (Hz)", "zeta MuJoCo"], rows, ".5g")
    table += (f"\nlinearised about the static equilibrium at ram height {y_lin:.6g} m"
              + (" (the mean of the scene's input)" if height is None else "")
              + "; reference: central-difference Jacobian of the hand-derived ODE; MuJoCo: mjd_transitionFD at "
              f"timestep {MODES_TIMESTEP:g} s (implicit), log(mu)/h. Coulomb friction excluded.")
    def write(out: Path) -> list[Path]:
        n = len(ref)
        mjc = [mj[i] if i < len(mj) else {"f_n": float("nan"), "zeta": float("nan")} for i in range(n)]
        return [write_csv(Path(out) / "modes.csv", [
            ("mode", "", [md["kind"] for md in ref]), ("f_n_reference", "Hz", [md["f_n"] for md in ref]),
            ("zeta_reference", "-", [md["zeta"] for md in ref]), ("f_n_mujoco", "Hz", [m["f_n"] for m in mjc]),
            ("zeta_mujoco", "-", [m["zeta"] for m in mjc]), ("height", "m", [y_lin] * n)])]

    return Report({"linearised_at_height_m": y_lin, "reference": ref, "mujoco": mj}, table, write)


