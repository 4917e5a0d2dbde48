import numpy as np
import pytest

from mbsuite import load_scene
from mbsuite.models.pantograph.equations import PantographODE
from mbsuite.models.pantograph.params import PantographParams


@pytest.fixture(scope="session")
def params() -> PantographParams:
    return PantographParams()


@pytest.fixture(scope="session")
def lab_scene():
    return load_scene("pantograph")


@pytest.fixture(scope="session")
def ode() -> PantographODE:
    return PantographODE()


@pytest.fixture(scope="session")
def random_thetas() -> np.ndarray:
    """120 random configurations over (and beyond) the working range."""
    rng = np.random.default_rng(20261122)
    return np.column_stack([rng.uniform(0.1, 1.2, 120), rng.uniform(0.1, 1.2, 120), rng.uniform(-0.6, 0.6, 120)])
