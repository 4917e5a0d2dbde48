"""Figures of the coupler analyses, in the style of Maniowski & Czauderna's Figs 6-10, plus the FPP revolution and the
double-coupler dynamics run.

Every function draws only the data it is given (no solving), on the `Axes` it is given or on a new
`matplotlib.figure.Figure` (`mbsuite.plotting`); none selects a backend or touches pyplot. Lengths are in metres (the
paper's non-dimensional model is R = 1 m), angles in radians. Symbols (defined again on each figure): phi_a, phi_b,
phi_c the spin angles of shafts a, b, c; O_b = (x_b, y_b, z_b) the centre of platform B; alpha_b its imposed
inclination; gamma the platform proportion angle; e_y the axial shift between the platforms; beta1 (azimuth in the
platform plane) and beta2 (elevation out of it) the direction of a link seen from a platform, index 0 = aligned pose;
c1-c5 the quality criteria (Eqs 16-20).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from ...plotting import figure, save
from .params import CouplerParams

_PI_TICKS = ([0.0, math.pi / 2, math.pi, 1.5 * math.pi, 2 * math.pi], ["0", "π/2", "π", "3π/2", "2π"])


def _geom(p: CouplerParams) -> str:
    return f"γ = {p.gamma:.4g} rad, $e_y$ = {p.e_y:g} m, R = {p.R:g} m"


def _phi_axis(ax: Any) -> None:
    ax.set_xticks(*_PI_TICKS)
    ax.set_xlim(0.0, 2 * math.pi)
    ax.set_xlabel(r"input angle $\varphi_a$ [rad]")


def _target(ax: Any, size: tuple[float, float]) -> tuple[Figure | None, Any]:
    if ax is not None:
        return None, ax
    return figure(1, 1, size=size)


def fig6(p: CouplerParams, revs: list[dict], ax: Any = None) -> Figure | Any:
    """Fig 6: output-angle fluctuation phi_a - phi_b - pi/2 over one revolution (its largest |.| about the mean is c1,
    Eq 16). `revs` as `criteria.revolutions` (so are Figs 7 and 8's)."""
    fig, ax = _target(ax, (8.0, 4.2))
    for c in revs:
        rev = c["rev"]
        ax.plot(rev.phi_a, rev.phi_a - rev.u[:, 0] - math.pi / 2, label=f"$α_b$ = {c['alpha_b']:g} rad")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    _phi_axis(ax)
    ax.set_ylabel(r"$\varphi_a - \varphi_b - \pi/2$ [rad]")
    ax.set_title("Single coupler: output-angle fluctuation over one revolution\n"
                 r"($\varphi_a$, $\varphi_b$ spin angles of shafts a, b; $α_b$ inclination of shaft b; "
                 + _geom(p) + ")", fontsize=9)
    if fig is not None:
        fig.legend(*ax.get_legend_handles_labels(), fontsize=8, loc="outside lower center", ncols=len(revs))
    else:
        ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    return fig if fig is not None else ax


def fig7(p: CouplerParams, revs: list[dict], ax: Any = None) -> Figure | Any:
    """Fig 7: the path of platform B's centre O_b in the x-z plane over one revolution (its x-range is c2, Eq 17)."""
    fig, ax = _target(ax, (7.5, 5.5))
    for c in revs:
        ax.plot(c["rev"].u[:, 1], c["rev"].u[:, 3], label=f"$α_b$ = {c['alpha_b']:g} rad")
    ax.plot([0.0], [0.0], "k+", ms=8, label="aligned pose ($α_b$ = 0)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("$x_b$ [m]")
    ax.set_ylabel("$z_b$ [m]")
    ax.set_title("Single coupler: path of the centre $O_b$ of platform B\n(x, z across the shaft axis y; "
                 + _geom(p) + ")", fontsize=9)
    ax.ticklabel_format(style="sci", scilimits=(-2, 2))
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(True, alpha=0.3)
    return fig if fig is not None else ax


def fig8(p: CouplerParams, revs: list[dict], axes: Sequence[Any] | None = None, column: int = 4) -> Figure | Any:
    """Fig 8: link-direction angles at one link end over a revolution, deviation from the aligned pose: beta1
    (azimuth in the platform plane; its maximum over links and ends is c3, Eq 18) and beta2 (elevation out of the
    platform plane; c4, Eq 19). `column` indexes the 8 link ends (links 1-4 at A, then at B); default link 1, end B."""
    fig = None
    if axes is None:
        fig, axes = figure(2, 1, size=(8.0, 6.2), sharex=True)
    end = ("A" if column < 4 else "B", column % 4 + 1)
    for c in revs:
        for ax, key in zip(axes, ("dbeta1", "dbeta2"), strict=True):
            ax.plot(c["rev"].phi_a, c[key][:, column], label=f"$α_b$ = {c['alpha_b']:g} rad")
    axes[0].set_ylabel(r"$\beta_1 - \beta_{1,0}$ [rad]")
    axes[1].set_ylabel(r"$\beta_2 - \beta_{2,0}$ [rad]")
    axes[0].set_title(f"Single coupler: direction of link {end[1]} seen from platform {end[0]}, deviation from the "
                      "aligned pose\n" r"$\beta_1$ azimuth in the platform plane, $\beta_2$ elevation out of it; "
                      + _geom(p), fontsize=9)
    _phi_axis(axes[1])
    if fig is not None:  # below the panels: the curves fill both of them
        fig.legend(*axes[0].get_legend_handles_labels(), fontsize=8, loc="outside lower center", ncols=len(revs))
    else:
        axes[0].legend(fontsize=8)
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    return fig if fig is not None else axes


_CRIT = {"c1": (r"$c_1$ = max|$\varphi_a-\varphi_b$ − mean| [rad]", "output-angle fluctuation (Eq 16)"),
         "c2": (r"$c_2$ = max $x_b$ − min $x_b$ [m]", "run-out of the centre $O_b$ along x (Eq 17)"),
         "c3": (r"$c_3$ = max|$\beta_1-\beta_{1,0}$| [rad]", "link azimuth deviation (Eq 18)"),
         "c4": (r"$c_4$ = max|$\beta_2-\beta_{2,0}$| [rad]", "link elevation deviation (Eq 19)")}


def fig9(rows: list[dict], axes: Any = None) -> Figure | Any:
    """Fig 9: c1-c4 against the inclination alpha_b; colour = gamma, line style = e_y. `rows` as
    `criteria_report().data["single"]`."""
    fig = None
    if axes is None:
        fig, axes = figure(2, 2, size=(11.0, 8.0))
    axes = np.asarray(axes)
    gammas = sorted({r["gamma"] for r in rows})
    eys = sorted({r["e_y"] for r in rows})
    styles = ["-", "--", ":", "-."]
    for ax, key in zip(axes.flat, ("c1", "c2", "c3", "c4"), strict=True):
        for gi, g in enumerate(gammas):
            for ei, ey in enumerate(eys):
                sel = sorted((r for r in rows if r["gamma"] == g and r["e_y"] == ey), key=lambda r: r["alpha_b"])
                ax.plot([r["alpha_b"] for r in sel], [r[key] for r in sel], styles[ei % 4], color=f"C{gi}", marker=".",
                        ms=4, label=f"γ = {g:g} rad, $e_y$ = {ey:g} m")
        ax.set_xlabel(r"inclination of shaft b $α_b$ [rad]")
        ax.set_ylabel(_CRIT[key][0])
        ax.set_title(_CRIT[key][1], fontsize=9)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        ax.grid(True, alpha=0.3)
    axes.flat[0].legend(fontsize=7, loc="upper left")
    if fig is not None:
        fig.suptitle("Single coupler quality criteria over one revolution (R = 1 m; γ platform proportion angle, "
                     "$e_y$ axial shift)", fontsize=10)
    return fig if fig is not None else axes


def fig10(rows: list[dict], ax: Any = None) -> Figure | Any:
    """Fig 10: c5 of the double coupler against the lateral offset z_c of the output shaft, one line per l_b, for the
    angle phi_bc = pi/2 between the middle platforms. At phi_bc = 0 the c5 values are rounding noise (full
    homokineticity): they are stated in the legend by their largest value instead of being drawn on a log axis. A
    missing point (NaN) is a geometry without a physical pose. `rows` as `criteria_report().data["double"]`."""
    fig, ax = _target(ax, (8.0, 5.0))
    lbs = sorted({r["l_b"] for r in rows})
    pbcs = sorted({r["phi_bc"] for r in rows})
    geo = rows[0] if rows else {}
    for li, lb in enumerate(lbs):
        for pbc in pbcs:
            sel = sorted((r for r in rows if r["l_b"] == lb and r["phi_bc"] == pbc), key=lambda r: r["z_c"])
            z = np.array([r["z_c"] for r in sel])
            c5 = np.array([r["c5"] for r in sel], float)
            if pbc == 0.0:
                fin = c5[np.isfinite(c5)]
                top = float(np.max(fin)) if fin.size else math.nan
                ax.plot(z, np.zeros_like(z), ":", color=f"C{li}", lw=1.0,
                        label=rf"$l_b$ = {lb:g} m, $\varphi_{{bc}}$ = 0: max $c_5$ = {top:.1g} rad (rounding)")
            else:
                ax.plot(z, c5, "-o", color=f"C{li}", ms=4,
                        label=rf"$l_b$ = {lb:g} m, $\varphi_{{bc}}$ = {pbc:.4g} rad")
    ax.set_xlabel("lateral offset of output shaft c $z_c$ [m]")
    ax.set_ylabel(r"$c_5$ = max|$\varphi_a-\varphi_c$ − mean| [rad]")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    ax.set_ylim(bottom=0.0)
    ax.set_title("Double coupler: input-output angle fluctuation $c_5$ (Eq 20)\n"
                 rf"$l_b$ middle-shaft length, $\varphi_{{bc}}$ angle between its platforms; "
                 rf"γ = {geo.get('gamma', math.nan):.4g} rad, $e_y$ = {geo.get('e_y', math.nan):g} m, "
                 f"R = {geo.get('R', math.nan):g} m\n(a missing point: no physical pose, shaft b would have to tilt "
                 "beyond what $e_y$ allows)", fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    ax.grid(True, alpha=0.3)
    return fig if fig is not None else ax


def fpp_figure(p: CouplerParams, phi_a: np.ndarray, u: np.ndarray, alpha_bx: float, alpha_bz: float) -> Figure:
    """The single-coupler pose over one revolution (`coupler fpp`): phi_a - phi_b - pi/2 and the centre O_b."""
    fig, axes = figure(2, 1, size=(8.0, 6.0), sharex=True)
    axes[0].plot(phi_a, phi_a - u[:, 0] - math.pi / 2, color="C0")
    axes[0].set_ylabel(r"$\varphi_a - \varphi_b - \pi/2$ [rad]")
    for k, name in ((1, "$x_b$"), (2, "$y_b$"), (3, "$z_b$")):
        axes[1].plot(phi_a, u[:, k], label=name)
    axes[1].set_ylabel("centre of platform B [m]")
    fig.legend(*axes[1].get_legend_handles_labels(), fontsize=8, loc="outside lower center", ncols=3)
    _phi_axis(axes[1])
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    fig.suptitle(f"Single coupler pose over one revolution: $α_{{bx}}$ = {alpha_bx:g} rad, $α_{{bz}}$ = "
                 f"{alpha_bz:g} rad, " + _geom(p), fontsize=9)
    axes[0].set_title(r"$\varphi_a$, $\varphi_b$ spin angles of shafts a, b; centre of platform B at "
                      "($x_b$, $e_y$ + $y_b$, $z_b$)", fontsize=9)
    return fig


_LABELS = {"torque_in": "input torque $T_{in}$ (servo on shaft a)", "torque_out": "load torque on shaft c"}


def dynamics_figure(res: Any) -> Figure:
    """Double-coupler dynamics run (`coupler dynamics`): input torque, output-angle error against the kinematic
    (rigid) solution, closure residual and link forces against time."""
    fig, axes = figure(4, 1, size=(9.0, 9.0), sharex=True)
    t = res.t
    s = res.signals
    panels = [
        (("torque_in", "torque_out"), "torque [N m]"),
        (("phi_c_err",), r"$\varphi_c - \varphi_{c,kin}$ [rad]"),
        (("closure_residual",), "closure residual [m]"),
        (tuple(k for k in s if k.startswith("link_force_")), "link force (tension > 0) [N]"),
    ]
    for ax, (keys, label) in zip(axes, panels, strict=True):
        drawn = [k for k in keys if k in s]
        for k in drawn:
            ax.plot(t, s[k], lw=0.8, label=_LABELS.get(k, k.replace("link_force_", "link ")))
        if not drawn:
            ax.text(0.5, 0.5, "not recorded by this scene", transform=ax.transAxes, ha="center", va="center")
        if len(drawn) > 1:
            ax.legend(fontsize=6, loc="upper right", ncols=4)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4))
    axes[-1].set_xlabel("time t [s]")
    sc = res.scene or {}
    inp = sc.get("input") or {}
    t0 = max(float((sc.get("solver") or {}).get("t_settle", 0.0)), float(inp.get("t_ramp", 0.0)))
    for ax in axes:
        ax.axvline(t0, color="k", lw=0.6, ls="--")
    axes[-1].annotate("statistics window →", (t0, 0.05), xycoords=("data", "axes fraction"), fontsize=7,
                      xytext=(3, 0), textcoords="offset points")
    axes[0].set_title(f"Double coupler {sc.get('model', 'coupler')}/{sc.get('name', '')} ({res.engine}): "
                      f"ω = {inp.get('omega', math.nan):.4g} rad/s, $T_{{load}}$ = "
                      f"{inp.get('load_torque', math.nan):.4g} N m\n"
                      r"$\varphi_{c,kin}$: output angle of the rigid mechanism at the same $\varphi_a$", fontsize=9)
    return fig


def figs678(p: CouplerParams, revs: list[dict], out: Path) -> list[Path]:
    """Write Figs 6-8 (fig6_phi_difference.png, fig7_centre_path.png, fig8_link_angles.png) of geometry `p` from the
    revolutions `revs` (`criteria.revolutions`)."""
    return [save(fig6(p, revs), out / "fig6_phi_difference.png"), save(fig7(p, revs), out / "fig7_centre_path.png"),
            save(fig8(p, revs), out / "fig8_link_angles.png")]
