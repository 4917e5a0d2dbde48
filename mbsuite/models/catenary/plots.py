"""The catenary's figures, drawn only from the runs they are given: contact force, wire height and steady-arm uplift
of single passages (`force_uplift_figure`), each pantograph's force and wire height on a train (`train_figure`). Both
mark the line the passage ran (`mesh.line_of(params)`, through `marks.line_marks`): its supports (grey lines), droppers
(brown ticks at the top of each panel), stitch wires (orange spans), the overlaps of two contact wires (cyan hatching)
and the contact wires' anchors (triangles), name the marks present in the x-axis label (`marks_legend`) and the line in
the title (`marks.line_label`)."""

from __future__ import annotations

import textwrap
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

    from .analysis import CatenaryRun
    from .params import CatenaryParams
    from .train import TrainRun

#: how the line's marks are drawn: supports, droppers (ticks at the top of a panel), stitch-wire spans, the overlaps of
#: two contact wires (hatched, unfilled: the statistics window's grey and a stitch wire's orange show through) and the
#: contact wires' anchors (triangles under the dropper ticks, in their wire's colour where the figure gives one)
SUPPORT_STYLE = {"color": "0.55", "lw": 0.6, "zorder": -1}
DROPPER_STYLE = {"color": "tab:brown", "lw": 0.5, "alpha": 0.6}
STITCH_STYLE = {"color": "tab:orange", "alpha": 0.12, "zorder": -2}
OVERLAP_STYLE = {"facecolor": "none", "edgecolor": "tab:cyan", "hatch": "//", "lw": 0.0, "alpha": 0.35, "zorder": -2}
ANCHOR_STYLE = {"marker": "v", "s": 36, "zorder": 4, "clip_on": False}
INSULATOR_STYLE = {"color": "tab:red", "alpha": 0.35, "lw": 0.0, "zorder": -1}
#: the further statistics windows (`params.windows`) at their edges
WINDOW_EDGE_STYLE = {"color": "0.35", "lw": 0.8, "ls": (0, (4, 3)), "zorder": -1}
ANCHOR_COLOUR = "k"
#: the colours of the lines: per dropper law (others: `OTHER_LAW`), per contact wire of a route (in the line's order,
#: `Line.contacts`), per pantograph of a train; none of them a mark's colour (grey, brown, orange, cyan)
LAW_COLOURS = {"slack": "tab:blue", "linear": "tab:red"}
OTHER_LAW = "tab:green"
WIRE_COLOURS = ("tab:purple", "tab:olive", "tab:pink", "navy")
PANTO_COLOURS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:olive", "tab:pink", "navy", "k")
#: the x-axis label's text for each kind of mark (`marks_legend` names those a figure shows)
MARKS_LEGEND = {"supports": "grey lines: supports", "droppers": "brown ticks: droppers",
                "stitch": "orange spans: stitch wires", "overlaps": "cyan hatching: overlap of two contact wires",
                "anchors": "triangles: anchors, {}", "insulators": "red bands: section insulators",
                "windows": "dashed lines: the edges of the further statistics windows"}
#: the x-axis label's width (characters) before it wraps
WRAP = 140


def marks_legend(x: str, m: dict[str, list]) -> str:
    """The x-axis label "`x` [m] (...)" naming the marks `m` (`marks.line_marks`) present, from `MARKS_LEGEND`: the
    anchors by wire and position ("triangles: anchors, contact_b at 300 m, contact_a at 480 m")."""
    parts = [MARKS_LEGEND[k] for k in ("supports", "droppers", "stitch", "overlaps", "insulators", "windows")
             if m.get(k)]
    if m.get("anchors"):
        parts.append(MARKS_LEGEND["anchors"].format(", ".join(f"{w} at {xa:g} m" for xa, w in m["anchors"])))
    if not parts:
        return f"{x} [m]"
    return "\n".join(textwrap.wrap(f"{x} [m] ({'; '.join(parts)})", width=WRAP))


