"""Figures of the rotational model, without pyplot: each function returns a `matplotlib.figure.Figure` made by
`mbsuite.plotting.figure`, so it works headless and in notebooks alike."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from ...plotting import figure


def coupled_clutches_figure(table: Mapping[str, Any], ref_t: np.ndarray, ref_w: np.ndarray) -> Figure:
    """CoupledClutches: the speeds w1..w4 of the four inertias J1..J4 [rad/s] of the Dymola reference (lines) with the
    hand path and MuJoCo on the 0.1 s grid (markers), and the differences on that grid (lower panel). `table` is
    `analysis.coupled_clutches_table()`; `ref_t`, `ref_w` the reference series (`coupled_clutches.load_reference()`)."""
    fig, (ax0, ax1) = figure(2, 1, size=(10.0, 7.0), sharex=True, height_ratios=(2.0, 1.0))
    grid = np.asarray(table["grid"])
    w_ref = np.asarray(table["w_ref"])
    for i in range(4):
        ax0.plot(ref_t, ref_w[i], color=f"C{i}", lw=1.0, label=f"w{i + 1} = speed of J{i + 1}, Dymola reference")
        for eng, mk in (("reference", "o"), ("mujoco", "+")):
            if eng in table:
                ax0.plot(grid, np.asarray(table[eng]["w"])[:, i], mk, color=f"C{i}", ms=5, mfc="none")
    for e in table.get("reference_events", []):
        ax0.axvline(e["t"], color="0.6", lw=0.6, ls=":")
    ax0.plot([], [], "ko", mfc="none", label="hand path (every 0.1 s)")
    ax0.plot([], [], "k+", label="MuJoCo (every 0.1 s)")
    ax0.plot([], [], color="0.6", ls=":", label="clutch mode changes (reference)")
    ax0.set(ylabel="speed w [rad/s]", title="Modelica CoupledClutches: J1 -clutch1- J2 -clutch2- J3 -clutch3- J4")
    ax0.grid(True, alpha=0.3)
    ax0.legend(fontsize=7, ncol=2, loc="upper right")
    for eng, lab, base in (("reference", "hand path − Dymola", w_ref), ("mujoco", "MuJoCo − hand path", None)):
        if eng not in table:
            continue
        b = base if base is not None else np.asarray(table["reference"]["w"])
        dev = np.max(np.abs(np.asarray(table[eng]["w"]) - b), axis=1)
        keep = dev > 0  # exact zeros (the common initial state at t = 0) have no place on a log axis
        ax1.semilogy(grid[keep], dev[keep], "o-" if eng == "reference" else "+-", label=lab)
    ax1.set(xlabel="time t [s]", ylabel="max over w1..w4 of |Δw| [rad/s]",
            title="differences on the 0.1 s grid (exact zeros, e.g. the common initial state, not drawn)")
    ax1.grid(True, which="both", alpha=0.3)
    ax1.legend(fontsize=7)
    return fig
