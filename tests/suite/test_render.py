"""Every shipped MJCF can be looked at: it renders offscreen (EGL, headless) from its own camera to an image that is
neither black nor empty — lit, with the mechanism's geometry in view.

The rendering runs in a child process with `MUJOCO_GL=egl` set before mujoco is imported (the GL backend is chosen
once per process)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

import mbsuite

FILES = mbsuite.model_files("mjcf")

RENDER = r"""
import json, sys
import numpy as np
import mujoco
import mbsuite

mbsuite.native.load()
out = {}
for name, path in sorted(mbsuite.model_files("mjcf").items()):
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    if m.nkey:
        mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    with mujoco.Renderer(m, 240, 320) as r:
        r.update_scene(d, camera=0 if m.ncam else -1)
        img = r.render().astype(float)
    values, counts = np.unique(img.reshape(-1, 3), axis=0, return_counts=True)
    background = values[np.argmax(counts)]
    differs = np.abs(img - background).sum(axis=2) > 30.0
    out[name] = {"ncam": int(m.ncam), "nlight": int(m.nlight), "brightness": float(img.mean()),
                 "not_background": float(differs.mean())}
print(json.dumps(out))
"""


# The failures of a machine without headless OpenGL, as MuJoCo and PyOpenGL word them (the traceback's last line):
# no libEGL or no PyOpenGL, no EGL device, or a driver without the device-platform extensions.
NO_EGL = (
    "ImportError: ('Unable to load EGL library'",
    "ImportError: Failed to import OpenGL backend (MUJOCO_GL='egl')",
    "ImportError: Cannot initialize a EGL device display.",
    "ImportError: eglQueryDevicesEXT is not available.",
    "ImportError: eglGetPlatformDisplayEXT is not available.",
)


@pytest.fixture(scope="module")
def renders() -> dict:
    env = {**os.environ, "MUJOCO_GL": "egl"}
    proc = subprocess.run([sys.executable, "-c", RENDER], capture_output=True, text=True, timeout=600, env=env)
    last = proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else ""
    if proc.returncode != 0 and last.startswith(NO_EGL):
        pytest.skip(f"offscreen rendering unavailable: {last}")
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("name", sorted(FILES))
def test_model_file_renders_lit_and_visible(renders, name):
    r = renders[name]
    assert r["ncam"] >= 1, f"{name}: no camera (menagerie style: a named camera framing the mechanism)"
    assert r["nlight"] >= 1, f"{name}: no light"
    assert r["brightness"] > 25.0, f"{name}: image nearly black (mean brightness {r['brightness']:.1f}/255)"
    assert r["not_background"] > 0.02, f"{name}: only {100 * r['not_background']:.2f} % of the image is not background"
