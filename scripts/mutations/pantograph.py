"""Seeded defects in the Eppinger pantograph: hand-derived equations, MuJoCo plugins and model file, linearisation,
orifice, statics, inputs and health figures."""

from mutations.mutation import Mutation

EQ = "mbsuite/models/pantograph/equations.py"
PLUGIN = "mbsuite/models/pantograph/native/pantograph.c"
MODELFILES = "mbsuite/models/pantograph/modelfiles.py"
NON_DEFAULT = "tests/pantograph/test_non_default_physics.py"
CROSS = "tests/pantograph/test_cross_paths.py"

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("pantograph_eom_centripetal_sign", EQ,
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[2] - t[0]),",
             "self.K12 * td[1] ** 2 * s12 + self.K13 * td[2] ** 2 * math.sin(t[0] - t[2]),",
             "a sign flipped in a centripetal term of the hand-derived equations of motion (Eq 3.10)", CROSS),
    Mutation("pantograph_operating_point_at_y_op", "mbsuite/models/pantograph/inputs.py",
             "        return p.y_op + u.amplitude\n", "        return p.y_op\n",
             "the linearisation point shifted by the input amplitude (y_op instead of the mean input y_op + A)",
             "tests/pantograph/test_freqresp.py"),
    Mutation("pantograph_laminar_band_x10", "mbsuite/models/pantograph/params.py",
             "R_LAMINAR = 0.99999", "R_LAMINAR = 0.9999",
             "the orifice's laminar band widened ten times", "tests/pantograph/test_orifice_band.py"),
    Mutation("pantograph_elbow_spring_sign_in_plugin", PLUGIN,
             "  double Te = e->ke * (te - M_PI + q1 + q2);", "  double Te = -e->ke * (te - M_PI + q1 + q2);",
             "the elbow spring's torque with its sign flipped in the MuJoCo plugin", CROSS),
    Mutation("pantograph_plugin_compression_sign", PLUGIN,
             "- P / V * c->Ap * dxp;", "+ P / V * c->Ap * dxp;",
             "the nonlinear cylinder's compression term with the printed sign of Eq 3.18 (erratum 11) in the MuJoCo "
             "plugin: a growing volume raises the pressure", CROSS),
    Mutation("pantograph_plugin_linear_cylinder_spring_sign", PLUGIN,
             "c->kc * (P - c->lb * cos(c->alpha - t1))", "c->kc * (c->lb * cos(c->alpha - t1) - P)",
             "the linear cylinder's spring force kc (P - x_p) of Eq 3.26 reversed in the MuJoCo plugin", CROSS),
    Mutation("pantograph_plugin_exact_kinematics_ignored", PLUGIN,
             'e->exact = kin && !strcmp(kin, "exact");', "e->exact = 0;",
             "the effect value elbow_kinematics = exact ignored by the elbow plugin (B.6 used; erratum 22)", CROSS),
    Mutation("pantograph_elbow_damper_printed_sign", EQ,
             "+ self.p.be * (e.dtheta_e * td[0] - td[1])", "- self.p.be * (e.dtheta_e * td[0] - td[1])",
             "the elbow damper be with the thesis' printed sign (erratum 9): it feeds energy in (be = 0 in Table 3-I)",
             NON_DEFAULT),
    Mutation("pantograph_unilateral_contact_not_in_mujoco", MODELFILES,
             'if cfg.contact == "unilateral" else ""', 'if cfg.contact == "push-only" else ""',
             "the effect value contact = unilateral never reaches the MuJoCo model: the wire pulls the head too",
             NON_DEFAULT),
    Mutation("pantograph_knuckle_friction_from_head", MODELFILES,
             'frictionloss="{_f(c2)}"', 'frictionloss="{_f(ch)}"',
             "the knuckle joint's Coulomb friction read from the head's (c2 = ch = 0.45 N m in Table 3-I)",
             NON_DEFAULT),
    Mutation("pantograph_orifice_never_choked", EQ,
             "r = max(r, CHOKED_RATIO)", "r = max(r, 0.0)",
             "the orifice flow below the critical pressure ratio follows the subsonic law (falls) instead of choking",
             NON_DEFAULT),
    Mutation("pantograph_smooth_coulomb_scale_inverted", EQ,
             "np.tanh(w / self.p.omega_s)", "np.tanh(w * self.p.omega_s)",
             "the smooth Coulomb law's velocity scale omega_s multiplied instead of divided", NON_DEFAULT),
    Mutation("pantograph_static_cylinder_torque_uses_x_p", EQ,
             "R[0] += p.Pg * p.Ap * self.cylinder_lever(t[0])[1]",
             "R[0] += p.Pg * p.Ap * self.cylinder_lever(t[0])[0]",
             "the static equilibrium's cylinder torque with the lever x_p = lb cos(alpha - t1) instead of its "
             "derivative lb sin(alpha - t1) (3.19/3.20)", CROSS),
    Mutation("pantograph_linear_input_gain_doubled", "mbsuite/models/pantograph/linearise.py",
             "B = (lin.rhs(0.0, x0, y_w0 + h) - lin.rhs(0.0, x0, y_w0 - h)) / (2 * h)",
             "B = (lin.rhs(0.0, x0, y_w0 + h) - lin.rhs(0.0, x0, y_w0 - h)) / h",
             "the linearisation's input matrix B twice too large (the central difference not halved): the linear "
             "FRF doubles", "tests/pantograph/test_freqresp.py"),
    Mutation("pantograph_modes_zeta_over_damped_frequency", "mbsuite/models/pantograph/linearise.py",
             '"zeta": -v.real / wn,', '"zeta": -v.real / v.imag,',
             "the modes' damping ratio -Re/|lambda| computed as -Re/Im (the damped frequency)", NON_DEFAULT),
    Mutation("pantograph_omega_max_oscillatory_only", "mbsuite/models/pantograph/linearise.py",
             "return float(np.max(np.abs(linear_model(p, cfg, y_w)[4])))",
             "return float(np.max(np.abs(linear_model(p, cfg, y_w)[4].imag)))",
             "the health figure's fastest mode taken from the oscillatory modes only: the nonlinear cylinder's pole "
             "(163 1/s) missed, stability_margin under-reads", NON_DEFAULT),
    Mutation("pantograph_excursion_room_to_far_edge", "mbsuite/models/pantograph/health.py",
             "room = min(theta0[i] - lo, hi - theta0[i])", "room = max(theta0[i] - lo, hi - theta0[i])",
             "the excursion figure measures the room to the far edge of the working range (under-reads)",
             "tests/pantograph/test_health.py"),
    Mutation("pantograph_step_time_ignored", "mbsuite/models/pantograph/inputs.py",
             'float(inp.get("t_step", d["t_step"].default))', 'float(d["t_step"].default)',
             "a step input's time t_step ignored (the default 0.1 s used)", NON_DEFAULT),
)
