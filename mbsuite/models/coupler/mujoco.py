"""MuJoCo dynamics of the double coupler: input shaft a velocity-servoed to a constant speed, output shaft c with a load
torque and an imposed misalignment (inclination alpha_cx, alpha_cz and lateral offset x_c, z_c), intermediate shaft b
floating on its 8 SS links (soft <connect> equalities).

The model is the shipped `mjcf/coupler_double.xml` edited through MjSpec (`modelfiles.mjspec_variant` for the design,
then here): shaft c keeps only its axial slide y_c (along the base y axis) and its spin phi_c, its body is placed at the
misaligned pose; a velocity actuator drives phi_a, a motor applies the load on phi_c. Effects (scene [effects]):
gravity (on/off), link_inertia ("real" | "massless": link mass and inertia scaled by `massless_factor`), friction
(frictionloss `joint_friction` in every S joint and the output bearing).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ...engines import mujoco_engine as me
from ...errors import SceneError, SolverError
from ...results import SimResult
from . import reference as ref
from .modelfiles import PHI_B_OFFSET, _mounted, _quat_z_to, link_inertia, mjspec_variant, phi_c_offset
from .params import CouplerParams

INPUT_KEYS = ("omega", "load_torque", "alpha_cx", "alpha_cz", "x_c", "z_c", "t_ramp")
INPUT_DEFAULTS = {"omega": 4 * math.pi, "load_torque": 1000.0, "alpha_cx": 0.0, "alpha_cz": 0.0, "x_c": 0.0,
                  "z_c": 0.05, "t_ramp": 0.25}


def _inputs(scene) -> dict[str, float]:
    inp = {**INPUT_DEFAULTS, **{k: v for k, v in scene.input.items() if k != "type"}}
    for k in INPUT_KEYS:
        v = inp[k]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise SceneError(f"coupler input {k!r} must be a finite number, got {v!r}")
    if inp["omega"] <= 0:
        raise SceneError(f"coupler input omega = {inp['omega']!r} rad/s must be positive")
    if inp["t_ramp"] < 0:
        raise SceneError(f"coupler input t_ramp = {inp['t_ramp']!r} s must be >= 0")
    return {k: float(inp[k]) for k in INPUT_KEYS}


def _id(m, kind, name: str) -> int:
    return mujoco.mj_name2id(m, kind, name)


def build(p: CouplerParams, effects: dict, inp: dict[str, float], timestep: float, integrator: str):
    """Compile the dynamics model and return (model, data, info) with data at the assembled initial pose (rest)."""
    if p.solref_timeconst < 2.0 * timestep:
        raise SceneError(
            f"solver.timestep = {timestep:g} s is too large for the soft link closures: MuJoCo needs solref_timeconst "
            f"({p.solref_timeconst:g} s) >= 2 timestep and would silently stiffen it (closure residual 300x larger at "
            f"5 ms); use timestep <= {p.solref_timeconst / 2:g} s or raise params.solref_timeconst")
    spec = mjspec_variant(p, "double")
    massless = effects["link_inertia"] == "massless"
    scale = p.massless_factor if massless else 1.0
    it, ia = link_inertia(p, p.m_link * scale)
    for k in range(8):
        b = spec.body(f"link{k + 1}")
        b.mass = p.m_link * scale
        b.inertia = [it, it, ia]
        j = spec.joint(f"link{k + 1}_ball")
        j.frictionloss = p.joint_friction if effects["friction"] else 0.0
    # shaft c: only y_c (base y) and phi_c remain; its body sits at the imposed misalignment
    for name in ("x_c", "z_c", "alpha_cz", "alpha_cx"):
        spec.delete(spec.joint(name))
    Rc = ref.rot_z(inp["alpha_cz"]) @ ref.rot_x(inp["alpha_cx"])
    bc = spec.body("shaft_c")
    bc.pos = [inp["x_c"], 2 * p.e_y + p.l_b, inp["z_c"]]
    w = math.sqrt(max(0.0, 1.0 + np.trace(Rc))) / 2
    bc.quat = [w, (Rc[2, 1] - Rc[1, 2]) / (4 * w), (Rc[0, 2] - Rc[2, 0]) / (4 * w), (Rc[1, 0] - Rc[0, 1]) / (4 * w)]
    spec.joint("y_c").axis = Rc.T @ np.array([0.0, 1.0, 0.0])
    spec.joint("phi_c").frictionloss = p.joint_friction if effects["friction"] else 0.0
    spec.option.gravity = [0.0, 0.0, -9.81] if effects["gravity"] else [0.0, 0.0, 0.0]
    act = spec.add_actuator()
    act.name = "drive"
    act.target = "phi_a"
    act.trntype = mujoco.mjtTrn.mjTRN_JOINT
    act.set_to_velocity(kv=p.kv_drive)
    load = spec.add_actuator()
    load.name = "load"
    load.target = "phi_c"
    load.trntype = mujoco.mjtTrn.mjTRN_JOINT
    load.set_to_motor()
    m = me.load_model(spec)
    me.set_integrator(m, integrator, timestep)
    # connect anchors on shaft b: the driven joint points (MuJoCo would take them from the unassembled qpos0)
    pts = _mounted(p, "double")
    for k in range(8):
        e = _id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"link{k + 1}")
        m.eq_data[e, 3:6] = (pts["BA"] if k < 4 else pts["BC"])[ref.NEXT[k % 4]]
        m.eq_solref[e] = [p.solref_timeconst, p.solref_dampratio]
    d = mujoco.MjData(m)
    u = assemble(p, m, d, inp, 0.0)
    return m, d, {"u0": u}


def assemble(p: CouplerParams, m, d, inp: dict[str, float], phi_a: float, guess=None) -> np.ndarray:
    """Set qpos to the exact kinematic pose (reference FPP) at phi_a, links aligned with their closures."""
    x = np.array([phi_a, inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]])
    u = ref._ramp_double(p, x) if guess is None else ref.solve_double(p, x, guess)
    phi_c, yc, xb, yb, zb, phi_b, abx, abz = u

    def q(name: str) -> int:
        return m.jnt_qposadr[_id(m, mujoco.mjtObj.mjOBJ_JOINT, name)]

    d.qpos[:] = 0.0
    d.qpos[q("phi_a")] = phi_a
    for name, v in (("x_b", xb), ("y_b", yb), ("z_b", zb), ("alpha_bz", abz), ("alpha_bx", abx),
                    ("phi_b", phi_b - PHI_B_OFFSET), ("y_c", yc), ("phi_c", phi_c - phi_c_offset(p))):
        d.qpos[q(name)] = v
    for k in range(8):
        d.qpos[q(f"link{k + 1}_ball"):q(f"link{k + 1}_ball") + 4] = [1, 0, 0, 0]
    mujoco.mj_kinematics(m, d)
    # rotate each link (minimal rotation, no spin) so that its far end meets its platform point
    for k in range(8):
        bid = _id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{k + 1}")
        parent = m.body_parentid[bid]
        start = d.xpos[bid]
        e = _id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"link{k + 1}")
        sb = _id(m, mujoco.mjtObj.mjOBJ_BODY, "shaft_b")
        end = d.xpos[sb] + d.xmat[sb].reshape(3, 3) @ m.eq_data[e, 3:6]
        Rpar = d.xmat[parent].reshape(3, 3)
        qb = m.body_quat[bid]
        Rb = np.zeros(9)
        mujoco.mju_quat2Mat(Rb, qb)
        dloc = Rb.reshape(3, 3).T @ Rpar.T @ (end - start)
        d.qpos[q(f"link{k + 1}_ball"):q(f"link{k + 1}_ball") + 4] = _quat_z_to(dloc)
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    return u


def _ramp(t: float, t_ramp: float) -> float:
    """Smooth 0 -> 1 (C1) over t_ramp."""
    if t_ramp <= 0 or t >= t_ramp:
        return 1.0
    s = t / t_ramp
    return s * s * (3 - 2 * s)


def run(scene) -> SimResult:
    """Time simulation of the double coupler (MuJoCo or the kinematic/quasi-static reference)."""
    p: CouplerParams = scene.build_params()
    inp = _inputs(scene)
    if scene.solver.engine == "reference":
        return run_reference(scene, p, inp)
    sv = scene.solver
    m, d, info = build(p, dict(scene.effects), inp, sv.timestep, sv.integrator)
    n = int(round(sv.duration / sv.timestep))
    every = max(1, int(round(sv.sample_dt / sv.timestep))) if sv.sample_dt > 0 else 1
    ia = m.jnt_qposadr[_id(m, mujoco.mjtObj.mjOBJ_JOINT, "phi_a")]
    va = m.jnt_dofadr[_id(m, mujoco.mjtObj.mjOBJ_JOINT, "phi_a")]
    servo_tol = max(0.05 * abs(inp["omega"]), 1.0)  # a stable servo tracks to load/kv ~ 5e-3 rad/s
    ic = m.jnt_qposadr[_id(m, mujoco.mjtObj.mjOBJ_JOINT, "phi_c")]
    vc = m.jnt_dofadr[_id(m, mujoco.mjtObj.mjOBJ_JOINT, "phi_c")]
    eq_ids = [_id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"link{k + 1}") for k in range(8)]
    link_ids = [_id(m, mujoco.mjtObj.mjOBJ_BODY, f"link{k + 1}") for k in range(8)]
    rec: dict[str, list] = {k: [] for k in ("t", "phi_a", "phi_c", "omega_c", "torque_in", "closure_residual",
                                            "forces")}
    for i in range(n + 1):
        if i % every == 0:
            mujoco.mj_forward(m, d)  # constraint forces consistent with the recorded state
            eq_rows = np.flatnonzero(d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
            efc_id = d.efc_id[eq_rows]
            res = 0.0
            forces = np.zeros(8)
            for k, e in enumerate(eq_ids):
                rows = eq_rows[efc_id == e]
                res = max(res, float(np.linalg.norm(d.efc_pos[rows])))
                # force on body1 (the link) from the constraint, along the link axis (tension > 0)
                lhat = d.xmat[link_ids[k]].reshape(3, 3)[:, 2]
                forces[k] = float(lhat @ d.efc_force[rows])
            rec["t"].append(d.time)
            rec["phi_a"].append(d.qpos[ia])
            rec["phi_c"].append(d.qpos[ic] + phi_c_offset(p))
            rec["omega_c"].append(d.qvel[vc])
            rec["torque_in"].append(d.actuator_force[0])
            rec["closure_residual"].append(res)
            rec["forces"].append(forces)
        if i == n:
            break
        s = _ramp(d.time, inp["t_ramp"])
        d.ctrl[0] = inp["omega"] * s
        d.ctrl[1] = -inp["load_torque"] * s
        mujoco.mj_step(m, d)
        me.check_finite(m, d, f"coupler scene {scene.name or '(unnamed)'}")
        if abs(d.qvel[va] - d.ctrl[0]) > servo_tol:  # finite but garbage: the stiff input servo went unstable
            raise SolverError(
                f"coupler scene {scene.name or '(unnamed)'}: the input velocity servo (kv = {p.kv_drive:g} N m s/rad) "
                f"is unstable with integrator {sv.integrator} at timestep {sv.timestep:g} s (speed error "
                f"{abs(d.qvel[va] - d.ctrl[0]):.3g} rad/s at t = {d.time:.4g} s); reduce solver.timestep or use "
                "implicitfast/implicit, which treat the servo's damping implicitly")
    t = np.array(rec["t"])
    phi_a, phi_c = np.array(rec["phi_a"]), np.array(rec["phi_c"])
    phi_kin = kinematic_output(p, inp, phi_a, info["u0"])
    forces = np.array(rec["forces"])
    signals = {"phi_a": phi_a, "phi_c": phi_c, "phi_c_kin": phi_kin, "phi_c_err": phi_c - phi_kin,
               "omega_c": np.array(rec["omega_c"]), "torque_in": np.array(rec["torque_in"]),
               "torque_out": np.full_like(t, inp["load_torque"]) * np.array([_ramp(x, inp["t_ramp"]) for x in t]),
               "closure_residual": np.array(rec["closure_residual"])}
    for k in range(8):
        signals[f"link_force_{k + 1}"] = forces[:, k]
    res = SimResult(t, {k: v for k, v in signals.items() if k in scene.outputs or k == "phi_c_err"},
                    {k: OUTPUTS[k] for k in signals}, "mujoco", scene=scene.to_dict())
    res.stats = stats(t, signals, sv.t_settle, inp)
    res.stats["warnings"] = me.warnings_raised(d)
    res.stats["solref"] = [p.solref_timeconst, p.solref_dampratio]
    return res


def kinematic_output(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, u0: np.ndarray) -> np.ndarray:
    """phi_c from the double-coupler FPP at each sampled phi_a (continuation from the initial pose)."""
    out = np.empty_like(phi_a)
    u = u0
    rest = [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]
    turn = np.zeros(8)
    turn[[0, 5]] = 2 * math.pi  # phi_c and phi_b advance with phi_a
    for i, pa in enumerate(phi_a):
        guess = u.copy()
        if i:
            guess[0] += pa - phi_a[i - 1]
            guess[5] += pa - phi_a[i - 1]
        # solve at phi_a wrapped to one turn: the FPP's absolute tolerance cannot be met by sin/cos of an angle of
        # 1000 rad (long runs), and the pose is 2 pi-periodic in phi_a, phi_b, phi_c
        k = round(pa / (2 * math.pi))
        u = ref.solve_double(p, np.array([pa - 2 * math.pi * k, *rest]), guess - k * turn) + k * turn
        out[i] = u[0]
    return out


def stats(t: np.ndarray, s: dict[str, np.ndarray], t_settle: float, inp: dict[str, float]) -> dict:
    """Headline numbers over the settled window t >= max(t_settle, t_ramp)."""
    w = t >= max(t_settle, inp["t_ramp"])
    if not np.any(w):
        w = np.ones_like(t, bool)
    tin = s["torque_in"][w]
    f = np.array([s[f"link_force_{k + 1}"][w] for k in range(8)])
    mean_t = float(np.mean(tin))
    return {
        "window_start": float(t[w][0]),
        "revolutions": float((s["phi_a"][w][-1] - s["phi_a"][w][0]) / (2 * math.pi)),
        "phi_c_err_max": float(np.max(np.abs(s["phi_c_err"][w]))),
        "phi_c_err_rms": float(np.sqrt(np.mean(s["phi_c_err"][w] ** 2))),
        "phi_c_kin_fluctuation_pp": float(np.ptp(s["phi_a"][w] - s["phi_c_kin"][w])),
        "closure_residual_max": float(np.max(s["closure_residual"][w])),
        "closure_residual_max_all": float(np.max(s["closure_residual"])),
        "torque_in_mean": mean_t,
        "torque_in_ripple_pp": float(np.ptp(tin)),
        "torque_in_ripple_rel": float(np.ptp(tin) / abs(mean_t)) if mean_t else math.inf,
        "link_force_max_abs": float(np.max(np.abs(f))),
        "link_force_mean": [float(x) for x in np.mean(f, axis=1)],
    }


def kinematic_derivatives(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, u0: np.ndarray,
                          h: float = 1e-4) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """FPP solution u (n, 8) along phi_a and its first and second derivatives du/dphi_a, d2u/dphi_a2 (central
    differences of converged FPP solutions, step h)."""
    rest = [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]
    U, D1, D2 = (np.empty((phi_a.size, 8)) for _ in range(3))
    u = u0
    for i, pa in enumerate(phi_a):
        g = u.copy()
        if i:
            g[[0, 5]] += pa - phi_a[i - 1]
        u = ref.solve_double(p, np.array([pa, *rest]), g)
        up = ref.solve_double(p, np.array([pa + h, *rest]), u)
        um = ref.solve_double(p, np.array([pa - h, *rest]), u)
        U[i], D1[i], D2[i] = u, (up - um) / (2 * h), (up - 2 * u + um) / h**2
    return U, D1, D2


def shaft_b_energy(p: CouplerParams, u: np.ndarray, du: np.ndarray) -> float:
    """Kinetic energy of shaft b (mass m_shaft_b at (0, l_b/2, 0), inertia diag(I_t, I_a, I_t) in its frame) for
    coordinates u and rates du (DOUBLE_UNKNOWNS order)."""
    _, _, xd, yd, zd, phd, axd, azd = du
    _, _, _, _, _, ph, ax, az = u
    Rz, Rx = ref.rot_z(az), ref.rot_x(ax)
    R = Rz @ Rx @ ref.rot_y(ph)
    w = azd * np.array([0.0, 0.0, 1.0]) + axd * (Rz @ np.array([1.0, 0.0, 0.0])) + phd * (Rz @ Rx @ ref.EY)
    v = np.array([xd, yd, zd]) + np.cross(w, R @ np.array([0.0, p.l_b / 2, 0.0]))
    Ib = R @ np.diag([p.i_shaft_b_trans, p.i_shaft_b_axial, p.i_shaft_b_trans]) @ R.T
    return 0.5 * p.m_shaft_b * float(v @ v) + 0.5 * float(w @ Ib @ w)


def run_reference(scene, p: CouplerParams, inp: dict[str, float]) -> SimResult:
    """Rigid-shaft reference: phi_a(t) from the ramped speed, all coordinates from the FPP, and the input torque from
    the power balance with massless links and no gravity or friction:
    T_in phi_a' = d/dt (E_b + I_c phi_c'^2 / 2) + T_load phi_c' (+ I_a phi_a'' phi_a'), E_b shaft b's kinetic energy."""
    sv = scene.solver
    dt = sv.sample_dt or 10 * sv.timestep
    t = np.arange(0.0, sv.duration + 0.5 * dt, dt)
    om = np.array([inp["omega"] * _ramp(x, inp["t_ramp"]) for x in t])
    al = np.gradient(om, t)
    phi_a = np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t))])
    u0 = ref._ramp_double(p, np.array([0.0, inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]]))
    U, D1, _ = kinematic_derivatives(p, inp, phi_a, u0)
    rates = D1 * om[:, None]
    energy = np.array([shaft_b_energy(p, U[i], rates[i]) for i in range(t.size)])
    energy += 0.5 * p.i_shaft_c * rates[:, 0] ** 2
    tl = inp["load_torque"] * np.array([_ramp(x, inp["t_ramp"]) for x in t])
    power = np.gradient(energy, t) + tl * rates[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_in = np.where(om > 0, power / np.where(om > 0, om, 1.0), tl * D1[:, 0]) + p.i_shaft_a * al
    signals = {"phi_a": phi_a, "phi_c": U[:, 0], "phi_c_kin": U[:, 0], "phi_c_err": np.zeros_like(t),
               "omega_c": rates[:, 0], "torque_in": t_in, "torque_out": tl}
    sig = {key: v for key, v in signals.items() if key in scene.outputs or key == "phi_c_err"}
    res = SimResult(t, sig, {key: OUTPUTS[key] for key in sig}, "reference", scene=scene.to_dict())
    w = t >= max(sv.t_settle, inp["t_ramp"])
    res.stats = {"torque_in_mean": float(np.mean(t_in[w])), "torque_in_ripple_pp": float(np.ptp(t_in[w])),
                 "torque_in_ripple_quasi_static_pp": float(np.ptp(tl[w] * D1[w, 0])),
                 "speed_ratio_min": float(np.min(D1[w, 0])), "speed_ratio_max": float(np.max(D1[w, 0])),
                 "phi_c_kin_fluctuation_pp": float(np.ptp(phi_a[w] - U[w, 0]))}
    return res


OUTPUTS = {"phi_a": "rad", "phi_c": "rad", "phi_c_kin": "rad", "phi_c_err": "rad", "omega_c": "rad/s",
           "torque_in": "N m", "torque_out": "N m", "closure_residual": "m",
           **{f"link_force_{k + 1}": "N" for k in range(8)}}
