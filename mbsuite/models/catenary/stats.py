"""EN 50318 statistics of a coupled run, as the model README states them.

- The contact force is low-pass filtered at 20 Hz by a 4th-order Butterworth applied forwards and backwards (zero
  phase, `scipy.signal.sosfiltfilt`) on the whole record, then windowed to x in [240, 360] m.
- Fm, sigma (population standard deviation), Fm +/- 3 sigma, actual max/min: on the filtered force in the window.
- Percentage of contact loss and the loss events: on the unfiltered force in the window. Events are classed by
  duration as the thesis quotes Peters: short arcs < 5 ms, damaging 5-20 ms, power loss > 20 ms.
- Uplift: the largest CW displacement from its static position at the steady arms inside the window (x = 240, 300,
  360 m), over the whole run.
- Section insulators (`insulator_statistics`, only on a line with some on a contact wire): the filtered force's mean,
  max and min and the unfiltered force's max, min and losses while the head is on each one.
"""

from __future__ import annotations

import numpy as np

from ...errors import SolverError
from ...statistics import Statistic
from .mesh import line_of
from .params import CatenaryParams

#: EN 50318:2002 accepted ranges (catenary.md), speed (km/h) -> statistic -> (low, high); units N, mm, %
ACCEPTED_RANGES: dict[int, dict[str, tuple[float, float]]] = {
    250: {"Fm": (110, 120), "sigma": (26, 31), "stat_max": (190, 210), "stat_min": (20, 40), "max": (175, 210),
          "min": (50, 75), "uplift_mm": (48, 55), "loss_pct": (0, 0)},
    300: {"Fm": (110, 120), "sigma": (32, 40), "stat_max": (210, 230), "stat_min": (-5, 20), "max": (190, 225),
          "min": (30, 55), "uplift_mm": (55, 65), "loss_pct": (0, 0)},
}
STAT_NAMES = {"Fm": "mean contact force Fm (N)", "sigma": "standard deviation sigma (N)",
              "stat_max": "statistical max Fm+3sigma (N)", "stat_min": "statistical min Fm-3sigma (N)",
              "max": "actual max (N)", "min": "actual min (N)", "uplift_mm": "max uplift at support (mm)",
              "loss_pct": "percentage of contact loss (%)"}
#: the window of the statistics (EN 50318:2002, 6.2: the middle spans of the reference line)
WINDOW = "the statistics window [params.window_start, params.window_end] (EN 50318: the middle two spans)"
_FILTERED = "the contact force low-pass filtered at 20 Hz (4th-order Butterworth, zero phase; EN 50318 6.2)"
_PER = "p{k}_{name}"  # a train's pantograph k = 1, 2, ... (leading first)
#: the statistics of a passage (`SPEC.statistics`; `SimResult.statistics`), per pantograph in a train
STATISTICS: dict[str, Statistic] = {
    "Fm": Statistic("N", f"mean of {_FILTERED}", WINDOW, per=_PER),
    "sigma": Statistic("N", f"population standard deviation of {_FILTERED}", WINDOW, per=_PER),
    "stat_max": Statistic("N", "statistical maximum Fm + 3 sigma", WINDOW, per=_PER),
    "stat_min": Statistic("N", "statistical minimum Fm - 3 sigma", WINDOW, per=_PER),
    "max": Statistic("N", f"largest sample of {_FILTERED}", WINDOW, per=_PER),
    "min": Statistic("N", f"smallest sample of {_FILTERED}", WINDOW, per=_PER),
    "uplift_mm": Statistic("mm", "largest contact-wire rise above its static position at the steady arms inside the "
                                 "window", "the whole run, at the supports inside the window", per=_PER),
    "loss_pct": Statistic("%", "share of the samples with zero (unfiltered) contact force", WINDOW, per=_PER),
    "static_contact_force": Statistic("N", "contact force of the static equilibrium of pantograph and line before "
                                           "the passage", "the start of the run", per=_PER),
    "quality_pass": Statistic("-", "every EN 50367 / TSI Energy criterion of the scene's [quality] section met",
                              WINDOW, kind="verdict", per=_PER),
    **{f"quality_{c}_pass": Statistic("-", f"the EN 50367 criterion {c} met ([quality] limits)", WINDOW,
                                      kind="verdict")
       for c in ("mean_force", "sigma", "stat_min", "contact_loss", "arcing_nq", "uplift")},
    "quality_nq_pct": Statistic("%", "arcing measure NQ: summed durations of the losses of at least "
                                     "[quality] arc_min_duration over the window's time (EN 50367)", WINDOW),
}
LOSS_CLASSES = (("short_lt_5ms", 0.0, 0.005), ("damaging_5_20ms", 0.005, 0.020), ("power_loss_gt_20ms", 0.020, np.inf))


