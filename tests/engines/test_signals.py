"""The time signals evaluate identically in Python and in the native core (shapes, schedules and inputs of the
models are evaluated by C inside the step loop and by numpy in the hand-derived paths)."""

import ctypes

import numpy as np
import pytest

from mbsuite.engines import native
from mbsuite.engines.signals import Constant, Pulse, Ramp, Sine, Step, Table
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
