"""Plots in the style of the seed's Figs 6-10 (matplotlib, Agg backend, PNG)."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .params import CouplerParams  # noqa: E402

FIG_ALPHAS = (0.0175, 0.035, 0.0525)  # seed Figs 6-8


def _save(fig, path: Path) -> list[Path]:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return [path]


def fig9(rows: list[dict], path: Path) -> list[Path]:
    """c1-c4 vs alpha_b, one colour per gamma, one line style per e_y (Fig 9)."""
    fig, axs = plt.subplots(2, 2, figsize=(10, 7))
    gammas = sorted({r["gamma"] for r in rows})
    eys = sorted({r["e_y"] for r in rows})
    styles = ["-", "--", ":", "-."]
    for ax, key, unit in zip(axs.flat, ("c1", "c2", "c3", "c4"), ("rad", "-", "rad", "rad"), strict=True):
        for gi, g in enumerate(gammas):
            for ei, ey in enumerate(eys):
                sel = [r for r in rows if r["gamma"] == g and r["e_y"] == ey]
                ax.plot([r["alpha_b"] for r in sel], [r[key] for r in sel], styles[ei % 4], color=f"C{gi}",
                        label=f"gamma={g:g}, e_y={ey:g}")
        ax.set_xlabel("alpha_b [rad]")
        ax.set_ylabel(f"{key} [{unit}]")
        ax.grid(True, alpha=0.3)
    axs[0, 0].legend(fontsize=7)
    return _save(fig, path)


def fig10(rows: list[dict], path: Path) -> list[Path]:
    """c5 vs z_c for l_b and phi_bc (Fig 10)."""
    fig, ax = plt.subplots(figsize=(7, 4.5))
    lbs = sorted({r["l_b"] for r in rows})
    pbcs = sorted({r["phi_bc"] for r in rows})
    for li, lb in enumerate(lbs):
        for pi_, pbc in enumerate(pbcs):
            sel = [r for r in rows if r["l_b"] == lb and r["phi_bc"] == pbc]
            ax.plot([r["z_c"] for r in sel], [r["c5"] for r in sel], ["-o", "--s"][pi_ % 2], color=f"C{li}", ms=3,
                    label=f"l_b={lb:g}, phi_bc={pbc:.3g}")
    ax.set_xlabel("z_c [R]")
    ax.set_ylabel("c5 [rad]")
    ax.set_yscale("symlog", linthresh=1e-12)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    return _save(fig, path)


def figs678(p: CouplerParams, out: Path) -> list[Path]:
    """Figs 6-8: phi_a - phi_b, the path of O_b in the xz-plane and the link angles over a revolution."""
    from .analysis import single_criteria

    res = [single_criteria(p, a, 181) for a in FIG_ALPHAS]
    f6, ax = plt.subplots(figsize=(7, 4))
    for a, c in zip(FIG_ALPHAS, res, strict=True):
        rev = c["rev"]
        ax.plot(rev.phi_a, rev.phi_a - rev.u[:, 0], label=f"alpha_b={a:g}")
    ax.axhline(math.pi / 2, color="k", lw=0.5)
    ax.set_xlabel("phi_a [rad]")
    ax.set_ylabel("phi_a - phi_b [rad]")
    ax.legend()
    ax.grid(True, alpha=0.3)
    files = _save(f6, out / "fig6_phi_difference.png")
    f7, ax = plt.subplots(figsize=(5, 5))
    for a, c in zip(FIG_ALPHAS, res, strict=True):
        ax.plot(c["rev"].u[:, 1], c["rev"].u[:, 3], label=f"alpha_b={a:g}")
    ax.set_aspect("equal")
    ax.set_xlabel("x_b [R]")
    ax.set_ylabel("z_b [R]")
    ax.legend()
    ax.grid(True, alpha=0.3)
    files += _save(f7, out / "fig7_centre_path.png")
    f8, axs = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    for a, c in zip(FIG_ALPHAS, res, strict=True):
        axs[0].plot(c["rev"].phi_a, np.degrees(c["dbeta1"][:, 4]), label=f"alpha_b={a:g}")
        axs[1].plot(c["rev"].phi_a, np.degrees(c["dbeta2"][:, 4]), label=f"alpha_b={a:g}")
    axs[0].set_ylabel("beta1 - beta1_0 [deg] (link 1, end B)")
    axs[1].set_ylabel("beta2 - beta2_0 [deg] (link 1, end B)")
    axs[1].set_xlabel("phi_a [rad]")
    axs[0].legend()
    for ax in axs:
        ax.grid(True, alpha=0.3)
    files += _save(f8, out / "fig8_link_angles.png")
    return files
