"""Modelica CoupledClutches: the mode sequence with event times and w1..w4 every 0.1 s from both paths vs Dymola.

Hand path: the event-exact DOP853 simulation; MuJoCo path: RK4 at `--timestep` with the stick/slip state machine as
the native core's stepper (event times interpolated within the step). The reference is the Modelica Association's
result in mbsuite/models/rotational/data/msl/ (the model `rotational`; this runs `mbsuite rotational
coupled-clutches`).

Usage: .venv/bin/python scripts/drives_coupled_clutches.py [--timestep 1e-4]
"""

from __future__ import annotations

import sys

from mbsuite.cli import main

if __name__ == "__main__":
    sys.exit(main(["rotational", "coupled-clutches", *sys.argv[1:]]))
