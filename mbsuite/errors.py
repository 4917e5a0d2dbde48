"""Errors raised by mbsuite. Every message names what is wrong (file, key, parameter, value)."""


class MbsuiteError(Exception):
    """Base class of every mbsuite error."""


class SceneError(MbsuiteError, ValueError):
    """A scene file or scene dictionary is malformed: unknown key, unknown effect, bad value."""


class ParameterError(MbsuiteError, ValueError):
    """A physical parameter is non-physical (negative mass, zero length, ...)."""


class ModelFileError(MbsuiteError, ValueError):
    """A URDF/MJCF file is missing or malformed, or does not hold what the model needs."""


class GeometryError(MbsuiteError, ValueError):
    """The linkage cannot reach the requested configuration (e.g. operating height out of reach)."""


class SolverError(MbsuiteError, RuntimeError):
    """A solver diverged, produced non-finite values, or failed to converge."""
