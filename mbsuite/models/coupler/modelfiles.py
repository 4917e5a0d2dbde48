"""Model files of the single and double coupler: URDF spanning trees with named closure points, MJCF with link bodies.

Both files are generated from `CouplerParams` by this module (`urdf_text`, `mjcf_text`); the shipped files
`models_urdf/coupler_{single,double}.urdf` and `mjcf/coupler_{single,double}.xml` are the baseline output, written by
`scripts/coupler_write_models.py` (a test checks they are identical to a fresh generation). Design variants are made
either by generating text or by editing the shipped MJCF through `mujoco.MjSpec` (`mjspec_variant`) or the shipped
Pinocchio model's placements (`pinocchio.pin_variant`); tests check the edits equal the generated variants.

Joint coordinates vs the paper's (reference.py): every joint is the paper's coordinate with zero at the assembled,
aligned pose. Platform frames in the files are the *mounted* frames, so
    phi_b = q[phi_b] - pi/2,   phi_c = q[phi_c] + phi_bc,   every other joint q = paper coordinate
(x_b, y_b, z_b are deviations of o^b from (0, e_y, 0); y_c of o^c from (0, 2 e_y + l_b, 0)).
URDF cannot express loops: each SS link is a closure `|p(frame_b) - p(frame_a)| = length`, stated by the custom
element <mbsuite_closure name=... frame_a=... frame_b=... length=.../> (ignored by URDF parsers, read by
`closures_from_urdf`). In the MJCF each SS link is a body with a ball joint at its driving-side end and a
<connect> equality at the other.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ModelFileError
from .params import CouplerParams
from .reference import NEXT, platform_points, rot_y

PHI_B_OFFSET = -math.pi / 2  # phi_b = q_phi_b + PHI_B_OFFSET


def phi_c_offset(p: CouplerParams) -> float:
    """phi_c - q(phi_c) [rad]: the mounted frame of shaft c is turned by phi_bc."""
    return p.phi_bc  # phi_c = q_phi_c + phi_bc


def _f(x: float) -> str:
    s = f"{float(x):.15g}"
    return "0" if s in ("-0", "0") else s


def _v(v) -> str:
    return " ".join(_f(x) for x in v)


@dataclass(frozen=True)
class Closure:
    """One SS link of a URDF spanning tree: |p(frame_b) - p(frame_a)| = length."""

    name: str
    frame_a: str
    frame_b: str
    length: float


def _mounted(p: CouplerParams, kind: str) -> dict[str, np.ndarray]:
    """Local joint-point coordinates on each platform in the files' mounted frames."""
    loc = platform_points(p.gamma, p.R)
    out = {"A": loc, "B": loc @ rot_y(PHI_B_OFFSET).T}
    if kind == "double":
        out["BA"] = out.pop("B")
        out["BC"] = loc @ rot_y(PHI_B_OFFSET + p.phi_bc).T + np.array([0.0, p.l_b, 0.0])
        out["C"] = loc @ rot_y(phi_c_offset(p)).T
    return out


def closures(p: CouplerParams, kind: str) -> list[Closure]:
    """The SS links as closures between named joint-point frames (link k joins driving point k to driven k+1)."""
    l = p.link_length
    if kind == "single":
        return [Closure(f"link{k + 1}", f"A_S{k + 1}", f"B_S{NEXT[k] + 1}", l) for k in range(4)]
    if kind == "double":
        return ([Closure(f"link{k + 1}", f"A_S{k + 1}", f"BA_S{NEXT[k] + 1}", l) for k in range(4)]
                + [Closure(f"link{k + 5}", f"C_S{k + 1}", f"BC_S{NEXT[k] + 1}", l) for k in range(4)])
    raise ModelFileError(f"unknown coupler kind {kind!r}; valid: ['single', 'double']")


def _check_kind(kind: str) -> None:
    if kind not in ("single", "double"):
        raise ModelFileError(f"unknown coupler kind {kind!r}; valid: ['single', 'double']")


# ------------------------------------------------------------------------------------------------------------- URDF
def _urdf_joint(name: str, jtype: str, parent: str, child: str, xyz=(0, 0, 0), axis=None) -> str:
    s = f'  <joint name="{name}" type="{jtype}">\n    <parent link="{parent}"/>\n    <child link="{child}"/>\n'
    s += f'    <origin xyz="{_v(xyz)}" rpy="0 0 0"/>\n'
    if axis is not None:
        s += f'    <axis xyz="{_v(axis)}"/>\n    <limit lower="-1000" upper="1000" effort="1e9" velocity="1e6"/>\n'
    return s + "  </joint>\n"


