"""Design sweeps of a pantograph under the catenary: speed x design-parameter grids through mbsuite's sweep API.

    grid = design_grid(scene, speeds=[150, 200, 250, 300, 320], vary={"m1": [5.4, 7.2, 9.0, 10.8],
                                                                     "F0": [100.0, 140.0]}, workers=2)
    plot_grid(grid, "out/design")      # sigma/Fm, statistical minimum and contact loss over the grid, per panel

Every point is one passage of the scene (`run_scene`, or `run_train_scene` for a `[train]` scene: the statistics of
its last pantograph) with the scene's parameters overridden by the point's values (names of `CatenaryParams`); it
returns the eight statistics, sigma/Fm and the quality verdicts (`quality.assess`, limits from the scene's
`[quality]` section). Points run through `mbsuite.analysis.sweep.run_sweep` (process pool by default, a Dask cluster
or a resumable store as that API offers); the compiled step core makes one point of the reference scene about 1.2 s
of CPU.
"""

from __future__ import annotations

import dataclasses
import itertools
import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import ParameterError
from ...limits import Limit, limit_of
from ...schema import Items, Section
from .params import CatenaryParams

if TYPE_CHECKING:
    from matplotlib.figure import Figure as MplFigure

#: statistics each point returns (besides sigma/Fm and the verdicts)
POINT_STATS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm", "loss_pct")


def evaluate(job: tuple[dict, float, dict[str, float]]) -> dict[str, Any]:
    """One grid point: `job = (scene dict, speed km/h, {parameter: value})`. Module-level so it pickles to any
    executor. Speeds above the EN 50119 limit are run (the regime is returned), not warned about in the workers."""
    import time

    from ...scenes import scene_from_dict
    from .analysis import run_scene, run_train_scene
    from .config import CriticalSpeedWarning, speed_regime
    from .quality import assess, criteria_from

    c0 = time.process_time()
    scene_d, speed, values = job
    scene = scene_from_dict(scene_d)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalSpeedWarning)
        if "train" in scene.sections:
            run = run_train_scene(scene, speed_kmh=speed, **values)
            stats, dt = run.stats[-1], run.dt
        else:
            run = run_scene(scene, speed_kmh=speed, **values)
            stats, dt = run.stats, run.dt
        regime = speed_regime(run.params, speed / 3.6)
    q = assess(stats, speed, criteria_from(scene.sections.get("quality")), stats["n_samples_window"] * dt)
    out = {k: float(stats[k]) for k in POINT_STATS}
    out.update({"speed_kmh": float(speed), **{k: float(v) for k, v in values.items()},
                "sigma_over_Fm": float(stats["sigma"] / stats["Fm"]) if stats["Fm"] > 0 else float("inf"),
                "quality_pass": bool(q["pass"]), "speed_ratio": float(regime["speed_ratio"]),
                "cpu_s": time.process_time() - c0,
                **{f"{k}_pass": bool(r["pass"]) for k, r in q["rows"].items()}})
    return out


def _as_list(v: Any) -> Any:
    """A numpy array or range as the list it holds (anything else as given, for the declaration to check)."""
    return v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, range) else v


#: the inputs of a design grid: speeds (km/h) and, per varied `CatenaryParams` field, its values (that field's range)
GRID_INPUTS = Section("catenary design grid", {
    "speeds": Items(Limit(lo=0.0, hi=1000.0, lo_open=True, hi_open=True, unit="km/h", doc="train speed"), min=1,
                    unit="km/h", doc="train speeds"),
    "vary": Section("varied catenary parameters", {
        f.name: Items(f.metadata["limit"].optional(), min=1, unit=f.metadata["limit"].unit, doc=f.metadata["limit"].doc)
        for f in dataclasses.fields(CatenaryParams) if "limit" in f.metadata},
        doc="parameter name = list of values (a CatenaryParams field)"),
}, required=("speeds", "vary"))


def design_grid(scene, speeds: Sequence[float], vary: Mapping[str, Sequence[float]], *, workers: int = 0,
                progress: bool | None = None, **sweep_kw: Any) -> dict[str, Any]:
    """Evaluate the grid speeds x vary[name1] x vary[name2] ... (`evaluate` at each point) with `run_sweep`;
    `sweep_kw` goes to `run_sweep` (executor, scheduler, store, max_points). Parameter names are `CatenaryParams`
    fields; every combination is validated before anything runs (a bad value is a `ParameterError` naming it)."""
    from ...analysis.sweep import run_sweep

    checked = GRID_INPUTS.check({"speeds": _as_list(speeds),
                                 "vary": {k: _as_list(v) for k, v in vary.items()} if isinstance(vary, Mapping)
                                 else vary}, "the catenary design grid", ParameterError)
    speeds, vary = checked["speeds"], {k: checked["vary"][k] for k in vary}  # the caller's order: the plot's axes
    names = list(vary)
    base = scene.build_params()
    combos = list(itertools.product(*[list(vary[n]) for n in names])) if names else [()]
    for c in combos:  # validate every design before any passage runs
        dataclasses.replace(base, **dict(zip(names, c, strict=True)))
    scene_d = scene.to_dict()
    points = [(scene_d, float(v), dict(zip(names, c, strict=True))) for v in speeds for c in combos]
    from .native_core import library

    library()  # compile/load the core once before the pool forks
    results = run_sweep(evaluate, points, workers=workers, progress=progress, desc="catenary design grid",
                        **sweep_kw)
    return {"speeds": [float(v) for v in speeds], "vary": {n: [float(x) for x in vary[n]] for n in names},
            "points": results, "resolution": resolution(scene)}


