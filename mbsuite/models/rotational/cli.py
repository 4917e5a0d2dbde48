"""The `rotational` command group: `mbsuite rotational coupled-clutches`, Modelica's CoupledClutches on both paths
against the Modelica Association's Dymola result (a table with units; `--out DIR` writes CSV with SI units in the
header, the comparison figure and summary.json)."""

from __future__ import annotations

import argparse
import math
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from ...cli.options import add_error_estimate, add_scene_options
from ...errors import MbsuiteError
from ...limits import Limit
from ...settings import DEFAULT_MAX_STEPS
from ...trust.health import judge_estimate

if TYPE_CHECKING:  # numpy, the results and the scenes where the command runs: its --help loads none of them
    import numpy as np

#: the commands `register` adds (read by the command line's light parser without importing the model)
CLI_COMMANDS = {"rotational": "Modelica Rotational examples: CoupledClutches on both paths vs the Dymola reference"}

#: most time steps of `rotational coupled-clutches` (scene runs are guarded by the scene's solver.max_steps)
MAX_STEPS = DEFAULT_MAX_STEPS
#: valid range of `--timestep`, checked before any work
TIMESTEP = Limit(lo=0.0, lo_open=True, hi=1e-2, unit="s", doc="MuJoCo timestep")


def register(sub, add_common, emit) -> str:
    """Add the `rotational` command group to the top-level parser; returns the group's command name."""
    p = sub.add_parser("rotational", help=CLI_COMMANDS["rotational"])
    rsub = p.add_subparsers(dest="rotational_command", required=True)
    q = rsub.add_parser("coupled-clutches", help="Modelica CoupledClutches: both paths vs the Dymola reference")
    q.add_argument("--timestep", type=float, default=1e-4, help="MuJoCo step (s; the scene's default)")
    add_scene_options(q)
    add_error_estimate(q)
    add_common(q)
    q.set_defaults(func=partial(coupled_clutches_cmd, emit))
    return "rotational"


def _check_steps(flag: str, duration: float, dt: float) -> None:
    """Size guard: duration / dt time steps at most MAX_STEPS."""
    n = duration / dt
    if n > MAX_STEPS:
        raise MbsuiteError(f"{flag}: {duration:g} s at a step of {dt:g} s is {n:.3g} steps; at most {MAX_STEPS:.3g} "
                           "(shorten the run or enlarge the step)")


def _solver_options(sc, a: argparse.Namespace):
    """The scene with `--allow-inaccurate` and `--max-steps` applied (`mbsuite.cli.options.add_scene_options`)."""
    upd = {}
    if getattr(a, "allow_inaccurate", False):
        upd["allow_inaccurate"] = True
    if getattr(a, "max_steps", None) is not None:
        upd["max_steps"] = a.max_steps
    return sc.replace(solver=upd) if upd else sc


def _options(a: argparse.Namespace) -> dict:
    """The options as given (None: not given): with the scene, what reruns it."""
    return {flag: getattr(a, flag[2:].replace("-", "_")) for flag in (
        "--timestep", "--error-estimate", "--allow-inaccurate", "--max-steps")
        if hasattr(a, flag[2:].replace("-", "_"))}


def _e(x: float | None) -> str:
    """A small difference for a table: 3 significant digits in exponent form, '-' for none."""
    return "-" if x is None else f"{x:.2e}"


def _nan(x: float | None) -> float:
    return math.nan if x is None else float(x)


