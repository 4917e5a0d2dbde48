"""Build hook: the repository keeps the model files at its top level (`mjcf/`, `models_urdf/`, the source of truth);
a wheel carries a copy of them inside the package (`mbsuite/_modelfiles/`), where `mbsuite.paths` finds them."""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

MODEL_DIRS = ("mjcf", "models_urdf")


class BuildPyWithModelFiles(build_py):
    """`build_py` that also copies the top-level model directories into the built package."""

    def run(self) -> None:
        super().run()
        root = Path(__file__).resolve().parent
        target = Path(self.build_lib) / "mbsuite" / "_modelfiles"
        for name in MODEL_DIRS:
            dest = target / name
            if dest.exists():
                shutil.rmtree(dest)
            shutil.copytree(root / name, dest)


setup(cmdclass={"build_py": BuildPyWithModelFiles})
