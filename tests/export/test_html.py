"""The exported web page in headless Chromium: it loads with no console error and no network, draws the
creature (pixels differ from the empty scene), and the picture changes as the slider moves time on.
Runs where Debian's ``chromium`` and npm's ``playwright-core`` are installed (``.ci/run`` installs both)."""

from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.export import write_poses


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
    for node in gl.nodes:  # a rigged creature: its skinned mesh
        if node.skin is not None:
            node.mesh, node.skin = None, None
    empty = base64.b64encode(b"".join(gl.save_to_bytes())).decode("ascii")
    out.write_text(text.replace(b64, empty))
    return out


@pytest.mark.parametrize("creature", ["butterfly3d", "fish", "boids"])  # the planar butterfly wears the 3D one's rig
def test_the_page_plays_each_rigged_creature_offline(runs, creature, tmp_path, chromium):
    """The page as ``lifelike-mj export`` writes it by default: the creatures rigged, skinned and textured."""
    import importlib

    _, poses = runs(creature)
    looks = {"butterfly3d": "butterfly", "butterfly2d": "butterfly", "fish": "fish", "boids": "boids"}[creature]
    # a flock: 40 birds rigged and the others as plain bodies, which keeps the page (and the test) light
    rigs = importlib.import_module(f"lifelike_mj.{looks}.look").rigs(poses)[:40]
    page = write_poses(poses, tmp_path / f"{creature}.html", parameters={"creature": creature}, rigs=rigs)
    text = page.read_text()
    assert "<script src" not in text and 'src="http' not in text  # one file: the viewer and the run inside
    span = float(poses.t_s[-1] - poses.t_s[0])
    k1 = poses.n_frames // 5
    # the later time: the frame whose poses differ most from the first's (a flapping wing may be back in place)
    turn = np.abs(np.sum(poses.quat_wxyz * poses.quat_wxyz[k1], axis=2)).min(axis=1)
    k2 = k1 + 1 + int(np.argmin(turn[k1 + 1 : -1]))  # not the last frame: the end is the start again
    t1, t2 = round(float(poses.t_s[k1] - poses.t_s[0]), 3), round(float(poses.t_s[k2] - poses.t_s[0]), 3)
    empty = without_creature(page, tmp_path / "empty.html")
    r = chromium.check("html", str(page), str(empty), str(tmp_path), str(t1), str(t2))
    assert r["errors"] == [] and r["network"] == [], r
    assert r["paused"] is True and r["duration"] == pytest.approx(span, abs=1e-3)
    # a flock's wing beat: one shared cycle, looped on top of the run (the birds' phases are in its channels)
    assert r["appended"] == (["bird wingbeat"] if creature == "boids" else []), r["appended"]
    assert r[f"time_{t1}"] == pytest.approx(t1, abs=1e-3) and r[f"time_{t2}"] == pytest.approx(t2, abs=1e-3)
    first, later, empty = r["shots"]
    assert chromium.changed_pixels(first, empty) > 50  # the creature is drawn (ten fish in a 5 m tank are small)
    assert chromium.changed_pixels(first, later) > 20  # and moves as time goes on
