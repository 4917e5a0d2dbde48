"""`mbsuite render SCENE --out PNG`: a scene's MuJoCo model rendered offscreen, headless (EGL), to a PNG that holds the
image MuJoCo's own renderer makes of the scene's model in its initial state."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest

DIRECT = r"""
import json, sys
import mujoco
import mbsuite

scene = mbsuite.load_scene(sys.argv[1])
model, data = scene.spec.mujoco_model(scene)
mujoco.mj_forward(model, data)
with mujoco.Renderer(model, 120, 160) as r:
    r.update_scene(data, camera=0 if model.ncam else -1)
    print(json.dumps(r.render().tolist()))
"""


def _cli(*argv: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    return subprocess.run([sys.executable, "-m", "mbsuite.cli", *argv], capture_output=True, text=True, env=env,
                          timeout=300)


@pytest.mark.slow
@pytest.mark.parametrize("scene", ["pantograph"])
def test_render_writes_the_scene_as_mujoco_draws_it(tmp_path, scene):
    from matplotlib.image import imread

    out = tmp_path / "scene.png"
    run = _cli("render", scene, "--out", str(out), "--width", "160", "--height", "120", "--json")
    assert run.returncode == 0, run.stderr
    assert json.loads(run.stdout)["image"] == str(out)
    img = np.rint(imread(out)[..., :3] * 255).astype(int)
    assert img.shape == (120, 160, 3)
    env = {**os.environ, "MUJOCO_GL": "egl"}
    direct = subprocess.run([sys.executable, "-c", DIRECT, scene], capture_output=True, text=True, env=env,
                            timeout=300, check=True)
    assert np.array_equal(img, np.array(json.loads(direct.stdout)))
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50  # a picture, not a blank


def test_render_refuses_a_model_without_mujoco_by_name(tmp_path, capsys):
    from mbsuite.cli import main

    assert main(["render", "rotational/coupled_clutches", "--out", str(tmp_path / "x.png")]) == 2
    assert "model 'rotational' has no MuJoCo model" in capsys.readouterr().err
    assert main(["render", "pantograph", "--out", str(tmp_path / "x.jpg")]) == 2
    assert "give a .png file" in capsys.readouterr().err
