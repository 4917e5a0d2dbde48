"""The pantograph's health figures (`mbsuite.trust.health`): `step_figures` of a MuJoCo run, known before it steps
(`stability_margin`, `nyquist_ratio`), and the `excursion` of a run of either path, judged by `mbsuite.run`."""

from __future__ import annotations

import math

import numpy as np

from ...scenes import Scene
from ...trust.health import Figure, nyquist_ratio, stability_margin
from .equations import PantographConfig
from .inputs import InputSignal, operating_height
from .linearise import omega_max
from .params import PantographParams

#: bound on h * omega_max per MuJoCo integrator as a fraction of its stability limit (`mbsuite.trust.health`): rk4 1.4,
#: the Euler family 0.1, discrete 0.01. Chosen from the error measured against the reference (lab scene, Coulomb off,
#: 2 / 4.25 / 8.5 Hz; README "Health figures"): near each bound the physics error is about 1 % (rk4 0.61-0.78 % at
#: h omega = 1.22, 2.4-27 % at 1.46-2.44; Euler family ~0.1 h omega: 0.61-0.89 % at 0.061, 4.4 % at 0.49; discrete
#: ~1.4 h omega: 0.99-1.2 % at 0.0098, 5.9-7.4 % at 0.061). First-order methods damp or detune the fastest mode by
#: O(h omega), hence their tighter bounds.
STABILITY_FRACTION = {"rk4": 0.5, "euler": 0.05, "implicit": 0.1, "implicitfast": 0.1, "discrete": 0.005}
#: the geometric working range of the absolute link angles (the range `PantographODE.equilibrium` accepts)
WORKING_RANGE = ((0.0, 0.5 * math.pi), (0.0, 0.5 * math.pi), (-0.5 * math.pi, 0.5 * math.pi))


def step_figures(scene: Scene, p: PantographParams, cfg: PantographConfig, u: InputSignal) -> list[Figure]:
    """The health figures of a MuJoCo run known before it steps: `stability_margin` (h times the highest natural
    frequency of the linearisation at the operating height) and, for a sine ram, `nyquist_ratio`."""
    s = scene.solver
    w = omega_max(p, cfg, operating_height(scene, p))
    figs = [stability_margin(s.timestep, w, s.integrator, fraction=STABILITY_FRACTION.get(s.integrator, 0.5))]
    if u.kind == "sine":
        figs.append(nyquist_ratio(s.timestep, u.frequency))
    return figs


def excursion(theta: np.ndarray, theta0: np.ndarray) -> Figure:
    """Plausibility: the largest excursion of a link angle from the equilibrium, relative to the distance from the
    equilibrium to the edge of the working range (0 < theta_1, theta_2 < pi/2, |theta_h| < pi/2). Above 1 the linkage
    has folded or passed the vertical: the result is not a pantograph's motion."""
    val = 0.0
    for i, (lo, hi) in enumerate(WORKING_RANGE):
        room = min(theta0[i] - lo, hi - theta0[i])
        dev = np.abs(theta[:, i] - theta0[i])
        val = max(val, float(np.max(dev)) / room if np.all(np.isfinite(dev)) else math.inf)
    return Figure("excursion", val, 1.0, "", "largest link-angle excursion / room to the edge of the working range",
                  "reduce the input amplitude or solver.timestep; check the parameters")
