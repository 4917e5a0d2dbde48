"""Every mass- and inertia-like parameter declares a lower limit that refuses, by name, what MuJoCo would refuse
("mass and inertia of moving bodies must be larger than mjMINVAL", naming no parameter); at the limit MuJoCo itself
builds the model (the independent check: MuJoCo's own loader)."""

from __future__ import annotations

import dataclasses

import pytest

import mbsuite
from mbsuite.limits import limit_of
from mbsuite.registry import get_model

MODELS = ("pantograph", "coupler", "iftomm", "catenary")


def _mass_like(model: str) -> list[str]:
    cls = get_model(model).params_cls
    return [f.name for f in dataclasses.fields(cls)
            if f.metadata.get("limit") is not None and f.metadata["limit"].unit in ("kg", "kg m^2")]


CASES = [(m, k) for m in MODELS for k in _mass_like(m)] + [("coupler", "massless_factor")]


def test_the_mass_like_parameters_are_found():
    assert {m for m, _ in CASES} == {"pantograph", "coupler", "catenary"}  # iftomm's bars are fixed in its files
    assert {"m_link", "m_shaft_b", "i_shaft_a", "i_shaft_c", "i_shaft_b_axial", "i_shaft_b_trans"} <= {
        k for m, k in CASES if m == "coupler"}


@pytest.mark.parametrize("model,key", CASES)
def test_a_value_below_the_floor_is_refused_by_name_and_the_floor_builds(model, key):
    lim = limit_of(get_model(model).params_cls, key)
    assert lim.lo is not None and lim.lo > 0 and not lim.lo_open, f"{model}.{key} declares no positive floor"
    sc = mbsuite.load_scene(model)
    if key == "massless_factor":
        sc = sc.replace(effects={"link_inertia": "massless"})  # the effect that uses it
    for bad in (lim.lo / 10, 1e-12, 0.0):
        with pytest.raises(mbsuite.ParameterError, match=rf"{key} = .* set in Python \(Scene\.replace\) is invalid"):
            sc.replace(params={key: bad})
    spec = sc.spec
    if spec.mujoco_model is not None:
        # the partners of the checks across fields: A + B >= C of shaft b, the massless link's inertia
        extra = {"i_shaft_b_trans": {"i_shaft_b_axial": lim.lo}}.get(key, {})
        spec.mujoco_model(sc.replace(params={key: lim.lo, **extra}))  # MuJoCo accepts the floor


def test_the_coupler_link_inertia_floor_across_parameters():
    """A link's axial inertia m r^2 / 2 (hand-computed in the patterns) below 1e-12 kg m^2 is refused naming the
    parameters: the real link when the scene is built, the massless link (m = m_link massless_factor) when MuJoCo's
    model is built; at 1e-12 MuJoCo builds both. Shaft b's principal inertias must satisfy A + B >= C."""
    sc = mbsuite.load_scene("coupler")
    with pytest.raises(mbsuite.ParameterError, match=r"m_link = 1e-06 kg, link_radius = 0\.001 m give the real link "
                                                     r"an axial inertia .* = 5e-13 kg m\^2"):
        sc.replace(params={"m_link": 1e-6, "link_radius": 1e-3})
    sc.spec.mujoco_model(sc.replace(params={"m_link": 1e-6, "link_radius": 2e-6 ** 0.5}))
    ml = sc.replace(effects={"link_inertia": "massless"})
    with pytest.raises(mbsuite.ParameterError, match=r"m_link = 1\.0 kg, massless_factor = 1e-06, link_radius = 0\.001"
                                                     r" m give the massless link an axial inertia .* = 5e-13 kg m\^2"):
        ml.spec.mujoco_model(ml.replace(params={"m_link": 1.0, "massless_factor": 1e-6, "link_radius": 1e-3}))
    ml.spec.mujoco_model(ml.replace(params={"m_link": 1.0, "massless_factor": 1e-6, "link_radius": 2e-6 ** 0.5}))
    with pytest.raises(mbsuite.ParameterError, match=r"i_shaft_b_axial = 20\.0 kg m\^2 > 2 i_shaft_b_trans"):
        sc.replace(params={"i_shaft_b_trans": 9.0})
