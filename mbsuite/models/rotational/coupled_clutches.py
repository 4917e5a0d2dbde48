"""Modelica's `Rotational.Examples.CoupledClutches` (MSL 4.1.0) on the shared rotor library's friction machinery.

torque 10 sin(2 pi 5 t) -> J1 -> clutch1 -> J2 -> clutch2 -> J3 -> clutch3 -> J4, J1..J4 = 1 kg m^2, J1.w(0) = 10 rad/s.
Clutch k: fn = fn_max * f_norm_k(t) with fn_max = 20 N, sliding torque mu * cgeo * fn (mu = 0.5, cgeo = 1), breakaway
peak = 1.1 x sliding. f_norm_1 = sin(2 pi 0.2 t + pi/2) (released at t = 1.25 s), f_norm_2 and f_norm_3 step 0 -> 1 at
0.4 s and 0.9 s. Reference: the Modelica Association's Dymola result (MSL 4.1.0), see `reference_path()`. The schedules
and the drive torque are `mbsuite.engines.inputs` (Sine, Step), evaluated alike by the hand path and in C.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ...components.rotational.interfaces import Friction, Part, RotorSystem, Source
from ...engines.inputs import Signal, Sine, Step
from .examples import data_file

T_END = 1.5
FN_MAX = 20.0
MU = 0.5
PEAK = 1.1
F_DRIVE = 5.0


def f_norm(k: int) -> Signal:
    """Normal-force schedule of clutch k (Modelica's sin1, step1, step2), as a signal both paths evaluate alike."""
    if k == 1:
        return Sine(amplitude=1.0, frequency=0.2, phase=math.pi / 2)
    return Step(height=1.0, t0={2: 0.4, 3: 0.9}[k])


def build_system() -> RotorSystem:
    """The CoupledClutches rotor system: J1..J4 joined by clutch1..3, the sine torque on J1."""
    clutches = [
        Friction(f"clutch{k}", k - 1, k, [Part(f"clutch{k}", MU * FN_MAX, schedule=f_norm(k))], peak=PEAK)
        for k in (1, 2, 3)
    ]
    src = Source("torque", 0, 10.0, 0.0, shape=Sine(amplitude=1.0, frequency=F_DRIVE))
    return RotorSystem(names=["J1", "J2", "J3", "J4"], J=np.ones(4), B=np.zeros(4), frictions=clutches,
                       sources=[src], breaks=[0.4, 0.9, 1.25])


Q0 = (0.0, 0.0, 0.0, 0.0)
W0 = (10.0, 0.0, 0.0, 0.0)

MODE_CODE = {"backward": -1, "stuck": 0, "forward": 1, "free": 2}


REFERENCE_CSV = "CoupledClutches_MSL-4.1.0_reference.csv"


def reference_path() -> Path:
    """The Modelica Association's reference result (MSL 4.1.0), shipped inside the package in `data/msl/`
    (provenance and licence in the README there)."""
    return data_file(REFERENCE_CSV)


def load_reference(path: Path | None = None) -> dict[str, np.ndarray]:
    """The Dymola result: time, w1..w4 and the clutch modes (duplicate rows at events are kept)."""
    d = np.genfromtxt(path or reference_path(), delimiter=",", names=True)
    w1 = d["J1w"]
    w2 = w1 + d["clutch1w_rel"]
    w3 = w2 + d["clutch2w_rel"]
    w4 = w3 + d["clutch3w_rel"]
    return {"t": d["time"], "w": np.vstack([w1, w2, w3, w4]),
            "modes": np.vstack([d["clutch1mode"], d["clutch2mode"], d["clutch3mode"]]).astype(int)}


def reference_events(ref: dict[str, np.ndarray]) -> list[dict]:
    """Mode changes of the reference (event instants are duplicated rows in the CSV)."""
    out = []
    t = ref["t"]
    for k in range(3):
        m = ref["modes"][k]
        for i in np.nonzero(np.diff(m))[0]:
            out.append({"t": float(t[i + 1]), "element": f"clutch{k + 1}", "from": int(m[i]), "to": int(m[i + 1])})
    return sorted(out, key=lambda e: (e["t"], e["element"]))


def events_as_codes(events: list[dict]) -> list[dict]:
    """Mode changes as {t, element, from, to} with the modes as codes (`MODE_CODE`)."""
    return [{"t": e["t"], "element": e["element"], "from": MODE_CODE[e["from"]], "to": MODE_CODE[e["to"]]}
            for e in events]


def closed_form_early(t: np.ndarray) -> np.ndarray:
    """Exact w1, w2 for t < 0.4 s (only clutch 1 slides backward with torque 10 cos(0.4 pi t) on J1/J2).

    J1: w1' = 10 sin(10 pi t) - 10 cos(0.4 pi t); J2: w2' = +10 cos(0.4 pi t)."""
    s = 10.0 * np.sin(0.4 * np.pi * t) / (0.4 * np.pi)
    w1 = 10.0 + 10.0 * (1 - np.cos(10 * np.pi * t)) / (10 * np.pi) - s
    w2 = s
    return np.vstack([w1, w2])


def match_events(ours: list[dict], ref: list[dict]) -> list[dict]:
    """Pair event lists (same element and transition, in order); returns rows with both times."""
    rows = []
    pool = list(ours)
    for r in ref:
        cand = [o for o in pool if o["element"] == r["element"] and o["from"] == r["from"] and o["to"] == r["to"]]
        o = cand[0] if cand else None
        if o is not None:
            pool.remove(o)
        rows.append({"element": r["element"], "from": r["from"], "to": r["to"], "t_ref": r["t"],
                     "t": None if o is None else o["t"]})
    for o in pool:
        rows.append({"element": o["element"], "from": o["from"], "to": o["to"], "t_ref": None, "t": o["t"]})
    return rows
