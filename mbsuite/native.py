"""The one call that makes MuJoCo know mbsuite's engine plugins (see `mbsuite.engines.native`):

    import mbsuite.native
    mbsuite.native.load()
"""

from .engines.native import NativeBuildError, build, library_path, load, plugin_names

__all__ = ["NativeBuildError", "build", "library_path", "load", "plugin_names"]
