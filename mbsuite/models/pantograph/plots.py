"""Figures in the style of the thesis: the frequency response (Fig 5-7) and time histories (Figs 5-1..5-6).

Plot functions return a `matplotlib.figure.Figure` (made with `mbsuite.plotting.figure`, no pyplot, no backend
chosen); write one with `mbsuite.plotting.save(fig, path)`. Symbols (defined on every figure):
IN = y_w, the ram (input) height; F1 = l1 sin(theta_1), the lower arm's share of the contact height; F2 = l2
sin(theta_2), the upper arm's; HD = lh sin(theta_h), the head's; y_d = F1 + F2 + HD, the contact-point height.
The figures draw only the data they are given (curves and runs come from `freqresp.py`).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from ...plotting import figure

THESIS_RESONANCES = (4.25, 8.75, 19.5)
COLORS = {"linear": "k", "reference": "tab:blue", "mujoco": "tab:orange", "mujoco_no_coulomb": "tab:green"}
STYLES = {"linear": "-", "reference": "o", "mujoco": "x", "mujoco_no_coulomb": "+"}
LABELS = {"linear": "linearisation about y_op + A (Coulomb off)", "reference": "hand-derived, event-exact friction",
          "mujoco": "MuJoCo (frictionloss)", "mujoco_no_coulomb": "MuJoCo, Coulomb friction off"}
SIGNAL_DOC = {"y_w": "IN = y_w: ram (input) height", "F1": "F1 = l1 sin(theta_1): lower arm",
              "F2": "F2 = l2 sin(theta_2): upper arm", "HD": "HD = lh sin(theta_h): head",
              "y_d": "y_d = F1 + F2 + HD: contact point"}
SYMBOLS = ("IN = y_w: ram (input) height;  F1 = l1 sin(theta_1), F2 = l2 sin(theta_2), HD = lh sin(theta_h): the "
           "heights the lower arm, upper arm and head add to the contact point;  y_d = F1 + F2 + HD: contact-point "
           "height.")


def plot_freqresp(freqs: np.ndarray, curves: Mapping[str, Mapping[str, np.ndarray]]) -> Figure:
    """Amplitude ratio |X|/|IN| and phase of X relative to IN of the fundamental at each forcing frequency, for
    X = F1, F2, HD, y_d and each method in `curves` (method -> signal -> complex ratio), with the thesis' simulated
    resonances (4.25, 8.75, 19.5 Hz) dotted."""
    fig, axes = figure(2, 4, size=(15, 7.0), sharex=True)
    for j, s in enumerate(("F1", "F2", "HD", "y_d")):
        for m, c in curves.items():
            kw = {"color": COLORS.get(m, "gray"), "label": LABELS.get(m, m)}
            fmt = STYLES.get(m, ".")
            mk = {} if fmt == "-" else {"ms": 4, "mfc": "none"}
            axes[0, j].plot(freqs, np.abs(c[s]), fmt, **kw, **mk)
            axes[1, j].plot(freqs, np.degrees(np.unwrap(np.angle(c[s]))), fmt, **kw, **mk)
        axes[0, j].set_title(SIGNAL_DOC[s], fontsize=9)
        axes[0, j].set_yscale("log")
        axes[0, j].set_ylabel(f"|{s}| / |IN| [m/m]")
        axes[1, j].set_ylabel(f"phase of {s} - phase of IN [deg]")
        axes[1, j].set_xlabel("forcing frequency [Hz]")
        for ax in axes[:, j]:
            ax.grid(True, alpha=0.3)
            for fr in THESIS_RESONANCES:
                ax.axvline(fr, color="gray", lw=0.6, ls=":")
    axes[0, 0].legend(fontsize=7, loc="lower left")
    fig.suptitle("Pantograph frequency response to the ram IN = y_op + A (1 - cos 2 pi f t) (dotted: the thesis' "
                 "simulated resonances 4.25 / 8.75 / 19.5 Hz)", fontsize=10)
    fig.text(0.5, 0.005, SYMBOLS, ha="center", va="bottom", fontsize=8, wrap=True)
    fig.get_layout_engine().set(rect=(0, 0.04, 1, 0.96))
    return fig


def plot_time_histories(runs: Mapping[float, object], window: float = 1.0) -> Figure:
    """The simulated counterparts of the thesis' Figs 5-1..5-6 as separate panels: one column per forcing frequency
    (`runs`: frequency -> SimResult with y_w, HD, F2, F1), one row per signal, each the deviation from its mean over
    the last `window` seconds (mm). The thesis' own curves are not drawn: the suite holds no digitised values of
    them (its resonances are compared in the frequency response, Fig 5-7)."""
    names = ("y_w", "HD", "F2", "F1")
    freqs = sorted(runs)
    fig, axes = figure(len(names), len(freqs), size=(2.6 * len(freqs) + 1.0, 8.0), sharex=True, squeeze=False)
    for col, f in enumerate(freqs):
        res = runs[f]
        t = np.asarray(res.t)
        mask = t >= t[-1] - window
        for row, name in enumerate(names):
            ax = axes[row, col]
            v = np.asarray(res[name])[mask]
            ax.plot(t[mask] - t[mask][0], 1e3 * (v - v.mean()), color=f"C{row}", lw=1.0)
            ax.grid(True, alpha=0.3)
            if row == 0:
                ax.set_title(f"{f:g} Hz", fontsize=10)
            if col == 0:
                ax.set_ylabel(f"{'IN' if name == 'y_w' else name} - mean [mm]")
            if row == len(names) - 1:
                ax.set_xlabel("time in the last second [s]")
    fig.suptitle("Simulated time responses (MuJoCo) at the forcing frequencies of the thesis' Figs 5-1..5-6, "
                 "deviations from the mean (the thesis' curves are not overlaid: no digitised values ship)",
                 fontsize=10)
    fig.text(0.5, 0.005, SYMBOLS, ha="center", va="bottom", fontsize=8, wrap=True)
    fig.get_layout_engine().set(rect=(0, 0.04, 1, 0.96))
    return fig