def _urdf_inertial(name: str, mass: float, ixx: float, iyy: float, izz: float) -> str:
    return (f'  <link name="{name}">\n    <inertial>\n      <origin xyz="0 0 0" rpy="0 0 0"/>\n'
            f'      <mass value="{_f(mass)}"/>\n      <inertia ixx="{_f(ixx)}" ixy="0" ixz="0" iyy="{_f(iyy)}" '
            f'iyz="0" izz="{_f(izz)}"/>\n    </inertial>\n  </link>\n')


def _urdf_chain(prefix: str, origin, child: str) -> str:
    """Six joints x, y, z (prismatic, base axes), alpha_z, alpha_x, phi (revolute): R = R_z R_x R_y (reference.py)."""
    names = [f"x_{prefix}", f"y_{prefix}", f"z_{prefix}", f"alpha_{prefix}z", f"alpha_{prefix}x", f"phi_{prefix}"]
    types = ["prismatic"] * 3 + ["revolute"] * 3
    axes = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (0, 0, 1), (1, 0, 0), (0, 1, 0)]
    links = [f"{prefix}_{n}" for n in ("px", "py", "pz", "rz", "rx")] + [child]
    s, parent = "", "world"
    for i in range(6):
        s += _urdf_joint(names[i], types[i], parent, links[i], origin if i == 0 else (0, 0, 0), axes[i])
        if i < 5:
            s += f'  <link name="{links[i]}"/>\n'
        parent = links[i]
    return s


def _urdf_points(body: str, prefix: str, pts: np.ndarray) -> str:
    s = ""
    for k, q in enumerate(pts):
        s += _urdf_joint(f"{prefix}_S{k + 1}_mount", "fixed", body, f"{prefix}_S{k + 1}", q)
        s += f'  <link name="{prefix}_S{k + 1}"/>\n'
    return s


def urdf_text(p: CouplerParams, kind: str) -> str:
    """URDF spanning tree of the single or double coupler (see module docstring for coordinates and closures)."""
    _check_kind(kind)
    pts = _mounted(p, kind)
    g = p.geometry()
    head = (f'<?xml version="1.0"?>\n<!-- mbsuite 4-link coupler ({kind}), generated by '
            f"mbsuite.models.coupler.modelfiles.urdf_text; geometry {', '.join(f'{k}={_f(v)}' for k, v in g.items())}"
            f" link_length={_f(p.link_length)}.\n     Joint coordinates: phi_b = q(phi_b) - pi/2"
            + (", phi_c = q(phi_c) + phi_bc" if kind == "double" else "")
            + "; all other joints equal the paper's coordinates (zero = aligned, assembled pose).\n"
            "     SS links are loop closures |p(frame_b) - p(frame_a)| = length, listed as <mbsuite_closure>. -->\n")
    s = head + f'<robot name="coupler_{kind}">\n  <link name="world"/>\n'
    s += _urdf_joint("phi_a", "revolute", "world", "shaft_a", (0, 0, 0), (0, 1, 0))
    s += _urdf_inertial("shaft_a", 1.0, p.i_shaft_a / 2, p.i_shaft_a, p.i_shaft_a / 2)
    s += _urdf_points("shaft_a", "A", pts["A"])
    if kind == "single":
        s += _urdf_chain("b", (0, p.e_y, 0), "platform_b")
        s += _urdf_inertial("platform_b", 1.0, p.i_shaft_c / 2, p.i_shaft_c, p.i_shaft_c / 2)
        s += _urdf_points("platform_b", "B", pts["B"])
    else:
        s += _urdf_chain("b", (0, p.e_y, 0), "shaft_b")
        s += _urdf_inertial("shaft_b", p.m_shaft_b, p.i_shaft_b_trans, p.i_shaft_b_axial, p.i_shaft_b_trans)
        s += _urdf_points("shaft_b", "BA", pts["BA"])
        s += _urdf_points("shaft_b", "BC", pts["BC"])
        s += _urdf_chain("c", (0, 2 * p.e_y + p.l_b, 0), "shaft_c")
        s += _urdf_inertial("shaft_c", 1.0, p.i_shaft_c / 2, p.i_shaft_c, p.i_shaft_c / 2)
        s += _urdf_points("shaft_c", "C", pts["C"])
    for c in closures(p, kind):
        s += (f'  <mbsuite_closure name="{c.name}" type="SS" frame_a="{c.frame_a}" frame_b="{c.frame_b}" '
              f'length="{_f(c.length)}"/>\n')
    return s + "</robot>\n"


