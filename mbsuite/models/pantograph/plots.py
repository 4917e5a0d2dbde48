"""Plots in the style of the thesis: time histories (Figs 5-1..5-6) and the frequency-response plot (Fig 5-7)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

THESIS_FREQS = (2.0, 3.5, 4.5, 6.5, 8.5, 10.0)
COLORS = {"linear": "k", "reference": "tab:blue", "mujoco": "tab:orange", "mujoco_no_coulomb": "tab:green"}
STYLES = {"linear": "-", "reference": "o", "mujoco": "x", "mujoco_no_coulomb": "+"}


def plot_freqresp(path: Path, freqs: np.ndarray, curves: dict[str, dict[str, np.ndarray]]) -> Path:
    fig, axes = plt.subplots(2, 4, figsize=(15, 6.5), sharex=True)
    for j, s in enumerate(("F1", "F2", "HD", "y_d")):
        for m, c in curves.items():
            kw = {"color": COLORS.get(m, "gray"), "label": m}
            if STYLES[m] == "-":
                axes[0, j].plot(freqs, np.abs(c[s]), "-", **kw)
                axes[1, j].plot(freqs, np.degrees(np.unwrap(np.angle(c[s]))), "-", **kw)
            else:
                axes[0, j].plot(freqs, np.abs(c[s]), STYLES[m], ms=4, mfc="none", **kw)
                axes[1, j].plot(freqs, np.degrees(np.unwrap(np.angle(c[s]))), STYLES[m], ms=4, mfc="none", **kw)
        axes[0, j].set_title(f"{s} / IN")
        axes[0, j].set_yscale("log")
        axes[1, j].set_xlabel("frequency (Hz)")
        for ax in axes[:, j]:
            ax.grid(True, alpha=0.3)
            for fr in (4.25, 8.75, 19.5):
                ax.axvline(fr, color="gray", lw=0.6, ls=":")
    axes[0, 0].set_ylabel("amplitude ratio (-)")
    axes[1, 0].set_ylabel("phase (deg)")
    axes[0, 0].legend()
    fig.suptitle("Pantograph frequency response (dotted: thesis' simulated resonances 4.25 / 8.75 / 19.5 Hz)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_time_histories(out: Path, scene, freqs: tuple[float, ...] = THESIS_FREQS) -> list[Path]:
    """Fig 5-1..5-6 style: IN, HD, F2, F1 (deviations from the static values, offset) over the last second."""
    from .analysis import run

    files = []
    fig, axes = plt.subplots(2, 3, figsize=(14, 7))
    for ax, f in zip(axes.flat, freqs, strict=True):
        sc = scene.replace(input={"type": "sine", "frequency": f}, solver={"engine": "mujoco"},
                           outputs=["y_w", "HD", "F2", "F1"])
        res = run(sc)
        t = res.t
        mask = t >= t[-1] - 1.0
        for k, (name, lab) in enumerate((("y_w", "IN"), ("HD", "HD"), ("F2", "F2"), ("F1", "F1"))):
            v = res[name][mask]
            ax.plot(t[mask] - t[mask][0], 1e3 * (v - v.mean()) - 8.0 * k, label=lab)
        ax.set_title(f"{f:g} Hz")
        ax.set_xlabel("time (s)")
        ax.set_ylabel("displacement (mm, offset)")
        ax.grid(True, alpha=0.3)
    axes.flat[0].legend(loc="upper right", fontsize=8)
    fig.suptitle("Simulated time responses (MuJoCo), curves offset by 8 mm as in Figs 5-1..5-6")
    fig.tight_layout()
    p = out / "time_histories.png"
    fig.savefig(p, dpi=110)
    plt.close(fig)
    files.append(p)
    return files
