"""MuJoCo dynamics of the double coupler: input shaft a velocity-servoed to a constant speed, output shaft c with a load
torque and an imposed misalignment (inclination alpha_cx, alpha_cz and lateral offset x_c, z_c), intermediate shaft b
floating on its 8 SS links (soft <connect> equalities).

The model is the shipped `mjcf/coupler_double.xml` edited through MjSpec (`modelfiles.mjspec_variant` for the design,
then here): shaft c keeps only its axial slide y_c (along the base y axis) and its spin phi_c, its body is placed at the
misaligned pose; a velocity actuator drives phi_a, a motor applies the load on phi_c. Effects (scene [effects]):
gravity (on/off), link_inertia ("real" | "massless": link mass and inertia scaled by `massless_factor`), friction
(frictionloss `joint_friction` in every S joint and the output bearing).

A run is one call of mbsuite's native core (`engines.core.Stepper`): the start-up ramps of speed and load are a
precomputed input array, every `sample_dt` the core records the joint coordinates, the drive torque, the rows of the
8 closure equalities (position residual and force) and the two end points of every link, all at the state of that
instant; the servo's stability is a plausibility bound on the drive torque (`servo_bound`). Afterwards, in numpy and
for all samples at once: the closure residuals, the link tensions, and the kinematic output phi_c,kin by the batched
FPP (`kinematic_pose`, Gauss-Newton started from the simulated pose of every sample).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ... import results
from ...engines import core
from ...engines import mujoco_engine as me
from ...errors import GeometryError, SceneError, SolverError
from ...health import Figure
from ...limits import Limit
from ...results import SimResult
from . import reference as ref
from .modelfiles import PHI_B_OFFSET, _mounted, _quat_z_to, link_inertia, mjspec_variant, phi_c_offset, raise_on_gaps
from .params import CouplerParams

#: the scene input of type "constant_speed": valid range, unit, meaning and the default used when a scene omits the
#: key (the scene loader fills it in, so every output shows the value the run used)
INPUTS: dict[str, Limit] = {
    "omega": Limit(lo=0.0, lo_open=True, hi=1000.0, unit="rad/s", default=4 * math.pi,
                   doc="input shaft speed after the ramp"),
    "load_torque": Limit(lo=-1e7, hi=1e7, unit="N m", default=1000.0,
                         doc="load torque on the output shaft, opposing its rotation"),
    "alpha_cx": Limit(lo=-0.5, hi=0.5, unit="rad", default=0.0, doc="output shaft inclination about x"),
    "alpha_cz": Limit(lo=-0.5, hi=0.5, unit="rad", default=0.0, doc="output shaft inclination about z"),
    "x_c": Limit(lo=-1e3, hi=1e3, unit="m", default=0.0, doc="output shaft lateral offset along x"),
    "z_c": Limit(lo=-1e3, hi=1e3, unit="m", default=0.0, doc="output shaft lateral offset along z"),
    "t_ramp": Limit(lo=0.0, hi=1e3, unit="s", default=0.25,
                    doc="duration of the smooth speed and load ramp from rest"),
}
INPUT_KEYS = tuple(INPUTS)
INPUT_DEFAULTS = {k: lim.default for k, lim in INPUTS.items()}


def _inputs(scene) -> dict[str, float]:
    """The run's inputs: the scene's (checked and completed with the declared defaults by the scene loader), checked
    again here for scenes built without it."""
    inp = {**INPUT_DEFAULTS, **{k: v for k, v in scene.input.items() if k != "type"}}
    return {k: INPUTS[k].check(f"coupler input {k}", inp[k], SceneError) for k in INPUT_KEYS}


def _id(m, kind, name: str) -> int:
    return mujoco.mj_name2id(m, kind, name)


def build(p: CouplerParams, effects: dict, inp: dict[str, float], timestep: float, integrator: str):
    """Compile the dynamics model and return (model, data, info) with data at the assembled initial pose (rest)."""
    # a time constant a few last bits below 2 timestep (1e-3 s at 0.5 ms, from arithmetic or a change of 1e-12 ... 1e-9)
    # is at the limit, not past it: MuJoCo's clamp would change it by less than 1e-6 relative
    if p.solref_timeconst < 2.0 * timestep * (1.0 - 1e-6):
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
    # every closure of the edited model assembles at the initial (FPP) pose: link end on its driven joint point
    sb = _id(m, mujoco.mjtObj.mjOBJ_BODY, "shaft_b")
    gaps = []
    for k in range(8):
        e = _id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"link{k + 1}")
        end = d.site_xpos[_id(m, mujoco.mjtObj.mjOBJ_SITE, f"link{k + 1}_end")]
        gaps.append((f"link{k + 1}", f"link{k + 1}",
                     float(np.linalg.norm(end - d.xpos[sb] - d.xmat[sb].reshape(3, 3) @ m.eq_data[e, 3:6]))))
    raise_on_gaps("coupler_double.xml edited for this scene (MjSpec)", gaps, p.link_length, "MuJoCo")
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


def ramp(t, t_ramp: float):
    """Smooth 0 -> 1 (C1: s^2 (3 - 2 s), s = t / t_ramp) over t_ramp; a float or an array of times."""
    t = np.asarray(t, dtype=float)
    s = np.clip(t / t_ramp, 0.0, 1.0) if t_ramp > 0 else np.ones_like(t)
    y = np.where(s >= 1.0, 1.0, s * s * (3 - 2 * s))
    return float(y) if y.ndim == 0 else y


def servo_tol(inp: dict[str, float]) -> float:
    """Speed error (rad/s) beyond which the input velocity servo is not tracking: a stable servo tracks to
    load/kv ~ 5e-3 rad/s, an unstable one grows without bound."""
    return max(0.05 * abs(inp["omega"]), 1.0)


def servo_bound(p: CouplerParams, inp: dict[str, float]) -> float:
    """Plausibility bound on the drive torque: the velocity servo's torque is kv (ctrl - omega_a), so
    |torque_in| <= kv servo_tol is exactly |speed error| <= servo_tol."""
    return p.kv_drive * servo_tol(inp)


def ramp_input(inp: dict[str, float], nstep: int, timestep: float) -> np.ndarray:
    """The ctrl rows (drive speed, load torque) of steps 0..nstep-1: both ramped smoothly from rest, row k at
    t_k = k timestep."""
    s = ramp(np.arange(nstep) * timestep, inp["t_ramp"])
    return np.column_stack([inp["omega"] * s, -inp["load_torque"] * s])


#: joints whose coordinates give the pose for the kinematic reference, in DOUBLE_UNKNOWNS order
POSE_JOINTS = ("phi_c", "y_c", "x_b", "y_b", "z_b", "phi_b", "alpha_bx", "alpha_bz")


def link_sites(k: int) -> tuple[str, str]:
    """(driving-side site, far-end site) of link k = 0..7: the link body's origin and its end."""
    return (f"A_S{k + 1}" if k < 4 else f"C_S{k - 3}"), f"link{k + 1}_end"


