"""Seeded defects in the layers below the models: engine core, signals, health, limits, sweep store."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("health_stability_figure_under_reads", "mbsuite/health.py",
             'Figure("stability_margin", h * omega_max,', 'Figure("stability_margin", 0.1 * h * omega_max,',
             "the stability-margin figure under-reads ten times (inaccurate timesteps pass quietly)",
             "tests/pantograph"),
    Mutation("core_input_row_one_step_late", "mbsuite/engines/native/core.c",
             "      const double* row = J->ctrl + k * J->ctrl_ncol;",
             "      const double* row = J->ctrl + (k > 0 ? k - 1 : 0) * J->ctrl_ncol;",
             "the input row applied one step late (each step gets the previous step's input)", "tests/engines"),
    Mutation("signals_c_sine_phase", "mbsuite/engines/native/core.c",
             "s[2] * sin(2.0 * M_PI * s[3] * (t - s[5]) + s[4])",
             "s[2] * sin(2.0 * M_PI * s[3] * (t - s[5]) + 1.001 * s[4])",
             "the C evaluation of a sine input with its phase off by 0.1 %", "tests/engines"),
    Mutation("limits_upper_end_ignored", "mbsuite/limits.py",
             "        if self.hi is not None and (value > self.hi or (self.hi_open and value == self.hi)):",
             "        if False:",
             "every declared upper limit ignored (too large values accepted silently)",
             "tests/suite/test_reliability.py"),
    Mutation("store_checksum_not_verified", "mbsuite/analysis/sweep/store.py",
             "        if digest(body) != rec[\"sha256\"]:\n            self._report(n, offset, \"checksum mismatch",
             "        if False:\n            self._report(n, offset, \"checksum mismatch",
             "the sweep store trusts records whose checksum fails (a forged result comes back)",
             "tests/suite/test_store.py"),
)
