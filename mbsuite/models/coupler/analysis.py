"""Analyses of the coupler: Jacobian/mobility/screws (Maniowski & Czauderna, Sect. 2.3, 3.2, Table 2) and quality
criteria c1-c5 (Eqs 16-20, Figs 6-10), as `mbsuite.results.Report`s.

Criteria definitions (README has the discussion):
- c1 = max |(phi_a - phi_b) - mean| over a revolution (Eq 16 without the pi/2 mounting offset); c1_pp = peak-to-peak.
- c2 = max(x_b) - min(x_b) (Eq 17); the z-range is also reported (the path of O_b is a closed curve).
- beta1/beta2 (Fig 3c is not in the text): at each end of each link, with u = R_P^T l_hat the link direction in the
  platform P's own frame (y = platform normal), beta2 = asin(u_y) is the elevation out of the platform plane and
  beta1 = atan2(u_z, u_x) the azimuth in the platform plane. c3 = max |beta1 - beta1_0|, c4 = max |beta2 - beta2_0|
  (deviations from the aligned pose, i.e. the bushing deflection), maxima over links, both ends and the revolution.
- c5 = max |(phi_a - phi_c) - mean| (Eq 20 without the constant offset -phi_bc).
c1 and c5 are the extrema of a smooth periodic function located between the samples (`refined_extremum`), the mean is
taken over one period without the closing sample (`periodic_mean`).
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ...errors import GeometryError, ParameterError
from ...results import Report, format_table, write_csv
from .double import DOUBLE_TURN, double_revolution, solve_double
from .geometry import NEXT, rot_y
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
from .single import (
    SINGLE_UNKNOWNS,
    SinglePose,
    SingleRevolution,
    ramp_single,
    single_points,
    single_revolution,
    solve_single,
)

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


# ---------------------------------------------------------------------------------------------------------- criteria
def link_angles(R_P: np.ndarray, lhat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(beta1, beta2) of unit link vectors lhat (k, 3) at a platform with rotation R_P (module docstring)."""
    u = lhat @ R_P
    return np.arctan2(u[:, 2], u[:, 0]), np.arcsin(np.clip(u[:, 1], -1, 1))


def single_angles(p: CouplerParams, rev: SingleRevolution) -> tuple[np.ndarray, np.ndarray]:
    """beta1, beta2 over the revolution: arrays (n, 8) = 4 links x (end A, end B)."""
    b1, b2 = [], []
    for phi, u in zip(rev.phi_a, rev.u, strict=True):
        a, b, _, Rb = single_points(p, phi, rev.alpha_bx, rev.alpha_bz, u)
        lv = b[NEXT] - a
        lh = lv / np.linalg.norm(lv, axis=1)[:, None]
        x1, x2 = link_angles(rot_y(phi), lh)
        y1, y2 = link_angles(Rb, lh)
        b1.append(np.r_[x1, y1])
        b2.append(np.r_[x2, y2])
    return np.array(b1), np.array(b2)


def _dev(x: np.ndarray, x0: np.ndarray) -> np.ndarray:
    return (x - x0 + math.pi) % (2 * math.pi) - math.pi


def periodic_mean(values: np.ndarray) -> float:
    """Mean over one period of samples at phi_a = phi_0 + 2 pi k / (n - 1), k = 0..n-1, whose last sample closes the
    revolution (the same pose as the first): the closing sample is left out, so no point counts twice. For a smooth
    periodic function this rectangle rule on the open grid is spectrally accurate (it is exact for every harmonic
    below n - 1), unlike a trapezoid over the closed grid counted naively."""
    v = np.asarray(values, float)
    return float(v[:-1].mean())


