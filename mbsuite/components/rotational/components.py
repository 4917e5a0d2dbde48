"""Components of `Modelica.Mechanics.Rotational` (Modelica Standard Library 4.1.0, Modelica Association) as friction
elements, rows and sources of a rotor system (`interfaces.RotorSystem`), with the equations of
`Modelica/Mechanics/Rotational/Components/*.mo`:
* `clutch` (`Components.Clutch`): sliding torque mu0 cgeo fn_max f_normalized(t), breakaway peak x that, modes of
  `Interfaces.PartialFriction` (the rotor system's friction element);
* `brake` (`Components.Brake`): the same between a shaft and the support, on w_relfric = w (the flange speed);
* `one_way_clutch` (`Components.OneWayClutch`): freewheel in parallel with a clutch; its own 3-state logic (stuck =
  locked or w_rel <= 0; startForward when the holding torque sa > tau0_max; tau0_max = peak2 tau0 engaged,
  tau0_max_low = eps0 mu0 cgeo fn_max disengaged, eps0 = 1e-4, peak2 = max(peak, 1 + eps0));
* `planetary_ring_row` (`Components.IdealPlanetary`): (1 + ratio) w_carrier = w_sun + ratio w_ring with a massless
  ring: the ring speed as a row over the rotors, so elements on the ring act through it (virtual work);
* `ideal_gear_row` (`Components.IdealGear`): w_a = ratio w_b, flange b as a row over the rotors;
* `quadratic_speed_torque` (`Sources.QuadraticSpeedDependentTorque`, TorqueDirection = true: tau = tau_nominal
  (w/w_nominal)^2); other torque sources are `mbsuite.engines.inputs` shapes (Step, Sine, Pulse, Ramp) of a `Source`;
* spring-damper: `interfaces.Spring` with `D` (`Components.SpringDamper`: tau = c phi_rel + d w_rel).
"""

from __future__ import annotations

import math

import numpy as np

from ...engines.inputs import Signal
from ...errors import ParameterError
from .interfaces import Friction, Part, Source

MU0 = 0.5  #: Modelica's default mu_pos = [0, 0.5]
EPS0 = 1.0e-4  #: OneWayClutch: relative hysteresis epsilon (tau0_max_low = eps0 mu0 cgeo fn_max)


def clutch(name: str, a: int, b: int, fn_max: float, *, cgeo: float = 1.0, peak: float = 1.0,
           f_normalized: Signal | None = None, g: tuple[float, ...] | None = None) -> Friction:
    """Modelica `Clutch` between flange_a (rotor a) and flange_b (rotor b): w_rel = w_b - w_a (or g . w)."""
    if not (math.isfinite(fn_max) and fn_max >= 0 and math.isfinite(cgeo) and cgeo >= 0):
        raise ParameterError(f"clutch '{name}': fn_max and cgeo must be >= 0, got {fn_max!r}, {cgeo!r}")
    return Friction(name, a, b, [Part(name, MU0 * cgeo * fn_max, schedule=f_normalized)], peak=peak, g=g)


def brake(name: str, body: int, n: int, fn_max: float, *, cgeo: float = 1.0, peak: float = 1.0,
          f_normalized: Signal | None = None, g: tuple[float, ...] | None = None) -> Friction:
    """Modelica `Brake` on rotor `body` (of n) against the support: w_relfric = w of the flange (or g . w), so its
    modes read as Modelica's (forward = the shaft turning positive)."""
    row = g if g is not None else tuple(1.0 if i == body else 0.0 for i in range(n))
    return clutch(name, body, -1, fn_max, cgeo=cgeo, peak=peak, f_normalized=f_normalized, g=row)


def one_way_clutch(name: str, a: int, b: int, fn_max: float, *, cgeo: float = 1.0, peak: float = 1.0,
                   f_normalized: Signal | None = None) -> Friction:
    """Modelica `OneWayClutch` between flange_a (rotor a) and flange_b (rotor b), w_rel = w_b - w_a >= 0."""
    f = clutch(name, a, b, fn_max, cgeo=cgeo, peak=max(peak, 1.0 + EPS0), f_normalized=f_normalized)
    f.one_way_hold = EPS0 * MU0 * cgeo * fn_max
    return f


def planetary_ring_row(ratio: float, sun: int, carrier: int, n: int) -> np.ndarray:
    """`IdealPlanetary` with a massless ring: (1 + ratio) w_carrier = w_sun + ratio w_ring, so
    w_ring = ((1 + ratio) w_carrier - w_sun) / ratio as a row over the n rotors."""
    if not (math.isfinite(ratio) and ratio > 0):
        raise ParameterError(f"planetary ratio (ring/sun teeth) must be > 0, got {ratio!r}")
    row = np.zeros(n)
    row[carrier] += (1.0 + ratio) / ratio
    row[sun] -= 1.0 / ratio
    return row


def ideal_gear_row(ratio: float, a: int, n: int) -> np.ndarray:
    """`IdealGear` (w_a = ratio w_b) with flange b massless: w_b = w_a / ratio as a row over the n rotors."""
    if not (math.isfinite(ratio) and ratio != 0):
        raise ParameterError(f"gear ratio must be finite and non-zero, got {ratio!r}")
    row = np.zeros(n)
    row[a] = 1.0 / ratio
    return row


def quadratic_speed_torque(label: str, body: int, tau_nominal: float, w_nominal: float) -> Source:
    """`QuadraticSpeedDependentTorque` (TorqueDirection = true): tau = tau_nominal (w / w_nominal)^2."""
    if not (math.isfinite(w_nominal) and w_nominal > 0):
        raise ParameterError(f"quadratic load '{label}': w_nominal must be > 0 rad/s, got {w_nominal!r}")
    return Source(label, body, 0.0, 0.0, c2=tau_nominal / w_nominal**2)