def lowpass(force: np.ndarray, dt: float, cutoff: float, order: int) -> np.ndarray:
    """Zero-phase Butterworth low-pass (forwards and backwards) of a uniformly sampled force."""
    from scipy.signal import butter, sosfiltfilt  # here: scipy.signal costs ~0.5 s to import, the model list needs none

    fs = 1.0 / dt
    if not cutoff < fs / 2:
        raise SolverError(f"filter cut-off {cutoff} Hz is not below the Nyquist frequency {fs / 2} Hz of the record")
    sos = butter(order, cutoff, fs=fs, output="sos")
    if force.size <= 3 * (2 * sos.shape[0] + 1):
        raise SolverError(f"the force record ({force.size} samples) is too short to filter (at least "
                          f"{3 * (2 * sos.shape[0] + 1) + 1} samples); lengthen the run [params.x_start, "
                          "params.x_end] or reduce solver.timestep")
    return sosfiltfilt(sos, force)


def loss_events(t: np.ndarray, x: np.ndarray, force: np.ndarray, dt: float) -> list[dict]:
    """Contact-loss events (force == 0) with start time/position and duration (s)."""
    lost = force <= 0.0
    if not lost.any():
        return []
    d = np.diff(lost.astype(np.int8), prepend=0, append=0)
    starts = np.nonzero(d == 1)[0]
    ends = np.nonzero(d == -1)[0]
    out = []
    for s, e in zip(starts, ends, strict=True):
        dur = (e - s) * dt
        cls = next(name for name, lo, hi in LOSS_CLASSES if lo <= dur < hi)
        out.append({"kind": "contact_loss", "t_start": float(t[s]), "x_start": float(x[s]), "duration": float(dur),
                    "class": cls})
    return out


def in_window(x: np.ndarray, p: CatenaryParams) -> np.ndarray:
    """The samples in the statistics window [window_start, window_end]. A sample within 1e-3 of the sample spacing of
    an edge counts as on it: a sample that falls on an edge in exact arithmetic (x = V k dt = 240 m) lies a last bit
    to either side depending on the machine and on a 1e-12 change of V or dt, and would enter or leave the window."""
    tol = 1e-3 * float(np.median(np.abs(np.diff(x)))) if x.size > 1 else 0.0
    return (x >= p.window_start - tol) & (x <= p.window_end + tol)


def supports_in_window(support_x: np.ndarray, p: CatenaryParams) -> np.ndarray:
    """The supports whose steady arms count for the uplift: inside the window, a support within 1e-6 of a span of an
    edge (the window [240, 360] m starts and ends on supports) counting as on it, whatever its last bits."""
    tol = 1e-6 * p.span_length
    return (support_x >= p.window_start - tol) & (support_x <= p.window_end + tol)