def draw_line_marks(axes, p: CatenaryParams, wire_colours: dict[str, str] | None = None) -> dict[str, list]:
    """Mark the line of `p` on every axis of `axes` over the run [x_start, x_end] (`marks.line_marks`), the overlaps
    labelled "overlap" on the first axis, the anchors in their wire's colour (`wire_colours`: name -> colour; else
    `ANCHOR_COLOUR`); returns the marks drawn."""
    from .marks import line_marks
    from .mesh import line_of

    m = line_marks(line_of(p), (p.x_start, p.x_end))
    m["windows"] = sorted({float(e) for w in p.windows for e in w} - {p.window_start, p.window_end})
    colours = wire_colours or {}
    for k, ax in enumerate(axes):
        for xs in m["supports"]:
            ax.axvline(xs, **SUPPORT_STYLE)
        if m["droppers"]:
            ax.vlines(m["droppers"], 0.96, 1.0, transform=ax.get_xaxis_transform(), **DROPPER_STYLE)
        for a, b in m["stitch"]:
            ax.axvspan(a, b, **STITCH_STYLE)
        for a, b in m["overlaps"]:
            ax.axvspan(a, b, **OVERLAP_STYLE)
            if k == 0:
                ax.text(0.5 * (a + b), 0.93, "overlap", transform=ax.get_xaxis_transform(), ha="center", va="top",
                        fontsize=8, color="teal")
        for xa, w in m["anchors"]:
            ax.scatter([xa], [0.94], transform=ax.get_xaxis_transform(), color=colours.get(w, ANCHOR_COLOUR),
                       **ANCHOR_STYLE)
        for a, b, _ in m["insulators"]:
            ax.axvspan(a, b, **INSULATOR_STYLE)
        for xe in m["windows"]:
            ax.axvline(xe, **WINDOW_EDGE_STYLE)
    return m


def _arm_wire(line, name: str, x: float) -> str:
    """The contact wire of the uplift point `name` at `x` (`fe.arm_names`: "360_contact_a" where several contact
    wires have one at that support, else "360": the one contact wire there)."""
    head = f"{x:g}_"
    if name.startswith(head):
        return name[len(head):]
    return line.contacts[line.contacts_at(x)[0]].name


