"""Model-agnostic analyses: sweeps, fundamental projection, work-precision, error estimates, and the design
studies (`designspace`, `sensitivity`: Morris and Sobol; `optimise`: constrained, robust, Pareto)."""