def closures_from_urdf(path: str | Path) -> list[Closure]:
    """Read the <mbsuite_closure> elements of a coupler URDF (ModelFileError if none or malformed)."""
    try:
        root = ET.parse(str(path)).getroot()
    except (ET.ParseError, OSError) as exc:
        raise ModelFileError(f"cannot read closures from URDF {path}: {exc}") from exc
    out = []
    for el in root.iter("mbsuite_closure"):
        try:
            a = el.attrib
            out.append(Closure(a["name"], a["frame_a"], a["frame_b"], float(a["length"])))
        except (KeyError, ValueError) as exc:
            raise ModelFileError(f"malformed <mbsuite_closure> in {path}: {el.attrib}") from exc
    if not out:
        raise ModelFileError(f"URDF {path} states no <mbsuite_closure> loop closures")
    return out


# ------------------------------------------------------------------------------------------------------------- MJCF
def _quat_z_to(d: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) rotating +z onto the direction d."""
    d = d / np.linalg.norm(d)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(z, d)
    s = np.linalg.norm(axis)
    ang = math.atan2(s, float(z @ d))
    if s < 1e-15:
        return np.array([1.0, 0, 0, 0]) if d[2] > 0 else np.array([0.0, 1, 0, 0])
    axis /= s
    return np.concatenate([[math.cos(ang / 2)], math.sin(ang / 2) * axis])


def link_inertia(p: CouplerParams, mass: float) -> tuple[float, float]:
    """(transverse, axial) inertia of a solid rod of length l and radius r about its centre."""
    l, r = p.link_length, p.link_radius
    return mass * (l**2 / 12 + r**2 / 4), mass * r**2 / 2


def _mj_link(p: CouplerParams, name: str, start: np.ndarray, end: np.ndarray, ind: str) -> str:
    l = p.link_length
    it, ia = link_inertia(p, p.m_link)
    q = _quat_z_to(end - start)
    return (f'{ind}<body name="{name}" pos="{_v(start)}" quat="{_v(q)}">\n'
            f'{ind}  <joint name="{name}_ball" type="ball" damping="{_f(p.joint_damping)}"/>\n'
            f'{ind}  <inertial pos="0 0 {_f(l / 2)}" mass="{_f(p.m_link)}" diaginertia="{_f(it)} {_f(it)} {_f(ia)}"/>\n'
            f'{ind}  <geom name="{name}_rod" type="capsule" pos="0 0 {_f(l / 2)}" size="{_f(p.link_radius)} '
            f'{_f(l / 2)}" material="link" {_VIS}/>\n'
            f'{ind}  <site name="{name}_end" pos="0 0 {_f(l)}"/>\n{ind}</body>\n')


def _mj_sites(prefix: str, pts: np.ndarray, ind: str) -> str:
    return "".join(f'{ind}<site name="{prefix}_S{k + 1}" pos="{_v(q)}"/>\n' for k, q in enumerate(pts))


def _mj_chain(prefix: str, ind: str) -> str:
    j = [("x", "slide", "1 0 0"), ("y", "slide", "0 1 0"), ("z", "slide", "0 0 1"),
         (f"alpha_{prefix}z", "hinge", "0 0 1"), (f"alpha_{prefix}x", "hinge", "1 0 0"), ("phi", "hinge", "0 1 0")]
    out = ""
    for n, t, ax in j:
        name = f"{n}_{prefix}" if n in ("x", "y", "z", "phi") else n
        out += f'{ind}<joint name="{name}" type="{t}" axis="{ax}"/>\n'
    return out


#: visual-only elements of the MJCF (no physics: contype = conaffinity = 0, mass 0, bodies' inertia stated
#: explicitly): platform discs of radius DISC_RADIUS x R and thickness DISC_THICK x R behind each platform's joint plane
DISC_RADIUS = 1.12
DISC_THICK = 0.04
_VIS = 'contype="0" conaffinity="0" mass="0"'


def _span(p: CouplerParams, kind: str) -> tuple[float, float]:
    """Axial extent (y from, y to) of the mechanism in the base frame [m]."""
    return -0.5, (p.e_y if kind == "single" else 2 * p.e_y + p.l_b) + 0.5


def scene_layout(p: CouplerParams, kind: str) -> dict[str, np.ndarray]:
    """Positions of the visual-only elements for geometry `p`: the floor plane 1.6 R below the shaft axis (gravity is
    -z), its half-size, the key light, and the `overview` camera (position and x/y axes, looking at the mechanism's
    centre from the side and above)."""
    y0, y1 = _span(p, kind)
    yc, half = 0.5 * (y0 + y1), 0.5 * (y1 - y0)
    target = np.array([0.0, yc, 0.0])
    dist = 2.6 * max(half, 1.6 * p.R)
    pos = target + dist * np.array([0.85, -0.38, 0.36])
    f = (target - pos) / np.linalg.norm(target - pos)
    x = np.cross(f, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, f)
    return {"floor_pos": np.array([0.0, yc, -1.6 * p.R]),
            "floor_size": np.array([2.5 * p.R + half, 2.5 * p.R + half, 0.05]),
            "light_pos": np.array([0.0, yc, 4.0 * p.R + half]), "camera_pos": pos, "camera_xyaxes": np.r_[x, y]}


def _disc(p: CouplerParams, name: str, y_from: float, y_to: float, ind: str) -> str:
    return (f'{ind}<geom name="{name}" type="cylinder" fromto="0 {_f(y_from)} 0 0 {_f(y_to)} 0" '
            f'size="{_f(DISC_RADIUS * p.R)}" material="platform" {_VIS}/>\n')


def _discs(p: CouplerParams, kind: str) -> dict[str, tuple[str, float, float]]:
    """Platform discs: name -> (body, y_from, y_to) in the body's frame, on the side away from the links."""
    t = DISC_THICK * p.R
    d = {"platform_a_disc": ("shaft_a", -t, 0.0)}
    if kind == "single":
        d["platform_b_disc"] = ("platform_b", 0.0, t)
    else:
        d |= {"platform_ba_disc": ("shaft_b", 0.0, t), "platform_bc_disc": ("shaft_b", p.l_b - t, p.l_b),
              "platform_c_disc": ("shaft_c", 0.0, t)}
    return d


