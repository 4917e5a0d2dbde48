"""Results that must not depend on the machine (docs/reproducibility.md): the compiled layer is built with
`-ffp-contract=off`, so no compiler fuses a*b+c into an FMA whatever the target CPU, and the native results are the same
bits whether the library is built for the x86-64 baseline or for this CPU; the BLAS thread count leaves the shipped
results unchanged bit for bit.

The -march comparison runs in subprocesses (a process loads one native library), in parallel, each with its library
built into a temporary cache; the thread counts are switched in this process through OpenBLAS's own calls."""

from __future__ import annotations

import contextlib
import ctypes
import os
import platform
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mbsuite.engines import native

ROOT = Path(__file__).resolve().parents[2]

#: the native layer's work in one process: the drives' stick/slip stepper in the core's loop, the pantograph's engine
#: plugins, the catenary's step core, and the probe a*b+c; every recorded channel is saved for a bitwise comparison
NATIVE_RUNS = """
import sys
import numpy as np
import mbsuite
from mbsuite.engines import native
from mbsuite.models.catenary.fe import assemble
from mbsuite.models.catenary.pantographs import TwoMassPantograph
from mbsuite.models.catenary.params import CatenaryParams
from mbsuite.models.catenary.sim import CoupledSimulation

out = {"probe": np.array([native.load().mbs_fp_contract_probe(1 + 2.0**-30, 1 - 2.0**-30, -1.0)])}
r = mbsuite.run(mbsuite.load_scene("drives/step_up_pwm").replace(solver={"duration": 0.5, "t_settle": 0.25}),
                engine="mujoco")
out.update({f"drives.{k}": v for k, v in r.signals.items()})
r = mbsuite.run(mbsuite.load_scene("pantograph/lab").replace(solver={"duration": 2.0, "t_settle": 1.0}))
out.update({f"pantograph.{k}": v for k, v in r.signals.items()})
p = CatenaryParams(n_spans=3, element_length=0.5, x_end=170.0, window_start=60.0, window_end=120.0)
panto = TwoMassPantograph(p.m1, p.k1, p.c1, p.m2, p.k2, p.c2, p.F0)
c = CoupledSimulation(assemble(p), panto, 300 / 3.6, 2e-4, "slack").run(0.0, 170.0, native=True)
out.update({"catenary.force": c.force, "catenary.head": c.head, "catenary.wire": c.wire, "catenary.uplift": c.uplift})
np.savez(sys.argv[1], **out)
"""


