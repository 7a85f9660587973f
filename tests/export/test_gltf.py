"""Animated glTF of a run: read back with pygltflib, every body and geom where the simulation had it."""

import base64

import mujoco
import numpy as np
import pygltflib
import pytest

from lifelike_mj.butterfly import evolve3d
from lifelike_mj.butterfly.sim3d import Flight3D
from lifelike_mj.errors import UserError
from lifelike_mj.export.gltf import Z_UP_TO_Y_UP, write_gltf
from lifelike_mj.export.poses import drawn_geoms, record_poses


def _accessor(gl, i, blob):
    acc = gl.accessors[i]
    view = gl.bufferViews[acc.bufferView]
    dtype = {pygltflib.FLOAT: np.float32, pygltflib.UNSIGNED_SHORT: np.uint16, pygltflib.UNSIGNED_INT: np.uint32,
             pygltflib.SHORT: np.int16}
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[acc.type]
    raw = np.frombuffer(blob, dtype=dtype[acc.componentType], count=acc.count * width,
                        offset=view.byteOffset + (acc.byteOffset or 0))
    if acc.normalized:  # glTF 2.0 3.11: a normalized signed short c stands for max(c / 32767, -1)
        assert acc.componentType == pygltflib.SHORT
        raw = np.maximum(raw / 32767.0, -1.0)
    return raw.reshape(acc.count, width) if width > 1 else raw


def _blob(gl):
    uri = gl.buffers[0].uri
    if uri:
        return base64.b64decode(uri.split(",", 1)[1])
    return gl.binary_blob()


def _rot(q_xyzw):
    x, y, z, w = q_xyzw
    m = np.empty(9)
    mujoco.mju_quat2Mat(m, np.array([w, x, y, z], dtype=float))
    return m.reshape(3, 3)


@pytest.fixture(scope="module")
def flight():
    f = Flight3D(controller="steer", task=evolve3d.course(100))
    poses = record_poses(f, 1.0, fps=30.0)
    return f, poses


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_the_file_read_back_puts_every_geom_where_the_simulation_had_it(flight, tmp_path, suffix):
    f, poses = flight
    assert poses.n_frames == 31 and poses.t_s[-1] == pytest.approx(1.0, abs=f.dt)
    path = write_gltf(poses, tmp_path / f"run{suffix}")
    gl = pygltflib.GLTF2().load(str(path))
    blob = _blob(gl)
    root = gl.nodes[gl.scenes[0].nodes[0]]
    assert root.rotation == pytest.approx(list(Z_UP_TO_Y_UP))
    R_root = _rot(root.rotation)
    np.testing.assert_allclose(R_root @ [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], atol=1e-12)  # Z up -> Y up
    anim = gl.animations[0]
    outputs = {}
    for ch in anim.channels:
        s = anim.samplers[ch.sampler]
        outputs[(ch.target.node, ch.target.path)] = (_accessor(gl, s.input, blob), _accessor(gl, s.output, blob))
    m, d = f.model, f.data  # the state of the last frame
    geom_xpos = {}
    for b in range(len(poses.body_ids)):
        idx = root.children[[gl.nodes[c].name for c in root.children].index(poses.body_names[b])]
        times, trans = outputs[(idx, "translation")]
        _, rot = outputs[(idx, "rotation")]
        np.testing.assert_allclose(times, poses.t_s - poses.t_s[0], atol=1e-6)
        # every frame: the body where the simulation had it (1e-4 m, 1e-3 rad)
        np.testing.assert_allclose(trans, poses.position_m[:, b], atol=1e-4)
        rot = rot / np.linalg.norm(rot, axis=1, keepdims=True)  # as a reader does with 16-bit keys
        dots = np.abs(np.sum(rot[:, [3, 0, 1, 2]] * poses.quat_wxyz[:, b], axis=1))
        assert np.all(2 * np.arccos(np.minimum(1.0, dots)) < 1e-3)
        # the last frame, through the node tree: each geom's world position, back in MuJoCo's Z-up frame
        for c in gl.nodes[idx].children:
            node = gl.nodes[c]
            geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, node.name)
            world_y_up = R_root @ (trans[-1] + _rot(rot[-1]) @ np.array(node.translation))
            geom_xpos[geom] = R_root.T @ world_y_up
    drawn = drawn_geoms(m)
    assert sorted(geom_xpos) == sorted(int(g) for g in drawn[m.geom_bodyid[drawn] > 0])  # every drawn geom
    for geom, p in geom_xpos.items():
        np.testing.assert_allclose(p, d.geom_xpos[geom], atol=1e-4)