def force_uplift_figure(runs: list[CatenaryRun]) -> MplFigure:
    """Contact force (unfiltered and 20 Hz low-pass), contact-wire height at the contact point and uplift at the
    steady arms of the statistics window, against the pantograph position; one colour per dropper law, and on a route
    one per contact wire (its own force, its height under the head, the uplift at its steady arms; the head's summed
    force and the wire it meets in the law's colour); the window shaded, the line's marks (`draw_line_marks`)."""
    import numpy as np

    from ...plotting import figure
    from .marks import line_label, line_marks
    from .mesh import line_of

    p = runs[0].params
    line = line_of(p)
    route = any(r.result.wires for r in runs)
    wcol = {w.name: WIRE_COLOURS[i % len(WIRE_COLOURS)] for i, w in enumerate(line.contacts)} if route else {}
    anchors = {(round(xa, 9), w) for xa, w in line_marks(line, (p.x_start, p.x_end))["anchors"]}
    fig, axes = figure(3, 1, size=(11, 10), sharex=True)
    styles = ("-", "--", ":", "-.")
    ylim = (np.inf, -np.inf)
    for k, r in enumerate(runs):
        res = r.result
        c = LAW_COLOURS.get(r.dropper_law, OTHER_LAW)
        lab = f"{r.dropper_law} droppers"
        lw = 1.0 if k == 0 or not route else 0.6  # a route: a second law's per-wire lines thinner, same colours
        total = " (sum over the contact wires)" if res.wires else ""
        axes[0].plot(res.x, res.force, lw=0.4, alpha=0.4, color=c, label=f"{lab}: F{total}, unfiltered")
        axes[0].plot(res.x, r.filtered, lw=1.2, color=c, label=f"{lab}: F{total}, 20 Hz low-pass", zorder=3)
        if res.wires:
            axes[1].plot(res.x, 1000 * res.wire, lw=3.0, alpha=0.3, color=c, label=f"{lab}: the wire met (lowest)")
        else:
            axes[1].plot(res.x, 1000 * res.wire, lw=1.0, color=c, label=lab)
        for name, w in (res.wires or {}).items():  # a route's wires, each on its x-range
            on = np.asarray(w["on"], bool)
            axes[0].plot(res.x, np.where(on, w["force"], np.nan), lw=0.6 * lw, alpha=0.8, color=wcol.get(name, c),
                         label=f"{lab}: F on {name}, unfiltered")
            axes[1].plot(res.x, np.where(on, 1000 * w["wire"], np.nan), lw=lw, color=wcol.get(name, c),
                         label=f"{lab}: {name}")
        if res.wires:  # the heights of the wire met; a wire rising to its anchor leaves the panel
            lo, hi = float(np.nanmin(1000 * res.wire)), float(np.nanmax(1000 * res.wire))
            span = max(hi - lo, 1.0)
            ylim = (min(ylim[0], lo - 0.1 * span), max(ylim[1], hi + 0.5 * span))
            axes[1].set_ylim(*ylim)
        names = res.support_names or [f"{xs:g}" for xs in res.support_x]
        inside = [(j, float(xs), _arm_wire(line, names[j], float(xs))) for j, xs in enumerate(res.support_x)
                  if p.window_start <= xs <= p.window_end]
        inside = [(j, xs, w) for j, xs, w in inside if (round(xs, 9), w) not in anchors]  # pinned: uplift 0
        count: dict[str, int] = {}
        for j, xs, w in inside:
            n = count[w] = count.get(w, -1) + 1
            where = f" ({w})" if len(line.contacts) > 1 else ""
            axes[2].plot(res.x, 1000 * res.uplift[:, j], lw=lw, color=wcol.get(w, c), ls=styles[n % len(styles)],
                         label=f"{lab}: steady arm at {xs:g} m{where}")
    for ax in axes:
        ax.set_xlim(p.x_start, p.x_end)
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-3)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F [N]")
    axes[1].set_ylabel("contact-wire height at the\ncontact point [mm]")
    axes[2].set_ylabel("contact-wire uplift at\nthe steady arm [mm]")
    m = draw_line_marks(axes, p, wcol)
    axes[2].set_xlabel(marks_legend("pantograph position x", m))
    what = "EN 50318 reference scene" if runs[0].is_reference else "catenary passage"
    path = "" if runs[0].engine == "reference" else f" ({runs[0].engine} path)"
    axes[0].set_title(f"{what} on the {line_label(p)}, {runs[0].pantograph} pantograph{path}, "
                      f"{runs[0].speed_kmh:g} km/h;\nheights and uplift from the static state (grey: statistics "
                      "window)", fontsize=10)
    return fig


def train_figure(run: TrainRun, labels: list[str]) -> MplFigure:
    """Each pantograph's 20 Hz low-pass contact force and the contact-wire height at its contact point (on a route the
    lowest wire under it) against its own position, one colour per pantograph (`PANTO_COLOURS`); the statistics
    window shaded, the line's marks (`draw_line_marks`); `labels` names the pantographs."""
    from ...plotting import figure
    from .marks import line_label

    p = run.params
    fig, axes = figure(2, 1, size=(11, 7), sharex=True)
    for k, res in enumerate(run.results):
        c = PANTO_COLOURS[k % len(PANTO_COLOURS)]
        axes[0].plot(res.x, run.filtered[k], lw=1.0, color=c, label=f"{labels[k]}")
        axes[1].plot(res.x, 1000 * res.wire, lw=1.0, color=c, label=f"{labels[k]}")
    for ax in axes:
        ax.axvspan(p.window_start, p.window_end, color="0.9", zorder=-3)
        ax.set_xlim(p.x_start, p.x_end)
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0].set_ylabel("contact force F, 20 Hz low-pass [N]")
    axes[1].set_ylabel("contact-wire height at\nthe contact point [mm]")
    m = draw_line_marks(axes, p)
    axes[1].set_xlabel(marks_legend("each pantograph's own position x", m))
    axes[0].set_title(f"train of {len(run.names)} pantographs on the {line_label(p)}, {run.speed_kmh:g} km/h; wire "
                      "height from its static state (grey: statistics window)", fontsize=10)
    return fig
