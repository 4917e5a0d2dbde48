"""The Modelica Rotational examples of the `rotational` model (Modelica Standard Library 4.1.0, Modelica
Association, `Modelica.Mechanics.Rotational.Examples`) as rotor systems of the shared rotor library
(`mbsuite.components.rotational`: its `components` are the MSL's Clutch, Brake, OneWayClutch, IdealPlanetary,
IdealGear and QuadraticSpeedDependentTorque).

Examples: `Friction` (3 s), `OneWayClutch` (2 s), `OneWayClutchDisengaged` (2 s), `SimpleGearShift` (5 s), each
an `Example` with its rotor system, initial state, compared signals on the reference's names and mode conventions
(CoupledClutches: `coupled_clutches.py`). Reference results (CoupledClutches, Friction, OneWayClutch): the Modelica
Association's, in the package's `data/msl/` (README there).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ...components.rotational.components import (
    brake,
    clutch,
    one_way_clutch,
    planetary_ring_row,
    quadratic_speed_torque,
)
from ...components.rotational.interfaces import RefResult, RotorSystem, Source, Spring
from ...engines.inputs import Pulse, Ramp, Sine, Step
from ...errors import ModelFileError, ParameterError

TUBE = 2.0e-3  #: the Modelica Association's regression tube: 2e-3 of each signal's range


# ---- the examples -----------------------------------------------------------------------------------------------
@dataclass
class Example:
    """One MSL example: rotor system, initial state, duration, the compared signals (reference name -> function of
    (q, w) arrays), the friction elements' names in the reference, and the reference CSV (None: none published)."""

    name: str
    system: RotorSystem
    q0: tuple[float, ...]
    w0: tuple[float, ...]
    t_end: float
    signals: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]]
    compared: tuple[str, ...]
    reference: str | None = None
    mode_columns: dict[str, str] = field(default_factory=dict)  # element -> reference mode column
    units: dict[str, str] = field(default_factory=dict)


def _sig(signals: dict[str, tuple[Callable, str]]) -> tuple[dict, dict]:
    return {k: v[0] for k, v in signals.items()}, {k: v[1] for k, v in signals.items()}


def friction_example() -> Example:
    """`Examples.Friction`: torque 200 sin(100 t) until 0.5 s -> inertia3 (J 1, w 100) -> clutch (fn_max 160,
    engaged) -> inertia2 (J 0.05, w 90) -> spring-damper (c 160, d 1) -> brake (fn_max 1600, engaged at 0.5 s, on
    the support) = inertia1 (J 1, w 90)."""
    t_off = 0.5
    f = 50.0 / math.pi  # Modelica sine f = 50/pi Hz: 200 sin(100 t)
    sources = [Source("torque", 0, 200.0, shape=Sine(frequency=f)),
               # product with step2 (1 -> 0 at 0.5 s): subtract the same sine from 0.5 s on
               Source("torque_off", 0, -200.0, shape=Sine(frequency=f, t0=t_off, phase=2 * math.pi * f * t_off))]
    system = RotorSystem(names=["inertia3", "inertia2", "inertia1"], J=np.array([1.0, 0.05, 1.0]), B=np.zeros(3),
                         springs=[Spring("spring", 1, 2, 160.0, D=1.0)],
                         frictions=[clutch("clutch", 0, 1, 160.0),
                                    brake("brake", 2, 3, 1600.0, f_normalized=Step(t0=t_off))],
                         sources=sources, breaks=[t_off])
    sig, units = _sig({
        "clutch.phi_rel": (lambda q, w: q[1] - q[0], "rad"), "clutch.w_rel": (lambda q, w: w[1] - w[0], "rad/s"),
        "inertia3.phi": (lambda q, w: q[0], "rad"), "inertia3.w": (lambda q, w: w[0], "rad/s"),
        "spring.phi_rel": (lambda q, w: q[2] - q[1], "rad"), "spring.w_rel": (lambda q, w: w[2] - w[1], "rad/s"),
        "inertia2.w": (lambda q, w: w[1], "rad/s"), "inertia1.w": (lambda q, w: w[2], "rad/s")})
    return Example("msl_friction", system, (0.0, 0.0, 0.0), (100.0, 90.0, 90.0), 3.0, sig,
                   ("clutch.phi_rel", "clutch.w_rel", "inertia3.phi", "inertia3.w", "spring.phi_rel",
                    "spring.w_rel"), "Friction_MSL-4.1.0_reference.csv",
                   {"clutch": "clutch.mode", "brake": "brake.mode"}, units)


def _one_way_signals() -> tuple[dict, dict]:
    return _sig({
        "inertiaIn.phi": (lambda q, w: q[0], "rad"), "inertiaIn.w": (lambda q, w: w[0], "rad/s"),
        "oneWayClutch.phi_rel": (lambda q, w: q[1] - q[0], "rad"),
        "oneWayClutch.w_rel": (lambda q, w: w[1] - w[0], "rad/s"), "inertiaOut.w": (lambda q, w: w[1], "rad/s")})