def _run_all(script: str, tmp: Path, envs: dict[str, dict[str, str]]) -> dict[str, dict[str, np.ndarray]]:
    """Run `script` once per entry of `envs` (name -> extra environment), in parallel, each building its native
    library into `tmp`; the saved arrays by name."""
    (tmp / "runs.py").write_text(script)
    env0 = {k: v for k, v in os.environ.items() if k != native.EXTRA_CFLAGS_ENV}
    env0.update(PYTHONPATH=str(ROOT), MBSUITE_NATIVE_DIR=str(tmp / "native"))
    procs = {name: subprocess.Popen([sys.executable, str(tmp / "runs.py"), str(tmp / f"{name}.npz")], cwd=ROOT,
                                    env={**env0, **extra}, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for name, extra in envs.items()}
    out = {}
    for name, p in procs.items():
        _, err = p.communicate(timeout=300)
        assert p.returncode == 0, f"{name}: {err[-3000:]}"
        with np.load(tmp / f"{name}.npz") as z:
            out[name] = {k: z[k] for k in z.files}
    return out


def _differing(a: dict[str, np.ndarray], b: dict[str, np.ndarray]) -> dict[str, float]:
    """Channels that are not bitwise equal -> their largest difference relative to the channel's largest value."""
    assert a.keys() == b.keys()
    return {k: float(np.max(np.abs(a[k] - b[k])) / max(float(np.max(np.abs(a[k]))), 1e-300))
            for k in a if not np.array_equal(a[k], b[k])}


def _cpu_has_fma() -> bool:
    try:
        flags = Path("/proc/cpuinfo").read_text()
    except OSError:
        return False
    return any(line.startswith("flags") and " fma" in line for line in flags.splitlines())


def test_flags_forbid_contraction_and_extra_flags_are_keyed(monkeypatch):
    """`-ffp-contract=off` (and `-fno-fast-math`) are in the flags; $MBSUITE_NATIVE_EXTRA_CFLAGS comes after them
    (so a check can override them) and is part of the cache key (so such a build never replaces the default one)."""
    assert "-ffp-contract=off" in native.CFLAGS and "-fno-fast-math" in native.CFLAGS
    assert not any(f.startswith("-ffp-contract=") and f != "-ffp-contract=off" for f in native.CFLAGS)
    assert not any(f in native.CFLAGS for f in ("-ffast-math", "-Ofast", "-funsafe-math-optimizations"))
    monkeypatch.delenv(native.EXTRA_CFLAGS_ENV, raising=False)
    assert native.cflags() == native.CFLAGS
    key = native.build_key()
    monkeypatch.setenv(native.EXTRA_CFLAGS_ENV, "-march=x86-64 '-DNAME=two words'")
    assert native.cflags() == (*native.CFLAGS, "-march=x86-64", "-DNAME=two words")
    assert native.build_key() != key


def test_library_rounds_multiply_add_twice():
    """The library this process uses computes a*b+c with two roundings: (1 + 2^-30)(1 - 2^-30) - 1 is 0, not the
    -2^-60 an FMA gives. On aarch64, where every target has FMA and GCC fuses by default, this alone fails if the
    flag is lost; on x86-64 the next test builds for this CPU."""
    if os.environ.get(native.EXTRA_CFLAGS_ENV):
        pytest.skip(f"${native.EXTRA_CFLAGS_ENV} is set: this process's library is not the default build")
    assert not native.fuses_multiply_add()
    assert native.load().mbs_fp_contract_probe(1 + 2.0**-30, 1 - 2.0**-30, -1.0) == 0.0


def test_native_results_are_the_same_bits_for_baseline_and_this_cpu(tmp_path):
    """The drives stepper (0.5 s of step_up_pwm, lock-ups included), the pantograph plugins (2 s of the lab scene) and
    the catenary core (a 170 m passage with slack droppers) give bitwise the same records from a library built for
    the x86-64 baseline (no FMA) and one built with -march=native (FMA, AVX2 where the CPU has them).
    Control: the same sources built with contraction re-enabled (-ffp-contract=fast -mfma) fuse the probe and move
    every workload (measured: 1e-16 ... 6e-12 relative on these channels), so the comparison can tell."""
    if platform.machine().lower() not in ("x86_64", "amd64"):
        pytest.skip("the -march comparison is for x86-64 (on aarch64 every target has FMA: the probe test covers it)")
    if not _cpu_has_fma():
        pytest.skip("this CPU has no FMA: a build for it cannot differ from the baseline")
    runs = _run_all(NATIVE_RUNS, tmp_path, {
        "baseline": {"MBSUITE_NATIVE_EXTRA_CFLAGS": "-march=x86-64"},
        "this_cpu": {"MBSUITE_NATIVE_EXTRA_CFLAGS": "-march=native"},
        "fused": {"MBSUITE_NATIVE_EXTRA_CFLAGS": "-ffp-contract=fast -mfma"},
    })
    base, cpu, fused = runs["baseline"], runs["this_cpu"], runs["fused"]
    assert base["probe"][0] == 0.0 and cpu["probe"][0] == 0.0
    assert fused["probe"][0] == -(2.0**-60)
    assert not _differing(base, cpu), f"-march changed native results: {_differing(base, cpu)}"
    moved = {k.split(".")[0] for k in _differing(base, fused)}
    assert moved >= {"probe", "drives", "pantograph", "catenary"}, f"contraction did not move: {moved}"


def _openblas() -> list[tuple[ctypes.CDLL, str]]:
    """The OpenBLAS libraries numpy and scipy run on (scipy-openblas wheels), with their symbol suffix; [] if these
    are not the BLAS in use (then the thread count cannot be set here)."""
    import scipy

    found = []
    for pkg, pattern, suffix in ((np, "libscipy_openblas64_*", "64_"), (scipy, "libscipy_openblas-*", "")):
        libs = sorted((Path(pkg.__file__).parent.parent / f"{pkg.__name__}.libs").glob(pattern))
        if libs:
            lib = ctypes.CDLL(str(libs[0]))  # the copy already loaded (same file): dlopen returns its handle
            if hasattr(lib, f"scipy_openblas_set_num_threads{suffix}"):
                found.append((lib, suffix))
    return found


@contextlib.contextmanager
def _blas_threads(n: int):
    """numpy's and scipy's OpenBLAS on `n` threads inside (restored after); yields the counts they report."""
    libs = _openblas()
    before = [getattr(lib, f"scipy_openblas_get_num_threads{sfx}")() for lib, sfx in libs]
    try:
        for lib, sfx in libs:
            getattr(lib, f"scipy_openblas_set_num_threads{sfx}")(n)
        yield [getattr(lib, f"scipy_openblas_get_num_threads{sfx}")() for lib, sfx in libs]
    finally:
        for (lib, sfx), m in zip(libs, before, strict=True):
            getattr(lib, f"scipy_openblas_set_num_threads{sfx}")(m)


def _blas_workloads() -> dict[str, np.ndarray]:
    """Shipped results that go through numpy's and scipy's BLAS: coupler/double_lateral (its kinematic reference),
    the coupler's pose over one revolution (Gauss-Newton) and 180 m of the EN 50318 passage on 4 spans (the FE
    assembly and static solve). Each goes through BLAS: with OpenBLAS forced onto another CPU's kernels
    (OPENBLAS_CORETYPE=Sandybridge) they move by 7e-15 ... 2e-11 of each channel's largest value (measured)."""
    import mbsuite
    from mbsuite.models.coupler import single
    from mbsuite.models.coupler.params import CouplerParams

    out = {f"coupler.{k}": v for k, v in mbsuite.run("coupler/double_lateral").signals.items()}
    out["coupler_fpp.u"] = single.single_revolution(CouplerParams(), 0.0, 0.0, 73).u
    scene = mbsuite.load_scene("catenary/en50318").replace(
        params={"n_spans": 4, "x_end": 180.0, "window_start": 60.0, "window_end": 180.0})
    r = mbsuite.run(scene)
    out.update({f"catenary.{k}": v for k, v in r.signals.items()})
    out["catenary.stats"] = np.array([r.statistics[k] for k in ("Fm", "sigma", "stat_max", "stat_min", "max", "min")])
    return out


def test_results_do_not_depend_on_the_blas_thread_count():
    """The BLAS workloads with numpy's and scipy's OpenBLAS on 1 and on 2 threads: every signal and statistic
    bitwise equal (measured across processes too, OPENBLAS_NUM_THREADS=1 against the default, for every headline
    output of docs/reproducibility.md)."""
    if not _openblas():
        pytest.skip("numpy/scipy do not run on scipy-openblas here: the thread count cannot be set from the test")
    with _blas_threads(1) as n1:
        one = _blas_workloads()
    with _blas_threads(2) as n2:
        if set(n2) == {1}:
            pytest.skip("OpenBLAS keeps one thread here")
        two = _blas_workloads()
    assert set(n1) == {1} and set(n2) == {2}
    assert not _differing(one, two), f"BLAS threads changed results: {_differing(one, two)}"
