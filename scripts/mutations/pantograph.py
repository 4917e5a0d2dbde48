"""Seeded defects in the Eppinger pantograph: hand-derived equations, MuJoCo plugin, linearisation, orifice."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("pantograph_eom_centripetal_sign", "mbsuite/models/pantograph/equations.py",
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[2] - t[0]),",
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[0] - t[2]),",
             "a sign flipped in a centripetal term of the hand-derived equations of motion (Eq 3.10)",
             "tests/pantograph"),
    Mutation("pantograph_operating_point_at_y_op", "mbsuite/models/pantograph/inputs.py",
             "        return p.y_op + u.amplitude\n", "        return p.y_op\n",
             "the linearisation point shifted by the input amplitude (y_op instead of the mean input y_op + A)",
             "tests/pantograph"),
    Mutation("pantograph_laminar_band_x10", "mbsuite/models/pantograph/params.py",
             "R_LAMINAR = 0.99999", "R_LAMINAR = 0.9999",
             "the orifice's laminar band widened ten times", "tests/pantograph"),
    Mutation("pantograph_elbow_spring_sign_in_plugin", "mbsuite/models/pantograph/native/pantograph.c",
             "  double Te = e->ke * (te - M_PI + q1 + q2);", "  double Te = -e->ke * (te - M_PI + q1 + q2);",
             "the elbow spring's torque with its sign flipped in the MuJoCo plugin", "tests/pantograph"),
)
