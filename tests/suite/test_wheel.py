"""The package works outside the checkout: build the wheel from the tracked files, install it into a fresh venv in a
temporary directory, and there run a short scene of every model and load every shipped model file in both engines,
and (slow) every command of the command line, each with small arguments (`COMMANDS`, which names every command).

The fresh venv gets mbsuite from the wheel only (`pip install --no-deps`); its third-party dependencies are made
visible from the test's own environment through a `.pth` file (after the venv's own packages), so the test needs no
network and checks exactly what the wheel carries (model files, scenes, C sources of the engine plugins, READMEs).
"""

from __future__ import annotations

import argparse
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


NEEDS_GIT = pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(),
                               reason="needs the git checkout")

# every command of the command line with small arguments: (argv, the exit status it must give without a display)
COMMANDS = [
    (["list", "--json"], 0),
    (["pantograph", "fit-lumped", "--stages", "1", "--df", "0.5", "--starts", "2", "--order", "4", "--json"], 0),
    (["run", "iftomm/fourbar", "--json"], 0),
    (["view", "pantograph"], 2),  # no display here: the one-line message that points to offscreen rendering
    (["render", "iftomm/fourbar", "--out", "fourbar.png", "--width", "64", "--height", "48"], 0),
    (["sweep", "iftomm/fourbar", "--vary", "solver.duration=0.2,0.3", "--workers", "1", "--json"], 0),
    (["workprecision", "rotational/coupled_clutches", "--quick", "--repeats", "1", "--json"], 0),
    (["perturb", "iftomm/fourbar", "--duration", "0.2", "--eps", "1e-9", "--draws", "1", "--json"], 0),
    (["hardcases", "--json"], 0),
    (["sensitivity", "iftomm/fourbar", "--set", "solver.duration=0.2", "--vary", "params.gravity=9:10", "--vary",
      "input.rate=5:6", "--method", "morris", "--n", "2", "--workers", "1", "--json"], 0),
    (["optimise", "iftomm/fourbar", "--set", "solver.duration=0.2", "--vary", "params.gravity=9:10", "--objective",
      "final_angle", "--maxiter", "1", "--popsize", "5", "--workers", "1", "--json"], 0),
    (["catenary", "--json"], 0),
    (["coupler", "jacobian", "--json"], 0),
    (["coupler", "fpp", "--n", "24", "--json"], 0),
    (["coupler", "criteria", "--quick", "--json"], 0),
    (["coupler", "dynamics", "--json"], 0),
    (["drive", "design", "tables", "--json"], 0),
    (["drive", "design", "srmin", "--P", "500", "--wmin", "100", "--wrip", "10", "--Jl", "0.1", "--json"], 0),
    (["drive", "design", "cadjs", "--P", "200", "--srmin", "15", "--wmax", "400", "--vm", "100", "--tau-c", "8",
      "--json"], 0),
    (["drive", "design", "springsz", "--K", "100", "--xmax", "0.5", "--json"], 0),
    (["drive", "design", "gains", "--Jl", "0.1", "--ts", "0.5", "--taul", "1", "--w0", "300", "--P", "500", "--json"],
     0),
    (["drive", "run", "drives/step_up_pwm", "--duration", "0.2", "--json"], 0),
    (["run", "rotational/coupled_clutches", "--json"], 0),
    (["drive", "efficiency", "drives/step_up_efficiency", "--loads", "0.1", "--duration", "0.5", "--json"], 0),
    (["rotational", "coupled-clutches", "--json"], 0),
    (["pantograph", "equilibrium", "--json"], 0),
    (["pantograph", "modes", "--json"], 0),
    (["pantograph", "freqresp", "--methods", "linear", "--f-min", "1", "--f-max", "3", "--df", "1", "--json"], 0),
    (["equilibrium", "pantograph", "--json"], 0),
    (["modes", "pantograph", "--json"], 0),
    (["freqresp", "pantograph", "--methods", "linear", "--f-min", "1", "--f-max", "3", "--df", "1", "--json"], 0),
    (["run", "iftomm/fourbar", "--out", "fourbar_a"], 0),
    (["run", "iftomm/fourbar", "--set", "input.rate=5", "--out", "fourbar_b"], 0),
    (["compare", "fourbar_a", "fourbar_b", "--json"], 0),
]

PROBE_CLI = r"""
import contextlib, io, json, sys
from mbsuite.cli import main
out = []
for argv in json.loads(sys.argv[1]):
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(argv)
    out.append({"argv": argv, "code": code, "err": err.getvalue()[-500:]})
print(json.dumps(out))
"""


def _leaves(parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()) -> set[tuple[str, ...]]:
    """Every command of a parser as the words that name it (`("coupler", "fpp")`)."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        return {prefix}
    out: set[tuple[str, ...]] = set()
    seen: set[int] = set()
    for name, sub in subs[0].choices.items():
        if id(sub) not in seen:  # an alias is the same parser
            seen.add(id(sub))
            out |= _leaves(sub, (*prefix, name))
    return out


def test_the_wheel_commands_name_every_command():
    """`COMMANDS` (what the wheel test runs) holds every command the command line has: a new command is run too."""
    from mbsuite.cli.parser import build_parser

    leaves = _leaves(build_parser())
    named = {leaf for leaf in leaves if any(tuple(argv[:len(leaf)]) == leaf for argv, _ in COMMANDS)}
    assert named == leaves, sorted(leaves - named)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, Path, Path, dict]:
    """The wheel built from the tracked files and installed into a fresh venv: (python, site-packages, a working
    directory outside the checkout, the environment to run in)."""
    tmp_path = tmp_path_factory.mktemp("wheel")
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
    return py, site, work, env


@NEEDS_GIT
def test_wheel_installs_and_runs_every_model_outside_the_checkout(installed):
    py, site, work, env = installed
    env_dir = py.parent.parent
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


@NEEDS_GIT
@pytest.mark.slow
def test_wheel_runs_every_command_outside_the_checkout(installed):
    """Every command of the command line, from the installed wheel, in a directory outside the checkout: each exits
    as it must (0, or 2 with its one-line message for `view` without a display), none with an internal error."""
    py, _site, work, env = installed
    # headless, as a server runs it: no display, offscreen GL chosen before the first command imports mujoco
    env = {**{k: v for k, v in env.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}, "MUJOCO_GL": "egl"}
    run = subprocess.run([str(py), "-c", PROBE_CLI, json.dumps([argv for argv, _ in COMMANDS])], cwd=work,
                         capture_output=True, text=True, timeout=1800, env=env)
    assert run.returncode == 0, run.stderr[-3000:]
    results = json.loads(run.stdout.strip().splitlines()[-1])
    bad = [(r["argv"], r["code"], r["err"]) for r, (_, code) in zip(results, COMMANDS, strict=True)
           if r["code"] != code or "internal error" in r["err"]]
    assert not bad, bad
