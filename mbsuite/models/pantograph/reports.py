"""The pantograph's `equilibrium` and `modes` reports: the static equilibrium from the hand-derived equations,
Pinocchio and MuJoCo side by side, and the linearised modes from the hand-derived equations and from MuJoCo's own
linearisation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...errors import SceneError
from ...limits import Limit
from ...results import Report, format_table, write_csv
from ...scenes import Scene
from .equations import PantographODE
from .inputs import config_of, operating_height
from .linearise import linear_model, modes_from_eigs
from .modelfiles import q_to_theta
from .mujoco import MODES_TIMESTEP, MujocoPantograph, mujoco_modes


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
    if cfg.elbow == "compliant":
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
