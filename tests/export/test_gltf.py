"""Animated glTF of a run: read back with pygltflib, every body and geom where the simulation had it."""

import base64

import mujoco
import numpy as np
import pygltflib
import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.errors import UserError
from lifelike_mj.export.gltf import Z_UP_TO_Y_UP, write_gltf
from lifelike_mj.export.poses import drawn_geoms, record_poses


def _accessor(gl, i, blob):
    acc = gl.accessors[i]
    view = gl.bufferViews[acc.bufferView]
    dtype = {pygltflib.FLOAT: np.float32, pygltflib.UNSIGNED_SHORT: np.uint16, pygltflib.UNSIGNED_INT: np.uint32,
             pygltflib.SHORT: np.int16}
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}[acc.type]
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
    f = Flight3D(controller=flight3d.withdrawn_file("steer"), task=flight3d.course(100))
    poses = record_poses(f, 1.0, fps=30.0)
    return f, poses


def _slerp(times, keys_xyzw, t):
    """Spherical interpolation of unit quaternions ``keys_xyzw`` at ``times`` to the times ``t`` (glTF 2.0's
    LINEAR rotation sampler), written here apart from the exporter's own."""
    k = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    u = np.clip((t - times[k]) / (times[k + 1] - times[k]), 0.0, 1.0)[:, None]
    a, b = keys_xyzw[k], keys_xyzw[k + 1].copy()
    dot = np.sum(a * b, axis=1)
    b[dot < 0] *= -1.0
    theta = np.arccos(np.clip(np.abs(dot), -1.0, 1.0))[:, None]
    small = theta < 1e-6
    sin = np.where(small, 1.0, np.sin(theta))
    wa = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / sin)
    wb = np.where(small, u, np.sin(u * theta) / sin)
    q = wa * a + wb * b
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _turn(q1_wxyz, q2_wxyz):
    """The angle (rad) between rotations, row by row."""
    apart = np.where((np.sum(q1_wxyz * q2_wxyz, axis=1) < 0)[:, None], q1_wxyz + q2_wxyz, q1_wxyz - q2_wxyz)
    return 4.0 * np.arcsin(np.clip(np.linalg.norm(apart, axis=1) / 2.0, 0.0, 1.0))


def played(gl, blob, node: int, poses, b: int):
    """Node ``node``'s translation and rotation (wxyz) as a player interpolates them, at every sample of
    ``poses``; a channel without keys holds the node's own value."""
    anim = gl.animations[0]
    t = poses.t_s - poses.t_s[0]
    out = {"translation": np.tile(gl.nodes[node].translation, (len(t), 1)),
           "rotation": np.tile(np.array(gl.nodes[node].rotation)[[3, 0, 1, 2]], (len(t), 1)), "keys": {}}
    for ch in (c for c in anim.channels if c.target.node == node):
        s = anim.samplers[ch.sampler]
        assert s.interpolation == "LINEAR"
        times, values = _accessor(gl, s.input, blob).astype(float), _accessor(gl, s.output, blob).astype(float)
        assert times[0] == 0.0 and times[-1] == pytest.approx(t[-1], abs=1e-6) and np.all(np.diff(times) > 0)
        out["keys"][ch.target.path] = (times, values)
        if ch.target.path == "translation":
            out["translation"] = np.stack([np.interp(t, times, values[:, j]) for j in range(3)], axis=1)
        else:
            values /= np.linalg.norm(values, axis=1, keepdims=True)  # as a reader does with 16-bit keys
            out["rotation"] = _slerp(times, values, t)[:, [3, 0, 1, 2]]
    return out