def refined_extremum(g, phis: np.ndarray, vals: np.ndarray, guess_at, sign: float) -> tuple[float, float]:
    """The extremum (sign = +1: maximum, -1: minimum) of a smooth periodic g(phi_a) sampled as `vals` at `phis` (closed
    grid): the best sample is refined by bounded Brent minimisation of -sign g over its two neighbouring intervals
    (scipy `minimize_scalar`, xatol 1e-12 rad), each evaluation an FPP solve started from `guess_at(phi)`. The
    sampled maximum misses a peak between samples by ~g'' (dphi/2)^2 / 2 (0.55 % for c5 with 61 samples); the
    refined value is the peak to rounding. Returns (phi at the extremum, value)."""
    from scipy.optimize import minimize_scalar

    i = int(np.argmax(sign * vals[:-1]))
    dphi = phis[1] - phis[0]
    lo, hi = phis[i] - dphi, phis[i] + dphi
    res = minimize_scalar(lambda x: -sign * g(x, guess_at(x)), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-12})
    val = -sign * float(res.fun)
    if sign * val < sign * vals[i]:  # never below the best sample (a flat, rounding-level g)
        return float(phis[i]), float(vals[i])
    return float(res.x), val


def _fluctuation(g, phis: np.ndarray, d: np.ndarray, guess_at) -> dict:
    """c = max |d - mean| over the revolution with both extrema of d refined (`refined_extremum`), and the mean by
    `periodic_mean`."""
    mean = periodic_mean(d)
    phi_hi, hi = refined_extremum(g, phis, d, guess_at, 1.0)
    phi_lo, lo = refined_extremum(g, phis, d, guess_at, -1.0)
    c, at = (hi - mean, phi_hi) if hi - mean >= mean - lo else (mean - lo, phi_lo)
    return {"c": float(c), "pp": float(hi - lo), "mean": mean, "phi_a_at": float(at),
            "c_sampled": float(np.max(np.abs(d - mean)))}


def single_criteria(p: CouplerParams, alpha_b: float, n: int = 181) -> dict:
    """c1-c4 of the single coupler for inclination alpha_b (= alpha_bx) over one revolution; c1 with its extrema
    refined between samples (`refined_extremum`), c2-c4 the sampled extremes."""
    rev = single_revolution(p, alpha_b, 0.0, n)
    nom = single_revolution(p, 0.0, 0.0, 3)
    b10, b20 = single_angles(p, nom)
    b1, b2 = single_angles(p, rev)
    d = rev.phi_a - rev.u[:, 0]
    db1, db2 = _dev(b1, b10[0]), b2 - b20[0]

    def guess_at(x: float) -> np.ndarray:
        i = int(np.argmin(np.abs(rev.phi_a - x)))
        return rev.u[i] + np.array([x - rev.phi_a[i], 0.0, 0.0, 0.0])

    def g(x: float, guess: np.ndarray) -> float:
        return x - solve_single(p, x, alpha_b, 0.0, guess).u[0]

    fl = _fluctuation(g, rev.phi_a, d, guess_at)
    return {
        "c1": fl["c"], "c1_pp": fl["pp"], "c1_sampled": fl["c_sampled"], "mean_phi_a_minus_phi_b": fl["mean"],
        "c2": float(np.ptp(rev.u[:, 1])), "c2_z": float(np.ptp(rev.u[:, 3])),
        "c3": float(np.max(np.abs(db1))), "c4": float(np.max(np.abs(db2))),
        "rev": rev, "dbeta1": db1, "dbeta2": db2,
    }


def double_c5(p: CouplerParams, z_c: float, alpha_cx: float = 0.0, alpha_cz: float = 0.0, x_c: float = 0.0,
              n: int = 91) -> dict:
    """c5 = max |(phi_a - phi_c) - mean| of the double coupler over one revolution (Eq 20 without the constant -phi_bc):
    n samples by continuation, then both extrema of phi_a - phi_c refined between samples (`refined_extremum`; at
    phi_bc = pi/2 the peaks sit at phi_a = k 45 deg). Also the sampled value `c5_sampled`, the peak-to-peak
    fluctuation, the mean (`periodic_mean`), the input angle of the extremum, and the intermediate shaft's c1."""
    rev = double_revolution(p, alpha_cx, alpha_cz, x_c, z_c, n)
    rest = np.array([alpha_cx, alpha_cz, x_c, z_c], float)
    d = rev.phi_a - rev.u[:, 0]
    db = rev.phi_a - rev.u[:, 5]
    slope = DOUBLE_TURN / (2 * math.pi)

    def guess_at(x: float) -> np.ndarray:
        i = int(np.argmin(np.abs(rev.phi_a - x)))
        return rev.u[i] + (x - rev.phi_a[i]) * slope

    def g(x: float, guess: np.ndarray) -> float:
        return x - solve_double(p, np.concatenate([[x], rest]), guess)[0]

    fl = _fluctuation(g, rev.phi_a, d, guess_at)
    return {"c5": fl["c"], "c5_pp": fl["pp"], "c5_sampled": fl["c_sampled"], "mean": fl["mean"],
            "phi_a_at_c5": fl["phi_a_at"], "c1_intermediate": float(np.max(np.abs(db - periodic_mean(db)))),
            "rev": rev}


