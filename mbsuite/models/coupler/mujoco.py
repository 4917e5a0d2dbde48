"""MuJoCo dynamics of the double coupler: input shaft a velocity-servoed to a constant speed, output shaft c with a load
torque and an imposed misalignment (inclination alpha_cx, alpha_cz and lateral offset x_c, z_c), intermediate shaft b
floating on its 8 SS links (soft <connect> equalities).

The model is the shipped `mjcf/coupler_double.xml` edited through MjSpec (`mjspec_variant` for the design,
then here): shaft c keeps only its axial slide y_c (along the base y axis) and its spin phi_c, its body is placed at the
misaligned pose; a velocity actuator drives phi_a, a motor applies the load on phi_c. Effects (scene [effects]):
gravity (on/off), link_inertia ("real" | "massless": link mass and inertia scaled by `massless_factor`), friction
(frictionloss `joint_friction` in every S joint and the output bearing).

A run is one call of mbsuite's native core (`engines.core.Stepper`): the start-up ramps of speed and load are a
precomputed input array, every `sample_dt` the core records the joint coordinates, the drive torque, the rows of the
8 closure equalities (position residual and force) and the two end points of every link, all at the state of that
instant; the servo's stability is a plausibility bound on the drive torque (`servo_bound`). Afterwards, in numpy and
for all samples at once: the closure residuals, the link tensions, and the kinematic output phi_c,kin by the batched
FPP (`reference.kinematic_pose`, Gauss-Newton started from the simulated pose of every sample).
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np

from ... import results
from ...engines import core
from ...engines import mujoco_engine as me
from ...errors import ModelFileError, SceneError
from ...paths import mjcf_path
from ...results import SimResult
from .double import ramp_double, solve_double
from .filechecks import load_checked_mjcf
from .geometry import NEXT, PHI_B_OFFSET, closures, mounted_points, phi_c_offset, raise_on_gaps, rot_x, rot_z
from .modelfiles import DISC_RADIUS, link_inertia, platform_discs, quat_z_to, scene_layout
from .params import CouplerParams
from .reference import kinematic_pose
from .scenario import closure_figure, ramp, scene_inputs, time_mean


# -------------------------------------------------------------------------------------------- MjSpec design edits
def mjspec_variant(p: CouplerParams, kind: str, base: str | Path | None = None):
    """Design variant by editing the shipped MJCF through mujoco.MjSpec: platform sites, link bodies (pose, inertia,
    geometry, end site), shaft offsets (e_y, l_b) and the <connect> anchors. The file is checked first as it is
    (`load_checked_mjcf`: names, closures at q = 0, inertias). Returns the edited MjSpec."""
    path, _ = load_checked_mjcf(kind, base or mjcf_path(f"coupler_{kind}"))
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except Exception as exc:  # mujoco raises ValueError with the parser message
        raise ModelFileError(f"MuJoCo cannot read {path}: {exc}") from exc
    pts = mounted_points(p, kind)
    l = p.link_length
    it, ia = link_inertia(p, p.m_link)

    def set_sites(prefix: str) -> None:
        for k in range(4):
            spec.site(f"{prefix}_S{k + 1}").pos = pts[prefix][k]

    def set_link(name: str, start: np.ndarray, end: np.ndarray) -> None:
        b = spec.body(name)
        b.pos = start
        b.quat = quat_z_to(end - start)
        b.ipos = [0, 0, l / 2]
        b.mass = p.m_link
        b.inertia = [it, it, ia]
        g = spec.geom(f"{name}_rod")
        g.pos = [0, 0, l / 2]
        g.size = [p.link_radius, l / 2, 0]
        spec.site(f"{name}_end").pos = [0, 0, l]
        spec.joint(f"{name}_ball").damping = [p.joint_damping, 0.0, 0.0]

    set_sites("A")
    # the shafts' axial inertias (the generator's inertial: mass 1, diag(I/2, I, I/2) about the shaft axis y)
    out_body = "platform_b" if kind == "single" else "shaft_c"
    for body, i_axial in (("shaft_a", p.i_shaft_a), (out_body, p.i_shaft_c)):
        spec.body(body).inertia = [i_axial / 2, i_axial, i_axial / 2]
    driven = "B" if kind == "single" else "BA"
    set_sites(driven)
    eB = pts[driven] + np.array([0.0, p.e_y, 0.0])
    for k in range(4):
        set_link(f"link{k + 1}", pts["A"][k], eB[NEXT[k]])
    if kind == "single":
        spec.body("platform_b").pos = [0, p.e_y, 0]
    else:
        spec.body("shaft_b").pos = [0, p.e_y, 0]
        spec.body("shaft_b").ipos = [0, p.l_b / 2, 0]
        spec.body("shaft_b").mass = p.m_shaft_b
        spec.body("shaft_b").inertia = [p.i_shaft_b_trans, p.i_shaft_b_axial, p.i_shaft_b_trans]
        spec.geom("shaft_b_geom").fromto = [0, 0, 0, 0, p.l_b, 0]
        set_sites("BC")
        set_sites("C")
        yc = 2 * p.e_y + p.l_b
        spec.body("shaft_c").pos = [0, yc, 0]
        eBC = pts["BC"] + np.array([0.0, p.e_y - yc, 0.0])
        for k in range(4):
            set_link(f"link{k + 5}", pts["C"][k], eBC[NEXT[k]])
    for name, (_, y0, y1) in platform_discs(p, kind).items():  # visual only
        g = spec.geom(name)
        g.fromto = [0, y0, 0, 0, y1, 0]
        g.size = [DISC_RADIUS * p.R, 0, 0]
    lay = scene_layout(p, kind)
    spec.geom("floor").pos = lay["floor_pos"]
    spec.geom("floor").size = lay["floor_size"]
    spec.light("key").pos = lay["light_pos"]
    spec.camera("overview").pos = lay["camera_pos"]
    spec.camera("overview").alt.xyaxes = lay["camera_xyaxes"]
    for c in closures(p, kind):
        eq = spec.equality(c.name)
        data = np.array(eq.data)
        data[:3] = [0, 0, l]
        eq.data = data
    return spec


# ------------------------------------------------------------------------------------------ the scene's dynamics model
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
    # MuJoCo's friction is a soft constraint: below a slip speed set by its time constant (MuJoCo's default 20 ms) it
    # acts as a viscous drag, and the S joints' swing rates (~0.3 rad/s) stay below it; at the stiffest time constant
    # MuJoCo allows (2 timesteps, the default) the S joints dissipate the dry-friction power
    # (tests/coupler/test_dissipation.py). A set solref_friction_timeconst holds the friction model fixed across
    # timesteps (the work-precision study)
    tf = 2.0 * timestep if p.solref_friction_timeconst is None else p.solref_friction_timeconst
    if effects["friction"] and tf < 2.0 * timestep * (1.0 - 1e-6):
        raise SceneError(
            f"solver.timestep = {timestep:g} s is too large for the dry-friction constraints: MuJoCo needs "
            f"solref_friction_timeconst ({tf:g} s) >= 2 timestep and would silently stiffen it; use timestep <= "
            f"{tf / 2:g} s, raise params.solref_friction_timeconst or leave it unset (2 timesteps)")
    massless = effects["link_inertia"] == "massless"
    p.link_floor(massless)  # by name, before MuJoCo's own message (which names no parameter)
    spec = mjspec_variant(p, "double")
    scale = p.massless_factor if massless else 1.0
    it, ia = link_inertia(p, p.m_link * scale)
    for k in range(8):
        b = spec.body(f"link{k + 1}")
        b.mass = p.m_link * scale
        b.inertia = [it, it, ia]
        j = spec.joint(f"link{k + 1}_ball")
        j.frictionloss = p.joint_friction if effects["friction"] else 0.0
        j.solref_friction = [tf, 1.0]
    # shaft c: only y_c (base y) and phi_c remain; its body sits at the imposed misalignment
    for name in ("x_c", "z_c", "alpha_cz", "alpha_cx"):
        spec.delete(spec.joint(name))
    Rc = rot_z(inp["alpha_cz"]) @ rot_x(inp["alpha_cx"])
    bc = spec.body("shaft_c")
    bc.pos = [inp["x_c"], 2 * p.e_y + p.l_b, inp["z_c"]]
    w = math.sqrt(max(0.0, 1.0 + np.trace(Rc))) / 2
    bc.quat = [w, (Rc[2, 1] - Rc[1, 2]) / (4 * w), (Rc[0, 2] - Rc[2, 0]) / (4 * w), (Rc[1, 0] - Rc[0, 1]) / (4 * w)]
    spec.joint("y_c").axis = Rc.T @ np.array([0.0, 1.0, 0.0])
    spec.joint("phi_c").frictionloss = p.joint_friction if effects["friction"] else 0.0
    spec.joint("phi_c").solref_friction = [tf, 1.0]
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
    pts = mounted_points(p, "double")
    for k in range(8):
        e = _id(m, mujoco.mjtObj.mjOBJ_EQUALITY, f"link{k + 1}")
        m.eq_data[e, 3:6] = (pts["BA"] if k < 4 else pts["BC"])[NEXT[k % 4]]
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
    u = ramp_double(p, x) if guess is None else solve_double(p, x, guess)
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
        d.qpos[q(f"link{k + 1}_ball"):q(f"link{k + 1}_ball") + 4] = quat_z_to(dloc)
    d.qvel[:] = 0.0
    mujoco.mj_forward(m, d)
    return u


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
    m, d, _ = build(p, dict(scene.effects), scene_inputs(scene), scene.solver.timestep, scene.solver.integrator)
    mujoco.mj_forward(m, d)
    return m, d


def run_mujoco(scene) -> SimResult:
    """The `mujoco` path: time simulation of the double coupler in MuJoCo on mbsuite's native core (module
    docstring)."""
    p: CouplerParams = scene.build_params()
    inp = scene_inputs(scene)
    sv = scene.solver
    what = f"coupler scene {scene.name or '(unnamed)'} (MuJoCo)"
    m, d, _ = build(p, dict(scene.effects), inp, sv.timestep, sv.integrator)
    n = int(round(sv.duration / sv.timestep))
    every = max(1, int(round(sv.sample_dt / sv.timestep))) if sv.sample_dt > 0 else 1
    stepper = core.Stepper(m, d, channels(m, p, inp), every=every, what=what, hint=servo_hint(p, inp))
    tr = stepper.run(n, ctrl=ramp_input(inp, n, sv.timestep), ctrl_idx=[0, 1])
    signals = signals_of(p, inp, tr, what)
    st = stats(tr.t, signals, sv.t_settle, inp)
    counters = dict(warnings=tr.warnings, solref=[p.solref_timeconst, p.solref_dampratio], steps=tr.steps,
                    integrator=sv.integrator, timestep=sv.timestep)
    return results.assemble(scene, tr.t, signals, engine="mujoco", stats=counters, statistics=st,
                            always=("phi_c_err",), health=[closure_figure(st["closure_residual_max_all"], p)])


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


def stats(t: np.ndarray, s: dict[str, np.ndarray], t_settle: float, inp: dict[str, float]) -> dict:
    """Headline numbers over the settled window t >= max(t_settle, t_ramp)."""
    w = t >= max(t_settle, inp["t_ramp"])
    if not np.any(w):
        w = np.ones_like(t, bool)
    tin = s["torque_in"][w]
    f = np.array([s[f"link_force_{k + 1}"][w] for k in range(8)])
    mean_t = time_mean(t[w], tin)
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
