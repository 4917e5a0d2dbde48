"""One package per mechanism. A package that exports `SPEC` (a `mbsuite.registry.ModelSpec`) is registered."""
