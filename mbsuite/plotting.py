"""Figures without pyplot: every plot function of mbsuite draws on a `matplotlib.axes.Axes` it is given, or returns a
`matplotlib.figure.Figure` it made itself. Nothing here selects a backend or touches pyplot's global state, so the
same functions work headless, in scripts and in notebooks (where `display(fig)` or `fig` shows the figure)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def figure(nrows: int = 1, ncols: int = 1, *, size: tuple[float, float] = (8.0, 5.0), **kw: Any) -> tuple[Figure, Any]:
    """A new figure and its axes (`Figure.subplots`), attached to no pyplot window."""
    from matplotlib.figure import Figure  # here, not at import: a command that draws nothing does not pay for it

    fig = Figure(figsize=size, layout="constrained")
    return fig, fig.subplots(nrows, ncols, **kw)


def save(fig: Figure, path: str | Path, dpi: int = 110) -> Path:
    """Write `fig` (PNG by the suffix) and return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    return path
