"""Analyses of the coupler as `mbsuite.results.Report`s: the single coupler's Jacobian, mobility and screws
(Maniowski & Czauderna, Sect. 2.3, 3.2, Table 2), the quality criteria c1-c5 over a design grid (Eqs 16-20, Figs 6-10;
the criteria themselves: `criteria`) and the single coupler's pose over one revolution. Each report computes all its
data, figures' data included; its writer only writes and draws them (`plots`).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ...errors import GeometryError, ParameterError
from ...results import Report, format_table, write_csv
from .criteria import SAMPLES_SINGLE, double_c5, revolutions, single_c1, single_criteria
from .jacobian import (
    RANK_RTOL,
    Screw,
    analyse_jacobian,
    cond_asymptotic,
    paper_eq15_layout,
    screw_to_twist,
    single_jacobian,
    twist_to_screw,
)
from .params import GAMMAS_PAPER, CouplerParams
from .single import SINGLE_UNKNOWNS, SinglePose, ramp_single, single_points, single_revolution

TABLE2 = {  # the paper's Table 2: e_y -> (S1 point y, S2 point y, |pitch|, chi)
    0.0: (0.0, 0.0, 0.0, 3e5),
    0.05: (0.0720, -0.0220, 0.0011, 87.0),
    0.1: (0.1439, -0.0439, 0.0045, 85.0),
}


COND_WARN = 1e6  # condition numbers above this are reported with a SingularityWarning


class SingularityWarning(UserWarning):
    """The Jacobian is rank deficient (coplanar platforms): the condition number is infinite."""


def _closed_form_or_none(p: CouplerParams) -> float | None:
    """The closed-form aligned-pose condition number, or None where it does not exist (small R,
    `jacobian.cond_asymptotic`)."""
    try:
        return cond_asymptotic(p)
    except ParameterError:
        return None


# --------------------------------------------------------------------------------------------------- Jacobian report
#: columns of the mechanism Jacobian (twist of platform B: velocity of O_b, angular velocity) and their units: a
#: length rate [m/s] per velocity [m/s] is dimensionless, per angular velocity [rad/s] a length [m]
J_COLUMNS = ("v_x", "v_y", "v_z", "w_x", "w_y", "w_z")
J_UNITS = ("-", "-", "-", "m", "m", "m")


def _z(x: float) -> float:
    """A table entry with signed zeros and rounding-level values (|x| < 5e-15) shown as 0."""
    return 0.0 if abs(x) < 5e-15 else float(x)


def zero_pitch_pair(principal: list[Screw]) -> list[Screw] | None:
    """For a 2-system of finite-pitch screws with principal pitches of opposite sign, the two zero-pitch members of the
    cylindroid (the basis in which Table 2 lists its axes). None otherwise."""
    fin = [s for s in principal if math.isfinite(s.pitch)]
    if len(fin) != 2 or fin[0].pitch * fin[1].pitch >= 0:
        return None

    t1, t2 = screw_to_twist(fin[0]), screw_to_twist(fin[1])  # unit omegas, orthogonal, zero cross-pitch
    th = math.atan(math.sqrt(-fin[0].pitch / fin[1].pitch))
    out = [twist_to_screw(math.cos(th) * t1 + sgn * math.sin(th) * t2, np.zeros(3)) for sgn in (1, -1)]
    out.sort(key=lambda sc: int(np.argmax(np.abs(sc.axis))))
    return out


def jacobian_report(p: CouplerParams, phi_a: float = 0.0, alpha_bx: float = 0.0, alpha_bz: float = 0.0,
                    engine: str = "reference") -> Report:
    """Mechanism Jacobian of the single coupler at a solved pose: J, singular values, rank, chi, free motions."""
    if engine not in ("reference", "pinocchio"):
        from ...errors import SceneError

        raise SceneError(f"unknown engine {engine!r}; valid: ['reference', 'pinocchio']")
    if p.e_y == 0.0 and not (alpha_bx or alpha_bz):
        pose = SinglePose(phi_a, 0.0, 0.0, np.array([phi_a - math.pi / 2, 0.0, 0.0, 0.0]))
    else:
        pose = ramp_single(p, phi_a, alpha_bx, alpha_bz)
    _, _, ob, _ = single_points(p, pose.phi_a, alpha_bx, alpha_bz, pose.u)
    if engine == "pinocchio":
        from .pinocchio import PinCoupler

        pc = PinCoupler.build("single", p)
        q = pc.q_of({"phi_a": phi_a, "alpha_bx": alpha_bx, "alpha_bz": alpha_bz,
                     **dict(zip(SINGLE_UNKNOWNS, pose.u, strict=True))})
        J = pc.mechanism_jacobian(q)
    else:
        J = single_jacobian(p, pose)
    an = analyse_jacobian(J, ob)
    ratio = an.singular_values[-1] / an.singular_values[0]
    if an.rank < 4:
        warnings.warn(f"coupler Jacobian is rank {an.rank} < 4 at e_y = {p.e_y:g} (coplanar singularity): "
                      f"condition number infinite (sigma_min/sigma_max = {ratio:.1e} <= rtol {RANK_RTOL:g})",
                      SingularityWarning, stacklevel=2)
    elif an.cond > COND_WARN:
        warnings.warn(f"coupler Jacobian is nearly singular at e_y = {p.e_y:g}: condition number {an.cond:.3g} > "
                      f"{COND_WARN:g} (coplanar singularity approached)", SingularityWarning, stacklevel=2)
    zp = zero_pitch_pair(an.principal_screws)
    data = {
        "params": p.geometry(), "pose": {"phi_a": phi_a, "alpha_bx": alpha_bx, "alpha_bz": alpha_bz,
                                         "phi_b": pose.u[0], "x_b": pose.u[1], "y_b": pose.u[2], "z_b": pose.u[3]},
        "engine": engine,
        "J": J, "J_columns": list(J_COLUMNS), "J_units": list(J_UNITS),
        "J_paper_layout": paper_eq15_layout(J),
        "singular_values": an.singular_values, "rank": an.rank, "rank_rtol": RANK_RTOL,
        "cond": an.cond, "cond_closed_form": _closed_form_or_none(p),
        "principal_screws": [s.as_dict() for s in an.principal_screws],
        "zero_pitch_screws": [s.as_dict() for s in zp] if zp else None,
        "svd_basis_screws": [s.as_dict() for s in an.svd_screws],
    }
    if zp is not None and not (alpha_bx or alpha_bz):
        # Table 2's +-pitch: the zero-pitch pair turned by theta has pitches -+(d/2) sin(2 theta), d = axis distance
        d = float(np.linalg.norm(zp[0].point - zp[1].point))
        data["zero_pitch_axis_distance"] = d
        if p.e_y in TABLE2 and p.e_y > 0:
            h = TABLE2[p.e_y][2]
            data["paper_basis_angle"] = 0.5 * math.asin(min(1.0, h / (d / 2)))
    screws = [(label, f"S{i + 1}", sc) for label, lst in (("principal", an.principal_screws),
                                                          ("zero-pitch", zp or []), ("SVD basis", an.svd_screws))
              for i, sc in enumerate(lst)]
    cf = data["cond_closed_form"]
    table = (f"single coupler Jacobian at phi_a = {phi_a:.6g} rad, alpha_bx = {alpha_bx:.6g} rad, "
             f"alpha_bz = {alpha_bz:.6g} rad;\ngamma = {p.gamma:.6g} rad, e_y = {p.e_y:.6g} m, R = {p.R:.6g} m. "
             "l_dot = J w: link length rates [m/s]\nfrom the twist w = (v at O_b [m/s], omega [rad/s]) of "
             "platform B (Eqs 12-13)\n"
             + format_table(["link", *(f"J_{c} [{u}]" for c, u in zip(J_COLUMNS, J_UNITS, strict=True))],
                            [[f"{k + 1}", *(_z(x) for x in J[k])] for k in range(J.shape[0])], ".5f")
             + "\n\n" + format_table(["singular value", "value [units of J]"],
                                      [[f"sigma_{k + 1}", float(v)] for k, v in enumerate(an.singular_values)], ".6g")
             + f"\nrank {an.rank} (relative tolerance {RANK_RTOL:g}); condition number {an.cond:.6g} [-];\n"
             f"closed form R^2 cos(2 gamma)/e_y = {'n/a (R too small)' if cf is None else f'{cf:.6g}'} [-]"
             "\n\nfree motions (null space of J) as screws: a = unit axis, p = point of the axis nearest to O_b,\n"
             "h = pitch (inf = translation)\n"
             + format_table(["basis", "screw", "a_x [-]", "a_y [-]", "a_z [-]", "p_x [m]", "p_y [m]", "p_z [m]",
                             "h [m]"],
                            [[lab, nm, *(_z(x) for x in sc.axis), *(_z(x) for x in sc.point), _z(sc.pitch)]
                             for lab, nm, sc in screws], ".4g"))

    def write(out: Path) -> list[Path]:
        cols = [("link", "", np.arange(1, J.shape[0] + 1))]
        cols += [(f"J_{c}", u, J[:, i]) for i, (c, u) in enumerate(zip(J_COLUMNS, J_UNITS, strict=True))]
        files = [write_csv(out / "jacobian.csv", cols)]
        files.append(write_csv(out / "jacobian_singular_values.csv",
                               [("index", "", np.arange(1, an.singular_values.size + 1)),
                                ("sigma", "units of J", an.singular_values)]))
        files.append(write_csv(out / "jacobian_screws.csv", [
            ("basis", "", [lab for lab, _, _ in screws]), ("screw", "", [nm for _, nm, _ in screws]),
            *((f"axis_{c}", "-", [sc.axis[i] for _, _, sc in screws]) for i, c in enumerate("xyz")),
            *((f"point_{c}", "m", [sc.point[i] for _, _, sc in screws]) for i, c in enumerate("xyz")),
            ("pitch", "m", [sc.pitch for _, _, sc in screws])]))
        return files

    return Report(data, table, write)


ALPHAS = tuple(np.round(np.linspace(0.0, 0.07, 8), 4))  # up to +-4 deg (the paper's Sect. 5)
EYS = (0.1, 0.2, 0.3)
ZCS = tuple(np.round(np.linspace(0.0, 0.1, 6), 3))
LBS = (1.0, 2.0, 4.0)


def criteria_report(gammas=GAMMAS_PAPER, eys=EYS, alphas=ALPHAS, zcs=ZCS, lbs=LBS, phibcs=(0.0, math.pi / 2),
                    n: int = SAMPLES_SINGLE, fig_gamma: float = GAMMAS_PAPER[1]) -> Report:
    """c1-c4 vs (alpha_b, gamma, e_y) and c5 vs (z_c, phi_bc, l_b); plots in the style of Figs 6-10 with --out, Figs 6-8
    for the single coupler at gamma = `fig_gamma` (default 0.297 rad, the paper's middle design). Every criterion is
    located between the samples (`criteria`); n samples per revolution (the double coupler n // 2 + 1, at least 31)
    only bracket the extrema."""
    n_double = max(31, n // 2 + 1)
    single_rows, single = [], []
    for g in gammas:
        for ey in eys:
            p = CouplerParams(gamma=g, e_y=ey)
            for a in alphas:
                c = single_criteria(p, a, n)
                single.append({"gamma": g, "e_y": ey, "alpha_b": a,
                               **{k: c[k] for k in ("c1", "c1_pp", "c2", "c2_z", "c3", "c4")}})
                single_rows.append([g, ey, a, c["c1"], c["c2"], c["c3"], c["c4"]])
    double, double_rows = [], []
    pd = CouplerParams()  # the double coupler's geometry besides l_b and phi_bc: gamma = 17 deg, e_y = 0.1, R = 1
    for lb in lbs:
        for pbc in phibcs:
            p = CouplerParams(gamma=pd.gamma, e_y=pd.e_y, R=pd.R, l_b=lb, phi_bc=pbc)
            for z in zcs:
                try:
                    c = double_c5(p, z, n=n_double)
                    reason = ""
                except GeometryError as exc:  # shaft b too inclined for e_y: no physical pose (a solver failure raises)
                    c = {"c5": math.nan, "c5_pp": math.nan, "c5_sampled": math.nan, "c1_intermediate": math.nan}
                    reason = f"no physical pose: {exc}"
                double.append({"gamma": p.gamma, "e_y": p.e_y, "R": p.R, "l_b": lb, "phi_bc": pbc, "z_c": z,
                               "c5": c["c5"], "c5_pp": c["c5_pp"], "c5_sampled": c["c5_sampled"],
                               "c1_intermediate": c["c1_intermediate"], "reason": reason})
                double_rows.append([lb, pbc, z, c["c5"], c["c1_intermediate"]])
    data = {"single": single, "double": double,
            "double_geometry": {"gamma": pd.gamma, "e_y": pd.e_y, "R": pd.R},
            "samples_per_revolution": {"single": n, "double": n_double},
            "definitions": {"c1": "max|phi_a-phi_b-mean|", "c2": "max(x_b)-min(x_b)", "c3": "max|beta1-beta1_0|",
                            "c4": "max|beta2-beta2_0|", "c5": "max|phi_a-phi_c-mean|",
                            "extrema": "c1-c5 (and c1_b): every extremum located between the samples (bounded Brent "
                                       "on the FPP), the samples only bracket it; means over the open grid (closing "
                                       "sample left out)",
                            }}
    table = (f"single coupler criteria over one revolution (R = {CouplerParams().R:g} m; c1-c4: Eqs 16-19);\nevery "
             f"extremum located between the samples (Brent on the FPP; {n} samples per revolution, {n_double} "
             "for\nthe double coupler, only bracket them)\n"
             + format_table(["gamma [rad]", "e_y [m]", "alpha_b [rad]", "c1 [rad]", "c2 [m]", "c3 [rad]",
                             "c4 [rad]"], single_rows, ".4g")
             + f"\n\ndouble coupler c5 (Eq 20) at gamma = {pd.gamma:.5g} rad ({math.degrees(pd.gamma):.4g} deg), "
             f"e_y = {pd.e_y:g} m, R = {pd.R:g} m;\nc1_b = fluctuation of the intermediate shaft b; "
             "nan = no physical pose\n"
             + format_table(["l_b [m]", "phi_bc [rad]", "z_c [m]", "c5 [rad]", "c1_b [rad]"], double_rows, ".4g"))
    fig_p = CouplerParams(gamma=fig_gamma)
    revs = revolutions(fig_p)  # the data of Figs 6-8

    def write(out: Path) -> list[Path]:
        files = [write_csv(out / "criteria_single.csv",
                           [(k, u, [r[k] for r in single]) for k, u in (("gamma", "rad"), ("e_y", "m"),
                            ("alpha_b", "rad"), ("c1", "rad"), ("c1_pp", "rad"), ("c2", "m"), ("c2_z", "m"),
                            ("c3", "rad"), ("c4", "rad"))]),
                 write_csv(out / "criteria_double.csv",
                           [(k, u, [r[k] for r in double]) for k, u in (("gamma", "rad"), ("e_y", "m"), ("R", "m"),
                            ("l_b", "m"), ("phi_bc", "rad"), ("z_c", "m"), ("c5", "rad"), ("c5_pp", "rad"),
                            ("c5_sampled", "rad"), ("c1_intermediate", "rad"))])]
        from ...plotting import save
        from . import plots

        files += [save(plots.fig9(single), out / "fig9_criteria_single.png"),
                  save(plots.fig10(double), out / "fig10_c5_double.png")]
        files += plots.figs678(fig_p, revs, out)
        return files

    return Report(data, table, write)


def fpp_report(p: CouplerParams, alpha_bx: float, alpha_bz: float, n: int, engine: str = "reference") -> Report:
    """Single-coupler pose over one revolution (continuation), optionally cross-checked with Pinocchio."""
    rev = single_revolution(p, alpha_bx, alpha_bz, n)
    data = {"phi_a": rev.phi_a, "phi_b": rev.u[:, 0], "x_b": rev.u[:, 1], "y_b": rev.u[:, 2], "z_b": rev.u[:, 3],
            "params": p.geometry(), "alpha_bx": alpha_bx, "alpha_bz": alpha_bz}
    if engine == "pinocchio":
        from .pinocchio import PinCoupler, single_revolution_pin

        pr = single_revolution_pin(PinCoupler.build("single", p), alpha_bx, alpha_bz, rev.phi_a, rev.u[0])
        data["max_abs_diff_pinocchio"] = float(np.max(np.abs(pr - rev.u)))
    d = rev.phi_a - rev.u[:, 0]
    fl = single_c1(p, rev)
    data.update(c1=fl["c"], c1_sampled=fl["c_sampled"], grid_step=float(rev.phi_a[1] - rev.phi_a[0]))
    step = max(1, (n - 1) // 12)
    rows = [[rev.phi_a[i], rev.u[i, 0], rev.u[i, 1], rev.u[i, 2], rev.u[i, 3], d[i] - math.pi / 2]
            for i in range(0, n, step)]
    table = (f"single coupler pose over one revolution (Eqs 4-5), one row per {step} of the {n} samples;\n"
             f"gamma = {p.gamma:.6g} rad, e_y = {p.e_y:.6g} m, R = {p.R:.6g} m, alpha_bx = {alpha_bx:.6g} rad, "
             f"alpha_bz = {alpha_bz:.6g} rad;\nO_b = (x_b, e_y + y_b, z_b) is the centre of platform B\n"
             + format_table(["phi_a [rad]", "phi_b [rad]", "x_b [m]", "y_b [m]", "z_b [m]",
                             "phi_a-phi_b-pi/2 [rad]"], [[_z(x) for x in r] for r in rows], ".6g"))
    table += (f"\nc1 = max |phi_a - phi_b - mean| = {fl['c']:.6g} rad, located between the samples (Brent on the "
              f"FPP);\nread off this grid (spacing {data['grid_step']:.4g} rad) it would be {fl['c_sampled']:.6g} rad")
    if "max_abs_diff_pinocchio" in data:
        table += (f"\nmax |reference - Pinocchio| over the revolution: {data['max_abs_diff_pinocchio']:.3e} "
                  "(rad and m)")

    def write(out: Path) -> list[Path]:
        from ...plotting import save
        from . import plots

        return [write_csv(out / "fpp_single.csv", [("phi_a", "rad", rev.phi_a), ("phi_b", "rad", rev.u[:, 0]),
                                                   ("x_b", "m", rev.u[:, 1]), ("y_b", "m", rev.u[:, 2]),
                                                   ("z_b", "m", rev.u[:, 3])]),
                save(plots.fpp_figure(p, rev.phi_a, rev.u, alpha_bx, alpha_bz), out / "fpp_single.png")]

    return Report(data, table, write)
