"""The package works outside the checkout: build the wheel from the tracked files, install it into a fresh venv in a
temporary directory, and there run a short scene of every model and load every shipped model file in both engines.

The fresh venv gets mbsuite from the wheel only (`pip install --no-deps`); its third-party dependencies are made
visible from the test's own environment through a `.pth` file (after the venv's own packages), so the test needs no
network and checks exactly what the wheel carries (model files, scenes, C sources of the engine plugins, READMEs).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

PROBE = r"""
import json, sys
import mujoco, pinocchio as pin
import mbsuite
from mbsuite.engines import native

out = {"file": mbsuite.__file__, "runs": {}, "mjcf": {}, "urdf": {}}
for name in sorted(mbsuite.model_specs()):
    scene = mbsuite.load_scene(name)
    if name != "catenary":  # a passage is a fixed length of line: its short form is the 2-mass scene below
        scene = scene.replace(solver={"duration": min(scene.solver.duration, 0.3), "t_settle": 0.0})
    res = mbsuite.run(scene)
    out["runs"][name] = {k: float(abs(v).max()) for k, v in res.signals.items()}
native.load()
for name, path in mbsuite.model_files("mjcf").items():
    m = mujoco.MjModel.from_xml_path(str(path))
    pm = pin.buildModelFromMJCF(str(path))
    out["mjcf"][name] = [m.nbody, pm.nq]
for name, path in mbsuite.model_files("urdf").items():
    out["urdf"][name] = pin.buildModelFromUrdf(str(path)).nq
print(json.dumps(out))
"""


def _tracked_copy(dest: Path) -> Path:
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    for f in files:
        target = dest / f
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, target)
    return dest


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(), reason="needs the git checkout")
def test_wheel_installs_and_runs_every_model_outside_the_checkout(tmp_path):
    src = _tracked_copy(tmp_path / "src")
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "-w", str(tmp_path / "dist")],
                           capture_output=True, text=True, timeout=600)
    assert build.returncode == 0, build.stderr[-2000:]
    assert "deprecat" not in (build.stdout + build.stderr).lower(), "the build prints deprecation banners"
    (wheel,) = (tmp_path / "dist").glob("mbsuite-*.whl")

    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    # the wheel's files, unpacked as pip would (no network, no dependency resolution)
    inst = subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-compile", "--target", str(site),
                           str(wheel)], capture_output=True, text=True, timeout=300)
    assert inst.returncode == 0, inst.stderr[-2000:]
    # the dependencies' own .pth files (e.g. pin's cmeel prefix) must run, hence addsitedir; mbsuite itself is
    # found first in the venv's own site-packages (the checkout's editable finder, if any, comes after it)
    deps = sysconfig.get_paths()["purelib"]
    (site / "zz_deps.pth").write_text(f"import site; site.addsitedir({deps!r})\n")

    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "MBSUITE_MODELS_DIR")}
    run = subprocess.run([str(py), "-c", PROBE], cwd=work, capture_output=True, text=True, timeout=900, env=env)
    assert run.returncode == 0, run.stderr[-3000:]
    out = json.loads(run.stdout.strip().splitlines()[-1])
    assert out["file"].startswith(str(site)), out["file"]  # the wheel's copy, not the checkout
    assert set(out["runs"]) >= {"catenary", "coupler", "drives", "iftomm", "pantograph"}
    for name, sig in out["runs"].items():
        assert sig and all(0.0 <= v < 1e9 for v in sig.values()), (name, sig)
    shipped = {p.stem for p in (ROOT / "mjcf").glob("*.xml")}
    assert set(out["mjcf"]) == shipped and all(nb > 1 and nq > 0 for nb, nq in out["mjcf"].values())
    assert set(out["urdf"]) == {p.stem for p in (ROOT / "models_urdf").glob("*.urdf")}

    cli = subprocess.run([str(env_dir / "bin" / "python"), "-m", "mbsuite.cli", "run", "iftomm/fourbar", "--json"],
                         cwd=work, capture_output=True, text=True, timeout=300, env=env)
    assert cli.returncode == 0 and json.loads(cli.stdout)["signals"], cli.stderr[-2000:]
