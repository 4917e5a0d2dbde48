"""The checks a loader runs on a coupler model file (`ModelSpec.file_checks`): every name the model needs, each SS
link's closure at the stated length on its joint points at the assembled pose q = 0, and the moving bodies' inertias;
for MuJoCo (`check_mjcf`), for the MJCF read by Pinocchio and for the URDF (`pinocchio.PinMjcfCoupler`,
`pinocchio.PinCoupler` check themselves at load)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ...errors import ModelFileError
from .geometry import check_kind, closures, raise_on_gaps
from .modelfiles import closures_from_urdf
from .params import CouplerParams


def required_names(kind: str) -> dict[str, list[str]]:
    """Bodies, joints, sites and equalities the MJCF of `kind` must hold (the model and its runs look them up)."""
    check_kind(kind)
    nl = 4 if kind == "single" else 8
    driven = ["B"] if kind == "single" else ["BA", "BC", "C"]
    chain = (["x_b", "y_b", "z_b", "alpha_bz", "alpha_bx", "phi_b"]
             + ([] if kind == "single" else ["x_c", "y_c", "z_c", "alpha_cz", "alpha_cx", "phi_c"]))
    return {"body": ["coupler", "shaft_a", *(["platform_b"] if kind == "single" else ["shaft_b", "shaft_c"]),
                     *(f"link{k + 1}" for k in range(nl))],
            "joint": ["phi_a", *chain, *(f"link{k + 1}_ball" for k in range(nl))],
            "site": [f"{pre}_S{k + 1}" for pre in ["A", *driven] for k in range(4)]
                    + [f"link{k + 1}_end" for k in range(nl)],
            "equality": [f"link{k + 1}" for k in range(nl)]}


def check_inertias_mujoco(m, path: str | Path) -> None:
    """Every moving body (one with joints) of a compiled MuJoCo model has positive mass and a positive definite,
    physically consistent inertia (principal moments > 0 satisfying the triangle inequality); else ModelFileError."""
    import mujoco

    for b in range(1, m.nbody):
        if m.body_jntnum[b] == 0:
            continue
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
        I = np.sort(m.body_inertia[b])
        if not (m.body_mass[b] > 0 and I[0] > 0 and I[0] + I[1] >= I[2] * (1 - 1e-12)):
            raise ModelFileError(f"{path}: body {name!r} has mass {m.body_mass[b]:g} kg and principal inertia "
                                 f"{m.body_inertia[b].tolist()} kg m^2: a moving body needs mass > 0 and a positive "
                                 "definite inertia (triangle inequality)")


def check_mjcf(m, path: str | Path, kind: str, stated: CouplerParams | None = None) -> None:
    """The checks at load of a coupler MJCF compiled from `path` (unedited, at q = 0 = the assembled pose): every name
    the model needs is present, every <connect> is a connect between its link and the driven shaft, each link body
    starts at its driving joint point, its anchor lies at the stated link length (`stated`: the geometry the file is
    generated from, default `CouplerParams()`) and lands on the driven joint point, the link's end site sits on the
    anchor, and every moving body has a positive definite inertia. MuJoCo places the driven shaft's side of a connect
    at compile time, so any geometry would "close" in MuJoCo: these gaps are what shows a wrong file."""
    import mujoco

    stated = stated or CouplerParams()
    ob = mujoco.mjtObj
    kinds = {"body": ob.mjOBJ_BODY, "joint": ob.mjOBJ_JOINT, "site": ob.mjOBJ_SITE, "equality": ob.mjOBJ_EQUALITY}
    missing = [f"{t} {n!r}" for t, names in required_names(kind).items() for n in names
               if mujoco.mj_name2id(m, kinds[t], n) < 0]
    if missing:
        raise ModelFileError(f"{path}: the coupler_{kind} model needs {', '.join(missing)}, which the file lacks")
    d = mujoco.MjData(m)
    mujoco.mj_kinematics(m, d)
    driven_body = "platform_b" if kind == "single" else "shaft_b"
    l = stated.link_length
    gaps = []
    for c in closures(stated, kind):
        e = mujoco.mj_name2id(m, ob.mjOBJ_EQUALITY, c.name)
        b = mujoco.mj_name2id(m, ob.mjOBJ_BODY, c.name)
        b1, b2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
        if m.eq_type[e] != mujoco.mjtEq.mjEQ_CONNECT or b1 != b or \
                mujoco.mj_id2name(m, ob.mjOBJ_BODY, b2) != driven_body:
            raise ModelFileError(f"{path}: equality {c.name!r} must be a <connect> from body {c.name!r} to "
                                 f"{driven_body!r}")
        anchor = m.eq_data[e, 0:3]
        R = d.xmat[b].reshape(3, 3)
        site = lambda n: d.site_xpos[mujoco.mj_name2id(m, ob.mjOBJ_SITE, n)]  # noqa: E731
        end = d.site_xpos[mujoco.mj_name2id(m, ob.mjOBJ_SITE, f"{c.name}_end")]
        aw = d.xpos[b] + R @ anchor
        gaps.append((c.name, c.name, float(max(np.linalg.norm(d.xpos[b] - site(c.frame_a)),  # starts at its point
                                               abs(np.linalg.norm(anchor) - l),  # stated length
                                               np.linalg.norm(aw - site(c.frame_b)),  # lands on the driven point
                                               np.linalg.norm(end - aw)))))  # end site on the anchor
    raise_on_gaps(path, gaps, l, "MuJoCo")
    check_inertias_mujoco(m, path)


#: file stem -> coupler kind of the coupler model files (`check_model_file`)
FILE_STEMS = {"coupler_single": "single", "coupler_double": "double"}


def check_model_file(path: Path, engine: str, model) -> None:
    """The checks of a coupler model file (`coupler_single`, `coupler_double`) as a loader compiled it, for the
    engines' loaders (`ModelSpec.file_checks`), reusing the model's checks at load:

    - engine "mujoco", `model` an `mujoco.MjModel` of the MJCF: `check_mjcf` (names, each <connect> at the stated
      link length and on its joint points at q = 0, inertias);
    - engine "pinocchio", the MJCF read by Pinocchio: the file's <connect> anchors on Pinocchio's own frames
      (`pinocchio.PinMjcfCoupler`; `buildModelFromMJCF` drops the <connect>s, so they are read from the file);
    - engine "urdf", `model` a `pin.Model` of the URDF: its <mbsuite_closure> lengths against the frames at q = 0
      and the shafts' inertias (`pinocchio.PinCoupler`).

    Raises ModelFileError naming the file, the link (closure) and the residual."""
    path = Path(path)
    kind = FILE_STEMS.get(path.stem)
    if kind is None:
        raise ModelFileError(f"{path}: not a coupler model file; valid names: {sorted(FILE_STEMS)}")
    if engine == "mujoco":
        check_mjcf(model, path, kind)
    elif engine == "pinocchio":
        from .pinocchio import PinMjcfCoupler

        PinMjcfCoupler(kind, path)
    elif engine == "urdf":
        from .pinocchio import PinCoupler

        PinCoupler(kind, CouplerParams(), model, closures_from_urdf(path), str(path))
    else:
        raise ModelFileError(f"{path}: unknown engine {engine!r} for the coupler file checks; valid: "
                             "['mujoco', 'pinocchio', 'urdf']")


def load_checked_mjcf(kind: str, base: str | Path | None = None):
    """Compile the coupler MJCF `base` (default: the shipped file) as it is, check it (`check_mjcf`) and return
    (path, compiled model). A file that is not MJCF is a ModelFileError naming it."""
    from ...engines import mujoco_engine as me
    from ...paths import mjcf_path

    check_kind(kind)
    path = Path(base) if base is not None else mjcf_path(f"coupler_{kind}")
    m = me.load_model(path)
    check_mjcf(m, path, kind)
    return path, m