def channels(m: mujoco.MjModel, p: CouplerParams, inp: dict[str, float]) -> list[core.Channel]:
    """What a run records (at the state of each sampled instant):
    phi_a, the pose coordinates `q_<joint>` (POSE_JOINTS), omega_c; the drive torque `torque_in` with the servo's
    stability bound; per link k = 1..8 the closure's constraint rows `closure<k>` (position residual, bounded by the
    link length: a gap that wide is no mechanism any more) and `force<k>` (constraint force on the link, base axes), and
    the link's end points `start<k>`, `end<k>`."""
    J, S, E, A = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_SITE, mujoco.mjtObj.mjOBJ_EQUALITY, \
        mujoco.mjtObj.mjOBJ_ACTUATOR
    qadr = {n: int(m.jnt_qposadr[_id(m, J, n)]) for n in ("phi_a", *POSE_JOINTS)}
    bound = servo_bound(p, inp)
    ch = [core.Channel("phi_a", "qpos", qadr["phi_a"])]
    ch += [core.Channel(f"q_{n}", "qpos", qadr[n]) for n in POSE_JOINTS]
    ch.append(core.Channel("omega_c", "qvel", int(m.jnt_dofadr[_id(m, J, "phi_c")])))
    ch.append(core.Channel("torque_in", "actuator_force", _id(m, A, "drive"), 1, -bound, bound))
    for k in range(8):
        e = _id(m, E, f"link{k + 1}")
        start, end = link_sites(k)
        ch += [core.Channel(f"closure{k + 1}", "eq_pos", e, 3, -p.link_length, p.link_length),
               core.Channel(f"force{k + 1}", "eq_force", e, 3),
               core.Channel(f"start{k + 1}", "site_xpos", _id(m, S, start), 3),
               core.Channel(f"end{k + 1}", "site_xpos", _id(m, S, end), 3)]
    return ch


