"""The time signals evaluate identically in Python and in the native core (shapes, schedules and inputs of the
models are evaluated by C inside the step loop and by numpy in the hand-derived paths)."""

import ctypes
import math

import numpy as np
import pytest

from mbsuite.engines import native
from mbsuite.engines.inputs import Constant, Pulse, Ramp, Sine, Step, Table
from mbsuite.errors import ParameterError

SIGNALS = [
    Constant(2.5),
    Step(height=-3.0, offset=1.0, t0=0.4),
    Sine(amplitude=10.0, frequency=5.0, phase=0.3, offset=-1.0, t0=0.1),
    Ramp(height=2.0, duration=0.7, offset=0.5, t0=0.2),
    Ramp(height=2.0, duration=0.0, offset=0.5, t0=0.2),
    Pulse(amplitude=4.0, width=0.3, period=0.25, offset=1.0, t0=0.1, n=3),
    Pulse(amplitude=4.0, width=0.5, period=0.2),
    Table((0.0, 0.5, 0.5, 1.2), (1.0, 2.0, -1.0, 3.0)),
]


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: type(s).__name__)
def test_python_and_native_evaluations_agree(sig):
    lib = native.load()
    rng = np.random.default_rng(3)
    ts = np.concatenate([rng.uniform(-0.5, 2.0, 400), [0.0, 0.1, 0.2, 0.4, 0.5, 0.9, 1.2, 2.0]])
    spec = sig.spec()
    ptr = spec.ctypes.data_as(ctypes.c_void_p)
    c = np.array([lib.mbs_signal(ptr, float(t)) for t in ts])
    py = sig(ts)
    assert np.max(np.abs(c - py)) <= 1e-15 * max(1.0, np.max(np.abs(py)))


def test_signal_closed_forms():
    """Hand values: a sine at a quarter period, a ramp midway, the third pulse and after the last one."""
    assert Sine(amplitude=2.0, frequency=0.5)(0.5) == pytest.approx(2.0, abs=1e-15)
    assert Ramp(height=4.0, duration=2.0, t0=1.0)(2.0) == 2.0
    p = Pulse(amplitude=1.0, width=0.5, period=1.0, n=3)
    assert [p(t) for t in (0.25, 0.75, 2.25, 3.25)] == [1.0, 0.0, 1.0, 0.0]


def test_bad_signal_parameters_are_named():
    with pytest.raises(ParameterError, match="frequency"):
        Sine(frequency=float("nan"))
    with pytest.raises(ParameterError, match="width"):
        Pulse(width=1.5)
    with pytest.raises(ParameterError, match="non-decreasing"):
        Table((1.0, 0.0), (0.0, 1.0))


# Hand values of every kind at non-default parameters, (signal, [(t, value)]): the formulas of the Modelica sources
# written out by hand (offset before t0, the shape after), at the switching instants and between them.
CLOSED_FORMS = [
    (Constant(-7.25), [(-1.0, -7.25), (0.0, -7.25), (3.0, -7.25)]),
    # offset 1, height -3 from t0 = 0.4 on: 1 before, 1 - 3 = -2 from t0 (t0 itself included)
    (Step(height=-3.0, offset=1.0, t0=0.4), [(0.0, 1.0), (0.3999, 1.0), (0.4, -2.0), (5.0, -2.0)]),
    # -1 + 10 sin(2 pi 5 (t - 0.1) + 0.3): t0 -> -1 + 10 sin 0.3; a quarter period later (0.05 s) -> -1 + 10 cos 0.3
    (Sine(amplitude=10.0, frequency=5.0, phase=0.3, offset=-1.0, t0=0.1),
     [(0.0, -1.0), (0.1, -1.0 + 10.0 * math.sin(0.3)), (0.15, -1.0 + 10.0 * math.cos(0.3)),
      (0.2, -1.0 - 10.0 * math.sin(0.3)), (0.3, -1.0 + 10.0 * math.sin(0.3))]),
    # 0.5 before 0.2, rising by 2 over 0.7 s, held at 2.5 from 0.9
    (Ramp(height=2.0, duration=0.7, offset=0.5, t0=0.2),
     [(0.0, 0.5), (0.2, 0.5), (0.375, 1.0), (0.55, 1.5), (0.9, 2.5), (4.0, 2.5)]),
    (Ramp(height=2.0, duration=0.0, offset=0.5, t0=0.2), [(0.1999, 0.5), (0.2, 2.5), (1.0, 2.5)]),
    # 1 + 4 during the first 30 % (0.075 s) of each 0.25 s period from 0.1, three periods: on [0.1, 0.175),
    # [0.35, 0.425), [0.6, 0.675); off after the third period, and off before t0
    (Pulse(amplitude=4.0, width=0.3, period=0.25, offset=1.0, t0=0.1, n=3),
     [(0.0, 1.0), (0.1, 5.0), (0.17, 5.0), (0.18, 1.0), (0.36, 5.0), (0.5, 1.0), (0.61, 5.0), (0.7, 1.0),
      (0.86, 1.0), (1.11, 1.0), (2.0, 1.0)]),
    # linear through (0, 1), (0.5, 2), then a jump to -1 at 0.5, linear to (1.2, 3), held outside
    (Table((0.0, 0.5, 0.5, 1.2), (1.0, 2.0, -1.0, 3.0)),
     [(-1.0, 1.0), (0.25, 1.5), (0.85, 1.0), (1.2, 3.0), (2.0, 3.0)]),
]


@pytest.mark.parametrize("sig, values", CLOSED_FORMS, ids=lambda x: type(x).__name__ if hasattr(x, "spec") else "")
def test_each_kind_in_c_and_in_python_equals_its_closed_form(sig, values):
    """Both evaluations of every kind against hand values (the Python-vs-C test cannot see a defect the two share):
    measured 1.25e-14 (the sine a whole period on: 2 pi + 0.3 rounded, times the amplitude 10); bound 5e-14, 4x."""
    lib = native.load()
    spec = sig.spec()
    ptr = spec.ctypes.data_as(ctypes.c_void_p)
    for t, want in values:
        assert sig(t) == pytest.approx(want, abs=5e-14), (t, "python")
        assert lib.mbs_signal(ptr, t) == pytest.approx(want, abs=5e-14), (t, "C")
