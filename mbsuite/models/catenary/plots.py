"""The catenary's figures, drawn only from the runs they are given: contact force, wire height and steady-arm uplift
of single passages (`force_uplift_figure`), each pantograph's force and wire height on a train (`train_figure`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

    from .analysis import CatenaryRun
    from .train import TrainRun


def force_uplift_figure(runs: list[CatenaryRun]) -> MplFigure:
    """Contact force (unfiltered and 20 Hz low-pass), contact-wire height at the contact point and uplift at the
    steady arms of the statistics window, against the pantograph position; one colour per dropper law, the window
    shaded, the supports as vertical lines."""
    from ...plotting import figure

    p = runs[0].params
    fig, axes = figure(3, 1, size=(11, 10), sharex=True)
    colours = {"slack": "tab:blue", "linear": "tab:red"}
    styles = ("-", "--", ":", "-.")
    for r in runs:
        res = r.result
        c = colours.get(r.dropper_law, "tab:green")
        lab = f"{r.dropper_law} droppers"
        axes[0].plot(res.x, res.force, lw=0.4, alpha=0.4, color=c, label=f"{lab}: F, unfiltered")
        axes[0].plot(res.x, r.filtered, lw=1.2, color=c, label=f"{lab}: F, 20 Hz low-pass")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, color=c, label=lab)
        inside = [(j, xs) for j, xs in enumerate(res.support_x) if p.window_start <= xs <= p.window_end]
        for (j, xs), ls in zip(inside, (styles * len(inside))[:len(inside)], strict=True):
            axes[2].plot(res.x, 1000 * res.uplift[:, j], lw=1.0, color=c, ls=ls,
                         label=f"{lab}: steady arm at x = {xs:g} m")
    for ax in axes:
        ax.set_xlim(p.x_start, p.x_end)
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-1)
        for k in range(p.n_spans + 1):
            if p.x_start <= k * p.span_length <= p.x_end:
                ax.axvline(k * p.span_length, color="0.7", lw=0.5, zorder=-1)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F [N]")
    axes[1].set_ylabel("contact-wire height at the\ncontact point [mm]")
    axes[2].set_ylabel("contact-wire uplift at\nthe steady arm [mm]")
    axes[2].set_xlabel("pantograph position x [m] (thin vertical lines: supports)")
    what = "EN 50318 reference scene" if runs[0].is_reference else "catenary passage"
    path = "" if runs[0].engine == "reference" else f" ({runs[0].engine} path)"
    axes[0].set_title(f"{what}, {runs[0].pantograph} pantograph{path}, {runs[0].speed_kmh:g} km/h; heights and "
                      "uplift from the static state (grey: statistics window)", fontsize=10)
    return fig


def train_figure(run: TrainRun, labels: list[str]) -> MplFigure:
    """Each pantograph's 20 Hz low-pass contact force and the contact-wire height at its contact point against its
    own position (the statistics window shaded); `labels` names the pantographs."""
    from ...plotting import figure

    p = run.params
    fig, axes = figure(2, 1, size=(11, 7), sharex=True)
    for k, res in enumerate(run.results):
        axes[0].plot(res.x, run.filtered[k], lw=1.0, label=f"{labels[k]}")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, label=f"{labels[k]}")
    for ax in axes:
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-1)
        ax.set_xlim(p.x_start, p.x_end)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F, 20 Hz low-pass [N]")
    axes[1].set_ylabel("contact-wire height at\nthe contact point [mm]")
    axes[1].set_xlabel("each pantograph's own position x [m]")
    axes[0].set_title(f"train of {len(run.names)} pantographs, {run.speed_kmh:g} km/h; wire height from its static "
                      "state (grey: statistics window)", fontsize=10)
    return fig
