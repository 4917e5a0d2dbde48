"""Parameters of the rotational model: none a scene sets. Each example carries the Modelica Standard Library's own
parameters (MSL 4.1.0, `Modelica.Mechanics.Rotational.Examples`; stated in `examples.py` and `coupled_clutches.py`),
so that its results stay comparable with the Modelica Association's reference results."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class RotationalParams:
    """No scene parameters: a `[params]` key is an unknown parameter (the example's values are the MSL's)."""