def servo_hint(p: CouplerParams, inp: dict[str, float]) -> str:
    """The advice appended to a failed run: the stiff input servo is what goes unstable first."""
    return (f"the input velocity servo (kv = {p.kv_drive:g} N m s/rad; |torque_in| <= kv x {servo_tol(inp):g} rad/s "
            "of speed error while it tracks) is unstable at this integrator and timestep: reduce solver.timestep or "
            "use implicitfast/implicit, which treat the servo's damping implicitly (or, if it is merely too weak for "
            "the load, raise params.kv_drive)")


def view_model(scene) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The scene's double coupler as MuJoCo runs it (`mbsuite view`): its effects, assembled at the start pose."""
    p: CouplerParams = scene.build_params()
    m, d, _ = build(p, dict(scene.effects), _inputs(scene), scene.solver.timestep, scene.solver.integrator)
    mujoco.mj_forward(m, d)
    return m, d


def run(scene) -> SimResult:
    """Time simulation of the double coupler (MuJoCo or the kinematic/quasi-static reference)."""
    p: CouplerParams = scene.build_params()
    inp = _inputs(scene)
    if scene.solver.engine == "reference":
        return run_reference(scene, p, inp)
    sv = scene.solver
    what = f"coupler scene {scene.name or '(unnamed)'} (MuJoCo)"
    m, d, _ = build(p, dict(scene.effects), inp, sv.timestep, sv.integrator)
    n = int(round(sv.duration / sv.timestep))
    every = max(1, int(round(sv.sample_dt / sv.timestep))) if sv.sample_dt > 0 else 1
    stepper = core.Stepper(m, d, channels(m, p, inp), every=every, what=what, hint=servo_hint(p, inp))
    tr = stepper.run(n, ctrl=ramp_input(inp, n, sv.timestep), ctrl_idx=[0, 1])
    signals = signals_of(p, inp, tr, what)
    st = stats(tr.t, signals, sv.t_settle, inp)
    st.update(warnings=tr.warnings, solref=[p.solref_timeconst, p.solref_dampratio], steps=tr.steps,
              integrator=sv.integrator, timestep=sv.timestep)
    return results.assemble(scene, tr.t, signals, engine="mujoco", stats=st, always=("phi_c_err",),
                            health=[closure_figure(st["closure_residual_max_all"], p)])


#: bound of the MuJoCo closure residual over a whole run (start-up ramp included), relative to the link length: the
#: shipped scenes reach 4.4e-4 to 1.003e-3 l (the peak in the 0.25 s ramp, 9.5e-4 m; 2.8e-5 to 7.3e-5 m in steady
#: rotation), so 5e-3 l (5x the largest) flags closures torn open by a too-soft solref or a bad model
CLOSURE_BOUND_REL = 5e-3
#: the rigid reference solves every sample's FPP to |r| <= 1e-13 R^2 (a gap ~1e-14 l): 1e-9 l flags a failed solve
CLOSURE_BOUND_REL_REFERENCE = 1e-9


def closure_figure(value: float, p: CouplerParams, reference: bool = False) -> Figure:
    """The health figure `closure_residual`: the largest loop-closure gap over the run [m] against its bound
    (CLOSURE_BOUND_REL x link length; CLOSURE_BOUND_REL_REFERENCE for the rigid reference)."""
    rel = CLOSURE_BOUND_REL_REFERENCE if reference else CLOSURE_BOUND_REL
    fix = ("" if reference else "lower params.solref_timeconst (stiffer closures) or lengthen input.t_ramp (a gentler "
           "start-up)")
    return Figure("closure_residual", float(value), rel * p.link_length, "m",
                  f"largest SS-link closure gap over the run, bound {rel:g} x link length {p.link_length:.4g} m", fix)


def simulated_pose(p: CouplerParams, tr: core.Trajectory) -> np.ndarray:
    """(N, 8) FPP coordinates (DOUBLE_UNKNOWNS) of the simulated shafts at every recorded sample."""
    U = np.column_stack([tr[f"q_{n}"] for n in POSE_JOINTS])
    U[:, 0] += phi_c_offset(p)
    U[:, 5] += PHI_B_OFFSET
    return U


