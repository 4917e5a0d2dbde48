"""Modelica CoupledClutches: the mode sequence with event times and w1..w4 every 0.1 s from both paths vs Dymola.

Usage: .venv/bin/python scripts/drives_coupled_clutches.py [--timestep 1e-4]
"""

from __future__ import annotations

import sys

from mbsuite.cli import main

if __name__ == "__main__":
    sys.exit(main(["drive", "coupled-clutches", *sys.argv[1:]]))
