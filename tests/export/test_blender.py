"""Blender imports each exported file, and its animation puts every body where the simulation had it
(1e-4 m, 1e-3 rad) at three sampled frames: glTF in Debian's Blender 3.4 (``blender``), USD in Blender 5.0
as a Python module (PyPI's ``bpy``; Debian's build has no USD importer). ``.ci/run`` installs both; where one is
missing its tests skip, saying so."""

import json
import shutil
import subprocess
from pathlib import Path

import mujoco
import numpy as np
import pytest

from lifelike_mj.export import write_poses

BLENDER = shutil.which("blender")
#: Blender as a Python module (PyPI's bpy 5.0.1, in its own environment: .ci/run makes it), which imports USD:
#: Debian's Blender 3.4 is built without USD.
BPY = Path(__file__).resolve().parents[2] / ".ci" / "bpy" / "bin" / "python"
needs_blender = pytest.mark.skipif(BLENDER is None, reason="Blender is not installed (.ci/run installs Debian's blender)")
needs_bpy = pytest.mark.skipif(not BPY.exists(), reason="Blender's bpy module is not installed (.ci/run installs it "
                                                         "into .ci/bpy)")
#: Blender's glTF importer turns glTF's Y-up into Z-up and keeps Y-up in each object's own axes (it turns the
#: meshes instead): an object's matrix is the body's rotation times the inverse of this (+90 deg about X).
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


#: Keys this tight put Blender's interpolation (which may fall between keys) within the check's 1e-4 m and
#: 1e-3 rad of the simulation.
TIGHT = (2e-5, 0.02)


