"""The package version (also `mbsuite.__version__`; `pyproject.toml` holds the same string)."""

__version__ = "0.1.0"
