"""Model-agnostic engine plumbing: loading models with clear errors, callbacks, stepping, linear-algebra utilities."""
