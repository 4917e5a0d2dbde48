"""The perturbed run: `pytest --perturb EPS[:EPS_MAX] [--perturb-seed N]` runs only the tests that read
digit-sensitive quantities (marker `rounding`) and runs each of them, fixtures included, inside
`mbsuite.trust.perturbation.perturbed`: every parameter, scene input and initial state the test builds is changed by a
seeded relative draw of EPS (or of a size drawn per quantity in [EPS, EPS_MAX]). A stranger's machine changes the
last bits through its BLAS kernel, its libm or its SIMD level; the draws change them here, on any machine, without
touching the machine's settings (OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE stay as they are). A test that passes only
at one rounding reads an ill-conditioned quantity and fails here (docs/reproducibility.md, "Tests that read
crossings").

`rounding` is set by folder or file below (ROUNDING) and by `@pytest.mark.rounding` on single tests elsewhere.
`@pytest.mark.literal_inputs("why")` keeps a test out of the perturbed run: it compares a run with a closed form
written in the scene's literal numbers to round-off (1e-14), and a perturbed input is another problem whose closed form
differs by 1e-10; or it re-enacts a defect that only last-bit differences of the literal inputs trigger. Such a test
reads no crossing. A stability check made inside the perturbed run composes its draws with the run's. One
seed holds for the whole run, so a module fixture and the test that rebuilds its parameters see the same draws.
Runs in other processes (a CLI started with subprocess) and in other threads are not perturbed."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from mbsuite.trust.perturbation import perturbed

ROOT = Path(__file__).resolve().parent
#: folders and files whose every test reads digit-sensitive quantities (event times, lock instants, window means of
#: event-driven runs, statistics, bitwise comparisons of runs)
ROUNDING = ("drives", "engines/test_determinism.py", "suite/test_perturbation.py", "catenary/test_statistics.py")


def pytest_addoption(parser: pytest.Parser) -> None:
    g = parser.getgroup("mbsuite")
    g.addoption("--perturb", metavar="EPS[:EPS_MAX]", default=None,
                help="run only the tests marked `rounding`, each inside a seeded relative input perturbation of EPS "
                     "(or of a size drawn per quantity in [EPS, EPS_MAX]); e.g. 1e-12:1e-10")
    g.addoption("--perturb-seed", metavar="N", type=int, default=0, help="seed of the --perturb draws (default 0)")


def _parse(text: str) -> tuple[float, float | None]:
    parts = text.split(":")
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise pytest.UsageError(f"--perturb: {text!r} is not EPS or EPS:EPS_MAX (numbers, e.g. 1e-12:1e-10)") from None
    if len(vals) not in (1, 2) or not all(0.0 < v < 1e-3 for v in vals) or (len(vals) == 2 and vals[1] < vals[0]):
        raise pytest.UsageError(f"--perturb: {text!r} must be EPS or EPS:EPS_MAX with 0 < EPS <= EPS_MAX < 1e-3")
    return vals[0], (vals[1] if len(vals) == 2 else None)


def _rounding(item: pytest.Item) -> bool:
    rel = Path(str(item.path)).resolve().relative_to(ROOT).as_posix()
    return item.get_closest_marker("rounding") is not None or any(
        rel == r or rel.startswith(r.rstrip("/") + "/") for r in ROUNDING)


def pytest_configure(config: pytest.Config) -> None:
    opt = config.getoption("--perturb")
    config._mbsuite_perturb = None if opt is None else (*_parse(opt), config.getoption("--perturb-seed"))


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if _rounding(item) and item.get_closest_marker("rounding") is None:
            item.add_marker(pytest.mark.rounding)
    if config._mbsuite_perturb is None:
        return
    def perturbable(i: pytest.Item) -> bool:
        return i.get_closest_marker("rounding") is not None and i.get_closest_marker("literal_inputs") is None

    keep = [i for i in items if perturbable(i)]
    drop = [i for i in items if not perturbable(i)]
    if drop:
        config.hook.pytest_deselected(items=drop)
    items[:] = keep


def pytest_report_header(config: pytest.Config) -> str | None:
    p = config._mbsuite_perturb
    if p is None:
        return None
    eps, eps_max, seed = p
    size = f"{eps:g}" if eps_max is None else f"{eps:g} ... {eps_max:g}"
    return f"mbsuite: tests marked `rounding`, inputs perturbed by relative draws of {size} (seed {seed})"


def _wrapped(item: pytest.Item) -> Iterator[None]:
    p = item.config._mbsuite_perturb
    if p is None:
        return (yield)
    eps, eps_max, seed = p
    with perturbed(eps, seed, eps_max):
        return (yield)


@pytest.hookimpl(wrapper=True)
def pytest_runtest_setup(item: pytest.Item) -> Iterator[None]:
    return (yield from _wrapped(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_call(item: pytest.Item) -> Iterator[None]:
    return (yield from _wrapped(item))


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item: pytest.Item) -> Iterator[None]:
    return (yield from _wrapped(item))