def signals_of(p: CouplerParams, inp: dict[str, float], tr: core.Trajectory, what: str = "coupler") -> dict:
    """The output signals of a recorded run, vectorised: closure residual max_k |r_k|, link tensions l_hat_k . f_k
    (tension > 0), and the kinematic output from the batched FPP at every sample."""
    t = tr.t
    phi_a = tr["phi_a"]
    U = simulated_pose(p, tr)
    phi_kin = kinematic_pose(p, inp, phi_a, U, times=t, what=what)[:, 0]
    phi_c = U[:, 0]
    sig = {"phi_a": phi_a, "phi_c": phi_c, "phi_c_kin": phi_kin, "phi_c_err": phi_c - phi_kin,
           "omega_c": tr["omega_c"], "torque_in": tr["torque_in"],
           "torque_out": inp["load_torque"] * ramp(t, inp["t_ramp"]),
           "closure_residual": np.max([np.linalg.norm(tr[f"closure{k + 1}"], axis=1) for k in range(8)], axis=0)}
    for k in range(8):
        lvec = tr[f"end{k + 1}"] - tr[f"start{k + 1}"]
        lhat = lvec / np.linalg.norm(lvec, axis=1)[:, None]
        sig[f"link_force_{k + 1}"] = np.einsum("ni,ni->n", lhat, tr[f"force{k + 1}"])
    return sig


#: largest distance (rad for angles, R for lengths) between the simulated pose and the kinematic pose of a sample that
#: still counts as the same assembly branch; the soft closures keep them ~1e-4 apart (1e-3 in the start-up ramp)
BRANCH_TOL = 0.1


def kinematic_pose(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, guess: np.ndarray,
                   times: np.ndarray | None = None, what: str = "coupler") -> np.ndarray:
    """The FPP pose (N, 8) at every sampled phi_a, all samples at once (`reference.solve_double_wrapped_batch`),
    Gauss-Newton started from `guess` (the simulated pose). Same solutions as the per-sample continuation
    `kinematic_output` (tested to 1e-12); a sample that does not converge, or converges to a pose farther than
    BRANCH_TOL from its guess (another assembly branch), raises SolverError naming its time."""
    rest = np.array([inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]])
    try:
        U = ref.solve_double_wrapped_batch(p, phi_a, rest, guess, times=times)
    except (SolverError, GeometryError) as exc:
        raise type(exc)(f"{what}: kinematic reference: {exc}") from exc
    dev = np.max(np.abs(U - guess) / np.array([1, p.R, p.R, p.R, p.R, 1, 1, 1]), axis=1)
    far = np.flatnonzero(~(dev <= BRANCH_TOL))
    if far.size:
        i = int(far[0])
        at = f"t = {times[i]:.6g} s" if times is not None else f"sample {i}"
        raise SolverError(f"{what}: the kinematic pose at {at} (phi_a = {phi_a[i]:.6g} rad) is {dev[i]:.3g} away from "
                          f"the simulated one (more than {BRANCH_TOL:g}: another assembly branch, or closures torn "
                          f"open; {far.size} of {dev.size} samples)")
    return U


