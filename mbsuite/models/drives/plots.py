"""Figures of the drives model, without pyplot: each function returns a `matplotlib.figure.Figure` made by
`mbsuite.plotting.figure` (or draws on the `Axes` it is given), so it works headless and in notebooks alike.

Symbols (as in the model's README and Oldaker 1997, Chapter 3): omega_m, omega_s, omega_l the motor, spring-end
(spring system) and load speeds; theta the spring twist; tau_l the load torque; eta = P_out / P_in the efficiency
(Eqs 3.21-3.24, corrected); Sr the switching rate (energy cycles per second).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from ...plotting import figure

#: readable names of the loss terms of `drive.energy_balance` (the keys of `losses`), with the symbol they integrate
LOSS_LABELS: dict[str, str] = {
    "viscous_motor": "motor viscous drag (B_m ω_m²)",
    "viscous_spring": "spring-system viscous drag (B_s ω_s²)",
    "viscous_load": "load viscous drag (B_l ω_l²)",
    "motor_bearing": "motor bearing Coulomb (C_m |ω_m|)",
    "spring_bearing": "spring-system bearing Coulomb (C_s |ω_s|)",
    "load_bearing": "load bearing Coulomb (C_l |ω_l|)",
    "brake": "brake slip (τ_b |ω_s|)",
    "clutch": "clutch slip (τ_c |ω_s − ω_l|)",
    "clutch_a": "input clutch a slip (τ_c1 |ω_m − ω_s|)",
    "clutch_b": "output clutch b slip (τ_c2 |ω_s − ω_l|)",
    "lock_impact": "plastic lock-up (kinetic energy removed)",
}


def loss_label(key: str) -> str:
    """The readable name of a loss term (its key when the model has no name for it)."""
    return LOSS_LABELS.get(key, key.replace("_", " "))


def _is_cycle_point(p: Mapping[str, Any]) -> bool:
    """A steady operating point: a finite switching rate (at least two energy cycles in the averaging window)."""
    sr = p.get("switching_rate")
    return sr is not None and math.isfinite(float(sr))


def efficiency_figure(points: Sequence[Mapping[str, Any]], title: str = "") -> Figure:
    """Efficiency eta = P_out / P_in against the steady load speed |omega_l| (left) and the mean loss powers at each
    operating point as stacked bars (right), both ordered by load speed.

    `points` are `analysis.efficiency_point` dicts. A point without a complete energy cycle in the averaging window
    (switching rate not defined: the drive stalled or never switched) is not an operating point of the curve: it is
    drawn as a separate marker, not joined to the line."""
    pts = sorted(points, key=lambda p: abs(p["load_speed"]))
    ok = [p for p in pts if _is_cycle_point(p)]
    stall = [p for p in pts if not _is_cycle_point(p)]
    fig, (ax0, ax1) = figure(1, 2, size=(12.0, 4.8), width_ratios=(1.0, 1.25))
    sp = [abs(p["load_speed"]) for p in ok]
    ax0.plot(sp, [100 * p["efficiency"] for p in ok], "o-", color="C0", label="operating points, by speed")
    for p in ok:
        ax0.annotate(f"τ_l = {p['tau_l']:.3g} N m", (abs(p["load_speed"]), 100 * p["efficiency"]), fontsize=7,
                     xytext=(4, 4), textcoords="offset points")
    if stall:
        ax0.plot([abs(p["load_speed"]) for p in stall], [100 * np.nan_to_num(p["efficiency"]) for p in stall], "x",
                 color="C3", ms=9, mew=2, label="not switching (no complete\nenergy cycle): not on the curve")
    ax0.set(xlabel="steady load speed |ω_l| [rad/s]", ylabel="efficiency η = P_out / P_in [%]",
            title="efficiency against load speed")
    ax0.set_ylim(bottom=0)
    ax0.grid(True, alpha=0.3)
    ax0.legend(fontsize=7, loc="lower left")

    keys = sorted({k for p in pts for k in p["losses_W"]},
                  key=lambda k: -sum(abs(p["losses_W"].get(k, 0.0)) for p in pts))  # largest loss at the bottom
    x = np.arange(len(pts))
    bottom = np.zeros(len(pts))
    for i, k in enumerate(keys):
        v = np.array([p["losses_W"].get(k, 0.0) for p in pts])
        if not np.any(np.abs(v) > 1e-9 * max(1.0, float(np.max(np.abs(bottom))))):
            continue  # a term that is zero at every point (e.g. no lock-up loss) adds only a legend entry
        ax1.bar(x, v, bottom=bottom, label=loss_label(k), color=f"C{i % 10}")
        bottom += v
    ax1.set_xticks(x, [f"{abs(p['load_speed']):.0f}" + ("*" if not _is_cycle_point(p) else "") for p in pts],
                   rotation=45)
    ax1.set(xlabel="steady load speed |ω_l| [rad/s]   (* = not switching: no complete energy cycle)",
            ylabel="mean loss power [W]",
            title="losses at each operating point (largest term at the bottom)")
    ax1.grid(True, axis="y", alpha=0.3)
    ax1.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    fig.suptitle(f"{title}: open-loop runs over load torques τ_l [N m], averages over the steady window"
                 if title else "open-loop runs over load torques τ_l [N m]", fontsize=10)
    return fig


#: the panels of a drive run: (signals, y label, legend names)
_RUN_PANELS: tuple[tuple[tuple[str, ...], str, dict[str, str]], ...] = (
    (("w_motor", "w_spring", "w_load"), "speed ω [rad/s]",
     {"w_motor": "motor ω_m", "w_spring": "spring end / spring system ω_s", "w_load": "load ω_l"}),
    (("extension",), "spring twist θ [rad]", {"extension": "spring twist θ"}),
    (("E_in", "E_out", "E_loss"), "energy [J]",
     {"E_in": "input ∫τ_m ω_m dt", "E_out": "output ∫τ_l |ω_l| dt", "E_loss": "losses (bearings, slip, lock-ups)"}),
    (("u_brake", "u_clutch", "u_clutch_a", "u_clutch_b"), "command (1 = on) [-]",
     {"u_brake": "brake", "u_clutch": "clutch", "u_clutch_a": "input clutch a", "u_clutch_b": "output clutch b"}),
)


def run_figure(res: Any) -> Figure:
    """Time histories of a drive run (`mbsuite.results.SimResult` of a step-up or step-up/step-down scene): the three
    speeds, the spring twist, the cumulative energies and the clutch/brake commands (after their delays). Other
    mechanisms (the Modelica examples) get `SimResult.plot()` (`SimResult.panels`: signals of one unit and comparable
    scale share a panel)."""
    panels = [(ks, lab, names) for ks, lab, names in _RUN_PANELS if any(k in res.signals for k in ks)]
    if not any("w_load" in ks for ks, _, _ in panels):
        return res.plot()
    sc = res.scene or {}
    mech = sc.get("effects", {}).get("mechanism", "")
    own = ({"w_spring": "spring end ω_s", "extension": "spring twist θ = θ_m − θ_s (Fig 3.3)"} if mech == "step_up"
           else {"w_spring": "spring system ω_s", "extension": "spring twist θ = θ_s (Fig 3.4)"})
    fig, axes = figure(len(panels), 1, size=(10.0, 1.6 + 2.0 * len(panels)), sharex=True, squeeze=False)
    for ax, (ks, lab, names) in zip(axes[:, 0], panels, strict=True):
        names = {**names, **{k: v for k, v in own.items() if k in names}}
        for k in ks:
            if k in res.signals:
                step = k.startswith("u_")
                (ax.step if step else ax.plot)(res.t, res.signals[k], lw=0.9, label=names[k],
                                               **({"where": "post"} if step else {}))
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    axes[-1, 0].set_xlabel("time t [s]")
    kind = {"step_up": "step-up", "step_up_down": "step-up/step-down"}.get(mech, mech)
    fig.suptitle(f"drives/{sc.get('name', '')}: {kind} drive, {res.engine} path", fontsize=10)
    return fig


def cadjs_figure(designs: Sequence[Mapping[str, Any]]) -> Figure:
    """CADJS families (Eqs 5.9-5.13 corrected): spring rate K, clutch torque tau_c, largest twist x_max and highest
    switching rate Sr_max against the spring-system inertia J_s, one line per minimum switching rate Sr_min."""
    fig, axes = figure(2, 2, size=(10.0, 6.5), sharex=True)
    panels = (("K", "spring rate K [N m/rad]"), ("tau_c", "clutch torque τ_c [N m]"),
              ("x_max", "largest spring twist x_max [rad]"), ("Sr_max", "highest switching rate Sr_max [1/s]"))
    srs = sorted({d["Sr_min"] for d in designs})
    for ax, (k, lab) in zip(axes.flat, panels, strict=True):
        for i, sr in enumerate(srs):
            ds = sorted((d for d in designs if d["Sr_min"] == sr), key=lambda d: d["J_s"])
            ax.plot([d["J_s"] for d in ds], [d[k] for d in ds], "o-", color=f"C{i}", ms=3,
                    label=f"Sr_min = {sr:g} 1/s")
        ax.set_ylabel(lab)
        ax.grid(True, alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("spring-system inertia J_s [kg m²]")
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("CADJS design families (Oldaker 1997, Eqs 5.9-5.13 corrected)", fontsize=10)
    return fig


def design_tables_figure(rows: Sequence[Mapping[str, Any]]) -> Figure:
    """Relative difference [%] of our Chapter 5 design numbers from the thesis' printed Tables 5.2 and 6.2 and
    controller gains (`rows`: dicts with `label`, `ours`, `thesis`)."""
    fig, ax = figure(1, 1, size=(9.0, 0.25 * len(rows) + 1.6))
    diff = [100 * (r["ours"] / r["thesis"] - 1) for r in rows]
    y = np.arange(len(rows))
    ax.barh(y, diff, color=["C3" if abs(d) > 3 else "C0" for d in diff])
    ax.set_yticks(y, [r["label"] for r in rows], fontsize=7)
    ax.invert_yaxis()
    ax.axvline(0, color="k", lw=0.6)
    for s in (-3, 3):
        ax.axvline(s, color="0.5", lw=0.6, ls="--")
    ax.set(xlabel="(ours / thesis − 1) [%]   (dashed: ±3 %)",
           title="design tools against the thesis' Tables 5.2, 6.2 and gains (Sec. 5.4, Eq 6.1)")
    ax.grid(True, axis="x", alpha=0.3)
    return fig
