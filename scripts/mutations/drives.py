"""Seeded defects in the switched-mode drives (Oldaker 1997): event-exact path, MuJoCo plugin, controllers, design."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("drives_breakaway_scaled_1pct", "mbsuite/models/drives/event_exact.py",
             "        return float(self.peaks[e] * el[e])", "        return float(1.01 * self.peaks[e] * el[e])",
             "a clutch's stuck-torque bound (breakaway) scaled by 1.01 on the hand path", "tests/drives/test_friction.py"),
    Mutation("drives_lock_impact_dropped", "mbsuite/models/drives/drive.py",
             "    resid = e_in - e_out - sum(d.values()) - stored",
             "    resid = e_in - e_out - sum(v for k, v in d.items() if k != 'lock_impact') - stored",
             "a loss term (the kinetic energy removed by plastic locks) dropped from the energy balance",
             "tests/drives/test_drives.py"),
    Mutation("drives_event_one_step_late", "mbsuite/models/drives/native/drives.c",
             "  row[0] = te;", "  row[0] = te + S->dt;",
             "every mode change of the MuJoCo path located one step late", "tests/drives/test_native.py"),
    Mutation("drives_storage_time_truncated", "mbsuite/models/drives/commands.py",
             "        return int(math.floor(x + 0.5))", "        return int(math.floor(x))",
             "durations converted to controller samples by truncation where the thesis means whole samples",
             "tests/drives/test_drives.py"),
    Mutation("drives_sliding_torque_scaled_1pct", "mbsuite/models/drives/event_exact.py",
             "            sys.apply(f, e, d * el[e])", "            sys.apply(f, e, 1.01 * d * el[e])",
             "a slipping clutch's torque scaled by 1.01 in the dynamics (its loss bookkeeping unchanged)",
             "tests/drives/test_friction.py"),
    Mutation("drives_damper_loss_dropped", "mbsuite/models/drives/event_exact.py",
             "            dE[k0 + i] = s.D * d_w * d_w", "            dE[k0 + i] = 0.0",
             "a spring-damper's dissipation dropped from the energy bookkeeping", "tests/drives/test_msl.py"),
)