def _mj_header(p: CouplerParams, kind: str) -> str:
    lay = scene_layout(p, kind)
    return ("  <visual>\n    <headlight ambient=\"0.35 0.35 0.35\" diffuse=\"0.5 0.5 0.5\" specular=\"0.1 0.1 0.1\"/>\n"
            '    <global offwidth="1280" offheight="960"/>\n  </visual>\n'
            "  <asset>\n"
            '    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.55 0.65 0.78" rgb2="0.15 0.17 0.2" '
            'width="512" height="512"/>\n'
            '    <texture name="grid" type="2d" builtin="checker" width="512" height="512" rgb1="0.82 0.84 0.86" '
            'rgb2="0.72 0.74 0.77"/>\n'
            '    <material name="grid" texture="grid" texrepeat="4 4" texuniform="true" reflectance="0.05"/>\n'
            '    <material name="platform" rgba="0.45 0.55 0.7 0.35"/>\n'
            '    <material name="shaft" rgba="0.35 0.37 0.4 1"/>\n'
            '    <material name="link" rgba="0.85 0.45 0.15 1"/>\n'
            "  </asset>\n"
            "  <worldbody>\n"
            f'    <light name="key" pos="{_v(lay["light_pos"])}" dir="0 0 -1" directional="true" '
            'diffuse="0.6 0.6 0.6"/>\n'
            f'    <geom name="floor" type="plane" pos="{_v(lay["floor_pos"])}" size="{_v(lay["floor_size"])}" '
            'material="grid" contype="0" conaffinity="0"/>\n'
            f'    <camera name="overview" pos="{_v(lay["camera_pos"])}" xyaxes="{_v(lay["camera_xyaxes"])}"/>\n')


