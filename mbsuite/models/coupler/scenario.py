"""What a double-coupler run is given and gives back, the same on every path (`mujoco`, `reference`): the scene
input `constant_speed` (speed, load, misalignment of the output shaft, start-up ramp), the output signals, the smooth
start-up ramp and the health figure of the SS-link closures."""

from __future__ import annotations

import math

import numpy as np

from ...errors import SceneError
from ...limits import Limit
from ...statistics import Statistic
from ...trust.health import Figure
from .params import CouplerParams

#: the scene input of type "constant_speed": valid range, unit, meaning and the default used when a scene omits the
#: key (the scene loader fills it in, so every output shows the value the run used)
INPUTS: dict[str, Limit] = {
    "omega": Limit(lo=0.0, lo_open=True, hi=1000.0, unit="rad/s", default=4 * math.pi,
                   doc="input shaft speed after the ramp"),
    "load_torque": Limit(lo=-1e7, hi=1e7, unit="N m", default=1000.0,
                         doc="load torque on the output shaft, opposing its rotation"),
    "alpha_cx": Limit(lo=-0.5, hi=0.5, unit="rad", default=0.0, doc="output shaft inclination about x"),
    "alpha_cz": Limit(lo=-0.5, hi=0.5, unit="rad", default=0.0, doc="output shaft inclination about z"),
    "x_c": Limit(lo=-1e3, hi=1e3, unit="m", default=0.0, doc="output shaft lateral offset along x"),
    "z_c": Limit(lo=-1e3, hi=1e3, unit="m", default=0.0, doc="output shaft lateral offset along z"),
    "t_ramp": Limit(lo=0.0, hi=1e3, unit="s", default=0.25,
                    doc="duration of the smooth speed and load ramp from rest"),
}
INPUT_KEYS = tuple(INPUTS)
INPUT_DEFAULTS = {k: lim.default for k, lim in INPUTS.items()}


def scene_inputs(scene) -> dict[str, float]:
    """The run's inputs: the scene's (checked and completed with the declared defaults by the scene loader), checked
    again here for scenes built without it."""
    inp = {**INPUT_DEFAULTS, **{k: v for k, v in scene.input.items() if k != "type"}}
    return {k: INPUTS[k].check(f"coupler input {k}", inp[k], SceneError) for k in INPUT_KEYS}


def ramp(t, t_ramp: float):
    """Smooth 0 -> 1 (C1: s^2 (3 - 2 s), s = t / t_ramp) over t_ramp; a float or an array of times."""
    t = np.asarray(t, dtype=float)
    s = np.clip(t / t_ramp, 0.0, 1.0) if t_ramp > 0 else np.ones_like(t)
    y = np.where(s >= 1.0, 1.0, s * s * (3 - 2 * s))
    return float(y) if y.ndim == 0 else y


def time_mean(t: np.ndarray, f: np.ndarray) -> float:
    """The time average of samples f(t) over [t_0, t_end] by the trapezoidal rule (second order; exact to rounding for
    a periodic signal sampled over whole periods). A plain mean of the samples would count both ends of the window,
    a bias of O(dt): (f_0 + f_end) / 2 - mean over the sample count, 0.07 N m of a 44 N m ripple at 2 ms."""
    if t.size < 2 or t[-1] <= t[0]:
        return float(np.mean(f))
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)) / (t[-1] - t[0]))


#: bound of the MuJoCo closure residual over a whole run (start-up ramp included), relative to the link length: the
#: shipped scenes reach 1.9e-4 to 1.003e-3 l (the peak in the 0.25 s ramp, 9.5e-4 m; 2.8e-5 to 7.4e-5 m in steady
#: rotation), so 5e-3 l (5x the largest) flags closures torn open by a too-soft solref or a bad model
CLOSURE_BOUND_REL = 5e-3
#: the rigid reference solves every sample's FPP to |r| <= 1e-13 R^2 (a gap ~1e-14 l): 1e-9 l flags a failed solve
CLOSURE_BOUND_REL_REFERENCE = 1e-9


def closure_figure(value: float, p: CouplerParams, reference: bool = False) -> Figure:
    """The health figure `closure_residual`: the largest loop-closure gap over the run [m] against its bound
    (CLOSURE_BOUND_REL x link length; CLOSURE_BOUND_REL_REFERENCE for the rigid reference)."""
    rel = CLOSURE_BOUND_REL_REFERENCE if reference else CLOSURE_BOUND_REL
    fix = ("" if reference else "lower params.solref_timeconst (stiffer closures) or lengthen input.t_ramp (a gentler "
           "start-up)")
    return Figure("closure_residual", float(value), rel * p.link_length, "m",
                  f"largest SS-link closure gap over the run, bound {rel:g} x link length {p.link_length:.4g} m", fix)


#: the output signals of a run (both paths) and their SI units
#: the window the statistics of a run are taken over (the settled, constant-speed part)
WINDOW = "the settled window t >= max(solver.t_settle, input.t_ramp)"
#: the statistics of a run (`SPEC.statistics`; `SimResult.statistics`; `mujoco.stats`, `reference.run_reference`)
STATISTICS = {
    "window_start": Statistic("s", "the first sample of the window", WINDOW),
    "revolutions": Statistic("-", "input-shaft revolutions over the window", WINDOW),
    "phi_c_err_max": Statistic("rad", "largest |phi_c - phi_c,kin| (output angle against the rigid kinematics)",
                               WINDOW),
    "phi_c_err_rms": Statistic("rad", "RMS of phi_c - phi_c,kin", WINDOW),
    "phi_c_kin_fluctuation_pp": Statistic("rad", "peak-to-peak of phi_a - phi_c (the joint's angle fluctuation)",
                                          WINDOW),
    "closure_residual_max": Statistic("m", "largest SS-link closure gap", WINDOW),
    "closure_residual_max_all": Statistic("m", "largest SS-link closure gap", "the whole run, ramp included"),
    "torque_in_mean": Statistic("N m", "time mean of the input torque", WINDOW),
    "torque_in_ripple_pp": Statistic("N m", "peak-to-peak of the input torque", WINDOW),
    "torque_in_ripple_rel": Statistic("-", "peak-to-peak of the input torque over |its mean|", WINDOW),
    "torque_in_ripple_quasi_static_pp": Statistic("N m", "peak-to-peak of the quasi-static input torque "
                                                         "load torque x dphi_c/dphi_a", WINDOW),
    "speed_ratio_min": Statistic("-", "smallest speed ratio dphi_c/dphi_a", WINDOW),
    "speed_ratio_max": Statistic("-", "largest speed ratio dphi_c/dphi_a", WINDOW),
    "link_force_max_abs": Statistic("N", "largest |axial force| of the eight SS links", WINDOW),
    "link_force_mean": Statistic("N", "mean axial force of each SS link 1..8", WINDOW, kind="numbers"),
}

OUTPUTS = {"phi_a": "rad", "phi_c": "rad", "phi_c_kin": "rad", "phi_c_err": "rad", "omega_c": "rad/s",
           "torque_in": "N m", "torque_out": "N m", "closure_residual": "m",
           **{f"link_force_{k + 1}": "N" for k in range(8)}}