ALPHAS = tuple(np.round(np.linspace(0.0, 0.07, 8), 4))  # up to +-4 deg (the paper's Sect. 5)
EYS = (0.1, 0.2, 0.3)
ZCS = tuple(np.round(np.linspace(0.0, 0.1, 6), 3))
LBS = (1.0, 2.0, 4.0)


def criteria_report(gammas=GAMMAS_PAPER, eys=EYS, alphas=ALPHAS, zcs=ZCS, lbs=LBS, phibcs=(0.0, math.pi / 2),
                    n: int = 121) -> Report:
    """c1-c4 vs (alpha_b, gamma, e_y) and c5 vs (z_c, phi_bc, l_b); plots in the style of Figs 6-10 with --out."""
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
                    c = double_c5(p, z, n=max(31, n // 2 + 1))
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
            "samples_per_revolution": {"single": n, "double": max(31, n // 2 + 1)},
            "definitions": {"c1": "max|phi_a-phi_b-mean|", "c2": "max(x_b)-min(x_b)", "c3": "max|beta1-beta1_0|",
                            "c4": "max|beta2-beta2_0|", "c5": "max|phi_a-phi_c-mean|",
                            "extrema": "c1 and c5: extrema refined between samples (bounded Brent on the FPP); "
                                       "mean over the open grid (closing sample left out); c2-c4: sampled",
                            }}
    table = (f"single coupler criteria over one revolution (R = {CouplerParams().R:g} m; c1-c4: Eqs 16-19)\n"
             + format_table(["gamma [rad]", "e_y [m]", "alpha_b [rad]", "c1 [rad]", "c2 [m]", "c3 [rad]",
                             "c4 [rad]"], single_rows, ".4g")
             + f"\n\ndouble coupler c5 (Eq 20) at gamma = {pd.gamma:.5g} rad ({math.degrees(pd.gamma):.4g} deg), "
             f"e_y = {pd.e_y:g} m, R = {pd.R:g} m;\nc1_b = fluctuation of the intermediate shaft b; "
             "nan = no physical pose\n"
             + format_table(["l_b [m]", "phi_bc [rad]", "z_c [m]", "c5 [rad]", "c1_b [rad]"], double_rows, ".4g"))

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
        files += plots.figs678(CouplerParams(gamma=0.297), out)
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
    data["c1_sampled"] = float(np.max(np.abs(d - periodic_mean(d))))
    step = max(1, (n - 1) // 12)
    rows = [[rev.phi_a[i], rev.u[i, 0], rev.u[i, 1], rev.u[i, 2], rev.u[i, 3], d[i] - math.pi / 2]
            for i in range(0, n, step)]
    table = (f"single coupler pose over one revolution (Eqs 4-5), one row per {step} of the {n} samples;\n"
             f"gamma = {p.gamma:.6g} rad, e_y = {p.e_y:.6g} m, R = {p.R:.6g} m, alpha_bx = {alpha_bx:.6g} rad, "
             f"alpha_bz = {alpha_bz:.6g} rad;\nO_b = (x_b, e_y + y_b, z_b) is the centre of platform B\n"
             + format_table(["phi_a [rad]", "phi_b [rad]", "x_b [m]", "y_b [m]", "z_b [m]",
                             "phi_a-phi_b-pi/2 [rad]"], [[_z(x) for x in r] for r in rows], ".6g"))
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
