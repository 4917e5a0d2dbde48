"""Seeded defects in the 4-link couplers (Maniowski & Czauderna): kinematics, Jacobian, criteria, both dynamic paths."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("coupler_jacobian_row_swapped", "mbsuite/models/coupler/jacobian.py",
             "    return np.hstack([lh, np.cross(links_to - o, lh)])",
             "    J = np.hstack([lh, np.cross(links_to - o, lh)])\n    return J[[1, 0, *range(2, len(J))]]",
             "two rows of the mechanism Jacobian swapped (links mislabelled)", "tests/coupler"),
    Mutation("coupler_jacobian_moment_sign", "mbsuite/models/coupler/jacobian.py",
             "    return np.hstack([lh, np.cross(links_to - o, lh)])",
             "    return np.hstack([lh, np.cross(lh, links_to - o)])",
             "the moment part of the Jacobian with the cross product reversed (sign flipped)", "tests/coupler"),
    Mutation("coupler_cond_R_not_squared", "mbsuite/models/coupler/jacobian.py",
             "    s_moment = 2 * p.R * math.cos(math.pi / 4 - p.gamma) * l0 / l",
             "    s_moment = 2 * math.cos(math.pi / 4 - p.gamma) * l0 / l",
             "the closed-form condition number missing a factor R", "tests/coupler"),
    Mutation("coupler_friction_off_in_output_bearing", "mbsuite/models/coupler/mujoco.py",
             "    spec.joint(\"phi_c\").frictionloss = p.joint_friction if effects[\"friction\"] else 0.0",
             "    spec.joint(\"phi_c\").frictionloss = 0.0",
             "the output bearing's friction left out of the MuJoCo coupler", "tests/coupler"),
)