def one_way_clutch_example() -> Example:
    """`Examples.OneWayClutch`: torque 10 sin(6 pi t) -> inertiaIn (J 1, w -0.5) -> one-way clutch (peak 25,
    fn_max 3, engaged by a pulse: width 50 %, period 1.3 s, from 0.3 s) -> inertiaOut (J 1, w 0)."""
    pulse = Pulse(amplitude=1.0, width=0.5, period=1.3, t0=0.3)
    system = RotorSystem(names=["inertiaIn", "inertiaOut"], J=np.ones(2), B=np.zeros(2),
                         frictions=[one_way_clutch("oneWayClutch", 0, 1, 3.0, peak=25.0, f_normalized=pulse)],
                         sources=[Source("torque", 0, 10.0, shape=Sine(frequency=3.0))],
                         breaks=[0.3, 0.95, 1.6])
    sig, units = _one_way_signals()
    return Example("msl_one_way_clutch", system, (0.0, 0.0), (-0.5, 0.0), 2.0, sig,
                   ("inertiaIn.phi", "inertiaIn.w", "oneWayClutch.phi_rel", "oneWayClutch.w_rel"),
                   "OneWayClutch_MSL-4.1.0_reference.csv", {}, units)


def one_way_clutch_disengaged_example() -> Example:
    """`Examples.OneWayClutchDisengaged`: torque 0.3 + 10 sin(4 pi t) -> inertiaIn (J 1, w -0.5) -> one-way clutch
    (peak 25, fn_max 3, never engaged: f_normalized = 0) -> inertiaOut (J 1, w 0) with a load torque -0.3 N m."""
    system = RotorSystem(names=["inertiaIn", "inertiaOut"], J=np.ones(2), B=np.zeros(2),
                         frictions=[one_way_clutch("oneWayClutch", 0, 1, 3.0, peak=25.0,
                                                   f_normalized=Step(height=0.0))],
                         sources=[Source("torque", 0, 10.0, shape=Sine(frequency=2.0)),
                                  Source("torque_offset", 0, 0.3), Source("torqueLoad", 1, -0.3)])
    sig, units = _one_way_signals()
    return Example("msl_one_way_clutch_disengaged", system, (0.0, 0.0), (-0.5, 0.0), 2.0, sig,
                   ("inertiaIn.phi", "inertiaIn.w", "oneWayClutch.phi_rel", "oneWayClutch.w_rel"), None, {}, units)


RATIO_PLANETARY = 75.0 / 50.0


def simple_gear_shift_example() -> Example:
    """`Examples.SimpleGearShift`: torque step 20 N m at 0.5 s -> engine (J 1) = planetary sun; load (J 10, quadratic
    load -20 N m at 100 rpm) = carrier; ring massless, held by a brake (cgeo 2, fn_max 100, f = 1 - ramp) and
    coupled to the sun by a clutch (cgeo 2, fn_max 100, f = ramp 0 -> 1 over 2.0-2.1 s); ratio 75/50."""
    r, n = RATIO_PLANETARY, 2
    ring = planetary_ring_row(r, sun=0, carrier=1, n=n)
    sun = np.array([1.0, 0.0])
    ramp = Ramp(height=1.0, duration=0.1, t0=2.0)
    inv = Ramp(height=-1.0, duration=0.1, t0=2.0, offset=1.0)
    system = RotorSystem(names=["engine", "load"], J=np.array([1.0, 10.0]), B=np.zeros(2),
                         frictions=[clutch("clutch", 0, -1, 100.0, cgeo=2.0, f_normalized=ramp,
                                           g=tuple(ring - sun)),
                                    brake("brake", 0, n, 100.0, cgeo=2.0, f_normalized=inv, g=tuple(ring))],
                         sources=[Source("torqueStep", 0, 20.0, shape=Step(t0=0.5)),
                                  quadratic_speed_torque("quadraticSpeedDependentTorque", 1, -20.0,
                                                         10.471975511966)],
                         breaks=[0.5, 2.0, 2.1])
    sig, units = _sig({
        "engine.w": (lambda q, w: w[0], "rad/s"), "load.w": (lambda q, w: w[1], "rad/s"),
        "engine.phi": (lambda q, w: q[0], "rad"), "load.phi": (lambda q, w: q[1], "rad"),
        "clutch.w_rel": (lambda q, w: (ring - sun) @ w, "rad/s"), "brake.w": (lambda q, w: ring @ w, "rad/s")})
    return Example("msl_simple_gear_shift", system, (0.0, 0.0), (0.0, 0.0), 5.0, sig,
                   ("engine.w", "load.w", "clutch.w_rel", "brake.w"), None, {}, units)


EXAMPLES: dict[str, Callable[[], Example]] = {
    "msl_friction": friction_example,
    "msl_one_way_clutch": one_way_clutch_example,
    "msl_one_way_clutch_disengaged": one_way_clutch_disengaged_example,
    "msl_simple_gear_shift": simple_gear_shift_example,
}

