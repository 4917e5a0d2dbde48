"""Study (not a test): the declared accuracy of every shipped scene, checked by its own error estimate.

For every shipped scene of every model that declares headline outputs (`ModelSpec.accuracy`), on the scene's own path
(and with `--all-paths` on every path of its model), the scene runs with `error_estimate=True` (the scene refined once
and twice, `mbsuite.trust.estimate`) and the script prints one Markdown row per headline: value, declared tolerance,
estimated error, observed order, whether the tolerance holds, and the wall seconds of the run and of the estimate
(the refined copies, on `--workers` processes).

    python scripts/declared_accuracy.py [--models pantograph drives] [--all-paths] [--workers 2] > declared.md
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings

from mbsuite import load_scene, model_specs, run


def _g(x: float) -> str:
    return f"{x:.4g}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--models", nargs="*", default=None)
    ap.add_argument("--scenes", nargs="*", default=None, help="model/scene names (default: every shipped scene)")
    ap.add_argument("--all-paths", action="store_true", help="every path of the model, not only the scene's own")
    ap.add_argument("--workers", type=int, default=0)
    a = ap.parse_args()
    refs = list(a.scenes or [])
    if not refs:
        for name, spec in sorted(model_specs().items()):
            if spec.accuracy is not None and (a.models is None or name in a.models):
                refs += [f"{name}/{s}" for s in spec.scene_files()]
    print("| scene | path | headline | value | tol | est. error | observed order | holds | run s | estimate s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    failed = 0
    for ref in refs:
        scene = load_scene(ref)
        engines = list(scene.spec.paths) if a.all_paths else [scene.solver.engine]
        for eng in engines:
            sc = scene.replace(solver={"engine": eng, "allow_inaccurate": True})
            print(f"running {ref} on {eng} ...", file=sys.stderr, flush=True)
            t0 = time.perf_counter()
            try:
                base = run(sc)
            except Exception as exc:  # noqa: BLE001 - a study reports every scene, failures included
                print(f"| {ref} | {eng} | (run failed: {type(exc).__name__}: {exc}) | | | | | | | |")
                failed += 1
                continue
            t1 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = run(sc, error_estimate=True, workers=a.workers)
            t2 = time.perf_counter()
            del base
            for r in res.error_estimate.rows:
                order = "-" if r.order is None else f"{r.order:.2f}"
                print(f"| {ref} | {eng} | {r.name} [{r.unit}] | {_g(r.value)} | {_g(r.tol)} | {r.error:.2g} | "
                      f"{order} | {'yes' if r.ok else '**no**'} | {t1 - t0:.2f} | {t2 - t1 - (t1 - t0):.2f} |",
                      flush=True)
                failed += not r.ok
    print(f"\n{failed} headline(s) past their tolerance or failed", file=sys.stderr)


if __name__ == "__main__":
    main()
