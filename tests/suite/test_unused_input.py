"""No input silently ignored: for every model x effect value x path, a parameter or section the configuration does not
use (`ModelSpec.uses`) is refused naming it, and one it uses is accepted; an effect value a path does not model
(`RunPath.lacks`) is refused when that path is asked to run it. The declarations were measured (a 10 % change of each
key moves no output where it is declared unused: `test_every_key_that_moves_nothing_is_declared_unused`, slow)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mbsuite
from mbsuite.errors import SceneError
from mbsuite.registry import get_model

MODELS = ("pantograph", "coupler", "iftomm", "catenary")


def _configs(model: str):
    """(label, effects) of the default scene and each effect value away from it, one at a time."""
    sc = mbsuite.load_scene(model)
    yield "default", {}
    for name, eff in sc.spec.effects.items():
        for v in eff.choices:
            if not (v is sc.effects[name] if isinstance(v, bool) else v == sc.effects[name]):
                yield f"{name}={v}", {name: v}


def _value(model: str, key: str):
    cls = get_model(model).params_cls
    f = next(f for f in dataclasses.fields(cls) if f.name == key)
    return (f.default or 1e-3) * 1.1 if key != "r_laminar" else 0.999995


CASES = [(m, label, eff) for m in MODELS for label, eff in _configs(m)]


@pytest.mark.parametrize("model,label,effects", CASES, ids=[f"{m}-{lab}" for m, lab, _ in CASES])
def test_a_key_the_configuration_does_not_use_is_refused_by_name(model, label, effects):
    spec = get_model(model)
    sc = mbsuite.load_scene(model).replace(effects=effects)
    for key, use in spec.uses.items():
        section, _, name = key.partition(".")
        for engine in spec.engines:
            why = use.unused_because(sc.effects, engine)
            if section == "params":
                change = {"params": {name: _value(model, name)}}
            else:  # a model section: the catenary's [pantograph] of the Eppinger pantograph
                change = {key: {"params": {"mh": 14.0}}}
            if use.unused_because(sc.effects, None) is not None:  # the effects alone do not use it: refused at once
                with pytest.raises(SceneError, match=rf"not used by this scene with these effects .*{key}"):
                    sc.replace(**change)
                continue
            got = sc.replace(**change)  # used by these effects: accepted
            assert (key in spec.unused(got.effects, engine, [key])) is (why is not None)  # and by this path?
            if why is not None:
                with pytest.raises(SceneError, match=rf"on the {engine} path .*{key} = .*used on the"):
                    spec.check_used(got, engine)
            elif not spec.unused(got.effects, engine, []):  # the path models these effects
                spec.check_used(got, engine)


def test_an_effect_value_a_path_does_not_model_is_refused_when_that_path_runs():
    """The pantograph's MuJoCo path has frictionloss only (no c tanh(w/omega_s)): `coulomb = "smooth"` on it would run
    the event-free law of `coulomb = true`; the reference path models it."""
    sc = mbsuite.load_scene("pantograph/lab").replace(effects={"coulomb": "smooth"}, params={"omega_s": 0.05},
                                                      solver={"duration": 0.05, "t_settle": 0.0})
    with pytest.raises(SceneError, match=r"coulomb = 'smooth' .* mujoco path does not model .* \['reference'\]"):
        mbsuite.run(sc)
    sc.spec.check_used(sc, "reference")


def test_a_path_setting_may_ride_along_until_the_other_path_runs():
    """A scene may carry one path's setting while another path is asked for on the way (run(..., engine=...)); the run
    of the path that ignores it refuses it, naming it and the path that uses it."""
    sc = mbsuite.load_scene("iftomm/bricard").replace(params={"penalty": 1e6}, solver={"duration": 0.05})
    with pytest.raises(SceneError, match=r"params\.penalty = 1000000\.0 .* used on the reference path only"):
        mbsuite.run(sc)
    assert np.isfinite(mbsuite.run(sc, engine="reference")["input_angle"]).all()


def test_uses_declarations_name_real_keys_and_values():
    """A typo in a declaration would switch its check off silently: the registry refuses it."""
    from mbsuite.registry import ModelSpec, Uses

    spec = get_model("iftomm")
    kw = {f.name: getattr(spec, f.name) for f in dataclasses.fields(ModelSpec)}
    with pytest.raises(ValueError, match="not a parameter"):
        ModelSpec(**{**kw, "uses": {"params.penalti": Uses(engines=("reference",))}})
    with pytest.raises(ValueError, match="not declared"):
        ModelSpec(**{**kw, "uses": {"params.penalty": Uses(effects={"mechanism": ("fourbars",)})}})


# --- the declarations measured: every key the configuration uses moves an output ----------------------------------
SHORT = {"pantograph": {"solver": {"duration": 0.4, "t_settle": 0.0}},
         "coupler": {"solver": {"duration": 0.5, "t_settle": 0.0}},
         "iftomm": {"solver": {"duration": 1.0}},
         "catenary": {"params": {"n_spans": 3, "x_end": 170.0, "window_start": 60.0, "window_end": 120.0}}}
#: the coupler's reference path is the rigid kinematic limit of any scene (its `what`): not narrowed by `uses`
EXEMPT_PATHS = {("coupler", "reference")}
#: size guards, like solver.max_steps: they refuse a run, they never change one
GUARDS = {"max_element_steps"}


def _fingerprint(res) -> list[np.ndarray]:
    stats = [float(v) for _, v in sorted(res.stats.items()) if isinstance(v, int | float)]
    return [np.asarray(v, float).ravel() for v in res.signals.values()] + [np.array(stats)]


def _moves(a: list[np.ndarray], b: list[np.ndarray]) -> bool:
    return len(a) != len(b) or any(x.shape != y.shape or not np.allclose(x, y, rtol=1e-9, atol=1e-12, equal_nan=True)
                                   for x, y in zip(a, b, strict=True))


SLOW_CASES = [(m, label, eff, e) for m, label, eff in CASES for e in get_model(m).engines
              if (m, e) not in EXEMPT_PATHS]


@pytest.mark.slow
@pytest.mark.parametrize("model,label,effects,engine", SLOW_CASES,
                         ids=[f"{m}-{lab}-{e}" for m, lab, _, e in SLOW_CASES])
def test_every_key_that_moves_nothing_is_declared_unused(model, label, effects, engine):
    """Each parameter this configuration accepts, changed by 10 % (or -10 % where +10 % leaves its range), moves
    some output or statistic of a short run; the keys that move nothing are exactly the ones `uses` refuses."""
    spec = get_model(model)
    try:
        short = {**SHORT[model], "solver": {**SHORT[model].get("solver", {}), "engine": engine,
                                            "allow_inaccurate": True}}  # a comparison of runs, not a result
        sc = mbsuite.load_scene(model).replace(effects=effects, **short)
        spec.check_used(sc, engine)
    except SceneError:
        pytest.skip("this path does not model these effects (refused by name)")
    base = _fingerprint(mbsuite.run(sc))
    still = []
    for f in dataclasses.fields(spec.params_cls):
        v = getattr(sc.build_params(), f.name)
        if f"params.{f.name}" in spec.unused(sc.effects, engine, [f"params.{f.name}"]) or v is None \
                or isinstance(v, list) or f.name in SHORT[model].get("params", {}) or f.name in GUARDS:
            continue
        for c in ([v * 1.1, v * 0.9] if v else [0.1, 1.0]) if not isinstance(v, int) else [v + 1, v - 1]:
            try:
                s2 = sc.replace(params={f.name: c})
            except mbsuite.MbsuiteError:
                continue
            if not _moves(base, _fingerprint(mbsuite.run(s2))):
                still.append(f.name)
            break
    assert still == [], f"{model} {label} on {engine}: {still} move no output but are not declared unused"
