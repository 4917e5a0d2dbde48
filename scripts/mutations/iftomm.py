"""Seeded defects in the IFToMM benchmark mechanisms: the Pinocchio and MuJoCo paths."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("iftomm_mujoco_gravity_sign", "mbsuite/models/iftomm/mujoco.py",
             "    m.opt.gravity[:] = [0.0, -gravity, 0.0]", "    m.opt.gravity[:] = [0.0, gravity, 0.0]",
             "gravity pointing up in the MuJoCo model of the benchmarks (a sign in the equations of motion)",
             "tests/iftomm"),
    Mutation("iftomm_pinocchio_gravity_scaled", "mbsuite/models/iftomm/pinocchio.py",
             "        self.model.gravity.linear = np.array([0.0, -gravity, 0.0])",
             "        self.model.gravity.linear = np.array([0.0, -0.999 * gravity, 0.0])",
             "gravity 0.1 % weak in the Pinocchio path of the benchmarks", "tests/iftomm"),
)