def resolution(scene) -> dict[str, float]:
    """The element length (m) and time step (s) every point of the scene's grid runs at: the statistics' accuracy
    follows from them (`accuracy.py`; `mbsuite catenary SCENE --error-estimate` estimates it for one point)."""
    return {"element_length": float(scene.build_params().element_length), "timestep": float(scene.solver.timestep)}


def plot_grid(grid: dict[str, Any], out: str | Path) -> list[Path]:
    """Write `grid_figure(grid)` as `design_grid.png` in `out`; returns the written PNG path(s)."""
    from ...plotting import save

    return [save(grid_figure(grid), Path(out) / "design_grid.png")]


def grid_figure(grid: dict[str, Any]) -> MplFigure:
    """σ/Fm, the statistical minimum Fm − 3σ and the contact loss over speed (x) and the first varied parameter (y),
    one row of panels per value of the other varied parameters; red numbers fail that criterion (EN 50367 limits:
    σ ≤ 0.3 Fm, Fm − 3σ > 0, no contact loss)."""
    from ...plotting import figure

    names = list(grid["vary"])
    speeds = grid["speeds"]
    ynames = names[:1]
    yvals = grid["vary"][ynames[0]] if ynames else [0.0]
    rest = names[1:]
    rest_combos = list(itertools.product(*[grid["vary"][n] for n in rest])) if rest else [()]
    idx = {}
    for pt in grid["points"]:
        key = (pt["speed_kmh"], pt[ynames[0]] if ynames else 0.0, tuple(pt[n] for n in rest))
        idx[key] = pt
    panels = (("sigma_over_Fm", "σ / Fm [-] (limit 0.3)", "sigma_pass"),
              ("stat_min", "Fm − 3σ [N] (must be > 0)", "stat_min_pass"),
              ("loss_pct", "contact loss [%] (must be 0)", "contact_loss_pass"))
    fig, axes = figure(len(rest_combos), 3, size=(15, 3.8 * len(rest_combos)), squeeze=False)
    for r, rc in enumerate(rest_combos):
        for c, (key, title, verdict) in enumerate(panels):
            ax = axes[r][c]
            Z = np.array([[idx[(v, y, rc)][key] for v in speeds] for y in yvals])
            bad = np.array([[not idx[(v, y, rc)][verdict] for v in speeds] for y in yvals])
            im = ax.pcolormesh(np.arange(len(speeds) + 1), np.arange(len(yvals) + 1), Z, shading="flat",
                               cmap="viridis")
            for (i, j), b in np.ndenumerate(bad):
                ax.text(j + 0.5, i + 0.5, f"{Z[i, j]:.3g}", ha="center", va="center", fontsize=7,
                        color="red" if b else "white", fontweight="bold" if b else "normal")
            ax.set_xticks(np.arange(len(speeds)) + 0.5, [f"{v:g}" for v in speeds])
            ax.set_yticks(np.arange(len(yvals)) + 0.5, [f"{y:g}" for y in yvals])
            ax.set_xlabel("train speed v [km/h]")
            ax.set_ylabel(_axis_label(ynames[0]) if ynames else "")
            sub = ", ".join(f"{n} = {v:g} {_unit(n)}".rstrip() for n, v in zip(rest, rc, strict=True))
            ax.set_title(f"{title}{'; ' + sub if sub else ''}\n(red numbers fail)", fontsize=9)
            fig.colorbar(im, ax=ax)
    res = grid.get("resolution")
    if res:
        fig.suptitle(f"every point at element length {res['element_length']:g} m, time step {res['timestep']:g} s",
                     fontsize=9)
    return fig


def _unit(name: str) -> str:
    try:
        return limit_of(CatenaryParams, name).unit or ""
    except Exception:  # noqa: BLE001 - a name without a declared unit gets none
        return ""


def _axis_label(name: str) -> str:
    try:
        doc = limit_of(CatenaryParams, name).doc or name
    except Exception:  # noqa: BLE001
        doc = name
    unit = _unit(name)
    return f"{name}: {doc}" + (f" [{unit}]" if unit else "")
