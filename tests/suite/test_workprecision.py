"""The work-precision machinery: the cheapest-setting table is right and a model without a study is a clear error.
(Each model's own study is tested with the model: tests/<model>/test_workprecision.py.)"""

from __future__ import annotations

import math

import pytest

from mbsuite import load_scene
from mbsuite.analysis.workprecision import Row, cheapest, workprecision


def test_cheapest_picks_the_fastest_row_meeting_each_tolerance():
    rows = [Row("a", "x", 1, 1.0, 1.0, 1.0, 0.1, 1e-3), Row("a", "x", 2, 0.5, 0.5, 0.5, 0.1, 5e-2),
            Row("b", "y", 3, 2.0, 2.0, 2.0, 0.1, 1e-7), Row("b", "y", 4, 0.1, 0.1, 0.1, math.nan, math.nan)]
    best = {(b["tol"], b["engine"]): b for b in cheapest(rows)}
    assert best[(1e-2, "any")]["setting"] == 1  # 2 is faster but misses 1e-2; NaN never qualifies
    assert best[(1e-4, "any")]["setting"] == 3
    assert best[(1e-6, "a")]["setting"] is None


def test_unknown_model_is_a_clear_error(monkeypatch):
    """A model whose suite module declares no study (a stand-in: every model ships one) is refused by name."""
    import types

    from mbsuite import MbsuiteError
    from mbsuite.registry import ModelSpec

    monkeypatch.setattr(ModelSpec, "suite", lambda self: types.SimpleNamespace())
    with pytest.raises(MbsuiteError, match="no work-precision study for model 'catenary'"):
        workprecision(load_scene("catenary"), repeats=1, quick=True)
    monkeypatch.undo()
    with pytest.raises(MbsuiteError, match="four-bar"):
        workprecision(load_scene("iftomm/bricard"), repeats=1, quick=True)


@pytest.mark.parametrize("a, b, expect", [(1.1, 1.0, 0.1), (0.9, 1.0, 0.1), (-3.0, -2.0, 0.5), (2.0, -2.0, 2.0),
                                          (1e-310, 0.0, 1e-10)])
def test_relative_error_is_measured_against_the_reference(a, b, expect):
    """|a - b| / |b|, b the reference (a run reading 10 % high is 0.1 off, not 0.1 / 1.1); a reference of 0 divides
    by the floor 1e-300. Hand values; rounding of the decimal inputs: measured 8.3e-16 relative, bound 1e-14."""
    from mbsuite.analysis.workprecision import _rel

    assert _rel(a, b) == pytest.approx(expect, rel=1e-14)
