"""The EN 50318 statistics on constructed records whose answers are known by hand: the filtered force (a zero-phase
Butterworth passes a sinusoid scaled by |H(f)|^2 with no phase), mean, standard deviation,
actual max/min in the window only, the uplift at the window's steady arms, and the contact-loss events counted and
classed by hand. Non-default filter cut-off and order, window and span."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.stats import en50318_statistics

DT, V = 1e-3, 50.0
#: 4 spans of 25 m (supports 0, 25, 50, 75, 100 m), window 40-80 m (t 0.8-1.6 s): the arms at 50 and 75 m count
P = CatenaryParams(n_spans=4, span_length=25.0, dropper_positions=[5.0, 12.5, 20.0], x_end=100.0, window_start=40.0,
                   window_end=80.0, filter_cutoff=15.0, filter_order=3)
T = DT * np.arange(2001)
X = V * T
SUPPORTS = np.array([0.0, 25.0, 50.0, 75.0, 100.0])
#: uplift peaks (m) as the pantograph passes each arm; the largest ones lie outside the window
PEAKS = np.array([0.09, 0.03, 0.05, 0.045, 0.08])
UPLIFT = PEAKS[None, :] * np.exp(-(((X[:, None] - SUPPORTS[None, :]) / 5.0) ** 2))


def _gain(f: float) -> float:
    """|H(f)|^2 of P's digital Butterworth low-pass (bilinear transform, cut-off prewarped) applied forwards and
    backwards: 1 / (1 + (tan(pi f dt) / tan(pi f_c dt))^(2n))."""
    return 1.0 / (1.0 + (np.tan(np.pi * f * DT) / np.tan(np.pi * P.filter_cutoff * DT)) ** (2 * P.filter_order))


def test_filtered_statistics_of_a_constructed_force():
    """F = 100 + 20 sin(2 pi 1.5 t) + 10 sin(2 pi 40 t) N, with a 60 N bump before the window and a 60 N dip after it
    (both far outside it: the actual max/min are the window's). In the window the filtered force is 100 +
    20 |H(1.5)|^2 sin + 10 |H(40)|^2 sin (0.027 N left of the 40 Hz part): measured 7.4e-6 N; bound 7.5e-5 N (10x;
    the default 4th order is 0.023 N off, the default 20 Hz cut-off 0.12 N). Fm, sigma (population), max, min and
    Fm +/- 3 sigma from that signal with numpy: measured <= 1.9e-7 N; bound 2e-6 N (10x; a sample standard deviation
    is 0.009 N off). The uplift: the largest of the window's arms over the whole run, per arm (measured exact; bound
    1e-12 mm)."""
    F = (100 + 20 * np.sin(2 * np.pi * 1.5 * T) + 10 * np.sin(2 * np.pi * 40 * T)
         + 60 * np.exp(-(((T - 0.2) / 0.1) ** 2)) - 60 * np.exp(-(((T - 1.9) / 0.05) ** 2)))
    s, ff = en50318_statistics(T, X, F, UPLIFT, SUPPORTS, DT, P)
    w = (X >= 40.0 - 1e-9) & (X <= 80.0 + 1e-9)
    ref = 100 + 20 * _gain(1.5) * np.sin(2 * np.pi * 1.5 * T[w]) + 10 * _gain(40.0) * np.sin(2 * np.pi * 40 * T[w])
    assert s["n_samples_window"] == 801
    assert np.max(np.abs(ff[w] - ref)) < 7.5e-5
    fm, sd = ref.mean(), ref.std()
    expect = {"Fm": fm, "sigma": sd, "stat_max": fm + 3 * sd, "stat_min": fm - 3 * sd, "max": ref.max(),
              "min": ref.min()}
    for k, v in expect.items():
        assert s[k] == pytest.approx(v, abs=2e-6), k
    assert F.max() > s["max"] + 30 and F.min() < s["min"] - 30  # the record outside the window goes further
    assert s["uplift_mm"] == pytest.approx(50.0, abs=1e-12)
    assert s["uplift_at_supports_mm"] == pytest.approx({"50": 50.0, "75": 45.0}, abs=1e-12)
    assert s["loss_pct"] == 0.0 and s["loss_events"] == []


def test_contact_loss_events_counted_by_hand():
    """A constant 100 N with the force at zero for 3, 12 and 25 samples inside the window (at 1 ms: one short arc,
    one damaging loss, one power loss, Peters' classes < 5 ms, 5-20 ms, > 20 ms) and for 30 samples before it: three
    events with their start times, positions and durations, 40 lost samples of the window's 801, and no event from
    outside the window."""
    F = np.full(T.size, 100.0)
    runs = {300: 30, 900: 3, 1100: 12, 1400: 25}  # first sample -> length
    for i0, n in runs.items():
        F[i0:i0 + n] = 0.0
    s, _ = en50318_statistics(T, X, F, UPLIFT, SUPPORTS, DT, P)
    ev = s["loss_events"]
    assert [e["class"] for e in ev] == ["short_lt_5ms", "damaging_5_20ms", "power_loss_gt_20ms"]
    assert [e["duration"] for e in ev] == pytest.approx([0.003, 0.012, 0.025], abs=1e-12)
    assert [e["t_start"] for e in ev] == pytest.approx([0.9, 1.1, 1.4], abs=1e-12)
    assert [e["x_start"] for e in ev] == pytest.approx([45.0, 55.0, 70.0], abs=1e-9)
    assert s["loss_counts"] == {"short_lt_5ms": 1, "damaging_5_20ms": 1, "power_loss_gt_20ms": 1}
    assert s["loss_pct"] == pytest.approx(100 * 40 / 801, rel=1e-12)


def test_uplift_charged_to_a_pantograph_of_a_train_only_near_the_arm():
    """On a train each pantograph is charged with a steady arm's uplift only while it is within 30 m of it (the model
    README): a constructed record where the arm at 50 m is lifted 80 mm while this pantograph is at 10 m (another
    pantograph passing it) and 40 mm when this one passes; the arm at 75 m 60 mm while it is at 20 m and 30 mm when it
    passes. Charged: 40 and 30 mm (measured exact; bound 1e-12 mm); alone, the whole record counts (80 and 60 mm)."""
    from mbsuite.models.catenary.passage import CoupledResult
    from mbsuite.models.catenary.train import _statistics

    def bump(xc: float, a: float) -> np.ndarray:
        return a * np.exp(-(((X - xc) / 3.0) ** 2))

    up = np.zeros((T.size, SUPPORTS.size))
    up[:, 2] = bump(10.0, 0.08) + bump(50.0, 0.04)
    up[:, 3] = bump(20.0, 0.06) + bump(75.0, 0.03)
    res = CoupledResult(t=T, x=X, force=np.full(T.size, 100.0), head=np.zeros(T.size), wire=np.zeros(T.size),
                        uplift=up, n_slack=np.zeros(T.size, dtype=np.int32), panto={}, support_x=SUPPORTS)
    train, _ = _statistics(res, DT, P, alone=False)
    assert train["uplift_at_supports_mm"] == pytest.approx({"50": 40.0, "75": 30.0}, abs=1e-12)
    assert train["uplift_mm"] == pytest.approx(40.0, abs=1e-12)
    single, _ = _statistics(res, DT, P, alone=True)
    assert single["uplift_at_supports_mm"] == pytest.approx({"50": 80.0, "75": 60.0}, abs=1e-12)
