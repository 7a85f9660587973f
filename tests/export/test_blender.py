"""Blender imports each exported file, and its animation puts every body where the simulation had it
(1e-4 m, 1e-3 rad) at three sampled frames. Runs where Debian's ``blender`` is installed (``.ci/run``
installs it); skipped, saying so, elsewhere."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from lifelike_mj.export import write_poses

BLENDER = shutil.which("blender")
pytestmark = pytest.mark.skipif(BLENDER is None, reason="Blender is not installed (.ci/run installs Debian's blender)")
#: Blender's glTF importer turns glTF's Y-up into Z-up and keeps Y-up in each object's own axes (it turns the
#: meshes instead): an object's matrix is the body's rotation times the inverse of this (+90 deg about X).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def _in_blender(path: Path, frames: list[int], bodies: dict[str, str]) -> dict:
    out = path.with_suffix(".json")
    script = Path(__file__).with_name("blender_pose.py")
    subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python", str(script), "--",
                    str(path), str(out), *map(str, frames)], check=True, capture_output=True, timeout=300,
                   env=dict(os.environ, BODIES=json.dumps(bodies)))
    return json.loads(out.read_text())


@pytest.mark.parametrize("suffix", [".glb", ".gltf", ".usdc"])
def test_blender_puts_every_body_where_the_simulation_had_it(runs, creature, suffix, tmp_path):
    if suffix == ".usdc":
        pytest.importorskip("pxr", reason="usd-core is not installed (the usd extra)")
        from pxr import Tf

        bodies = {}  # the prim names the USD writer gives the bodies (valid identifiers, unique)
        for name in runs(creature)[1].body_names:
            base = Tf.MakeValidIdentifier(name)
            prim, k = base, 1
            while prim in bodies:
                k += 1
                prim = f"{base}_{k}"
            bodies[prim] = name
    else:
        bodies = {}
    _, poses = runs(creature)
    path = write_poses(poses, tmp_path / f"{creature}{suffix}")
    frames = [0, poses.n_frames // 2 - 1, poses.n_frames - 1]
    got = _in_blender(path, frames, bodies)
    if "error" in got:
        pytest.skip(f"Blender {got['blender']}: {got['error']}")
    for k in frames:
        seen = got["frames"][str(k)]
        assert sorted(seen) == sorted(poses.body_names)
        for b, name in enumerate(poses.body_names):
            M = np.array(seen[name])
            np.testing.assert_allclose(M[:3, 3], poses.position_m[k, b], atol=1e-4)
            R = np.empty(9)
            mujoco.mju_quat2Mat(R, poses.quat_wxyz[k, b])
            turn = M[:3, :3] @ Y_UP_TO_Z_UP if suffix != ".usdc" else M[:3, :3]
            angle = np.arccos(np.clip((np.trace(turn @ R.reshape(3, 3).T) - 1.0) / 2.0, -1.0, 1.0))
            assert angle < 1e-3, (k, name, angle)


def test_the_readmes_blender_script_imports_a_flight_and_saves_it(runs, tmp_path):
    _, poses = runs("butterfly3d")
    glb = write_poses(poses, tmp_path / "flight.glb")
    script = Path(__file__).resolve().parents[2] / "examples" / "blender" / "import_flight.py"
    probe = tmp_path / "probe.py"
    probe.write_text("import bpy, json, sys\ns = bpy.context.scene\n"
                     "json.dump({'end': s.frame_end, 'fps': s.render.fps, 'camera': s.camera.name}, "
                     "open(sys.argv[-1], 'w'))\n")
    subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python", str(script), "--",
                    str(glb), str(tmp_path / "flight.blend")], check=True, capture_output=True, timeout=300)
    subprocess.run([BLENDER, "-b", str(tmp_path / "flight.blend"), "--python-exit-code", "1", "--python", str(probe),
                    "--", str(tmp_path / "scene.json")], check=True, capture_output=True, timeout=300)
    scene = json.loads((tmp_path / "scene.json").read_text())
    assert scene == {"end": poses.n_frames - 1, "fps": 30, "camera": "camera follow"}