def kinematic_output(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, u0: np.ndarray) -> np.ndarray:
    """phi_c from the double-coupler FPP at each sampled phi_a, one sample after the other by continuation from the
    initial pose u0 (the readable reference of `kinematic_pose`)."""
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
    differences of converged FPP solutions, step h), one sample after the other by continuation from u0 (the readable
    reference of `kinematic_rates`)."""
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


def shaft_b_energy_batch(p: CouplerParams, U: np.ndarray, dU: np.ndarray) -> np.ndarray:
    """`shaft_b_energy` for N samples (U, dU (N, 8)), vectorised: with b = R e_y the shaft axis,
    w = alpha_bz' e_z + alpha_bx' R_z e_x + phi_b' b, v = (x_b', y_b', z_b') + w x (l_b/2) b and
    E = m |v|^2 / 2 + (I_t |w|^2 + (I_a - I_t) (w . b)^2) / 2."""
    cx, sx, cz, sz = np.cos(U[:, 6]), np.sin(U[:, 6]), np.cos(U[:, 7]), np.sin(U[:, 7])
    b = np.column_stack([-sz * cx, cz * cx, sx])
    w = (dU[:, 7, None] * np.array([0.0, 0.0, 1.0]) + dU[:, 6, None] * np.column_stack([cz, sz, np.zeros_like(cz)])
         + dU[:, 5, None] * b)
    v = dU[:, 2:5] + np.cross(w, 0.5 * p.l_b * b)
    It, Ia = p.i_shaft_b_trans, p.i_shaft_b_axial
    wb = np.einsum("ni,ni->n", w, b)
    rot = It * np.einsum("ni,ni->n", w, w) + (Ia - It) * wb**2
    return 0.5 * p.m_shaft_b * np.einsum("ni,ni->n", v, v) + 0.5 * rot


def revolution_guess(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, n: int = 37) -> np.ndarray:
    """A guess (N, 8) of the FPP pose at any phi_a: one revolution by continuation (`reference.double_revolution`,
    n samples, branch jumps detected), whose 2 pi-periodic part (phi_b and phi_c less phi_a) is interpolated linearly
    at phi_a mod 2 pi (within ~1e-5 of the pose for n = 37)."""
    rev = ref.double_revolution(p, inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"], n=n)
    slope = ref.DOUBLE_TURN / (2 * math.pi)
    per = rev.u[:-1] - rev.phi_a[:-1, None] * slope
    G = np.column_stack([np.interp(phi_a, rev.phi_a[:-1], per[:, j], period=2 * math.pi) for j in range(8)])
    return G + phi_a[:, None] * slope


def kinematic_rates(p: CouplerParams, inp: dict[str, float], phi_a: np.ndarray, guess: np.ndarray, h: float = 1e-4,
                    times: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """FPP pose U (N, 8) along phi_a and du/dphi_a by central differences of converged poses (step h), all samples at
    once (the batched twin of `kinematic_derivatives`)."""
    rest = np.array([inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]])
    U = ref.solve_double_wrapped_batch(p, phi_a, rest, guess, times=times)
    up = ref.solve_double_wrapped_batch(p, phi_a + h, rest, U, times=times)
    um = ref.solve_double_wrapped_batch(p, phi_a - h, rest, U, times=times)
    return U, (up - um) / (2 * h)


def run_reference(scene, p: CouplerParams, inp: dict[str, float]) -> SimResult:
    """Rigid-shaft reference: phi_a(t) from the ramped speed, all coordinates from the FPP, and the input torque from
    the power balance with massless links and no gravity or friction:
    T_in phi_a' = d/dt (E_b + I_c phi_c'^2 / 2) + T_load phi_c' (+ I_a phi_a'' phi_a'), E_b shaft b's kinetic energy.
    The FPP is solved for all samples at once, started from one revolution of continuation (`revolution_guess`)."""
    sv = scene.solver
    dt = sv.sample_dt or 10 * sv.timestep
    t = np.arange(0.0, sv.duration + 0.5 * dt, dt)
    s = ramp(t, inp["t_ramp"])
    om = inp["omega"] * s
    al = np.gradient(om, t)
    phi_a = np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t))])
    U, D1 = kinematic_rates(p, inp, phi_a, revolution_guess(p, inp, phi_a), times=t)
    rates = D1 * om[:, None]
    energy = shaft_b_energy_batch(p, U, rates) + 0.5 * p.i_shaft_c * rates[:, 0] ** 2
    tl = inp["load_torque"] * s
    power = np.gradient(energy, t) + tl * rates[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t_in = np.where(om > 0, power / np.where(om > 0, om, 1.0), tl * D1[:, 0]) + p.i_shaft_a * al
    # closure gap of the rigid reference: |r_k| = ||l_k|^2 - l^2| at the solved poses, as a length |r_k| / (2 l)
    gap = np.max(np.abs(ref.double_residual_batch(p, np.column_stack(
        [phi_a - 2 * math.pi * np.round(phi_a / (2 * math.pi)), np.broadcast_to(
            [inp["alpha_cx"], inp["alpha_cz"], inp["x_c"], inp["z_c"]], (t.size, 4))]),
        U - np.round(phi_a / (2 * math.pi))[:, None] * ref.DOUBLE_TURN)), axis=1) / (2 * p.link_length)
    signals = {"phi_a": phi_a, "phi_c": U[:, 0], "phi_c_kin": U[:, 0], "phi_c_err": np.zeros_like(t),
               "omega_c": rates[:, 0], "torque_in": t_in, "torque_out": tl, "closure_residual": gap}
    w = t >= max(sv.t_settle, inp["t_ramp"])
    st = {"torque_in_mean": float(np.mean(t_in[w])), "torque_in_ripple_pp": float(np.ptp(t_in[w])),
          "torque_in_ripple_quasi_static_pp": float(np.ptp(tl[w] * D1[w, 0])),
          "speed_ratio_min": float(np.min(D1[w, 0])), "speed_ratio_max": float(np.max(D1[w, 0])),
          "phi_c_kin_fluctuation_pp": float(np.ptp(phi_a[w] - U[w, 0])), "closure_residual_max_all": float(gap.max())}
    return results.assemble(scene, t, signals, engine="reference", stats=st, always=("phi_c_err",),
                            health=[closure_figure(st["closure_residual_max_all"], p, reference=True)])


OUTPUTS = {"phi_a": "rad", "phi_c": "rad", "phi_c_kin": "rad", "phi_c_err": "rad", "omega_c": "rad/s",
           "torque_in": "N m", "torque_out": "N m", "closure_residual": "m",
           **{f"link_force_{k + 1}": "N" for k in range(8)}}
