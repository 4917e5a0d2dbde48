"""The linear pantographs under the wire (`linear_pantograph.py`): the 2-stage lumped pantograph with the reference's
parameters and the transfer-function pantograph built from the 2-mass model's exact transfer function both reproduce
the EN 50318 2-mass pantograph's passage (the catenary's own, in the compiled loop); their statics in closed form; the
`[pantograph]` section checked key by key; the shipped scenes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mbsuite import load_scene
from mbsuite.components.linear_pantograph import (
    LinearPantograph,
    LumpedParams,
    TransferParams,
    lumped,
    params_of,
    transfer,
)
from mbsuite.errors import ParameterError, SceneError
from mbsuite.models.catenary.analysis import simulate
from mbsuite.models.catenary.pantographs import TwoMassPantograph, build, validate_section
from mbsuite.models.catenary.params import CatenaryParams

P = CatenaryParams()
#: a short stretch of the EN 50318 line (0.43 s at 250 km/h), statistics over 10-28 m
SHORT = dataclasses.replace(P, x_end=P.x_start + 30.0, window_start=P.x_start + 10.0, window_end=P.x_start + 28.0)
STATS = ("Fm", "sigma", "stat_max", "stat_min", "max", "min", "uplift_mm")


def _reference_lumped() -> LumpedParams:
    return LumpedParams((P.m1, P.m2), (P.k1, P.k2), (P.c1, P.c2), P.F0)


def _two_mass_transfer() -> TransferParams:
    """The 2-mass pantograph's head receptance by hand: det = (m1 s^2 + c1 s + k1)(m2 s^2 + (c1 + c2) s + k1 + k2) -
    (c1 s + k1)^2, G = (m2 s^2 + (c1 + c2) s + k1 + k2) / det; its static uplift seen at the head is the contact force
    against a rigid wire at zero, F0 k1 / (k1 + k2)."""
    m1, k1, c1, m2, k2, c2 = P.m1, P.k1, P.c1, P.m2, P.k2, P.c2
    head, frame, link = np.array([m1, c1, k1]), np.array([m2, c1 + c2, k1 + k2]), np.array([c1, k1])
    den = np.polysub(np.polymul(head, frame), np.polymul(link, link))
    return TransferParams.from_tf(frame, den, P.F0 * k1 / (k1 + k2))


@pytest.fixture(scope="module")
def reference_run():
    return simulate(SHORT, 250.0, 2e-4)


@pytest.mark.parametrize("make", [lambda: lumped(_reference_lumped()),
                                  lambda: build("transfer", P, section={"params": _two_mass_transfer().section()})],
                         ids=["lumped", "transfer"])
def test_linear_pantographs_reproduce_the_two_mass_passage(reference_run, make):
    """The same trapezoidal rule on another realisation of the same model (Newmark on the chain, the 2-mass one-port;
    the first-order form of the chain, or of the hand-derived transfer function, the linear one-port): every
    statistic to rounding (measured <= 1.2e-12 relative on a 130 m stretch), the contact force to 1e-9 N."""
    run = simulate(SHORT, 250.0, 2e-4, pantograph=make())
    assert reference_run.timing["native"] and run.timing["native"]
    for k in STATS:
        assert run.stats[k] == pytest.approx(reference_run.stats[k], rel=1e-9, abs=1e-9), k
    np.testing.assert_allclose(run.result.force, reference_run.result.force, rtol=0, atol=1e-9)


@pytest.mark.parametrize("k_wire, y_wire", [(3000.0, 0.02), (5e4, -0.01), (0.0, 0.0)])
def test_statics_against_the_two_mass_pantograph(k_wire, y_wire):
    """`static` of the lumped and transfer-function pantographs against `TwoMassPantograph.static` (a 2 x 2 solve of
    its own): the same contact force and head; free (k_wire = 0) the head stands at F0 / k2."""
    ref = TwoMassPantograph(P.m1, P.k1, P.c1, P.m2, P.k2, P.c2, P.F0)
    f_ref = ref.static(y_wire, k_wire)
    for pan in (lumped(_reference_lumped()), transfer(_two_mass_transfer())):
        assert pan.static(y_wire, k_wire) == pytest.approx(f_ref, rel=1e-12, abs=1e-9)
        assert pan.head() == pytest.approx(ref.head(), rel=1e-9, abs=1e-12)
    if k_wire == 0.0:  # free: the uplift on the frame stretches the base spring only
        assert ref.head() == pytest.approx(P.F0 / P.k2)


def test_lumped_pantograph_signals_and_energy_are_the_chain():
    pan = lumped(LumpedParams((5.0, 8.0, 12.0), (6000.0, 3000.0, 80.0), (10.0, 20.0, 60.0), 90.0))
    f = pan.static(0.0, 1e9)
    assert f == pytest.approx(90.0 / (1 + 80.0 * (1 / 6000.0 + 1 / 3000.0)), rel=1e-6)
    s = pan.signals()
    assert list(s) == ["head_displacement", "stage_2_displacement", "frame_displacement"]
    # at rest the energy is the springs' minus the work of F0: here springs carry f and the base spring F0 - f
    x3 = (90.0 - f) / 80.0
    assert s["frame_displacement"] == pytest.approx(x3, rel=1e-6)
    assert pan.energy() == pytest.approx(0.5 * f * f * (1 / 6000 + 1 / 3000) + 0.5 * 80.0 * x3 * x3 - 90.0 * x3,
                                         rel=1e-6)
    with pytest.raises(Exception, match="no energy"):
        transfer(_two_mass_transfer()).energy()


@pytest.mark.parametrize("kind, section, match", [
    ("lumped", None, "takes its parameters"),
    ("lumped", {"params": {"m": [1.0], "k": [1.0], "c": [1.0]}}, "F0 missing; required: F0"),
    ("lumped", {"params": {"m": [1.0], "k": [1.0], "c": [1.0], "F0": 1.0, "x": 2}}, "unknown key\\(s\\) \\['x'\\]"),
    ("lumped", {"params": {"m": [1.0, 2.0], "k": [1.0], "c": [1.0], "F0": 1.0}}, "one length"),
    ("lumped", {"params": {"m": [-1.0], "k": [1.0], "c": [1.0], "F0": 1.0}}, "m\\[0\\]"),
    ("lumped", {"params": {"m": [1.0, 1.0], "k": [0.0, 1.0], "c": [1.0, 1.0], "F0": 1.0}}, "k\\[0\\]"),
    ("lumped", {"params": {"m": "heavy", "k": [1.0], "c": [1.0], "F0": 1.0}}, "m = 'heavy' .* must be a list"),
    ("lumped", {"params": {"m": [1.0], "k": [1.0], "c": [float("nan")], "F0": 1.0}}, "c\\[0\\] = nan .* is invalid"),
    ("lumped", {"params": {"m": [1.0], "k": [1.0], "c": [1.0], "F0": True}}, "F0"),
    ("lumped", {"effects": {"coulomb": False}, "params": {}}, "no effects"),
    ("lumped", {"param": {}}, "unknown key"),
    ("transfer", {"params": {"A": [[1.0, 2.0]], "B": [1.0], "C": [1.0], "F0": 1.0}}, "square"),
    ("transfer", {"params": {"A": [[1.0, 2.0], [3.0]], "B": [1.0], "C": [1.0], "F0": 1.0}}, "square"),
    ("transfer", {"params": {"A": [[-1.0]], "B": [1.0, 2.0], "C": [1.0], "F0": 1.0}}, "B, C of its size"),
    ("transfer", {"params": {"A": [[-1.0]], "B": [1.0], "C": [1.0]}}, "missing"),
])
def test_bad_pantograph_section_is_refused_by_name(kind, section, match):
    with pytest.raises(SceneError, match=match):
        params_of(kind, section)
    with pytest.raises(SceneError, match=match):
        build(kind, P, section=section)


def test_section_validator_tells_the_linear_pantographs_apart():
    lp = {"params": _reference_lumped().section()}
    tp = {"params": _two_mass_transfer().section()}
    assert validate_section(lp)["params"]["m"] == [P.m1, P.m2]
    assert validate_section(tp)["params"]["F0"] == pytest.approx(P.F0 * P.k1 / (P.k1 + P.k2))
    with pytest.raises(SceneError, match="B, C of its size"):
        validate_section({"params": {**tp["params"], "B": [1.0]}})
    # two stages are the 2-mass pantograph's model: made one, stepped in the compiled loop; three are not
    two = build("lumped", P, section=lp)
    assert isinstance(two, TwoMassPantograph) and two.name == "lumped"
    three = build("lumped", P, section={"params": LumpedParams((5.0, 8.0, 12.0), (6e3, 3e3, 80.0), (1.0, 2.0, 3.0),
                                                               90.0).section()})
    assert isinstance(three, LinearPantograph)
    with pytest.raises(SceneError, match="only the reference path"):
        build("lumped", P, engine="mujoco", section=lp)
    with pytest.raises(ParameterError, match="strictly proper"):
        TransferParams.from_tf([1.0, 0.0, 1.0], [1.0, 1.0, 1.0], 1.0)


@pytest.mark.parametrize("name, kind", [("en50318_lumped2", "lumped"), ("en50318_lumped3", "lumped"),
                                        ("en50318_transfer", "transfer")])
def test_shipped_scenes_build_their_pantograph(name, kind):
    scene = load_scene(f"catenary/{name}")
    assert scene.effects["pantograph"] == kind
    pan = build(kind, scene.build_params(), section=scene.sections["pantograph"])
    # the fitted pantographs press with the Eppinger pantograph's static contact force at its operating height
    assert pan.static(0.0, 1e12) == pytest.approx(88.7345, rel=1e-5)
