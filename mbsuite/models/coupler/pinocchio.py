"""Pinocchio path of the coupler kinematics: URDF spanning trees + stated closures, and the MJCF read by Pinocchio.

FPP from Pinocchio frame placements: residual r_k = |p(frame_b) - p(frame_a)| - l_k for every closure; its Jacobian in
joint velocities is, row by row, the unit link vector applied to the difference of the two joint-point Jacobians,
K_k = l_hat_k^T (J_b - J_a) (translational part, LOCAL_WORLD_ALIGNED). The mechanism Jacobian of the single coupler in
platform-B twist coordinates (v at o^b, omega; base axes) is K_B J_P^-1 with J_P the platform frame Jacobian of B's six
chain joints (columns restricted to them).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ...engines import pinocchio_engine as pe
from ...errors import ModelFileError, SolverError
from ...paths import urdf_path
from .double import DOUBLE_UNKNOWNS
from .fpp import check_physical
from .geometry import PHI_B_OFFSET, Closure, closures, mounted_points, phi_c_offset, raise_on_gaps
from .modelfiles import closures_from_urdf, urdf_text
from .params import CouplerParams
from .single import SINGLE_UNKNOWNS

LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def load_model(kind: str, p: CouplerParams | None = None) -> tuple[pin.Model, list[Closure]]:
    """The shipped URDF (p None) or a generated variant, with its closures."""
    if p is None:
        path = urdf_path(f"coupler_{kind}")
        return pe.load_urdf(path), closures_from_urdf(path)
    try:
        return pin.buildModelFromXML(urdf_text(p, kind)), closures(p, kind)
    except Exception as exc:  # pragma: no cover - generated text is valid
        raise ModelFileError(f"Pinocchio cannot build the generated coupler_{kind} URDF: {exc}") from exc


def pin_variant(model: pin.Model, p: CouplerParams, kind: str) -> tuple[pin.Model, list[Closure]]:
    """Design variant by editing a (baseline) Pinocchio model: joint-point frame placements (gamma, R, phi_bc, l_b)
    and the placements of the shaft chains (e_y, l_b). Returns a new model and the variant's closures."""
    m = model.copy()
    pts = mounted_points(p, kind)
    for prefix, q in pts.items():
        for k in range(4):
            for name in (f"{prefix}_S{k + 1}", f"{prefix}_S{k + 1}_mount"):
                fid = pe.frame_id(m, name)
                m.frames[fid].placement = pin.SE3(np.eye(3), q[k])
    m.jointPlacements[m.getJointId("x_b")] = pin.SE3(np.eye(3), np.array([0.0, p.e_y, 0.0]))
    if kind == "double":
        m.jointPlacements[m.getJointId("x_c")] = pin.SE3(np.eye(3), np.array([0.0, 2 * p.e_y + p.l_b, 0.0]))
    return m, closures(p, kind)


