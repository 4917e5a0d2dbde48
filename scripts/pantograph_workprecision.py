"""Work-precision study of the pantograph lab scene: what accuracy costs in time.

A thin front end of `mbsuite.analysis.workprecision` (the same study as `mbsuite workprecision pantograph/lab`):
MuJoCo timestep x integrator (euler, implicitfast, implicit, rk4, discrete) and the hand-derived path with scipy
methods x rtol, against Radau at rtol 1e-12 (checked against DOP853 at 1e-12); state error max |F1, F2, HD, y_d - ref|/A
and the physics metric (amplitude/phase of F1 and HD at the forcing frequency, contact-force statistics); wall time
median of N runs with min-max. Coulomb friction is off in the study (MuJoCo's frictionloss and the reference's
event-exact stick/slip are different models; their 0.4 % difference would be an error floor). The study measures
every setting, also those the health figures refuse (`allow_inaccurate`). The cost of the nonlinear cylinder's laminar
band (stiffness, steps, time per band width) is the companion study `scripts/pantograph_orifice_band.py`.

    python scripts/pantograph_workprecision.py [--scene pantograph/lab] [--repeats 5] [--out out/pantograph_wp]
"""

from __future__ import annotations

import argparse

from mbsuite import load_scene
from mbsuite.analysis.workprecision import workprecision


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="pantograph/lab")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="a reduced grid (smoke run)")
    ap.add_argument("--out", default="out/pantograph_workprecision")
    a = ap.parse_args()
    rep = workprecision(load_scene(a.scene), repeats=a.repeats, quick=a.quick, progress=print)
    print(rep.table)
    for f in rep.save(a.out, load_scene(a.scene).to_dict()):
        print(f"wrote {f}")


if __name__ == "__main__":
    main()
