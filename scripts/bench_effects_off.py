"""Benchmark (not a test): a switched-off effect costs nothing. Step cost of the model a scene builds with an effect
switched off vs a model built without that effect at all, side by side (ratio ~ 1.0 expected).

- pantograph (constant cylinder), Coulomb and viscous friction off (scene effects) vs the shipped MJCF with
  `frictionloss` and `damping` deleted from every joint through MjSpec (no friction rows can exist); neither loop
  installs the elbow's passive callback (its cost is bench_callbacks.py's subject);
- pantograph, cylinder 'constant' and elbow 'rigid' (no callback) vs the bare shipped MJCF (no callback either);
- coupler, friction off (the scene's model) vs the same scene built with friction on and then every
  `dof_frictionloss` zeroed by hand (the constraint rows disappear);
Each variant steps the same number of steps in the same Python loop (ctrl written each step), best of R repeats.

    python scripts/bench_effects_off.py [--steps 20000] [--repeats 7]
"""

from __future__ import annotations

import argparse

import mujoco
import numpy as np

from mbsuite import load_scene
from mbsuite.engines.mujoco_engine import step_cost
from mbsuite.models.coupler.mujoco import _inputs, build
from mbsuite.models.pantograph.mujoco import MujocoPantograph
from mbsuite.models.pantograph.reference import PantographConfig
from mbsuite.paths import mjcf_path
from mbsuite.results import format_table


def loop_cost(model, cbs: dict, q0: np.ndarray | None, steps: int, repeats: int, ctrl: float | None = None) -> float:
    return step_cost(model, cbs, q0, steps, repeats, ctrl)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000)
    ap.add_argument("--repeats", type=int, default=7)
    a = ap.parse_args()
    rows = []

    # constant cylinder: the shipped file's actuator; the elbow's passive callback is left out of both loops
    off = MujocoPantograph(config=PantographConfig(cylinder="constant", coulomb=False, viscous=False),
                           integrator="rk4", timestep=1e-3)
    spec = mujoco.MjSpec.from_file(str(mjcf_path("pantograph")))
    for j in spec.joints:
        j.frictionloss = 0.0
        j.damping = np.zeros_like(np.atleast_1d(j.damping))
    without_model = spec.compile()
    without_model.opt.integrator, without_model.opt.timestep = off.model.opt.integrator, off.model.opt.timestep
    q0 = off.equilibrium()
    c_off = loop_cost(off.model, {}, q0, a.steps, a.repeats, 1.58)
    c_without = loop_cost(without_model, {}, q0, a.steps, a.repeats, 1.58)
    rows.append(["pantograph: Coulomb + viscous off (scene) vs deleted from the MJCF", c_off * 1e6,
                 c_without * 1e6, c_off / c_without])

    cst = MujocoPantograph(config=PantographConfig(cylinder="constant", elbow="rigid"), integrator="rk4",
                           timestep=1e-3)
    bare = mujoco.MjModel.from_xml_path(str(mjcf_path("pantograph")))
    bare.opt.integrator, bare.opt.timestep = cst.model.opt.integrator, cst.model.opt.timestep
    c_cst = loop_cost(cst.model, cst.callback_set(), cst.equilibrium(), a.steps, a.repeats, 1.58)
    c_bare = loop_cost(bare, {}, cst.equilibrium(), a.steps, a.repeats, 1.58)
    rows.append(["pantograph: cylinder constant + elbow rigid (no callback) vs bare MJCF", c_cst * 1e6,
                 c_bare * 1e6, c_cst / c_bare])

    sc = load_scene("coupler/double_lateral")
    p, inp = sc.build_params(), _inputs(sc)
    m_off, d_off, _ = build(p, {**sc.effects, "friction": False}, inp, 5e-4, "implicitfast")
    m_on, d_on, _ = build(p, {**sc.effects, "friction": True}, inp, 5e-4, "implicitfast")
    m_on.dof_frictionloss[:] = 0.0
    n = a.steps // 4
    c1 = loop_cost(m_off, {}, d_off.qpos.copy(), n, a.repeats)
    c2 = loop_cost(m_on, {}, d_on.qpos.copy(), n, a.repeats)
    rows.append(["coupler: friction off (scene) vs built with friction, frictionloss zeroed", c1 * 1e6, c2 * 1e6,
                 c1 / c2])
    print(format_table(["effect switched off", "scene model us/step", "model without it us/step", "ratio"], rows,
                       ".3g"))
    print(f"\n{a.steps} steps (coupler {n}), best of {a.repeats}")


if __name__ == "__main__":
    main()