def mjcf_text(p: CouplerParams, kind: str) -> str:
    """MJCF of the single or double coupler: one root body `coupler` (welded to the world) holding the shafts; each SS
    link a body with a ball joint at its driving-side point and a <connect> to the driven platform at its far end."""
    _check_kind(kind)
    pts = _mounted(p, kind)
    g = p.geometry()
    l = p.link_length
    I2 = "    "
    s = (f'<!-- mbsuite 4-link coupler ({kind}), generated by mbsuite.models.coupler.modelfiles.mjcf_text;\n'
         f"     geometry {', '.join(f'{k}={_f(v)}' for k, v in g.items())} link_length={_f(l)}.\n"
         "     y = shaft axis. Joint coordinates: phi_b = q(phi_b) - pi/2"
         + (", phi_c = q(phi_c) + phi_bc" if kind == "double" else "")
         + "; zero = aligned, assembled pose. -->\n"
         f'<mujoco model="coupler_{kind}">\n  <compiler angle="radian" autolimits="true"/>\n'
         '  <option timestep="0.0005" integrator="implicitfast" gravity="0 0 -9.81"/>\n'
         + _mj_header(p, kind) +
         '    <body name="coupler">\n'
         f'      <body name="shaft_a">\n        <joint name="phi_a" type="hinge" axis="0 1 0"/>\n'
         f'        <inertial pos="0 0 0" mass="1" diaginertia="{_f(p.i_shaft_a / 2)} {_f(p.i_shaft_a)} '
         f'{_f(p.i_shaft_a / 2)}"/>\n'
         f'        <geom name="shaft_a_geom" type="cylinder" fromto="0 -0.5 0 0 0 0" size="0.1" material="shaft" '
         f'{_VIS}/>\n')
    discs = _discs(p, kind)

    def body_discs(body: str) -> str:
        return "".join(_disc(p, n, y0, y1, I2 * 2) for n, (b, y0, y1) in discs.items() if b == body)

    s += body_discs("shaft_a")
    s += _mj_sites("A", pts["A"], I2 * 2)
    driven = "B" if kind == "single" else "BA"
    # links of coupler 1: driving end at A_k, far end at driven point k+1 (nominal pose)
    eB = pts[driven] + np.array([0.0, p.e_y, 0.0])
    for k in range(4):
        s += _mj_link(p, f"link{k + 1}", pts["A"][k], eB[NEXT[k]], I2 * 2)
    s += "      </body>\n"
    if kind == "single":
        s += f'      <body name="platform_b" pos="0 {_f(p.e_y)} 0">\n' + _mj_chain("b", I2 * 2)
        s += (f'        <inertial pos="0 0 0" mass="1" diaginertia="{_f(p.i_shaft_c / 2)} {_f(p.i_shaft_c)} '
              f'{_f(p.i_shaft_c / 2)}"/>\n'
              f'        <geom name="shaft_b_geom" type="cylinder" fromto="0 0 0 0 0.5 0" size="0.1" material="shaft" '
              f'{_VIS}/>\n')
        s += body_discs("platform_b") + _mj_sites("B", pts["B"], I2 * 2) + "      </body>\n"
    else:
        s += f'      <body name="shaft_b" pos="0 {_f(p.e_y)} 0">\n' + _mj_chain("b", I2 * 2)
        s += (f'        <inertial pos="0 {_f(p.l_b / 2)} 0" mass="{_f(p.m_shaft_b)}" diaginertia="'
              f'{_f(p.i_shaft_b_trans)} {_f(p.i_shaft_b_axial)} {_f(p.i_shaft_b_trans)}"/>\n'
              f'        <geom name="shaft_b_geom" type="cylinder" fromto="0 0 0 0 {_f(p.l_b)} 0" size="0.1" '
              f'material="shaft" {_VIS}/>\n')
        s += body_discs("shaft_b") + _mj_sites("BA", pts["BA"], I2 * 2) + _mj_sites("BC", pts["BC"], I2 * 2)
        s += "      </body>\n"
        yc = 2 * p.e_y + p.l_b
        s += f'      <body name="shaft_c" pos="0 {_f(yc)} 0">\n' + _mj_chain("c", I2 * 2)
        s += (f'        <inertial pos="0 0 0" mass="1" diaginertia="{_f(p.i_shaft_c / 2)} {_f(p.i_shaft_c)} '
              f'{_f(p.i_shaft_c / 2)}"/>\n'
              f'        <geom name="shaft_c_geom" type="cylinder" fromto="0 0 0 0 0.5 0" size="0.1" material="shaft" '
              f'{_VIS}/>\n')
        s += body_discs("shaft_c") + _mj_sites("C", pts["C"], I2 * 2)
        # links of coupler 2: driving end at C_k, far end at BC_{k+1}, expressed in shaft_c's frame
        eBC = pts["BC"] + np.array([0.0, p.e_y, 0.0]) - np.array([0.0, yc, 0.0])
        for k in range(4):
            s += _mj_link(p, f"link{k + 5}", pts["C"][k], eBC[NEXT[k]], I2 * 2)
        s += "      </body>\n"
    s += "    </body>\n  </worldbody>\n  <equality>\n"
    body2 = "platform_b" if kind == "single" else "shaft_b"
    for c in closures(p, kind):
        s += f'    <connect name="{c.name}" body1="{c.name}" body2="{body2}" anchor="0 0 {_f(l)}"/>\n'
    return s + "  </equality>\n</mujoco>\n"


