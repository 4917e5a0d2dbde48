"""The Eppinger pantograph (mbsuite.models.pantograph) under the FE catenary through the thin adapters."""

from __future__ import annotations

import numpy as np
import pytest

from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.eppinger import EppingerMujoco, EppingerReference
from mbsuite.models.catenary.params import CatenaryParams

P_SHORT = dict(element_length=0.5, x_end=30.0, window_start=10.0, window_end=28.0)


def test_static_uplift_from_supply_pressure_same_in_both_paths():
    f_ref = EppingerReference().static(0.0, 5.0e4)
    f_mj = EppingerMujoco(timestep=1e-4).static(0.0, 5.0e4)
    assert f_ref == pytest.approx(f_mj, abs=1e-6)
    assert 20.0 < f_ref < 300.0  # a pantograph pressing on the wire with a plausible static force
    # more supply pressure, more uplift
    assert EppingerReference({"Pg": 1.1 * 710185.0}).static(0.0, 5.0e4) > f_ref


def test_eppinger_passage_consistent_contact_and_paths_agree():
    p = CatenaryParams(**P_SHORT)
    r_ref = simulate(p, 250.0, 1e-4, pantograph=EppingerReference())
    r_mj = simulate(p, 250.0, 1e-4, pantograph=EppingerMujoco(timestep=1e-4))
    for r in (r_ref, r_mj):
        res = r.result
        assert np.all(np.isfinite(res.force))
        expect = p.k_contact * np.maximum(res.head - res.wire, 0.0)
        assert np.max(np.abs(res.force - expect)) < 1e-6 * np.max(res.force)  # consistent within each step
    assert r_ref.stats["Fm"] == pytest.approx(r_mj.stats["Fm"], abs=0.5)
    assert r_ref.stats["sigma"] == pytest.approx(r_mj.stats["sigma"], abs=0.5)


def test_pressure_for_static_force_and_pantograph_that_cannot_hold_the_wire():
    from mbsuite.errors import ParameterError
    from mbsuite.models.catenary.eppinger import pressure_for_static_force, static_force

    pg = pressure_for_static_force(120.0)
    assert static_force({"Pg": pg}) == pytest.approx(120.0, abs=1e-6)
    assert pg > 710185.0
    heavy = {"mh": 2 * 13.5}  # doubled head mass: its weight exceeds the uplift at the Table 3-I pressure
    assert static_force(heavy) < 0
    p = CatenaryParams(**P_SHORT)
    with pytest.raises(ParameterError, match="does not press on the wire"):
        simulate(p, 250.0, 1e-4, pantograph=EppingerReference(heavy))