def en50318_statistics(t: np.ndarray, x: np.ndarray, force: np.ndarray, uplift: np.ndarray, support_x: np.ndarray,
                       dt: float, p: CatenaryParams, names: list[str] | None = None,
                       ff: np.ndarray | None = None) -> dict:
    """The eight EN 50318 statistics plus loss events (module docstring). `uplift` is (n_samples, n_supports) (m);
    `names` names its columns (default: the support's x, "%g"; NaN where its section was no longer stepped, every
    pantograph having passed it, `CatenaryParams.step_sections`); `ff` the filtered force if already at hand."""
    ff = lowpass(force, dt, p.filter_cutoff, p.filter_order) if ff is None else ff
    w = in_window(x, p)
    if w.sum() < 2:
        raise SolverError(f"the statistics window [params.window_start, params.window_end] = [{p.window_start:g}, "
                          f"{p.window_end:g}] m holds {int(w.sum())} sample(s) at solver.timestep = {dt:g} s; it "
                          "needs at least two: widen the window or reduce the timestep")
    fw = ff[w]
    fm, sd = float(fw.mean()), float(fw.std())
    sup = supports_in_window(support_x, p)
    up = uplift[:, sup]
    events = loss_events(t[w], x[w], force[w], dt)
    counts = {name: sum(1 for ev in events if ev["class"] == name) for name, _, _ in LOSS_CLASSES}
    return {
        "Fm": fm, "sigma": sd, "stat_max": fm + 3 * sd, "stat_min": fm - 3 * sd,
        "max": float(fw.max()), "min": float(fw.min()),
        "uplift_mm": float(1000 * np.nanmax(up)) if up.size else 0.0,
        "loss_pct": float(100.0 * np.mean(force[w] <= 0.0)),
        "uplift_at_supports_mm": {(f"{xs:g}" if names is None else names[i]): float(1000 * np.nanmax(up[:, j]))
                                  for j, (i, xs) in enumerate(zip(np.nonzero(sup)[0], support_x[sup], strict=True))},
        "loss_events": events, "loss_counts": counts,
        "n_samples_window": int(w.sum()),
    }, ff


def check_ranges(stats: dict, speed_kmh: float) -> dict[str, dict] | None:
    """Each statistic against the accepted range for this speed (None if the speed has no published range)."""
    key = int(round(speed_kmh))
    if abs(speed_kmh - key) > 1e-9 or key not in ACCEPTED_RANGES:
        return None
    out = {}
    for name, (lo, hi) in ACCEPTED_RANGES[key].items():
        v = stats[name]
        out[name] = {"value": v, "low": lo, "high": hi, "inside": bool(lo - 1e-12 <= v <= hi + 1e-12)}
    return out


def window_statistics(t: np.ndarray, x: np.ndarray, force: np.ndarray, ff: np.ndarray, uplift: np.ndarray,
                      support_x: np.ndarray, dt: float, p: CatenaryParams, names: list[str] | None = None,
                      wires: dict[str, dict[str, np.ndarray]] | None = None) -> dict[str, dict]:
    """The statistics of each window of `p.windows` ("<start>-<end>" m): the eight EN 50318 statistics of the same
    filtered force `ff` (the uplift at the steady arms of every contact wire at the window's supports), and on a
    route (`wires`: each contact wire's own record) each contact wire's own (`wire_statistics`) where it is under
    the head in that window."""
    import dataclasses

    out = {}
    wff = {n: lowpass(w["force"], dt, p.filter_cutoff, p.filter_order) for n, w in (wires or {}).items()}  # once
    for a, b in p.windows:
        q = dataclasses.replace(p, window_start=float(a), window_end=float(b), windows=())
        s, _ = en50318_statistics(t, x, force, uplift, support_x, dt, q, names, ff)
        if wires:
            s["wires"] = {n: wire_statistics(t, x, w["force"], w["on"], dt, q, wff[n]) for n, w in wires.items()
                          if np.sum(w["on"] & in_window(x, q)) > 1}  # a wire whose end is the window's edge: not
        out[f"{a:g}-{b:g}"] = s
    return out