def coupled_clutches_cmd(emit, a: argparse.Namespace) -> None:
    """`rotational coupled-clutches`: both paths against the Dymola reference (`analysis.coupled_clutches_table`)."""
    import numpy as np

    from ...results import Report, format_table
    from ...scenes import load_scene
    from . import coupled_clutches as cc  # here, not at parse time (the command's help imports no engine)
    from .analysis import coupled_clutches_table

    TIMESTEP.check("--timestep", a.timestep, MbsuiteError)
    _check_steps("--timestep", cc.T_END, a.timestep)
    scene = _solver_options(load_scene("rotational/coupled_clutches"), a)
    d = coupled_clutches_table(timestep=a.timestep, error_estimate=a.error_estimate, scene=scene)
    estimates = ""
    inaccurate = []
    for eng in ("reference", "mujoco"):  # each path's estimate against its tolerances (kept, flagged: exit 3)
        est = d[eng].pop("error_estimate", None)
        if est is None:
            continue
        d[eng]["error_estimate"] = est.to_dict()
        warned = judge_estimate(est.figures(), allow_inaccurate=scene.solver.allow_inaccurate,
                                what=f"rotational coupled-clutches, path {eng}")
        inaccurate += warned
        estimates += f"\n\n{eng} path: " + est.table() + "".join("\n" + w for w in warned)
    mode = {v: k for k, v in cc.MODE_CODE.items()}
    rows = []
    for i, r in enumerate(d["reference"]["events"]):
        m = d["mujoco"]["events"][i]
        rows.append([r["element"], mode.get(r["from"], r["from"]), mode.get(r["to"], r["to"]), r["t_ref"],
                     r["t"], m["t"], None if r["t"] is None else r["t"] - r["t_ref"],
                     None if m["t"] is None or r["t"] is None else m["t"] - r["t"]])
    t1 = format_table(["clutch", "from", "to", "t_Dymola [s]", "t_hand [s]", "t_MuJoCo [s]", "hand-Dym [s]",
                       "MuJoCo-hand [s]"], [r[:6] + [_e(x) for x in r[6:]] for r in rows], ".10g")
    w_ref, w_h, w_m = (np.asarray(x) for x in (d["w_ref"], d["reference"]["w"], d["mujoco"]["w"]))
    rows2 = [[g, *(np.round(wr, 6) + 0.0), _e(np.max(np.abs(wh - wr))), _e(np.max(np.abs(wm - wh)))]
             for g, wr, wh, wm in zip(d["grid"], w_ref, w_h, w_m, strict=True)]
    t2 = format_table(["t [s]"] + [f"w{k} [rad/s]" for k in range(1, 5)]
                      + ["dw hand-Dym [rad/s]", "dw MuJoCo-hand [rad/s]"], rows2, ".6g")
    t2 += ("\nw1..w4: speeds of the inertias J1..J4 (Dymola reference, rounded to 1e-6); dw: largest"
           " |difference|\nover w1..w4 (every path's values: --out DIR, coupled_clutches_w.csv).")
    ev_cols = [("clutch", "", [r[0] for r in rows]), ("from", "", [r[1] for r in rows]),
               ("to", "", [r[2] for r in rows])]
    ev_cols += [(n, "s", [_nan(r[i]) for r in rows]) for i, n in enumerate(
        ("t_dymola", "t_hand", "t_mujoco", "hand_minus_dymola", "mujoco_minus_hand"), start=3)]
    w_cols = [("t", "s", d["grid"])] + [(f"{src}_w{k + 1}", "rad/s", w[:, k]) for src, w in
                                        (("dymola", w_ref), ("hand", w_h), ("mujoco", w_m)) for k in range(4)]
    ref = cc.load_reference()
    write = partial(_write_coupled_clutches, d, ref["t"], ref["w"], ev_cols, w_cols)
    text = "clutch mode changes:\n" + t1 + "\n\nspeeds every 0.1 s:\n" + t2 + estimates
    rep = Report({"options": _options(a), **d, **({"warnings": inaccurate} if inaccurate else {})}, text, write)
    if inaccurate and not scene.solver.allow_inaccurate:
        rep.flag_inaccurate(inaccurate)
    emit(rep, a, scene.to_dict())


def _write_coupled_clutches(d: dict, ref_t: np.ndarray, ref_w: np.ndarray, ev_cols: list, w_cols: list,
                            out: Path) -> list[Path]:
    """The files of `rotational coupled-clutches --out`: events and speeds as CSV, the comparison figure."""
    from ...plotting import save
    from ...results import write_csv
    from .plots import coupled_clutches_figure

    fig = coupled_clutches_figure(d, ref_t, ref_w)
    return [write_csv(Path(out) / "coupled_clutches_events.csv", ev_cols),
            write_csv(Path(out) / "coupled_clutches_w.csv", w_cols),
            save(fig, Path(out) / "coupled_clutches.png")]
