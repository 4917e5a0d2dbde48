"""Model-agnostic analyses: sweeps, fundamental projection, work-precision."""