@dataclass
class PinCoupler:
    """A coupler spanning tree in Pinocchio with its closures; coordinates are the paper's (see geometry)."""

    kind: str
    p: CouplerParams
    model: pin.Model
    closures: list[Closure]
    source: str = ""  # the file the model was read from (named in the errors of the checks at load)

    @classmethod
    def build(cls, kind: str, p: CouplerParams | None = None, *, edit: bool = False) -> PinCoupler:
        """Shipped URDF (p None), generated URDF variant, or (edit=True) an edited copy of the shipped model."""
        shipped = str(urdf_path(f"coupler_{kind}")) if p is None or edit else f"generated coupler_{kind} URDF"
        if p is not None and edit:
            base, _ = load_model(kind)
            model, cl = pin_variant(base, p, kind)
        else:
            model, cl = load_model(kind, p)
        return cls(kind, p or CouplerParams(), model, cl, shipped)

    def __post_init__(self) -> None:
        self.data = self.model.createData()
        self.fa = [pe.frame_id(self.model, c.frame_a) for c in self.closures]
        self.fb = [pe.frame_id(self.model, c.frame_b) for c in self.closures]
        self.lengths = np.array([c.length for c in self.closures])
        self._check_at_load()
        self.iq = {self.model.names[j]: self.model.joints[j].idx_q for j in range(1, self.model.njoints)}
        self.iv = {self.model.names[j]: self.model.joints[j].idx_v for j in range(1, self.model.njoints)}
        self.unknowns = SINGLE_UNKNOWNS if self.kind == "single" else DOUBLE_UNKNOWNS
        self.offsets = {"phi_b": PHI_B_OFFSET, "phi_c": phi_c_offset(self.p)}

    def _check_at_load(self) -> None:
        """The closures assemble at q = 0 (the files' assembled pose): | |p_b - p_a| - l | <= CLOSURE_RTOL l for every
        stated closure; each moving shaft has mass > 0 and a positive definite inertia. Else ModelFileError naming the
        file, the closure and the residual."""
        src = self.source or f"coupler_{self.kind} URDF"
        r = self.residual(np.zeros(self.model.nq))
        raise_on_gaps(src, [(c.name, c.frame_b, float(abs(x))) for c, x in zip(self.closures, r, strict=True)],
                      float(np.min(self.lengths)), "Pinocchio")
        for j in range(1, self.model.njoints):
            I = self.model.inertias[j]
            if self.model.names[j].startswith("phi_") and not (
                    I.mass > 0 and np.linalg.eigvalsh(I.inertia)[0] > 0):
                raise ModelFileError(f"{src}: the body on joint {self.model.names[j]!r} has mass {I.mass:g} kg and "
                                     f"inertia eigenvalues {np.linalg.eigvalsh(I.inertia).tolist()}: a moving shaft "
                                     "needs mass > 0 and a positive definite inertia")

    # ---- coordinates
    def q_of(self, coords: dict[str, float]) -> np.ndarray:
        """Pinocchio configuration q from the paper's coordinates (names of `iq`; mounting offsets removed)."""
        q = np.zeros(self.model.nq)
        for k, v in coords.items():
            q[self.iq[k]] = v - self.offsets.get(k, 0.0)
        return q

    def coord(self, q: np.ndarray, name: str) -> float:
        """The paper's coordinate `name` at configuration q (mounting offset added)."""
        return float(q[self.iq[name]] + self.offsets.get(name, 0.0))

    # ---- kinematics
    def update(self, q: np.ndarray) -> None:
        """Joint Jacobians and frame placements at q (the data every other method reads)."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)

    def link_vectors(self) -> np.ndarray:
        """Link vectors p(frame_b) - p(frame_a) (k, 3) in base axes at the last `update`."""
        return np.array([self.data.oMf[b].translation - self.data.oMf[a].translation for a, b in zip(self.fa, self.fb,
                                                                                                     strict=True)])

    def residual(self, q: np.ndarray) -> np.ndarray:
        """Closure residuals |p_b - p_a| - l (call-through `update`)."""
        self.update(q)
        return np.linalg.norm(self.link_vectors(), axis=1) - self.lengths

    def constraint_jacobian(self) -> np.ndarray:
        """K (n_closures x nv): row k = l_hat_k^T (J_b - J_a), translational frame Jacobians in LOCAL_WORLD_ALIGNED.
        Requires `update(q)` first."""
        lv = self.link_vectors()
        lh = lv / np.linalg.norm(lv, axis=1)[:, None]
        rows = []
        for k, (a, b) in enumerate(zip(self.fa, self.fb, strict=True)):
            Ja = pin.getFrameJacobian(self.model, self.data, a, LWA)[:3]
            Jb = pin.getFrameJacobian(self.model, self.data, b, LWA)[:3]
            rows.append(lh[k] @ (Jb - Ja))
        return np.array(rows)

    def fpp(self, inputs: dict[str, float], guess: dict[str, float] | np.ndarray, *, tol: float = 1e-13,
            max_iter: int = 50) -> np.ndarray:
        """Solve the closures for the unknown coordinates (Gauss-Newton on the frame-placement residual, Jacobian
        K restricted to the unknown columns). Returns q."""
        q = guess.copy() if isinstance(guess, np.ndarray) else self.q_of(guess)
        for k, v in inputs.items():
            q[self.iq[k]] = v - self.offsets.get(k, 0.0)
        cols = [self.iv[n] for n in self.unknowns]
        qi = [self.iq[n] for n in self.unknowns]
        for _ in range(max_iter):
            r = self.residual(q)
            if np.max(np.abs(r)) <= tol * self.p.R:
                self._check(q)
                return q
            K = self.constraint_jacobian()[:, cols]
            q[qi] -= np.linalg.lstsq(K, r, rcond=None)[0]
        r = self.residual(q)
        raise SolverError(f"Pinocchio coupler_{self.kind} FPP did not converge (residual {np.max(np.abs(r)):.3e})")

    def _check(self, q: np.ndarray) -> None:
        if self.p.e_y <= 0:
            return
        lv = self.link_vectors()
        ey = np.array([0.0, 1.0, 0.0])

        def axis(frame: str) -> np.ndarray:
            return self.data.oMf[pe.frame_id(self.model, frame)].rotation @ ey

        if self.kind == "single":
            check_physical(self.p, lv, [ey, axis("platform_b")], "Pinocchio single coupler FPP")
        else:
            check_physical(self.p, lv[:4], [ey, axis("shaft_b")], "Pinocchio double coupler FPP")
            check_physical(self.p, -lv[4:], [axis("shaft_b"), axis("shaft_c")], "Pinocchio double coupler FPP")

    def coords(self, q: np.ndarray) -> np.ndarray:
        """The FPP unknowns (in `unknowns` order) at configuration q."""
        return np.array([self.coord(q, n) for n in self.unknowns])

    def mechanism_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Single coupler: J (4 x 6) in platform-B twist coordinates (v at o^b, omega), from K and the platform frame
        Jacobian: J = K[:, chain] J_P[:, chain]^-1."""
        if self.kind != "single":
            raise ModelFileError("mechanism_jacobian (4 x 6) is defined for the single coupler")
        self.update(q)
        cols = [self.iv[n] for n in ("x_b", "y_b", "z_b", "alpha_bz", "alpha_bx", "phi_b")]
        K = self.constraint_jacobian()[:, cols]
        JP = pin.getFrameJacobian(self.model, self.data, pe.frame_id(self.model, "platform_b"), LWA)[:, cols]
        return K @ np.linalg.inv(JP)