def _in_blender(path: Path, fps: float, times: list[str]) -> dict:
    """``blender_pose.py`` on ``path`` at ``times`` (s from the start): in Debian's Blender for glTF, in the bpy
    module for USD."""
    out = path.with_suffix(".json")
    script = Path(__file__).with_name("blender_pose.py")
    run = ([str(BPY), str(script)] if path.suffix.startswith(".usd")
           else [BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python", str(script)])
    subprocess.run([*run, "--", str(path), str(out), repr(fps), *times], check=True, capture_output=True,
                   timeout=300)
    return json.loads(out.read_text())


# (.gltf holds the same document as .glb, its buffer as base64: the validator and pygltflib read both back)
@pytest.mark.parametrize("suffix", [pytest.param(".glb", marks=needs_blender), pytest.param(".usdc", marks=needs_bpy)])
def test_blender_puts_every_body_where_the_simulation_had_it(runs, creature, suffix, tmp_path):
    _, poses = runs(creature)
    path = write_poses(poses, tmp_path / f"{creature}{suffix}", tolerance=TIGHT)
    samples = poses.frame_samples[[0, poses.n_frames // 2 - 1, poses.n_frames - 1]]
    samples[1] += 1  # a sample between frames (every creature here is sampled more often than its frames)
    assert samples[1] not in poses.frame_samples
    times = {k: repr(float(poses.t_s[k] - poses.t_s[0])) for k in samples}
    got = _in_blender(path, poses.fps, list(times.values()))
    if "error" in got:
        pytest.skip(f"Blender {got['blender']}: {got['error']}")
    for k in samples:
        seen = got["frames"][times[k]]
        assert sorted(seen) == sorted(poses.body_names)
        for b, name in enumerate(poses.body_names):
            M = np.array(seen[name])
            np.testing.assert_allclose(M[:3, 3], poses.position_m[k, b], atol=1e-4)
            R = np.empty(9)
            mujoco.mju_quat2Mat(R, poses.quat_wxyz[k, b])
            turn = M[:3, :3] @ Y_UP_TO_Z_UP if suffix != ".usdc" else M[:3, :3]
            angle = np.arccos(np.clip((np.trace(turn @ R.reshape(3, 3).T) - 1.0) / 2.0, -1.0, 1.0))
            assert angle < 1e-3, (k, name, angle)


@needs_blender
def test_blender_imports_an_armature_per_creature_whose_bones_follow_the_simulation(runs, creature, tmp_path):
    """Debian's Blender imports each rigged creature as an armature with one bone per body (named as in the MJCF)
    and the bones of its secondary motion; each bone's head is where the bone is (1e-4 m) and its turn between
    two of three times is the bone's (1e-3 rad; Blender keeps a bone's own axes, fixed by its importer)."""
    import importlib

    looks = {"butterfly3d": "butterfly", "butterfly2d": "butterfly", "fish": "fish", "boids": "boids"}[creature]
    _, poses = runs(creature)
    rigs = importlib.import_module(f"lifelike_mj.{looks}.look").rigs(poses)
    if creature == "boids":
        rigs = rigs[:12]  # a dozen birds are enough for Blender here
    path = write_poses(poses, tmp_path / f"{creature}.glb", tolerance=TIGHT, rigs=rigs)
    samples = poses.frame_samples[[0, poses.n_frames // 2 - 1, poses.n_frames - 1]]
    samples[1] += 1
    times = {k: repr(float(poses.t_s[k] - poses.t_s[0])) for k in samples}
    got = _in_blender(path, poses.fps, list(times.values()))
    assert sorted(got["armatures"]) == sorted(f"{r.name} rig" for r in rigs)
    for r in rigs:
        assert sorted(got["armatures"][f"{r.name} rig"]) == sorted(b.name for b in r.bones)
    assert {b.body for r in rigs for b in r.bones} - {None} >= {n for n in poses.body_names
                                                               if any(n == b.name for r in rigs for b in r.bones)}
    # a flock's wings play the shared wing beat, a glTF animation of its own: Blender's importer plays one
    # animation at a time (the run's), so only the birds' other bones are followed here
    first = None
    for k in samples:
        seen = got["bones"][times[k]]
        for r in rigs:
            for b in (b for b in r.bones if r.cycle_part(b) is None):
                M = np.array(seen[b.name])
                np.testing.assert_allclose(M[:3, 3], b.position_m[k], atol=1e-4)
        if first is None:
            first = (k, seen)
            continue
        k0, seen0 = first
        for r in rigs:
            for b in (b for b in r.bones if r.cycle_part(b) is None):  # the turn from the first time, in the world
                turn = np.array(seen[b.name])[:3, :3] @ np.array(seen0[b.name])[:3, :3].T
                R1, R0 = np.empty(9), np.empty(9)
                mujoco.mju_quat2Mat(R1, b.quat_wxyz[k])
                mujoco.mju_quat2Mat(R0, b.quat_wxyz[k0])
                want = R1.reshape(3, 3) @ R0.reshape(3, 3).T
                # |A - B| (Frobenius) = 2 sqrt(2) sin(angle / 2): unlike the trace's arccos, not thrown by Blender's
                # 32-bit matrices, whose columns are unit only to 1e-7
                angle = 2.0 * np.arcsin(min(1.0, np.linalg.norm(turn - want) / (2.0 * np.sqrt(2.0))))
                assert angle < 1e-3, (k, b.name, angle)


@needs_blender
def test_a_mesh_of_ones_own_bound_to_the_bones_follows_the_motion(runs, tmp_path):
    """The artist's route (docs/animators.md): a new mesh, given a vertex group named as a bone and an Armature
    modifier, moves with that bone: its centre is where the simulation has the left wing's hinge (1e-4 m)."""
    from lifelike_mj.butterfly.look import rigs

    _, poses = runs("butterfly3d")
    path = write_poses(poses, tmp_path / "flight.glb", tolerance=TIGHT, rigs=rigs(poses))
    samples = poses.frame_samples[[0, poses.n_frames // 2, poses.n_frames - 1]]
    times = [repr(float(poses.t_s[k] - poses.t_s[0])) for k in samples]
    out = tmp_path / "bind.json"
    subprocess.run([BLENDER, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                    str(Path(__file__).with_name("blender_bind.py")), "--", str(path), str(out), "butterfly rig",
                    "wing_left", repr(poses.fps), *times], check=True, capture_output=True, timeout=300)
    got = json.loads(out.read_text())
    b = poses.body_names.index("wing_left")
    moved = 0.0
    for k, t in zip(samples, times):
        np.testing.assert_allclose(got["cube"][t], poses.position_m[k, b], atol=1e-4)
        np.testing.assert_allclose(got["cube"][t], got["head"][t], atol=1e-5)
        moved = max(moved, float(np.linalg.norm(np.array(got["cube"][t]) - got["cube"][times[0]])))
    assert moved > 0.05  # the flight carried it along


SCRIPT = Path(__file__).resolve().parents[2] / "examples" / "blender" / "import_motion.py"


def _script(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    """The README's Blender command, run from ``cwd`` with relative paths."""
    return subprocess.run([BLENDER, "-b", "--factory-startup", "--python", str(SCRIPT), "--", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


@needs_blender
def test_the_readmes_blender_script_imports_saves_and_renders_from_relative_paths(runs, tmp_path):
    _, poses = runs("butterfly3d")
    (tmp_path / "runs").mkdir()
    write_poses(poses.frames(), tmp_path / "runs" / "flight.glb")  # a run at 30 frames/s
    slow = write_poses(poses, tmp_path / "runs" / "slow.glb")
    with slow.open("r+b") as fh:  # the same run, saying 24 frames/s: the scene takes its rate from the file
        data = fh.read()
        fh.seek(0)
        fh.write(data.replace(b'"per_s": 30.0', b'"per_s": 24.0').replace(b'"per_s":30.0', b'"per_s":24.0'))
    done = _script(tmp_path, "runs/flight.glb", "flight.blend", "--render", "flight.png", "--samples", "2",
                   "--size", "64x48")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Warning" not in done.stdout + done.stderr and "Traceback" not in done.stderr
    assert (tmp_path / "flight.png").stat().st_size > 0
    probe = tmp_path / "probe.py"
    probe.write_text("import bpy, json, sys\ns = bpy.context.scene\n"
                     "json.dump({'end': s.frame_end, 'fps': s.render.fps / s.render.fps_base, 'camera': s.camera.name}, "
                     "open(sys.argv[-1], 'w'))\n")
    for blend, fps in (("flight.blend", 30), ("slow.blend", 24)):
        if blend == "slow.blend":
            assert _script(tmp_path, "runs/slow.glb", blend).returncode == 0
        subprocess.run([BLENDER, "-b", str(tmp_path / blend), "--python-exit-code", "1", "--python", str(probe),
                        "--", str(tmp_path / "scene.json")], check=True, capture_output=True, timeout=300)
        scene = json.loads((tmp_path / "scene.json").read_text())
        span = poses.t_s[-1] - poses.t_s[0]
        assert scene == {"end": round(span * fps), "fps": pytest.approx(fps), "camera": "camera follow"}
    # what goes wrong: one sentence, status 2, nothing written
    (tmp_path / "bad.glb").write_bytes(b"glTF" + b"\0" * 40)
    broken = json.dumps({"asset": {"version": "2.0", "extras": {"frames": {"per_s": 30.0}}}, "scene": 0,
                         "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 3}]}).encode()
    broken += b" " * (-len(broken) % 4)
    (tmp_path / "broken.glb").write_bytes(b"glTF" + (2).to_bytes(4, "little") + (20 + len(broken)).to_bytes(4, "little")
                                          + len(broken).to_bytes(4, "little") + b"JSON" + broken)
    for args, says in ((["missing.glb", "x.blend"], "does not exist"), (["bad.glb", "x.blend"], "not a binary glTF"),
                       (["broken.glb", "x.blend"], "could not import"),
                       (["runs/flight.glb", "flight.blend"], "exists; give --overwrite"),
                       (["runs/flight.glb", "x.blend", "--camera", "nope"], "no camera 'nope'"),
                       (["runs/flight.glb", "nofolder/x.blend"], "does not exist"),
                       (["runs/flight.glb", "x.blend", "--size", "big"], "WIDTHxHEIGHT")):
        done = _script(tmp_path, *args)
        lines = [x for x in done.stderr.splitlines() if x.startswith("import_motion.py:")]
        assert done.returncode == 2 and len(lines) == 1 and says in lines[0], (args, done.stderr[-1500:])
        assert "Traceback" not in done.stderr
    assert not (tmp_path / "x.blend").exists()
