"""`mbsuite sensitivity SCENE --vary SECTION.KEY=LO:HI ...` (Morris screening or Sobol indices of the scene's headline
outputs) and `mbsuite optimise SCENE --vary ... --objective sigma` (the design minimising one output subject to bounds
on others, robust over several speeds, or the Pareto front against a second output): the design studies of
`mbsuite.analysis.sensitivity` and `mbsuite.analysis.optimise`, every point on the sweep machinery."""

from __future__ import annotations

import argparse
from typing import Any

from ..errors import MbsuiteError
from ..limits import Limit
from ..schema import Items, check_value
from .options import apply_speed, check_workers, load, sweep_options
from .output import emit
from .study import apply_sets

#: `--start SECTION.KEY=VALUE`: one number, in the key's SI unit (its range is the factor's, checked by the study)
START_VALUE = Items(Limit(doc="start value of a varied key"), min=1, max=1, doc="--start: one number (the key's unit)")
#: `--pareto a,b,c`: the levels of the `--against` output the front is traced at (its unit)
PARETO_LEVELS = Items(Limit(doc="a level of the --against output"), min=1, max=1000,
                      doc="--pareto: levels of the --against output (its unit)")


def cmd_sensitivity(args: argparse.Namespace) -> None:
    """Run the study and emit its ranked table (files under --out)."""
    from ..analysis import sensitivity

    scene = apply_speed(apply_sets(load(args), args.set_values), args)
    check_workers(args.workers)
    outputs = [x.strip() for x in args.outputs.split(",") if x.strip()] if args.outputs else None
    res = sensitivity.run(scene, args.vary or [], method=args.method, n=args.n, seed=args.seed, outputs=outputs,
                          levels=args.levels, workers=args.workers, options=sweep_options(args))
    emit(res.report(), args, scene.to_dict())


def operating_points(scene: Any, speed: str | None, over: list[str] | None) -> dict[str, list] | None:
    """`--speed` and `--over` as the operating points of the robust variant (a single speed is set on the scene
    instead, by the caller)."""
    from ..analysis.sweep import parse_values
    from .study import SECTIONS, split_key

    out: dict[str, list] = {}
    if speed is not None:
        out["input.speed"] = parse_values(speed)
    for text in over or []:
        section, key, values = split_key(text, "--over", (*SECTIONS, *scene.spec.sections))
        label = f"{section}.{key}"
        if label in out:
            raise MbsuiteError(f"--over {text!r}: {label} given twice (--speed sets input.speed)")
        out[label] = parse_values(values)
    return out or None


def start_design(scene: Any, texts: list[str] | None) -> dict[str, float] | None:
    """`--start SECTION.KEY=VALUE` as the start design {factor: value} (None without any)."""
    from ..analysis.sweep import parse_values
    from .study import SECTIONS, split_key

    if not texts:
        return None
    out = {}
    for text in texts:
        section, key, value = split_key(text, "--start", (*SECTIONS, *scene.spec.sections))
        (out[f"{section}.{key}"],) = check_value(START_VALUE, f"--start {section}.{key}", parse_values(value),
                                                 "the command line", MbsuiteError)
    return out


def cmd_optimise(args: argparse.Namespace) -> None:
    """Run the optimisation (or the Pareto front) and emit its report (files under --out)."""
    from ..analysis import optimise

    scene = apply_sets(load(args), args.set_values)
    check_workers(args.workers)
    cons: list[Any] = list(args.constraint or [])
    if args.band:
        cons.append(optimise.band(args.band))
    over = operating_points(scene, args.speed, args.over)
    if over and all(len(v) == 1 for v in over.values()):  # one operating point: set it on the scene
        scene = apply_sets(scene, [f"{k}={v[0]}" for k, v in over.items()])
        over = None
    start = start_design(scene, args.start)
    common = dict(start=start, objective=args.objective, constraints=cons, over=over, aggregate=args.aggregate,
                  penalty=args.penalty, maxiter=args.maxiter, popsize=args.popsize, seed=args.seed,
                  workers=args.workers, options=sweep_options(args))
    if args.pareto:
        from ..analysis.sweep import parse_values

        levels = check_value(PARETO_LEVELS, "--pareto", parse_values(args.pareto),
                             "the command line", MbsuiteError)
        res = optimise.pareto(scene, args.vary or [], against=args.against, levels=levels, **common)
        emit(res.report(), args, scene.to_dict())
        return
    res = optimise.run(scene, args.vary or [], **common)
    warned = []
    if args.error_estimate:
        optimise.rerun(res, scene, workers=args.workers)
        warned = optimise.judge_rerun(res, scene)
    rep = res.report()
    if warned:  # the optimum's error estimate above its tolerance: kept, flagged (exit 3) unless allowed
        rep.data["warnings"] = list(rep.data.get("warnings", [])) + warned
        rep.table += "\n" + "\n".join(warned)
        if not scene.solver.allow_inaccurate:
            rep.flag_inaccurate(warned)
    emit(rep, args, scene.to_dict())