def wire_statistics(t: np.ndarray, x: np.ndarray, force: np.ndarray, on: np.ndarray, dt: float,
                    p: CatenaryParams, ff: np.ndarray | None = None) -> dict:
    """One contact wire's own contact force in the window of `p` (a route's wire through an overlap): its force
    filtered as the head's (zero off its x-range), Fm, sigma, max, min of that filtered force over the window's
    samples on the wire, `contact_pct` (share of those samples with force > 0, unfiltered), the loss events where the
    wire had carried force before (its contact ends), where its contact starts and ends (`x_first_contact`,
    `x_last_contact`, m) and its impulse over the window (N s). `ff`: that filtered force if already at hand."""
    ff = lowpass(force, dt, p.filter_cutoff, p.filter_order) if ff is None else ff
    w = in_window(x, p) & on
    fw = ff[w]
    touched = np.maximum.accumulate(force > 0.0)  # contact losses count once the wire has carried the head
    events = loss_events(t[w & touched], x[w & touched], force[w & touched], dt) if np.any(w & touched) else []
    return {"Fm": float(fw.mean()), "sigma": float(fw.std()), "max": float(fw.max()), "min": float(fw.min()),
            "contact_pct": float(100.0 * np.mean(force[w] > 0.0)), "loss_events": events,
            "x_first_contact": float(x[w][np.argmax(force[w] > 0.0)]) if np.any(force[w] > 0.0) else None,
            "x_last_contact": float(x[w][len(x[w]) - 1 - np.argmax(force[w][::-1] > 0.0)])
            if np.any(force[w] > 0.0) else None,
            "impulse_Ns": float(np.sum(force[w]) * dt)}


def insulator_statistics(t: np.ndarray, x: np.ndarray, force: np.ndarray, ff: np.ndarray, dt: float,
                         p: CatenaryParams, wires: dict[str, dict[str, np.ndarray]] | None = None) -> dict[str, dict]:
    """The contact force at each section insulator on a contact wire (`line.SectionInsulator`, model README "Section
    insulators and point masses"), keyed "<wire>@<x>" (x its centre, "%g" m): over the samples whose head position x
    lies on [x_a, x_b] (`x_range`), the mean, max and min of the 20 Hz filtered force `ff` (`Fm`, `max`, `min`), the
    max and min of the unfiltered force (`raw_max`, `raw_min`), the share of those samples with zero unfiltered force
    (`loss_pct`), the loss events there (`n_losses`), `n_samples` (0, and None values, where the run does not pass
    it) and `whole` (False where the run starts or ends on it: the numbers then cover only the part run). On a route
    (`wires`: each contact wire's own record) the insulator's own wire's force, filtered as the head's.
    Empty for a line without insulators on its contact wires."""
    line = line_of(p)
    contact = {w.name for w in line.contacts}
    out = {}
    for s in line.insulators:
        if s.wire not in contact:
            continue
        f, fl = force, ff
        if wires and s.wire in wires:
            f = wires[s.wire]["force"]
            fl = lowpass(f, dt, p.filter_cutoff, p.filter_order)
        on = (x >= s.xa) & (x <= s.xb)
        passed = bool(x.size and x[0] <= s.xa and x[-1] >= s.xb)  # the run covers the whole insulator
        d: dict = {"wire": s.wire, "x": s.x, "x_range": [s.xa, s.xb], "n_samples": int(on.sum()), "whole": passed}
        if on.any():
            fo = fl[on]
            events = loss_events(t[on], x[on], f[on], dt)
            d.update({"Fm": float(fo.mean()), "max": float(fo.max()), "min": float(fo.min()),
                      "raw_max": float(f[on].max()), "raw_min": float(f[on].min()),
                      "loss_pct": float(100.0 * np.mean(f[on] <= 0.0)), "n_losses": len(events)})
        else:
            d.update(dict.fromkeys(("Fm", "max", "min", "raw_max", "raw_min", "loss_pct", "n_losses")))
        out[f"{s.wire}@{s.x:g}"] = d
    return out