def test_shapes_are_shared_and_bad_names_refused(flight, tmp_path):
    f, poses = flight
    gl = pygltflib.GLTF2().load(str(write_gltf(poses, tmp_path / "a.glb", parameters={"controller": "steer"})))
    prov = gl.asset.extras  # every output records the version, the command and every parameter
    assert prov["versions"]["lifelike-mj"] and prov["command"] and prov["parameters"] == {"controller": "steer"}
    assert prov["frames"]["count"] == 31 and prov["frames"]["per_s"] == pytest.approx(30.0, rel=1e-3)
    geoms = [n for n in gl.nodes if n.mesh is not None]
    assert len(gl.meshes) <= len(geoms)
    for mesh in gl.meshes:
        acc = gl.accessors[mesh.primitives[0].attributes.POSITION]
        assert acc.min is not None and acc.max is not None
    with pytest.raises(UserError, match=r"\.glb or \.gltf"):
        write_gltf(poses, tmp_path / "a.obj")
    with pytest.raises(UserError, match="single frame"):
        record_poses(f, 0.01, fps=30.0)


def _khronos(paths):
    """The Khronos glTF-Validator's report on each file (``.ci/run`` installs it with npm into ``.ci/node``),
    or None where it or ``node`` is missing."""
    import json
    import os
    import shutil
    import subprocess
    from pathlib import Path

    node = shutil.which("node")
    modules = Path(__file__).resolve().parents[2] / ".ci" / "node" / "node_modules"
    if node is None or not (modules / "gltf-validator").is_dir():
        return None
    out = subprocess.run([node, os.path.join(os.path.dirname(__file__), "validate_gltf.js"), *map(str, paths)],
                         capture_output=True, text=True, check=True, env=dict(os.environ, NODE_PATH=str(modules)),
                         timeout=120)
    return [json.loads(line) for line in out.stdout.splitlines()]


def test_every_creature_exports_with_one_mesh_per_shape_and_the_validators_blessing(runs, creature, tmp_path):
    _, poses = runs(creature)
    paths = [write_gltf(poses, tmp_path / f"{creature}{s}") for s in (".glb", ".gltf")]
    gl = pygltflib.GLTF2().load(str(paths[0]))
    blob = _blob(gl)
    n_geoms = sum(1 for n in gl.nodes if n.mesh is not None)
    if creature in ("fish", "boids"):
        assert len(gl.meshes) < 10 < n_geoms  # every fish, every bird shares its shape's one mesh
    assert [c.name for c in gl.cameras] == (["overview"] if creature in ("fish", "boids") else ["overview", "follow"])
    anim = gl.animations[0]
    last = {ch.target.node: _accessor(gl, anim.samplers[ch.sampler].output, blob)[-1]
            for ch in anim.channels if ch.target.path == "translation"}
    names = {n.name: n.translation for n in gl.nodes}  # a body that stays put has no channel: its node's pose
    names.update({gl.nodes[i].name: p for i, p in last.items()})
    for b, name in enumerate(poses.body_names):
        np.testing.assert_allclose(names[name], poses.position_m[-1, b], atol=1e-4)
    reports = _khronos(paths)
    if reports is None:
        pytest.skip("the Khronos glTF-Validator is not installed (.ci/run installs it with npm into .ci/node)")
    for r in reports:
        assert r["errors"] == 0 and r["warnings"] == 0, r