# ------------------------------------------------------------------------------------------------- checks at load
#: largest gap (relative to the link length) between a link's stated geometry and the model file at its assembled pose
#: q = 0: the files are written to 15 digits (gaps ~1e-16 l); a file rounded to 6 digits still passes, a changed link
#: length or a moved joint point fails by orders of magnitude
CLOSURE_RTOL = 1e-6


def required_names(kind: str) -> dict[str, list[str]]:
    """Bodies, joints, sites and equalities the MJCF of `kind` must hold (the model and its runs look them up)."""
    _check_kind(kind)
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


def raise_on_gaps(path: str | Path, gaps: list[tuple[str, str, float]], length: float, engine: str) -> None:
    """ModelFileError naming the file, the worst closure/body and its residual if any gap exceeds CLOSURE_RTOL x the
    link length. gaps: (closure, body, residual in m)."""
    bad = [g for g in gaps if not g[2] <= CLOSURE_RTOL * length]
    if bad:
        name, body, r = max(bad, key=lambda g: g[2] if math.isfinite(g[2]) else math.inf)
        raise ModelFileError(
            f"{path}: loop closure {name!r} (body {body!r}) does not assemble at the initial pose q = 0 ({engine}): "
            f"residual {r:.4g} m > {CLOSURE_RTOL:g} x link length {length:.6g} m ({len(bad)} of {len(gaps)} "
            "closures); the file's joint points and link lengths must match the stated geometry")


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

    _check_kind(kind)
    path = Path(base) if base is not None else mjcf_path(f"coupler_{kind}")
    m = me.load_model(path)
    check_mjcf(m, path, kind)
    return path, m


def write_baseline(root: Path | None = None) -> list[Path]:
    """Write the shipped baseline files (CouplerParams() defaults). Used by scripts/coupler_write_models.py."""
    from ...paths import models_root

    root = Path(root) if root is not None else models_root()
    p = CouplerParams()
    out = []
    for kind in ("single", "double"):
        u = root / "models_urdf" / f"coupler_{kind}.urdf"
        u.write_text(urdf_text(p, kind))
        m = root / "mjcf" / f"coupler_{kind}.xml"
        m.write_text(mjcf_text(p, kind))
        out += [u, m]
    return out


# ----------------------------------------------------------------------------------------------- MjSpec design edits
def mjspec_variant(p: CouplerParams, kind: str, base: str | Path | None = None):
    """Design variant by editing the shipped MJCF through mujoco.MjSpec: platform sites, link bodies (pose, inertia,
    geometry, end site), shaft offsets (e_y, l_b) and the <connect> anchors. The file is checked first as it is
    (`load_checked_mjcf`: names, closures at q = 0, inertias). Returns the edited MjSpec."""
    import mujoco

    from ...paths import mjcf_path

    path, _ = load_checked_mjcf(kind, base or mjcf_path(f"coupler_{kind}"))
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except Exception as exc:  # mujoco raises ValueError with the parser message
        raise ModelFileError(f"MuJoCo cannot read {path}: {exc}") from exc
    pts = _mounted(p, kind)
    l = p.link_length
    it, ia = link_inertia(p, p.m_link)

    def set_sites(prefix: str) -> None:
        for k in range(4):
            spec.site(f"{prefix}_S{k + 1}").pos = pts[prefix][k]

    def set_link(name: str, start: np.ndarray, end: np.ndarray) -> None:
        b = spec.body(name)
        b.pos = start
        b.quat = _quat_z_to(end - start)
        b.ipos = [0, 0, l / 2]
        b.mass = p.m_link
        b.inertia = [it, it, ia]
        g = spec.geom(f"{name}_rod")
        g.pos = [0, 0, l / 2]
        g.size = [p.link_radius, l / 2, 0]
        spec.site(f"{name}_end").pos = [0, 0, l]
        spec.joint(f"{name}_ball").damping = [p.joint_damping, 0.0, 0.0]

    set_sites("A")
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
    for name, (_, y0, y1) in _discs(p, kind).items():  # visual only
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