def single_revolution_pin(pc: PinCoupler, alpha_bx: float, alpha_bz: float, phis: np.ndarray,
                          start: np.ndarray) -> np.ndarray:
    """Pinocchio FPP along phis, each solve seeded with the previous pose (start: paper unknowns at phis[0])."""
    q = pc.q_of({"alpha_bx": alpha_bx, "alpha_bz": alpha_bz, "phi_a": phis[0], **dict(zip(SINGLE_UNKNOWNS, start,
                                                                                           strict=True))})
    out = []
    for phi in phis:
        q = pc.fpp({"phi_a": phi, "alpha_bx": alpha_bx, "alpha_bz": alpha_bz}, q)
        out.append(pc.coords(q))
    return np.array(out)


# ------------------------------------------------------------------------------------------ the MJCF read by Pinocchio
@dataclass
class PinMjcfCoupler:
    """The shipped MJCF read by Pinocchio (buildModelsAndConstraintsFromMJCF): ball-jointed link bodies, a composite
    joint (x, y, z, alpha_z, alpha_x, phi) per floating shaft and PointAnchorConstraintModels for the <connect>s."""

    kind: str
    path: Path

    def __post_init__(self) -> None:
        try:
            res = pin.buildModelsAndConstraintsFromMJCF(str(self.path))
        except Exception as exc:
            raise ModelFileError(f"Pinocchio cannot load MJCF {self.path}: {exc}") from exc
        self.model = res[0]
        self.cons = list(res[1]["point_anchor_constraint_models"])
        if len(self.cons) != (4 if self.kind == "single" else 8):
            raise ModelFileError(f"{self.path}: expected one <connect> per SS link, found {len(self.cons)}")
        # anchor frames of each connect (on the link body and on the driven platform)
        for i, c in enumerate(self.cons):
            self.model.addFrame(pin.Frame(f"anchor1_{i}", c.joint1_id, c.joint1_placement, pin.FrameType.OP_FRAME))
            self.model.addFrame(pin.Frame(f"anchor2_{i}", c.joint2_id, c.joint2_placement, pin.FrameType.OP_FRAME))
        self.f1 = [self.model.getFrameId(f"anchor1_{i}") for i in range(len(self.cons))]
        self.f2 = [self.model.getFrameId(f"anchor2_{i}") for i in range(len(self.cons))]
        self.data = self.model.createData()
        self._check_at_load()
        comp = {"single": {"b": "Composite_x_b"}, "double": {"b": "Composite_x_b", "c": "Composite_x_c"}}[self.kind]
        self.comp = {k: self.model.joints[self.model.getJointId(v)] for k, v in comp.items()}
        self.ia = self.model.joints[self.model.getJointId("phi_a")].idx_q

    def _check_at_load(self) -> None:
        """At the neutral (assembled) pose, from Pinocchio's own frames: each connect's anchor on its link lies at the
        stated link length (`CouplerParams()`, the geometry the file states) and on the driven joint point (Pinocchio
        also places the second anchor from the file's pose, so only these gaps show a wrong file); else
        ModelFileError naming the file, the link and the residual."""
        m, d = self.model, self.data
        pin.framesForwardKinematics(m, d, pin.neutral(m))
        stated = CouplerParams()
        gaps = []
        for i, c in enumerate(closures(stated, self.kind)):
            anchor = self.cons[i].joint1_placement.translation
            for name in (c.frame_a, c.frame_b):
                if not m.existFrame(name):
                    raise ModelFileError(f"{self.path}: the coupler_{self.kind} model needs site {name!r}")
            gaps.append((c.name, c.name, float(max(
                abs(np.linalg.norm(anchor) - c.length),
                np.linalg.norm(d.oMf[self.f1[i]].translation - d.oMf[m.getFrameId(c.frame_b)].translation),
                np.linalg.norm(d.oMi[self.cons[i].joint1_id].translation
                               - d.oMf[m.getFrameId(c.frame_a)].translation)))))
        raise_on_gaps(self.path, gaps, stated.link_length, "Pinocchio")

    def residual_and_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Closure residuals of the <connect> points and their Jacobian at q."""
        pin.computeJointJacobians(self.model, self.data, q)
        pin.updateFramePlacements(self.model, self.data)
        r, J = [], []
        for a, b in zip(self.f1, self.f2, strict=True):
            r.append(self.data.oMf[a].translation - self.data.oMf[b].translation)
            J.append(pin.getFrameJacobian(self.model, self.data, a, LWA)[:3]
                     - pin.getFrameJacobian(self.model, self.data, b, LWA)[:3])
        return np.concatenate(r), np.vstack(J)

    def fpp(self, inputs: dict[str, float], q0: np.ndarray | None = None, *, tol: float = 1e-13,
            max_iter: int = 60) -> np.ndarray:
        """Solve the connects for all free coordinates (ball joints, shaft chains) with the active coordinates fixed.
        inputs keys: phi_a, alpha_bx, alpha_bz (single) or phi_a, alpha_cx, alpha_cz, x_c, z_c (double)."""
        m = self.model
        q = pin.neutral(m) if q0 is None else q0.copy()
        fixed_v = [m.joints[m.getJointId("phi_a")].idx_v]
        q[self.ia] = inputs["phi_a"]
        # composite order: x, y, z, alpha_z, alpha_x, phi
        sets = {"b": {"alpha_bz": 3, "alpha_bx": 4}, "c": {"x_c": 0, "z_c": 2, "alpha_cz": 3, "alpha_cx": 4}}
        for sh, mapping in sets.items():
            if sh not in self.comp:
                continue
            j = self.comp[sh]
            for name, off in mapping.items():
                if name in inputs:
                    q[j.idx_q + off] = inputs[name]
                    fixed_v.append(j.idx_v + off)
        free = np.setdiff1d(np.arange(m.nv), fixed_v)
        for _ in range(max_iter):
            r, J = self.residual_and_jacobian(q)
            if np.max(np.abs(r)) <= tol:
                return q
            dv = np.zeros(m.nv)
            dv[free] = -np.linalg.lstsq(J[:, free], r, rcond=None)[0]
            q = pin.integrate(m, q, dv)
        raise SolverError(f"Pinocchio MJCF coupler_{self.kind} FPP did not converge (residual {np.max(np.abs(r)):.3e})")

    def fpp_ramp(self, inputs: dict[str, float], steps: int = 12) -> np.ndarray:
        """FPP from the assembled neutral pose by continuation: the inputs are ramped linearly from zero (the
        min-norm Gauss-Newton otherwise may land on the mirror branch with platform B through platform A)."""
        q = pin.neutral(self.model)
        for s in np.linspace(0.0, 1.0, steps + 1)[1:]:
            q = self.fpp({k: s * v for k, v in inputs.items()}, q)
        return q

    def shaft_coords(self, q: np.ndarray, shaft: str) -> np.ndarray:
        """(x, y, z, alpha_z, alpha_x, q_phi) of a floating shaft's composite joint."""
        j = self.comp[shaft]
        return q[j.idx_q:j.idx_q + 6].copy()


def pin_to_mujoco_qpos(pm: pin.Model, q: np.ndarray, mj_model) -> np.ndarray:
    """Map a Pinocchio configuration of the MJCF model to MuJoCo qpos (ball quaternions x,y,z,w -> w,x,y,z)."""
    import mujoco

    qpos = np.zeros(mj_model.nq)
    for j in range(1, pm.njoints):
        name = pm.names[j]
        jm = pm.joints[j]
        seg = q[jm.idx_q:jm.idx_q + jm.nq]
        if name.startswith("Composite_"):
            shaft = name[-1]
            names = [f"x_{shaft}", f"y_{shaft}", f"z_{shaft}", f"alpha_{shaft}z", f"alpha_{shaft}x", f"phi_{shaft}"]
            for n, v in zip(names, seg, strict=True):
                qpos[mj_model.jnt_qposadr[mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, n)]] = v
            continue
        adr = mj_model.jnt_qposadr[mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, name)]
        if jm.nq == 4:
            qpos[adr:adr + 4] = [seg[3], seg[0], seg[1], seg[2]]
        else:
            qpos[adr] = seg[0]
    return qpos
