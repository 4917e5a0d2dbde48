"""The pantograph's headline outputs, the tolerances its shipped settings meet, and how a run is refined.

Time runs (`mbsuite run pantograph/<scene>`), by the scene's input (the work-precision study's physics metric,
`cases.PantographStudy.physics_error`, in absolute units):
- sine: the amplitude (m) and phase (deg, relative to the ram's fundamental, in (-180, 180]) of F1 and HD at the
  forcing frequency, and the mean and standard deviation of the contact force (N), over the whole periods after
  `solver.t_settle` (`harmonic.whole_period_window`); with push-only contact also the share of that window without
  contact (`loss_pct`, %, the crossings of the unclipped spring force located by linear interpolation between samples);
- step: the settled contact force (mean after `t_settle`, N), the largest contact force after the step (N, the vertex
  of the parabola through the largest sample and its neighbours: not limited to the sample grid) and the settled
  contact height y_d (m);
- static: the settled contact force (N) and contact height (m).

Refinement: MuJoCo halves `solver.timestep` at its integrator's order (RK4: 2, the order its held ram input leaves it,
README "What accuracy costs"; the Euler family and `discrete`: 1); the frictionloss constraint's time constant is
2 timesteps, so the refined runs also sharpen MuJoCo's regularised Coulomb law towards exact stick/slip. The
reference path divides `solver.rtol` and `atol` by 10.

The frequency response (`mbsuite pantograph freqresp --error-estimate`) has its own headlines
(`freqresp.estimate_headlines`): the amplitude ratio and phase of F1 and HD at every grid frequency and every refined
peak frequency, per time method; its refined copies carry a `[freqresp]` section (`freqresp.validate_section`) that
marks them as such.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...analysis.harmonic import fundamental, whole_period_window
from ...errors import SceneError
from ...trust.estimate import Headline, Refinement, rtol_refinement, timestep_refinement

#: nominal order in the step of each MuJoCo integrator on this model (RK4: 2, limited by the ram input held over the
#: step; measured 4.0x per halving in the work-precision study, docs/accuracy.md)
ORDER = {"euler": 1.0, "implicit": 1.0, "implicitfast": 1.0, "rk4": 2.0, "discrete": 1.0}

#: declared tolerances of the time runs at the shipped settings (MuJoCo RK4 1 ms; reference LSODA rtol 1e-8), 3.6-8x
#: the largest estimate measured on every shipped scene and both paths (`python scripts/pantograph_accuracy.py`; the
#: reference path's estimates are all below 4e-5 of these): amplitudes 1.14e-5 m (unilateral HD, 4.4x; true error
#: against the event-exact reference at rtol 1e-11: 6.0e-6 m), phases 0.251 deg (unilateral HD, 4.0x; true 0.115),
#: contact-force mean 0.062 N (unilateral, 8x; true 0.027) and std 0.185 N (unilateral, 5.4x; true 0.143), contact
#: loss 0.114 % (unilateral, 4.4x; true 0.09 % against MuJoCo at 1/16 of the step). Step and static inputs (the lab
#: scene's effects, 1 mm at 0.1 s): settled force 0.226 N (4.4x; the stuck state Coulomb friction leaves converges
#: slowly in the step, observed order 0.4), largest force 0.086 N (5.8x), settled height 1.26e-6 m (8x); static: 0.
TOL = {
    "F1_amp": 5e-5, "HD_amp": 5e-5, "F1_phase": 1.0, "HD_phase": 1.0,
    "Fc_mean": 0.5, "Fc_std": 1.0, "loss_pct": 0.5,
    "Fc_settled": 1.0, "Fc_max": 0.5, "y_d_settled": 1e-5,
}

UNITS = {"F1_amp": "m", "HD_amp": "m", "F1_phase": "deg", "HD_phase": "deg", "Fc_mean": "N", "Fc_std": "N",
         "loss_pct": "%", "Fc_settled": "N", "Fc_max": "N", "y_d_settled": "m"}

DOCS = {
    "F1_amp": "amplitude of F1 at the forcing frequency (whole periods after t_settle)",
    "HD_amp": "amplitude of HD at the forcing frequency (whole periods after t_settle)",
    "F1_phase": "phase of F1 relative to the ram at the forcing frequency",
    "HD_phase": "phase of HD relative to the ram at the forcing frequency",
    "Fc_mean": "mean contact force over the whole periods after t_settle",
    "Fc_std": "standard deviation of the contact force over the whole periods after t_settle",
    "loss_pct": "share of the whole periods after t_settle without contact",
    "Fc_settled": "mean contact force after t_settle",
    "Fc_max": "largest contact force after the step (parabola through the largest sample and its neighbours)",
    "y_d_settled": "mean contact height after t_settle",
}

#: the signals each kind of input's headlines read
NEEDS = {"sine": ("F1", "HD", "y_w", "contact_force"), "step": ("contact_force", "y_d"),
         "static": ("contact_force", "y_d")}


def names(scene: Any) -> tuple[str, ...]:
    """The headline names of a time run of `scene` (module docstring)."""
    kind = scene.input.get("type", "sine")
    if kind == "sine":
        base = ("F1_amp", "F1_phase", "HD_amp", "HD_phase", "Fc_mean", "Fc_std")
        return (*base, "loss_pct") if scene.effects.get("contact") == "unilateral" else base
    if kind == "step":
        return ("Fc_settled", "Fc_max", "y_d_settled")
    return ("Fc_settled", "y_d_settled")


def headlines(scene: Any) -> tuple[Headline, ...]:
    """The scene's headlines with their tolerances: a time run's, or a frequency response's if the scene carries a
    `[freqresp]` section."""
    if scene.sections.get("freqresp"):
        from .freqresp import estimate_headlines

        return estimate_headlines(scene)
    return tuple(Headline(n, UNITS[n], TOL[n], DOCS[n]) for n in names(scene))


def _settle(scene: Any) -> float:
    s = scene.solver
    return s.t_settle or 0.5 * s.duration


def _signal(res: Any, name: str, need: tuple[str, ...]) -> np.ndarray:
    if name not in res.signals:
        raise SceneError(f"the pantograph's headline outputs need the output signals {list(need)}; {name!r} is not in "
                         f"this run's outputs {sorted(res.signals)} (add it to [outputs] signals)")
    return np.asarray(res.signals[name], float)


def phase_deg(c: complex, c_in: complex) -> float:
    """Phase of the complex amplitude `c` relative to the input's `c_in`, degrees in (-180, 180]."""
    return math.degrees(math.atan2((c / c_in).imag, (c / c_in).real))