#: units of every signal the examples produce (for the model's output table)
SIGNAL_UNITS: dict[str, str] = {k: u for f in EXAMPLES.values() for k, u in f().units.items()}


def example(name: str) -> Example:
    """The Modelica example `name` (one of `EXAMPLES`)."""
    if name not in EXAMPLES:
        raise ParameterError(f"unknown MSL example {name!r}; valid: {sorted(EXAMPLES)}")
    return EXAMPLES[name]()


# ---- results, references, comparisons ---------------------------------------------------------------------------
def signals_of(ex: Example, res: RefResult) -> dict[str, np.ndarray]:
    """The example's output signals from a run."""
    return {k: np.asarray(f(res.q, res.w), float) for k, f in ex.signals.items()}


def reference_path(ex: Example) -> Path:
    """Path of the example's reference result (Modelica Association, MSL 4.1.0) in the package's `data/msl/`."""
    if ex.reference is None:
        raise ModelFileError(f"{ex.name}: the Modelica Association publishes no reference result for this example")
    return data_file(ex.reference)


#: the Modelica Association's reference results, shipped inside the package (provenance and licence: README there)
DATA_DIR = Path(__file__).parent / "data" / "msl"


def data_file(name: str) -> Path:
    """A reference result in the package's `data/msl/` (a ModelFileError naming the file if it is missing)."""
    p = DATA_DIR / name
    if not p.is_file():
        raise ModelFileError(f"Modelica reference result not found: {p} (it ships inside the package in "
                             "mbsuite/models/rotational/data/msl/; a broken install?)")
    return p


def load_reference(ex: Example) -> dict[str, np.ndarray]:
    """The reference CSV as columns on their Modelica names (event rows duplicated, as published)."""
    with open(reference_path(ex)) as fh:
        names = [h.strip().strip('"') for h in fh.readline().split(",")]
    data = np.loadtxt(reference_path(ex), delimiter=",", skiprows=1)
    return {nm: data[:, i] for i, nm in enumerate(names)}


MODE_CODE = {"backward": -1, "stuck": 0, "forward": 1, "free": 2}


def reference_events(ex: Example, ref: dict[str, np.ndarray]) -> list[dict[str, Any]]:
    """Mode changes of the reference: from its mode columns; for the one-way clutch (no mode column) from w_rel:
    stuck while w_rel = 0 (|w_rel| < 1e-9 rad/s), the lock at the first such row, the release at the last."""
    t = ref["time"]
    out = []
    for el, col in ex.mode_columns.items():
        m = ref[col].astype(int)
        for i in np.nonzero(np.diff(m))[0]:
            out.append({"t": float(t[i + 1]), "element": el, "from": int(m[i]), "to": int(m[i + 1])})
    if "oneWayClutch.w_rel" in ref:
        st = (np.abs(ref["oneWayClutch.w_rel"]) < 1e-9).astype(int)
        for i in np.nonzero(np.diff(st))[0]:
            if st[i + 1]:
                out.append({"t": float(t[i + 1]), "element": "oneWayClutch", "from": 1, "to": 0})
            else:
                out.append({"t": float(t[i]), "element": "oneWayClutch", "from": 0, "to": 1})
    return sorted(out, key=lambda e: (e["t"], e["element"]))


def events_as_codes(events: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Mode changes as {t, element, from, to} with the modes as codes."""
    return [{"t": float(e["t"]), "element": e["element"], "from": MODE_CODE[e["from"]], "to": MODE_CODE[e["to"]]}
            for e in events]


def pair_events(ours: list[dict[str, Any]], ref: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Pair two event lists in order (same element and transition): rows with both times (None: unmatched)."""
    rows, pool = [], list(ours)
    for r in ref:
        o = next((x for x in pool if (x["element"], x["from"], x["to"]) == (r["element"], r["from"], r["to"])), None)
        if o is not None:
            pool.remove(o)
        rows.append({"element": r["element"], "from": r["from"], "to": r["to"], "t_ref": r["t"],
                     "t": None if o is None else o["t"]})
    rows += [{"element": o["element"], "from": o["from"], "to": o["to"], "t_ref": None, "t": o["t"]} for o in pool]
    return rows


def tube_check(ex: Example, res: RefResult, ref: dict[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """Every compared signal against the reference on the reference's time grid: the largest deviation relative to
    the regression tube TUBE x (range of the reference signal) (<= 1: inside). Ours is interpolated linearly from
    its output grid."""
    sig = signals_of(ex, res)
    t_ref = ref["time"]
    out = {}
    for k in ex.compared:
        y_ref = ref[k]
        y = np.interp(t_ref, res.t, sig[k])
        width = TUBE * float(np.ptp(y_ref))
        dev = np.abs(y - y_ref)
        i = int(np.argmax(dev))
        out[k] = {"max_dev": float(dev[i]), "tube": width, "ratio": float(dev[i] / width), "t": float(t_ref[i])}
    return out
