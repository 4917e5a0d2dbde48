"""Every pantograph kind in the catenary's compiled loop (`native/catenary.c`, `mbs_cat_run`, each pantograph through
its one-port) against the Python loops it replaced, which stay as its test oracles: the core's stages driven from
Python with the secant coupling (`train._Secant`, `stepwise=True`) and, for a single pantograph, the readable
`passage.Passage` (`native=False`)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mbsuite.errors import SceneError, SolverError
from mbsuite.models.catenary import train
from mbsuite.models.catenary.config import PassageConfig
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.pantographs import build_train
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.sim import CoupledSimulation
from mbsuite.scenes import load_scene

#: a 3-span line, 300 km/h: the slack droppers go slack, the contact force spans ~50-300 N
P3 = CatenaryParams(n_spans=3, element_length=0.5, x_end=140.0, window_start=60.0, window_end=120.0)


def _section(scene: str) -> dict | None:
    return load_scene(f"catenary/{scene}").sections.get("pantograph")


#: kind -> (pantograph name, engine, [pantograph] section of the shipped scene that runs it)
KINDS = {
    "2-mass": ("reference2mass", "reference", None),
    "lumped-3": ("lumped", "reference", "en50318_lumped3"),
    "transfer": ("transfer", "reference", "en50318_transfer"),
    "eppinger-mujoco": ("eppinger", "mujoco", "en50318_eppinger"),
    "eppinger-reference": ("eppinger", "reference", "en50318_eppinger"),
}


#: the hand-derived Eppinger path's Python oracles step its RK4 in Python (~1 ms a trial): a shorter stretch in the
#: default run (40 m: 4 800 steps, the first span and a half), the whole one behind the slow marker
SHORT = {"eppinger-reference": 40.0}


def _run(kind: str, pantographs: int = 1, aerodynamics: dict | None = None, **kw) -> train.TrainRun:
    name, engine, scene = KINDS[kind]
    p = P3 if kind not in SHORT or pantographs > 1 else dataclasses.replace(P3, x_end=SHORT[kind], window_start=10.0,
                                                                            window_end=SHORT[kind])
    cfg = PassageConfig(p, 300.0, 1e-4, (name,) * pantographs, (30.0,) * (pantographs - 1), "slack", "unilateral",
                        engine, _section(scene) if scene else None, aerodynamics=aerodynamics)
    return train.run_passage(cfg, **kw)


def _diff(a, b) -> dict[str, float]:
    out = {"force": float(np.max(np.abs(a.force - b.force))), "head": float(np.max(np.abs(a.head - b.head))),
           "wire": float(np.max(np.abs(a.wire - b.wire))), "uplift": float(np.max(np.abs(a.uplift - b.uplift)))}
    assert set(a.panto) == set(b.panto)
    for k in a.panto:
        out[k] = float(np.max(np.abs(a.panto[k] - b.panto[k])))
    return out


def _slow_train(kind: str, pantographs: int):
    return pytest.param(kind, pantographs, marks=pytest.mark.slow) if kind in SHORT and pantographs > 1 else \
        pytest.param(kind, pantographs)


@pytest.mark.parametrize("kind,pantographs", [_slow_train(k, n) for n in (1, 2) for k in KINDS])
def test_every_pantograph_kind_steps_in_the_compiled_loop_as_in_the_python_loop(kind, pantographs):
    """The compiled loop against the core's stages driven from Python, on one pantograph and a train of two (30 m
    apart). Measured: the 2-mass and the MuJoCo pantographs bit-equal (the same arithmetic and MuJoCo calls in the
    same order); the linear ones (their matrix products by BLAS in Python, by index-order sums in C) force <= 2.7e-9
    N of 50-300 N, heights, uplifts and outputs <= 2.7e-13 m. Bounds 3e-8 N and 3e-12 m (11x)."""
    a = _run(kind, pantographs, stepwise=True)
    b = _run(kind, pantographs)
    assert b.timing["native_loop"] and not a.timing["native_loop"]
    for ra, rb in zip(a.results, b.results, strict=True):
        assert np.array_equal(ra.t, rb.t) and np.array_equal(ra.x, rb.x)
        assert np.array_equal(ra.n_slack, rb.n_slack)
        d = _diff(ra, rb)
        assert d.pop("force") < 3e-8, kind
        assert max(d.values()) < 3e-12, (kind, d)


@pytest.mark.parametrize("kind", ["eppinger-mujoco", "eppinger-reference", "lumped-3"])
def test_a_single_pantograph_in_the_compiled_loop_equals_the_readable_python_passage(kind):
    """One pantograph: the compiled loop against `passage.Passage`, the readable Python twin (`native=False`), whose
    secant coupling and local solver are Python's own. Measured: force <= 6.4e-10 N, heights, uplifts and outputs
    (angles in rad) <= 1.3e-13; bounds 3e-8 N and 3e-12 (the test above's)."""
    a = _run(kind, native=False)
    b = _run(kind)
    assert b.timing["native_loop"] and not a.timing["native_loop"]
    ra, rb = a.results[0], b.results[0]
    assert np.array_equal(ra.n_slack, rb.n_slack)
    d = _diff(ra, rb)
    assert d.pop("force") < 3e-8, kind
    assert max(d.values()) < 3e-12, (kind, d)


#: the aerodynamic uplift of the runs below (`aerodynamics.py`): knuckle-trailing, at 300 km/h 27.8 N on the head and
#: 41.7 N on the frame of the leading pantograph, half that on a trailing one
AERO = {"running": "knuckle-trailing", "knuckle_trailing": {"head": 0.004, "frame": 0.006},
        "trailing_pantograph": {"knuckle_trailing": {"head": 0.002, "frame": 0.003}}}


@pytest.mark.parametrize("kind,pantographs,oracle", [*((k, 1, "stages") for k in KINDS), ("2-mass", 2, "stages"),
                                                      ("transfer", 2, "stages"), ("2-mass", 1, "passage")])
def test_with_aerodynamic_uplift_every_kind_steps_in_the_compiled_loop_as_in_the_python_loops(kind, pantographs,
                                                                                                oracle):
    """The uplift acts inside the compiled loop (each kind's one-port: the 2-mass port's constants, the linear port's
    constant term, the C ODE's generalised forces, the MuJoCo state's xfrc_applied) as in the Python oracles: the
    core's stages driven from Python (`stepwise`) and, for one pantograph, the readable `passage.Passage`. Measured:
    against the stages the 2-mass and MuJoCo pantographs bit-equal; otherwise force <= 5.1e-9 N of 60-300 N, heights,
    uplifts and outputs (angles in rad) <= 2.9e-13; bounds 3e-8 N and 3e-12 (the tests above', 6x and 10x). The uplift
    is on: the leading pantograph's static force exceeds the kind's without it (by 54-72 N)."""
    a = _run(kind, pantographs, AERO, **({"stepwise": True} if oracle == "stages" else {"native": False}))
    b = _run(kind, pantographs, AERO)
    assert b.timing["native_loop"] and not a.timing["native_loop"]
    assert [u.position for u in b.aerodynamics] == ["leading", "trailing"][:pantographs]
    for ra, rb in zip(a.results, b.results, strict=True):
        assert np.array_equal(ra.n_slack, rb.n_slack)
        d = _diff(ra, rb)
        assert d.pop("force") < 3e-8, kind
        assert max(d.values()) < 3e-12, (kind, d)
    name, engine, scene = KINDS[kind]
    p = P3
    plain = build_train([name], p, engine, 1e-4, _section(scene) if scene else None, "unilateral")[0]
    assert b.static_forces[0] > plain.static(0.0, p.k_contact) + 20.0


def test_a_pantograph_that_fails_inside_the_compiled_loop_is_named_with_its_engines_words():
    """A MuJoCo pantograph whose state turns non-finite mid-passage (its committed velocity poisoned between two
    chunks): the compiled loop stops at that step and the error names the pantograph, the time and MuJoCo's
    warning, in the words of the Python path's stepper."""
    name, engine, scene = KINDS["eppinger-mujoco"]
    cfg = PassageConfig(P3, 300.0, 1e-4, (name,), (), "slack", "unilateral", engine, _section(scene))
    adm = cfg.check()
    fe = assemble(P3)
    pans = build_train([name], P3, engine, 1e-4, _section(scene), "unilateral")
    sim = CoupledSimulation(fe, pans[0], adm.V, 1e-4, dropper_law="slack", contact="unilateral")
    tp = train.TrainPassage(sim, pans, sim.start(P3.x_start, P3.x_end), adm.offsets, compiled=True)
    tp.step()
    assert tp.status == "running" and tp.n == train.CHUNK
    port = tp.ports[0]._mp
    state = port.state()
    m = pans[0].m
    nq = m.nq
    state[1 + nq] = np.nan  # the integration state: time, qpos, qvel, ...: the first joint velocity
    port.set_state(state)
    words = r"pantograph 1 failed at t = 0\.500100 s \(x = 41\.67 m\): .*MuJoCo diverged \(warning badqvel"
    with pytest.raises(SolverError, match=words):
        tp.step()


def test_a_mixed_train_gives_the_section_to_its_sectioned_pantograph():
    """An Eppinger pantograph (its [pantograph] section) leading a 2-mass one (its numbers from [params]) in the
    compiled loop, as in the stage-driven loop (measured bit-equal; bounds as above); a train of two kinds that each
    read the section is refused, naming them."""
    sec = _section("en50318_eppinger")
    runs = [train.run_passage(PassageConfig(P3, 300.0, 1e-4, ("eppinger", "reference2mass"), (30.0,), "slack",
                                            "unilateral", "mujoco", sec), stepwise=s) for s in (True, False)]
    assert runs[0].engines == ["mujoco", "reference"] and runs[1].timing["native_loop"]
    for ra, rb in zip(runs[0].results, runs[1].results, strict=True):
        d = _diff(ra, rb)
        assert d.pop("force") < 3e-8 and max(d.values()) < 3e-12
    with pytest.raises(SceneError, match=r"\['eppinger', 'lumped'\]"):
        train.run_passage(PassageConfig(P3, 300.0, 1e-4, ("eppinger", "lumped"), (30.0,), "slack", "unilateral",
                                        "reference", sec))
