"""The checks of the shipped IFToMM model files, as a loader compiled them: bodies and joints present, positive
masses and inertias, and every stated loop closure (`geometry.DESIGN`) assembling at q = 0 (MuJoCo and Pinocchio)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

from ...errors import ModelFileError
from .geometry import BAR, CLOSURE_RTOL, DESIGN, MECHANISMS


def _closure_error(path, name: str, body: str, gap: float, engine: str) -> ModelFileError:
    return ModelFileError(f"{path}: loop closure {name!r} (body {body!r}) does not assemble at the initial pose q = 0 "
                          f"({engine}): residual {gap:.4g} m > {CLOSURE_RTOL:g} x bar length {BAR:g} m; the file's "
                          "pivots and bar lengths must match the stated geometry")


def check_mujoco_model(m: mujoco.MjModel, path, mechanism: str) -> None:
    """Checks at load of an IFToMM MJCF compiled from `path` (DESIGN): the bodies, joints and <connect>s are present
    and join the stated bodies; each connect's anchor is the stated point and meets the stated point of its second
    body at q = 0 (MuJoCo places the second side of a connect at compile time, so any geometry would "close"); every
    moving body has mass > 0 and a positive definite inertia (triangle inequality). Else ModelFileError naming the
    file, the body and the residual."""
    des = DESIGN[mechanism]
    ob = mujoco.mjtObj
    missing = [f"body {n!r}" for n in des["bodies"] if mujoco.mj_name2id(m, ob.mjOBJ_BODY, n) < 0]
    missing += [f"joint {n!r}" for n in des["joints"] if mujoco.mj_name2id(m, ob.mjOBJ_JOINT, n) < 0]
    missing += [f"connect {c[0]!r}" for c in des["closures"] if mujoco.mj_name2id(m, ob.mjOBJ_EQUALITY, c[0]) < 0]
    if missing:
        raise ModelFileError(f"{path}: the IFToMM {mechanism} needs {', '.join(missing)}, which the file lacks")
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)

    def world(body: str, pt) -> np.ndarray:
        if body == "world":
            return np.asarray(pt, float)
        b = mujoco.mj_name2id(m, ob.mjOBJ_BODY, body)
        return d.xpos[b] + d.xmat[b].reshape(3, 3) @ np.asarray(pt, float)

    for name, b1, a, b2, b in des["closures"]:
        e = mujoco.mj_name2id(m, ob.mjOBJ_EQUALITY, name)
        id2 = 0 if b2 == "world" else mujoco.mj_name2id(m, ob.mjOBJ_BODY, b2)
        if (m.eq_type[e] != mujoco.mjtEq.mjEQ_CONNECT or int(m.eq_obj1id[e]) != mujoco.mj_name2id(m, ob.mjOBJ_BODY, b1)
                or int(m.eq_obj2id[e]) != id2):
            raise ModelFileError(f"{path}: equality {name!r} must be a <connect> from body {b1!r} to {b2!r}")
        gap = max(float(np.linalg.norm(m.eq_data[e, 0:3] - np.asarray(a))),
                  float(np.linalg.norm(world(b1, a) - world(b2, b))))
        if not gap <= CLOSURE_RTOL * BAR:
            raise _closure_error(path, name, b2 if b2 != "world" else b1, gap, "MuJoCo")
    for i in range(1, m.nbody):
        if m.body_jntnum[i] == 0:
            continue
        inertia = np.sort(m.body_inertia[i])
        if not (m.body_mass[i] > 0 and inertia[0] > 0 and inertia[0] + inertia[1] >= inertia[2] * (1 - 1e-12)):
            raise ModelFileError(f"{path}: body {mujoco.mj_id2name(m, ob.mjOBJ_BODY, i)!r} has mass "
                                 f"{m.body_mass[i]:g} kg and principal inertia {m.body_inertia[i].tolist()} kg m^2: a "
                                 "moving body needs mass > 0 and a positive definite inertia (triangle inequality)")


def _pin_point(model: pin.Model, data: pin.Data, path, body: str, point) -> np.ndarray:
    """World position (after forward kinematics) of a point fixed in MJCF body `body` ("world": the point itself)."""
    if body == "world":
        return np.asarray(point, float)
    if not model.existFrame(body, pin.FrameType.BODY):
        raise ModelFileError(f"{path}: Pinocchio finds no body {body!r} in the file")
    f = model.frames[model.getFrameId(body, pin.FrameType.BODY)]
    return data.oMi[f.parentJoint].act(f.placement.act(np.asarray(point, float)))


def check_pinocchio_model(model: pin.Model, path, mechanism: str) -> None:
    """Checks at load of an IFToMM file read by Pinocchio (DESIGN): every stated closure assembles at the neutral
    pose q = 0 on Pinocchio's own frames, and the body of every joint has mass > 0 and a positive definite inertia.
    Else ModelFileError naming the file, the body and the residual."""
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    for name, b1, a, b2, b in DESIGN[mechanism]["closures"]:
        gap = float(np.linalg.norm(_pin_point(model, data, path, b1, a) - _pin_point(model, data, path, b2, b)))
        if not gap <= CLOSURE_RTOL * BAR:
            raise _closure_error(path, name, b2 if b2 != "world" else b1, gap, "Pinocchio")
    for j in range(1, model.njoints):
        inertia = model.inertias[j]
        eig = np.linalg.eigvalsh(inertia.inertia)
        if not (inertia.mass > 0 and eig[0] > 0):
            raise ModelFileError(f"{path}: the body on joint {model.names[j]!r} has mass {inertia.mass:g} kg and "
                                 f"inertia eigenvalues {eig.tolist()} kg m^2: a moving body needs mass > 0 and a "
                                 "positive definite inertia")


#: file stem -> mechanism of the IFToMM model files (`check_model_file`)
FILE_STEMS = {f"iftomm_{m}": m for m in MECHANISMS}


def check_model_file(path, engine: str, model) -> None:
    """The checks of an IFToMM model file (`iftomm_fourbar`, `iftomm_bricard`) as a loader compiled it, for the
    engines' loaders (`ModelSpec.file_checks`): engine "mujoco" with an `mujoco.MjModel` (`check_mujoco_model`),
    "pinocchio" or "urdf" with a `pin.Model` (`check_pinocchio_model`). Raises ModelFileError naming the file, the
    body/closure and the residual."""
    path = Path(path)
    mechanism = FILE_STEMS.get(path.stem)
    if mechanism is None:
        raise ModelFileError(f"{path}: not an IFToMM model file; valid names: {sorted(FILE_STEMS)}")
    if engine == "mujoco":
        check_mujoco_model(model, path, mechanism)
    elif engine in ("pinocchio", "urdf"):
        check_pinocchio_model(model, path, mechanism)
    else:
        raise ModelFileError(f"{path}: unknown engine {engine!r} for the IFToMM file checks; valid: "
                             "['mujoco', 'pinocchio', 'urdf']")
