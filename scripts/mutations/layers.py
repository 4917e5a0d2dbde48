"""Seeded defects in the layers below the models: engine core, signals, health, limits, sweep store."""

from mutations.mutation import Mutation

MUTATIONS: tuple[Mutation, ...] = (
    Mutation("health_stability_figure_under_reads", "mbsuite/trust/health.py",
             'Figure("stability_margin", h * omega_max,', 'Figure("stability_margin", 0.1 * h * omega_max,',
             "the stability-margin figure under-reads ten times (inaccurate timesteps pass quietly)",
             "tests/suite/test_health.py"),
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
    Mutation("health_nyquist_ratio_under_reads", "mbsuite/trust/health.py",
             'Figure("nyquist_ratio", f_input * 2.0 * h,', 'Figure("nyquist_ratio", f_input * h,',
             "the Nyquist-ratio figure measures the input frequency against 1/h instead of 1/(2h): it under-reads "
             "twice (an input with 5 steps per half period passes)", "tests/suite/test_health.py"),
    Mutation("health_nan_figure_passes", "mbsuite/trust/health.py",
             "        return math.isfinite(self.value) and self.value <= self.bound",
             "        return not self.value > self.bound",
             "a health figure that is NaN (a run gone non-finite) judged within its bound",
             "tests/suite/test_health.py"),
    Mutation("signals_pulse_one_period_too_many", "mbsuite/engines/inputs.py",
             "            on &= k < self.n", "            on &= k <= self.n",
             "a pulse train of n periods gives n + 1 pulses in the Python evaluation (off-by-one)",
             "tests/engines/test_signals.py"),
    Mutation("core_channel_columns_shifted", "mbsuite/engines/core.py",
             "        out, col = {}, 1", "        out, col = {}, 0",
             "the recorded channels read one column early (the first channel gets the time column, each other its "
             "neighbour's values)", "tests/engines/test_core.py"),
    Mutation("perturbation_draws_one_signed", "mbsuite/trust/perturbation.py",
             "        z = float(rng.standard_normal())", "        z = abs(float(rng.standard_normal()))",
             "perturbation draws all of one sign (|z| instead of a standard normal z): every copy is biased upwards",
             "tests/suite/test_perturbation.py"),
    Mutation("condition_kappa_under_reads", "mbsuite/trust/robustness.py",
             "    return Condition(y0, worst, worst / (eps * scale), eps, draws)",
             "    return Condition(y0, worst, worst / (eps * scale) / draws, eps, draws)",
             "the condition estimate of a derived quantity divided by the number of draws: kappa under-reads, and "
             "every audit that reads it passes", "tests/suite/test_perturbation.py"),
    Mutation("perturbation_range_ignored", "mbsuite/trust/perturbation.py",
             "        return self.eps * (self.eps_max / self.eps) ** float(rng.uniform()) * z",
             "        return self.eps * z",
             "a perturbation range [eps, eps_max] draws every quantity at its lower end: the rounding emulation of "
             "the perturbed test run is a hundred times weaker than stated", "tests/suite/test_perturbation.py"),
    Mutation("perturbation_mirror_dropped", "mbsuite/trust/perturbation.py",
             "        y = x * (1.0 - dz)", "        y = x * (1.0 + dz)",
             "a draw that would cross a declared range end is not mirrored: the quantity silently stays unperturbed",
             "tests/suite/test_perturbation.py"),
    Mutation("workprecision_rel_error_of_the_larger", "mbsuite/analysis/workprecision.py",
             "    return abs(a - b) / max(abs(b), floor)", "    return abs(a - b) / max(abs(a), abs(b), floor)",
             "the work-precision relative error divided by the larger of run and reference: it under-reads for runs "
             "that read high", "tests/suite/test_workprecision.py"),
    Mutation("store_key_partial_keywords_dropped", "mbsuite/analysis/sweep/encoding.py",
             "        args = canonical(encode_value([list(fn.args), dict(fn.keywords)])).decode()",
             "        args = canonical(encode_value(list(fn.args))).decode()",
             "a point's store key leaves out the keyword arguments bound with functools.partial: a study with a "
             "changed parameter is served the stored results of the old one", "tests/suite/test_store.py"),
    Mutation("store_numpy_scalar_as_python_number", "mbsuite/analysis/sweep/encoding.py",
             '        return {_TAG: "scalar", "dtype": obj.dtype.str, "v": encode_value(obj.item())}',
             "        return encode_value(obj.item())",
             "numpy scalars stored as plain Python numbers: float32(1) and 1.0 share a key (one's stored result "
             "served for the other) and come back with another type and precision", "tests/suite/test_store.py"),
    Mutation("store_array_shape_dropped", "mbsuite/analysis/sweep/encoding.py",
             "            return np.array(data, dtype=dt).reshape(shape)",
             "            return np.array(data, dtype=dt)",
             "arrays come back from the store flattened (a 2 x 3 result read as 6 values)",
             "tests/suite/test_store.py"),
    Mutation("schema_unknown_key_dropped", "mbsuite/schema.py",
             "        unknown = [k for k in data if k not in self.keys and not self._prefix(k)]",
             "        unknown: list[Any] = []",
             "a declared section silently drops a key it does not declare (a typo in a line file or a scene section "
             "runs on the default)", "tests/suite/test_declarations.py"),
    Mutation("cli_override_repeated_key_kept", "mbsuite/overrides.py",
             "            if old.key == new.key:", "            if old.key == new.key and False:",
             "the command line keeps the last of two overrides of one key (--set and --vary, or --vary twice): one "
             "is dropped silently", "tests/suite/test_overrides.py"),
    Mutation("statistics_undeclared_accepted", "mbsuite/statistics.py",
             "    missing = sorted(k for k in values if lookup(table, k) is None)\n"
             "    if missing:\n"
             "        raise KeyError(f\"model '{model}' declares no statistic {missing}; add them to its "
             "statistics\")\n"
             "    out: dict[str, float | bool] = {}\n"
             "    for k, v in values.items():\n"
             "        stat = lookup(table, k)\n",
             "    out: dict[str, float | bool] = {}\n"
             "    for k, v in values.items():\n"
             "        stat = lookup(table, k) or next(iter(table.values()))\n",
             "a statistic without a declaration accepted silently, under the first declared statistic's unit, "
             "definition and window",
             "tests/suite/test_statistics.py"),
    Mutation("band_system_not_checked", "mbsuite/registry.py",
             "        if system not in self.systems:",
             "        if system is None:",
             "a band constraint's unknown system accepted (a study optimises against a target that does not exist)",
             "tests/suite/test_statistics.py"),
    Mutation("studies_threads_ignored", "mbsuite/analysis/designspace.py",
             "in scene.spec.studies.threads else None",
             "in () else None",
             "the design studies ignore the paths a model declares thread-safe (MuJoCo studies start processes)",
             "tests/suite/test_statistics.py"),
)