def body_nodes(gl, poses) -> dict[str, int]:
    root = gl.nodes[gl.scenes[0].nodes[0]]
    return {gl.nodes[c].name: c for c in root.children if gl.nodes[c].name in poses.body_names}


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_the_file_read_back_puts_every_geom_where_the_simulation_had_it(flight, tmp_path, suffix):
    f, poses = flight
    assert poses.n_frames == 31 and poses.t_s[-1] == pytest.approx(1.0, abs=f.dt)
    assert poses.n_samples == round(1.0 / f.dt) + 1  # every step
    path = write_gltf(poses, tmp_path / f"run{suffix}", tolerance=(1e-4, 0.05))
    gl = pygltflib.GLTF2().load(str(path))
    blob = _blob(gl)
    root = gl.nodes[gl.scenes[0].nodes[0]]
    assert root.rotation == pytest.approx(list(Z_UP_TO_Y_UP))
    R_root = _rot(root.rotation)
    np.testing.assert_allclose(R_root @ [0.0, 0.0, 1.0], [0.0, 1.0, 0.0], atol=1e-12)  # Z up -> Y up
    m, d = f.model, f.data  # the state of the last sample
    geom_xpos = {}
    nodes = body_nodes(gl, poses)
    for b, name in enumerate(poses.body_names):
        got = played(gl, blob, nodes[name], poses, b)
        # every sample: the body where the simulation had it, within the keys' tolerance
        assert np.max(np.linalg.norm(got["translation"] - poses.position_m[:, b], axis=1)) <= 1e-4
        assert np.max(_turn(got["rotation"], poses.quat_wxyz[:, b])) <= np.radians(0.05)
        assert len(got["keys"]["rotation"][0]) < poses.n_samples  # and fewer keys than samples
        # the last sample, through the node tree: each geom's world position, back in MuJoCo's Z-up frame
        for c in gl.nodes[nodes[name]].children:
            node = gl.nodes[c]
            geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, node.name)
            q = got["rotation"][-1]
            world_y_up = R_root @ (got["translation"][-1] + _rot(q[[1, 2, 3, 0]]) @ np.array(node.translation))
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
    # materials named as the MJCF names them, one per look (every fish wears one fish_blue)
    looks = {"butterfly3d": {"wing", "body", "grid"}, "butterfly2d": {"wing", "body", "grid"},
             "fish": {"fish_blue", "fish_fin", "fish_eye", "sand", "glass", "back"}, "boids": {"type0", "floor", "edge"}}
    names = [mat.name for mat in gl.materials]
    assert looks[creature] <= set(names) and len(names) == len(set(names)), names
    # the model's ground texture (a checker) comes along as an image, repeated over the ground's coordinates
    ground = gl.materials[names.index({"fish": "sand", "boids": "floor"}.get(creature, "grid"))]
    tex = gl.textures[ground.pbrMetallicRoughness.baseColorTexture.index]
    assert gl.images[tex.source].mimeType == "image/png" and gl.samplers[tex.sampler].wrapS == pygltflib.REPEAT
    # every sample of the simulation (every step: 1,200/s for the butterflies, 60/s for the fish, each step of
    # the flock): each body within the default tolerance, 0.5 mm and 0.5 deg, and no two neighbouring rotation
    # keys more than 20 deg apart (the wings' included) where the samples are closer than that (a flock's
    # drawn heading may turn further in one step)
    nodes = body_nodes(gl, poses)
    keys, turned = [], set()
    for b, name in enumerate(poses.body_names):
        got = played(gl, blob, nodes[name], poses, b)
        assert np.max(np.linalg.norm(got["translation"] - poses.position_m[:, b], axis=1)) <= 0.0005, name
        assert np.max(_turn(got["rotation"], poses.quat_wxyz[:, b])) <= np.radians(0.5), name
        if "rotation" in got["keys"]:
            q = got["keys"]["rotation"][1][:, [3, 0, 1, 2]]
            if np.max(_turn(poses.quat_wxyz[1:, b], poses.quat_wxyz[:-1, b])) <= np.radians(20.0):
                assert np.max(_turn(q[1:], q[:-1])) <= np.radians(20.0) + 1e-4, name
                turned.add(name)
            keys.append(len(q))
    prov = gl.asset.extras["keys"]
    assert prov["samples"] == poses.n_samples and prov["tolerance_m"] == 0.0005 and prov["tolerance_deg"] == 0.5
    assert sorted(c["rotation"] for c in prov["per_body"].values() if c["rotation"] > 1) == sorted(keys)
    if creature == "butterfly3d":
        assert {"wing_left", "wing_right"} <= turned
    reports = _khronos(paths)
    if reports is None:
        pytest.skip("the Khronos glTF-Validator is not installed (.ci/run installs it with npm into .ci/node)")
    for r in reports:
        assert r["errors"] == 0 and r["warnings"] == 0, r