def loss_share(t: np.ndarray, u: np.ndarray) -> float:
    """Share of the span of `t` in which the unclipped contact force `u` is negative, each crossing located by linear
    interpolation between its samples (second order in the sample spacing, not limited to it)."""
    lost = 0.0
    for k in range(t.size - 1):
        a, b = u[k], u[k + 1]
        dt = t[k + 1] - t[k]
        if a < 0 and b < 0:
            lost += dt
        elif (a < 0) != (b < 0):
            x = a / (a - b)  # where the linear interpolant crosses zero, as a fraction of the interval
            lost += x * dt if a < 0 else (1.0 - x) * dt
    return lost / (t[-1] - t[0])


def peak_of_samples(t: np.ndarray, y: np.ndarray) -> float:
    """The largest value of a sampled signal: the vertex of the parabola through its largest sample and their
    neighbours (third order in the spacing for a smooth maximum), the sample itself at the record's ends."""
    i = int(np.argmax(y))
    if i == 0 or i == y.size - 1:
        return float(y[i])
    y0, y1, y2 = y[i - 1], y[i], y[i + 1]
    den = y0 - 2.0 * y1 + y2
    if den >= 0:
        return float(y1)
    off = 0.5 * (y0 - y2) / den
    return float(y1 - 0.25 * (y0 - y2) * off)


def values(scene: Any, res: Any) -> dict[str, float]:
    """The headline values of a time run's result (module docstring)."""
    if scene.sections.get("freqresp"):
        raise SceneError("a scene with a [freqresp] section is a frequency-response job (freqresp.estimate_values "
                         "gives its headline values), not a time run: remove the section to estimate a time run")
    kind = scene.input.get("type", "sine")
    need = NEEDS[kind]
    t = np.asarray(res.t, float)
    ts = _settle(scene)
    fc = _signal(res, "contact_force", need)
    if kind == "sine":
        f = float(scene.input["frequency"])
        c_in = fundamental(t, _signal(res, "y_w", need), f, ts)
        out = {}
        for s in ("F1", "HD"):
            c = fundamental(t, _signal(res, s, need), f, ts)
            out[f"{s}_amp"], out[f"{s}_phase"] = abs(c), phase_deg(c, c_in)
        m = whole_period_window(t, f, ts)
        out["Fc_mean"], out["Fc_std"] = float(np.mean(fc[m])), float(np.std(fc[m]))
        if scene.effects.get("contact") == "unilateral":
            ks = scene.build_params().ks
            y_d = _signal(res, "y_d", (*need, "y_d"))
            out["loss_pct"] = 100.0 * loss_share(t[m], ks * (y_d[m] - _signal(res, "y_w", need)[m]))
        return out
    m = t >= ts
    out = {"Fc_settled": float(np.mean(fc[m])), "y_d_settled": float(np.mean(_signal(res, "y_d", need)[m]))}
    if kind == "step":
        after = t >= float(scene.input["t_step"])
        out["Fc_max"] = peak_of_samples(t[after], fc[after])
    return out


def refinement(scene: Any) -> Refinement:
    """MuJoCo: halve the step at the integrator's order; reference: rtol / 10. A frequency response refines the
    setting of the method its `[freqresp]` section names."""
    fr = scene.sections.get("freqresp")
    engine = fr["method"] if fr else scene.solver.engine
    if engine == "mujoco":
        return timestep_refinement(ORDER[scene.solver.integrator])
    return rtol_refinement()
