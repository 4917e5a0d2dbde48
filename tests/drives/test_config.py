"""No input silently ignored: every drives mechanism x controller x switching option, built with one parameter its
configuration does not read, is a SceneError naming it; built with every parameter it reads (and nothing else) it
sets up. The parameters called unused really are: moving any of them leaves a run unchanged bit for bit (slow test,
the independent check of `config.used_params`). Every parameter set is complete for the mechanisms it is made for;
another mechanism's set is refused naming the set and what it lacks."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from mbsuite.errors import SceneError
from mbsuite.models.drives.config import (
    CONTROLLERS,
    OPTIONAL,
    SET_MECHANISMS,
    check_scene,
    used_params,
)
from mbsuite.models.drives.params import PARAM_SETS, DriveParams
from mbsuite.models.drives.scene_run import setup as run_setup  # a module-level `setup` is pytest's xunit hook
from mbsuite.scenes import load_scene, scene_from_dict
from mbsuite.trust import perturbation

ALL = [f.name for f in dataclasses.fields(DriveParams)]
BASE = {"step_up": "table_4_2", "step_up_down": "design_100w"}
#: a valid value of every parameter (from the sets; the rest within their declared ranges)
SAMPLE = {"max_tk": 0.05, "K_ctrl": 1.0, "Omega_ctrl": 100.0, "spring_max": 3.0, "peak": 1.1,
          **{k: v for ps in ("proto_100w", "example_500w", "table_4_2") for k, v in PARAM_SETS[ps].items()}}


def _combos():
    for mech, kinds in CONTROLLERS.items():
        for kind, closed, bearings, delays, added, matching, ref in itertools.product(
                kinds, (False, True), (True, False), (True, False), (False, True), (False, True), (False, True)):
            if (mech == "step_up_down" and matching) or (kind == "motor_resonant" and closed):
                continue  # refused configurations (test_refused_effects)
            if mech == "step_up" and ref and not closed:
                continue  # the open-loop step-up drive takes no reference (test_refused_effects)
            yield mech, kind, closed, bearings, delays, added, matching, ref


def _scene(mech, kind, closed, bearings, delays, added, matching, ref, params):
    eff = {"mechanism": mech, "controller": kind, "closed_loop": closed,
           "bearing_friction": bearings, "clutch_delays": delays, "added_motor_inertia": added,
           "clutch_matching": matching}
    inp = {"type": "reference", **({"value": 300.0} if ref else {})}
    return scene_from_dict({"model": "drives", "effects": eff, "params": {"set": BASE[mech], **params}, "input": inp,
                            "solver": {"duration": 0.2, "t_settle": 0.0}})


COMBOS = list(_combos())


@pytest.mark.parametrize("combo", COMBOS, ids=["-".join(str(x) for x in c) for c in COMBOS])
def test_every_configuration_reads_what_it_uses_and_refuses_the_rest(combo):
    base = _scene(*combo, {}).build_params().resolved(BASE[combo[0]])
    straight = base.get("tau_0") is not None
    used = used_params(combo[0], {"controller": combo[1], "closed_loop": combo[2], "bearing_friction": combo[3],
                                  "clutch_delays": combo[4], "added_motor_inertia": combo[5]},
                       {"value": 1.0} if combo[7] else {}, straight)
    given = {k: base[k] for k in used if base[k] is not None}
    if combo[5]:
        given["J_add"] = 1.42e-3
    sc = _scene(*combo, given)
    run_setup(sc)  # every read parameter given: no error
    unused = [k for k in ALL if k not in used]
    assert unused
    for k in unused:
        # tau_0 switches the motor to the straight line, so then the given Eq 4.1 constants are the unread ones
        needle = "tau_0 is set" if k == "tau_0" else rf"parameter\(s\) {k} = "
        one = dataclasses.replace(sc, params={**given, k: SAMPLE[k]})  # the loader's checks are not the point here
        with pytest.raises(SceneError, match=needle):
            check_scene(one, one.build_params().resolved(BASE[combo[0]]))
    with pytest.raises(SceneError, match=r"parameter\(s\) "):  # and through the run's set-up
        run_setup(_scene(*combo, {**given, unused[0]: SAMPLE[unused[0]]}))


def test_refused_effects():
    sc = load_scene("drives/step_up_resonant")
    for upd, needle in (({"controller": "motor_resonant", "closed_loop": True}, "closed_loop = true"),
                        ({"anti_windup": False}, "anti_windup = false"),
                        ({"controller": "energy_packet"}, "controller = 'energy_packet'")):
        with pytest.raises(SceneError, match=needle):
            run_setup(sc.replace(effects=upd))
    with pytest.raises(SceneError, match="clutch_matching"):
        run_setup(load_scene("drives/susd_500w_open").replace(effects={"clutch_matching": True}))
    with pytest.raises(SceneError, match="input.value"):
        run_setup(sc.replace(input={"value": 100.0}))


@pytest.mark.parametrize("ps", sorted(SET_MECHANISMS))
def test_every_parameter_set_is_complete_for_its_mechanisms(ps):
    """Each set gives every non-optional parameter each of its mechanisms' configurations reads (the controller
    defaults of OPTIONAL aside)."""
    for mech in SET_MECHANISMS[ps]:
        if mech not in CONTROLLERS:
            continue
        p = DriveParams().resolved(ps)
        for kind, closed in itertools.product(CONTROLLERS[mech], (False, True)):
            used = used_params(mech, {"controller": kind, "closed_loop": closed}, {}, p.get("tau_0") is not None)
            assert [k for k in used - OPTIONAL if p[k] is None] == [], (ps, mech, kind, closed)


def test_another_mechanisms_set_is_refused_by_name():
    """The 500 W step-up/step-down set on the step-up drive (once `TypeError: '>=' ... NoneType` inside the run)."""
    sc = load_scene("drives/step_up_pwm")
    with pytest.raises(SceneError, match=r"parameter set 'example_500w' .* lacks \['tau_c', 'twist_tol'\] needed by "
                                         r"mechanism 'step_up'"):
        run_setup(sc.replace(params={"set": "example_500w", "tau_b": 2.0}))  # refused as the scene loads
    # giving what it lacks makes it a step-up drive (duty and t_l are the scene's already)
    run_setup(sc.replace(params={"set": "example_500w", "tau_b": 2.0, "tau_c": 20.0, "twist_tol": 0.5}))


@pytest.mark.slow
@pytest.mark.parametrize("combo", [c for c in COMBOS if c[3:7] == (True, True, False, False)])
def test_unused_parameters_change_nothing(combo):
    """Independent of `used_params`: each parameter it calls unused, moved by x1.3 in the resolved set (which the
    run reads), leaves a 0.2 s run unchanged bit for bit."""
    from mbsuite.models.drives import scene_run
    from mbsuite.models.drives.analysis import simulate_scene

    sc = _scene(*combo, {})
    base = sc.build_params().resolved(BASE[combo[0]])
    used = used_params(combo[0], sc.effects, sc.input, base.get("tau_0") is not None)
    ref = simulate_scene(sc)[0]
    orig = scene_run.check_scene
    for k in [k for k in ALL if k not in used and base.get(k) is not None and k != "tau_0"]:
        moved = dict(base, **{k: base[k] * 1.3 if base[k] else 0.1})
        try:
            scene_run.check_scene = lambda *a: None
            res = simulate_scene(sc.replace(params={k: moved[k]}))[0]
        finally:
            scene_run.check_scene = orig
        assert np.array_equal(res.w, ref.w) and np.array_equal(res.q, ref.q), k


@pytest.mark.parametrize("key", ["J_m", "J_s", "J_l"])
def test_rotor_inertia_floor(key):
    """Below the declared floor 1e-9 kg m^2 a rotor inertia is refused naming it (once MuJoCo's singular-inertia
    warnings); at the floor the MuJoCo model is built with it (diag(M) holds it: `MujocoRotorSim`'s own check)."""
    from mbsuite.components.rotational.mujoco_sim import MujocoRotorSim
    from mbsuite.errors import ParameterError
    from mbsuite.paths import mjcf_path

    sc = load_scene("drives/step_up_pwm")
    with pytest.raises(ParameterError, match=rf"{key} = 5e-10\b.* is invalid; valid: \[1e-09, 1000\]"):
        sc.replace(params={key: 5e-10})
    run = run_setup(sc.replace(params={key: 1e-9}))
    sim = MujocoRotorSim(run.system, mjcf_path(run.mjcf), timestep=1e-4)
    i = ["J_m", "J_s", "J_l"].index(key)
    # the floor itself (in the perturbed tests: moved by the draw in force, at most 8 sizes)
    assert abs(run.system.J[i] - 1e-9) <= 8e-9 * perturbation.size()
    assert sim.m.body_inertia[sim.m.jnt_bodyid[sim.jnt[i]]][2] == run.system.J[i]
