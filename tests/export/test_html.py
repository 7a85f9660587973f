"""The exported web page in headless Chromium: it loads with no console error and no network, draws the
creature (pixels differ from the empty scene), and the picture changes as the slider moves time on.
Runs where Debian's ``chromium`` and npm's ``playwright-core`` are installed (``.ci/run`` installs both)."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from lifelike_mj.export import write_poses

MODULES = Path(__file__).resolve().parents[2] / ".ci" / "node" / "node_modules"
CHROMIUM = shutil.which("chromium")
pytestmark = pytest.mark.skipif(
    CHROMIUM is None or shutil.which("node") is None or not (MODULES / "playwright-core").is_dir(),
    reason="Chromium or playwright-core is not installed (.ci/run installs Debian's chromium and npm's playwright-core)")


def in_chromium(*args: str) -> dict:
    """``page_check.js`` run by Node on ``args``: its JSON report."""
    out = subprocess.run(["node", str(Path(__file__).with_name("page_check.js")), *args], capture_output=True,
                         text=True, timeout=240, check=True,
                         env=dict(os.environ, NODE_PATH=str(MODULES), CHROMIUM=CHROMIUM))
    return json.loads(out.stdout.strip().splitlines()[-1])


def changed_pixels(a: str, b: str) -> int:
    """Pixels whose colour differs by more than 8 of 255 in some channel between two screenshots."""
    x = np.asarray(Image.open(a).convert("RGB"), dtype=int)
    y = np.asarray(Image.open(b).convert("RGB"), dtype=int)
    return int(np.sum(np.abs(x - y).max(axis=2) > 8))


def without_creature(page: Path, out: Path) -> Path:
    """The same page with the creatures' meshes taken out of its glTF: the empty scene, seen by the same camera."""
    import base64
    import re

    import pygltflib

    text = page.read_text()
    b64 = re.search(r'src="data:model/gltf-binary;base64,([^"]+)"', text).group(1)
    gl = pygltflib.GLTF2.load_from_bytes(base64.b64decode(b64))
    bodies = [n for n in gl.nodes if n.extras.get("mujoco_body")]
    for body in bodies:
        for child in body.children:
            gl.nodes[child].mesh = None
    empty = base64.b64encode(b"".join(gl.save_to_bytes())).decode("ascii")
    out.write_text(text.replace(b64, empty))
    return out


def test_the_page_plays_each_creature_offline(runs, creature, tmp_path):
    _, poses = runs(creature)
    page = write_poses(poses, tmp_path / f"{creature}.html", parameters={"creature": creature})
    text = page.read_text()
    assert "<script src" not in text and 'src="http' not in text  # one file: the viewer and the run inside
    span = float(poses.t_s[-1] - poses.t_s[0])
    k1 = poses.n_frames // 5
    # the later time: the frame whose poses differ most from the first's (a flapping wing may be back in place)
    turn = np.abs(np.sum(poses.quat_wxyz * poses.quat_wxyz[k1], axis=2)).min(axis=1)
    k2 = k1 + 1 + int(np.argmin(turn[k1 + 1 : -1]))  # not the last frame: the end is the start again
    t1, t2 = round(float(poses.t_s[k1] - poses.t_s[0]), 3), round(float(poses.t_s[k2] - poses.t_s[0]), 3)
    empty = without_creature(page, tmp_path / "empty.html")
    r = in_chromium("html", str(page), str(empty), str(tmp_path), str(t1), str(t2))
    assert r["errors"] == [] and r["network"] == [], r
    assert r["paused"] is True and r["duration"] == pytest.approx(span, abs=1e-3)
    assert r[f"time_{t1}"] == pytest.approx(t1, abs=1e-3) and r[f"time_{t2}"] == pytest.approx(t2, abs=1e-3)
    first, later, empty = r["shots"]
    assert changed_pixels(first, empty) > 50  # the creature is drawn (ten fish in a 5 m tank are small)
    assert changed_pixels(first, later) > 20  # and moves as time goes on
