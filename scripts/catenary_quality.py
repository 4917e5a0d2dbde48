"""The current-collection quality report (AC criteria) of every shipped catenary scene at 250 and 300 km/h: one
table row per scene, speed and pantograph with each criterion's value and verdict, printed and written as JSON.

    .venv/bin/python scripts/catenary_quality.py [--speeds 250 300] [--scenes ...] [--out out/catenary_quality]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import mbsuite
from mbsuite.models.catenary.analysis import run_scene, run_train_scene
from mbsuite.models.catenary.quality import CRITERIA, criteria_from
from mbsuite.models.catenary.reports import quality_of, train_assessments
from mbsuite.results import format_table

SCENES = ("en50318", "en50318_linear", "en50318_eppinger", "eppinger_lab", "en50318_two_pantographs", "en50318_aero",
          "en50318_route", "en50318_route_two_pantographs")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speeds", type=float, nargs="+", default=[250.0, 300.0])
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--out", default="out/catenary_quality")
    a = ap.parse_args()
    rows, data = [], []
    for name in a.scenes:
        scene = mbsuite.load_scene(f"catenary/{name}")
        crit = criteria_from(scene.sections.get("quality"))
        for v in a.speeds:
            if "train" in scene.sections:
                run = run_train_scene(scene, speed_kmh=v)
                qs = [(f"p{k + 1} {n}", q) for k, (n, q) in enumerate(zip(run.names, train_assessments(run, crit),
                                                                             strict=True))]
            else:
                run = run_scene(scene, speed_kmh=v)
                qs = [(run.pantograph, quality_of(run, crit))]
            for who, q in qs:
                rows.append([name, v, who, *[f"{q['rows'][c]['value']:.2f}{'' if q['rows'][c]['pass'] else ' X'}"
                                             for c in CRITERIA], "pass" if q["pass"] else "FAIL"])
                data.append({"scene": name, "speed_kmh": v, "pantograph": who, "quality": q})
            print(rows[-1], flush=True)
    print(format_table(["scene", "km/h", "pantograph", *CRITERIA, "verdict"], rows))
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "quality.json").write_text(json.dumps(data, indent=1))


if __name__ == "__main__":
    main()
