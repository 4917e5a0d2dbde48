"""Model-agnostic analyses: sweeps, fundamental projection, work-precision, error estimates, the design
studies (`designspace`, `sensitivity`: Morris and Sobol; `optimise`: constrained, robust, Pareto) and the comparison
of earlier runs' summaries (`compare`)."""
