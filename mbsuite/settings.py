"""Solver settings of a run: which path (engine) runs it, MuJoCo's integrator and step, the equations path's scipy
method and tolerances, the run's length and its size guard. Every model declares its defaults as one `SolverSettings`
(`ModelSpec.solver`); a scene's `[solver]` section overrides them key by key."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

from .errors import SceneError
from .limits import Limit

INTEGRATORS = ("euler", "implicit", "implicitfast", "rk4", "discrete")
SCIPY_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")
DEFAULT_MAX_STEPS = 5e7  # size guard; a scene or --max-steps may raise it


@dataclass(frozen=True)
class SolverSettings:
    """Solver settings. MuJoCo uses `integrator` and `timestep`; the reference path uses `method`, `rtol`, `atol`,
    `max_step`. `duration` is the simulated time (s); `t_settle` the part of it treated as start-up transient.
    `max_steps` guards against a legal but enormous job (duration / timestep steps, also the sample count): raise it
    deliberately for a long run. `allow_inaccurate` keeps a result whose health figures exceed their bounds, with a
    loud warning in the result (default: such a run is an error)."""

    engine: str = "mujoco"
    integrator: str = "implicitfast"
    timestep: float = 5e-4
    method: str = "LSODA"
    rtol: float = 1e-8
    atol: float = 1e-10
    max_step: float = 0.0  # 0 = unlimited
    duration: float = 10.0
    t_settle: float = 0.0
    sample_dt: float = 0.0  # output sampling interval; 0 = every step (MuJoCo) / solver's dense output at timestep
    allow_inaccurate: bool = False
    max_steps: float = DEFAULT_MAX_STEPS

    def check(self, engines: tuple[str, ...], where: Callable[..., str] | None = None) -> SolverSettings:
        """Check every setting (type, finiteness, range, the size guard); a SceneError names the first bad one and,
        through `where(key)` (a phrase with a leading space; `where()` for a check across settings), where its value
        came from. Returns the settings with every number as a Python float (any real number type is accepted)."""
        w = where or (lambda key=None: "")
        words = {"engine": Limit(kind=str, choices=tuple(engines), doc="the path that runs the scene"), **SOLVER_WORDS}
        for name, lim in words.items():
            lim.check(f"solver.{name}", getattr(self, name), SceneError, w(name))
        s = dataclasses.replace(self, **{name: lim.check(f"solver.{name}", getattr(self, name), SceneError, w(name))
                                         for name, lim in SOLVER_LIMITS.items()})
        if s.t_settle >= s.duration:
            raise SceneError(
                f"solver.t_settle ({s.t_settle}) must be shorter than solver.duration ({s.duration}){w()}")
        if s.timestep >= s.duration:
            raise SceneError(f"solver.timestep ({s.timestep} s) must be shorter than solver.duration "
                             f"({s.duration} s){w()}")
        if s.engine == "reference" and s.max_step > 0 and s.duration / s.max_step > s.max_steps:
            raise SceneError(
                f"solver.duration / solver.max_step = {s.duration:g} s / {s.max_step:g} s = "
                f"{s.duration / s.max_step:.3g} steps exceeds solver.max_steps = {s.max_steps:.3g}{w()}; enlarge "
                "solver.max_step or raise solver.max_steps (CLI: --max-steps) if you mean it")
        steps = s.duration / s.timestep
        if steps > s.max_steps:
            raise SceneError(
                f"solver.duration / solver.timestep = {s.duration:g} s / {s.timestep:g} s = {steps:.3g} steps "
                f"exceeds solver.max_steps = {s.max_steps:.3g}{w()}; shorten the run, enlarge the step, or raise "
                "solver.max_steps (CLI: --max-steps) if you mean it")
        if s.sample_dt > 0 and s.sample_dt > s.duration:
            raise SceneError(f"solver.sample_dt ({s.sample_dt} s) must not exceed solver.duration "
                             f"({s.duration} s){w()}")
        return s


#: the valid words of the solver's word settings (`engine`'s are the model's paths)
SOLVER_WORDS = {
    "integrator": Limit(kind=str, choices=INTEGRATORS, doc="MuJoCo's integrator"),
    "method": Limit(kind=str, choices=SCIPY_METHODS, doc="scipy's method on the reference path"),
    "allow_inaccurate": Limit(kind=bool, doc="keep a result whose health figures exceed their bounds (loudly)"),
}

# the valid range of every numeric solver setting (the error message and the docs read this table)
SOLVER_LIMITS = {
    "timestep": Limit(lo=0.0, lo_open=True, hi=1.0, unit="s", doc="MuJoCo step / output grid of the reference path"),
    "rtol": Limit(lo=1e-14, hi=0.1, doc="relative tolerance of the reference path"),
    "atol": Limit(lo=0.0, lo_open=True, hi=1.0, doc="absolute tolerance of the reference path"),
    "max_step": Limit(lo=0.0, hi=1.0, unit="s", doc="largest step of the reference path (0: unlimited)"),
    "duration": Limit(lo=0.0, lo_open=True, hi=1e5, unit="s", doc="simulated time"),
    "t_settle": Limit(lo=0.0, hi=1e5, unit="s", doc="start-up transient left out of statistics"),
    "sample_dt": Limit(lo=0.0, hi=1e5, unit="s", doc="output sampling interval (0: every step)"),
    "max_steps": Limit(lo=1.0, hi=1e12, doc="size guard: most steps (and samples) a run may take"),
}
