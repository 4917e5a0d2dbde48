"""The suite's headline in under a minute: the pantograph's frequency response from its linearisation and from MuJoCo
time simulations (with the thesis' resonances beside), and the EN 50318 validation table of the catenary at 250 and
300 km/h. Every step writes CSV, PNG and summary.json under `--out` (default `out/demo`); a closing summary says what
was found and where the files are.

    python scripts/demo.py                   # ~1 min on 2 cores
    python scripts/demo.py --reference       # also the event-exact hand-derived path at every frequency (minutes)
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import sys
import time
from pathlib import Path

from mbsuite.cli import main as mbsuite


def _step(title: str, argv: list[str]) -> tuple[dict, float]:
    """Run one mbsuite command in-process (its table goes to stdout), return its summary.json and wall time."""
    print(f"\n== {title}\n$ mbsuite {' '.join(argv)}", flush=True)
    t0 = time.perf_counter()
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = mbsuite(argv)
    wall = time.perf_counter() - t0
    print(buf.getvalue(), end="", flush=True)
    if rc != 0:
        raise SystemExit(rc)
    out = Path(argv[argv.index("--out") + 1])
    return json.loads((out / "summary.json").read_text())["results"], wall


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/demo", help="output directory (default out/demo)")
    ap.add_argument("--reference", action="store_true",
                    help="add the event-exact hand-derived path to the frequency sweep (slow: minutes)")
    args = ap.parse_args(argv)
    os.environ.setdefault("MBSUITE_PROGRESS", "1")  # progress on stderr also when it is a log file
    out = Path(args.out)
    t_all = time.perf_counter()

    methods = "linear,mujoco,reference" if args.reference else "linear,mujoco"
    fr, t_fr = _step("Pantograph frequency response 1-30 Hz (Eppinger's lab test)",
                     ["pantograph", "freqresp", "--methods", methods, "--out", str(out / "pantograph_freqresp")])
    cat = {}
    t_cat = 0.0
    for v in (250, 300):
        cat[v], t = _step(f"EN 50318 reference catenary at {v} km/h",
                          ["catenary", "catenary/en50318", "--speed", str(v), "--out", str(out / f"en50318_{v}")])
        t_cat += t

    print("\n== Summary", flush=True)
    peaks = fr.get("peaks_hz", {})
    for m, pk in peaks.items():
        print(f"pantograph {m:>17}: F1 peaks {', '.join(f'{x:.2f}' for x in pk['F1'])} Hz; "
              f"HD peaks {', '.join(f'{x:.2f}' for x in pk['HD'])} Hz")
    if "thesis_resonances_simulated_hz" in fr:
        print(f"thesis (Eppinger 1984): simulated {fr['thesis_resonances_simulated_hz']} Hz, "
              f"measured {fr['thesis_resonances_measured_hz']} Hz")
    for v, r in cat.items():
        inside = r.get("all_inside_ranges")
        verdict = {True: "every statistic inside the standard's range", False: "OUTSIDE the standard's ranges",
                   None: "statistics in the table above"}[inside]
        print(f"EN 50318 at {v} km/h: {verdict}")
    print(f"files: {out.resolve()}/ (CSV with SI units, PNG, summary.json per step)")
    print(f"wall time: frequency response {t_fr:.1f} s, catenary {t_cat:.1f} s, "
          f"total {time.perf_counter() - t_all:.1f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
