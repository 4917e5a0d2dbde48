"""What a pantograph scene asks for: its effects (`config_of`), its ram input y_w(t) (`INPUTS`, `input_of`), the
height the motion takes place about (`operating_height`) and the state a run starts from (`start_of`), shared by both
engine paths and the analyses.

The ram is EQSIM's YW: a sine y_w = y_op + A (1 - cos w t), a step or a static height.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import SceneError
from ...limits import Limit
from ...scenes import Scene
from .params import PantographParams

if TYPE_CHECKING:
    from .equations import PantographConfig, PantographODE

_INITIAL = Limit(kind=str, choices=("equilibrium", "fortran"), default="equilibrium",
                 doc="'equilibrium' (static equilibrium at y_w(0)) or 'fortran' (the thesis' start: no equilibrium)")
#: the scene input keys of each input type, with their valid ranges and defaults (`ModelSpec.inputs`)
INPUTS: dict[str, dict[str, Limit]] = {
    "sine": {
        "amplitude": Limit(lo=0.0, hi=0.2, unit="m", default=1.85e-3,
                           doc="half peak-to-peak A of y_w = y_op + A (1 - cos 2 pi f t); thesis 1.85 mm"),
        "frequency": Limit(lo=0.0, lo_open=True, hi=100.0, unit="Hz", default=2.0,
                           doc="ram frequency; the thesis sweeps 1-30 Hz, its rigid links are not valid far above"),
        "initial": _INITIAL,
    },
    "static": {"initial": _INITIAL},
    "step": {
        "height": Limit(lo=-0.5, hi=0.5, unit="m", default=1e-3, doc="step of the ram height at t_step"),
        "t_step": Limit(lo=0.0, unit="s", default=0.1, doc="time of the step"),
        "initial": _INITIAL,
    },
}


def config_of(scene: Scene) -> PantographConfig:
    """The scene's effects as a `PantographConfig`."""
    from .equations import PantographConfig  # here: the equations import scipy.optimize; listing models needs none

    return PantographConfig(**dict(scene.effects))


@dataclass(frozen=True)
class InputSignal:
    """The ram height y_w(t) (m): sine y_op + A (1 - cos 2 pi f t), step y_op + h (t >= t_step), or static y_op.
    Accepts a float or an array of times."""

    kind: str
    y_op: float
    amplitude: float = 0.0
    frequency: float = 0.0
    t_step: float = 0.0

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        if self.kind == "sine":
            y = self.y_op + self.amplitude * (1.0 - np.cos(2.0 * math.pi * self.frequency * t))
        elif self.kind == "step":
            y = self.y_op + np.where(t >= self.t_step, self.amplitude, 0.0)
        else:
            y = np.full_like(t, self.y_op)
        return float(y) if y.ndim == 0 else y


def input_of(scene: Scene, p: PantographParams) -> InputSignal:
    """The scene's ram input; its keys were checked against `INPUTS` by the scene loader (defaults filled in)."""
    inp = scene.input
    kind = inp.get("type", "sine")
    if kind == "sine":
        d = INPUTS["sine"]
        return InputSignal("sine", p.y_op, float(inp.get("amplitude", d["amplitude"].default)),
                           float(inp.get("frequency", d["frequency"].default)))
    if kind == "step":
        d = INPUTS["step"]
        return InputSignal("step", p.y_op, float(inp.get("height", d["height"].default)), 0.0,
                           float(inp.get("t_step", d["t_step"].default)))
    return InputSignal("static", p.y_op)


def operating_height(scene: Scene, p: PantographParams) -> float:
    """The ram height the motion takes place about, where `freqresp` and `modes` linearise: the mean of the input.
    Sine y_op + A (1 - cos wt): y_op + A; step: its final level y_op + height; static: y_op. (Linearising at y_op
    instead shifts the 8.5 Hz HD ratio by -2.7 % at A = 1.85 mm: the operating point moves with A.)"""
    u = input_of(scene, p)
    if u.kind in ("sine", "step"):
        return p.y_op + u.amplitude
    return p.y_op


@dataclass(frozen=True)
class Start:
    """The state a run starts from: `x0` the hand-derived state, `theta0` the absolute angles of the static
    equilibrium at y_w(0) (the origin of the `excursion` figure), `at_rest` True for that equilibrium (scene input
    `initial = "equilibrium"`), False for the thesis' FORTRAN start."""

    x0: np.ndarray
    theta0: np.ndarray
    at_rest: bool


def start_of(scene: Scene, ode: PantographODE, u: InputSignal) -> Start:
    """The start of a run of `scene`: the static equilibrium at y_w(0) (default) or the thesis' FORTRAN start
    (erratum 18; not an equilibrium: theta_1 = theta_2 = asin((y_op + A) / (2 l1)), theta_h = 0, at rest)."""
    eq = ode.equilibrium(u(0.0))
    theta0 = ode.theta(eq[: ode.nq])
    if scene.input.get("initial", "equilibrium") != "fortran":
        return Start(eq, theta0, True)
    if ode.nq != 3:
        raise SceneError("initial = 'fortran' needs the compliant elbow")
    p = ode.p
    t1 = math.asin((p.y_op + u.amplitude) / (2.0 * p.l1))
    x0 = eq.copy()
    x0[:3] = [t1, t1, 0.0]
    if ode.cfg.cylinder == "linear":
        x0[-1] = ode.cylinder_lever(t1)[0]
    return Start(x0, theta0, False)
