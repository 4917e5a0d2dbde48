"""The catenary's figures, drawn only from the runs they are given: contact force, wire height and steady-arm uplift
of single passages (`force_uplift_figure`), each pantograph's force and wire height on a train (`train_figure`). Both
mark the line the passage ran (`mesh.line_of(params)`, through `marks.line_marks`): its supports (grey lines), droppers
(ticks at the top of each panel) and stitch wires (shaded spans), and name it in the title (`marks.line_label`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

    from .analysis import CatenaryRun
    from .params import CatenaryParams
    from .train import TrainRun

#: how the line's marks are drawn: supports, droppers (ticks at the top of a panel), stitch-wire spans
SUPPORT_STYLE = {"color": "0.55", "lw": 0.6, "zorder": -1}
DROPPER_STYLE = {"color": "tab:brown", "lw": 0.5, "alpha": 0.6}
STITCH_STYLE = {"color": "tab:orange", "alpha": 0.12, "zorder": -2}


def draw_line_marks(axes, p: CatenaryParams) -> dict[str, list]:
    """Mark the line of `p` on every axis of `axes` over the run [x_start, x_end] (`marks.line_marks`); returns the
    marks drawn."""
    from .marks import line_marks
    from .mesh import line_of

    m = line_marks(line_of(p), (p.x_start, p.x_end))
    for ax in axes:
        for xs in m["supports"]:
            ax.axvline(xs, **SUPPORT_STYLE)
        if m["droppers"]:
            ax.vlines(m["droppers"], 0.96, 1.0, transform=ax.get_xaxis_transform(), **DROPPER_STYLE)
        for a, b in m["stitch"]:
            ax.axvspan(a, b, **STITCH_STYLE)
    return m


#: the x-axis label naming the marks
MARKS_LEGEND = "{x} [m] (grey lines: supports; brown ticks: droppers; orange: stitch wires)"


def force_uplift_figure(runs: list[CatenaryRun]) -> MplFigure:
    """Contact force (unfiltered and 20 Hz low-pass), contact-wire height at the contact point and uplift at the
    steady arms of the statistics window, against the pantograph position; one colour per dropper law, the window
    shaded, the supports as vertical lines."""
    from ...plotting import figure
    from .marks import line_label

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
        for (name, w), ls in zip((res.wires or {}).items(), (":", "-.", "--"), strict=False):  # a route's wires
            axes[0].plot(res.x, w["force"], lw=0.6, ls=ls, color="0.3", label=f"{lab}: F on {name}, unfiltered")
        names = res.support_names or [f"{xs:g}" for xs in res.support_x]
        inside = [(j, names[j]) for j, xs in enumerate(res.support_x) if p.window_start <= xs <= p.window_end]
        for (j, name), ls in zip(inside, (styles * len(inside))[:len(inside)], strict=True):
            axes[2].plot(res.x, 1000 * res.uplift[:, j], lw=1.0, color=c, ls=ls,
                         label=f"{lab}: steady arm at x = {name} m")
    for ax in axes:
        ax.set_xlim(p.x_start, p.x_end)
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-3)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F [N]")
    axes[1].set_ylabel("contact-wire height at the\ncontact point [mm]")
    axes[2].set_ylabel("contact-wire uplift at\nthe steady arm [mm]")
    draw_line_marks(axes, p)
    axes[2].set_xlabel(MARKS_LEGEND.format(x="pantograph position x"))
    what = "EN 50318 reference scene" if runs[0].is_reference else "catenary passage"
    path = "" if runs[0].engine == "reference" else f" ({runs[0].engine} path)"
    axes[0].set_title(f"{what} on the {line_label(p)}, {runs[0].pantograph} pantograph{path}, "
                      f"{runs[0].speed_kmh:g} km/h;\nheights and uplift from the static state (grey: statistics "
                      "window)", fontsize=10)
    return fig


def train_figure(run: TrainRun, labels: list[str]) -> MplFigure:
    """Each pantograph's 20 Hz low-pass contact force and the contact-wire height at its contact point against its
    own position (the statistics window shaded); `labels` names the pantographs."""
    from ...plotting import figure
    from .marks import line_label

    p = run.params
    fig, axes = figure(2, 1, size=(11, 7), sharex=True)
    for k, res in enumerate(run.results):
        axes[0].plot(res.x, run.filtered[k], lw=1.0, label=f"{labels[k]}")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, label=f"{labels[k]}")
    for ax in axes:
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-3)
        ax.set_xlim(p.x_start, p.x_end)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F, 20 Hz low-pass [N]")
    axes[1].set_ylabel("contact-wire height at\nthe contact point [mm]")
    draw_line_marks(axes, p)
    axes[1].set_xlabel(MARKS_LEGEND.format(x="each pantograph's own position x"))
    axes[0].set_title(f"train of {len(run.names)} pantographs on the {line_label(p)}, {run.speed_kmh:g} km/h; wire "
                      "height from its static state (grey: statistics window)", fontsize=10)
    return fig
