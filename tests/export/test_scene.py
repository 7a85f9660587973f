"""Scenes (``lifelike-mj export scene``): several creatures in one file, one scale (metres), one root, one
ground, named cameras; every body and bone within the key tolerance *in scene metres*; bad scenes refused in
one sentence before any simulation."""

import json
import math
from pathlib import Path

import numpy as np
import pygltflib
import pytest
from test_gltf import _blob, _khronos, _turn
from test_rigs import _local

from lifelike_mj.boids import look
from lifelike_mj.cli import main
from lifelike_mj.cli.scene import scene_parts
from lifelike_mj.export.rig import qconj, qmul, qrot
from lifelike_mj.export.scene import write_scene

TOL_M, TOL_DEG = 0.0005, 0.5
GARDEN = Path(__file__).parents[2] / "examples" / "scenes" / "garden.json"

SCENE = {
    "format": "lifelike-mj/scene", "version": 1, "name": "test", "duration_s": 0.6, "fps": 30, "ground_half_m": 6,
    "parts": [
        {"name": "garden", "creature": "butterfly3d", "at_m": [0.5, 0.0, 1.0], "yaw_deg": 30,
         "options": {"garden": 2, "seed": 4}, "follow": ["b0_butterfly"]},
        {"name": "pond", "creature": "fish", "at_m": [0, -3, 0], "options": {"n": 3, "seed": 1, "tank_scale": 0.4}},
        {"name": "flock", "creature": "boids", "at_m": [-2.0, -2.0, 4.0], "bird_length_m": 0.2, "still": False,
         "options": {"n": 12, "seed": 2, "start": 300}, "follow": ["boid3"]},
    ],
}


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    parts = scene_parts(SCENE, quiet=True)
    path = write_scene(parts, tmp_path_factory.mktemp("scene") / "scene.glb", tolerance=(TOL_M, TOL_DEG),
                       ground_half_m=SCENE["ground_half_m"])
    gl = pygltflib.GLTF2().load(str(path))
    return parts, path, gl, _blob(gl)


def _world(gl, blob, top: int, t: np.ndarray) -> dict:
    """Every node's world pose under the root's child ``top`` (MuJoCo's Z-up scene frame): position, rotation
    (w, x, y, z) and uniform scale, composed down the node tree as a player does."""
    out = {}

    def walk(node, pp, pq, ps):
        p, q = _local(gl, blob, node, t)
        s = (gl.nodes[node].scale or [1.0])[0]
        wp, wq, ws = pp + ps * qrot(pq, p), qmul(pq, q), ps * s
        out[gl.nodes[node].name] = (wp, wq, ws)
        for c in gl.nodes[node].children or []:
            walk(c, wp, wq, ws)

    walk(top, np.zeros((len(t), 3)), np.tile([1.0, 0.0, 0.0, 0.0], (len(t), 1)), 1.0)
    return out


def test_a_scene_is_one_file_in_metres_with_one_root_one_ground_and_named_cameras(scene):
    parts, path, gl, blob = scene
    root = gl.nodes[gl.scenes[0].nodes[0]]
    # one root (the skinned meshes beside it are placed by their joints alone), one ground, a node per part
    assert root.name == "lifelike-mj"
    assert all(gl.nodes[i].skin is not None for i in gl.scenes[0].nodes[1:])
    children = [gl.nodes[c].name for c in root.children]
    assert children.count("ground") == 1 and {"garden", "pond", "flock"} <= set(children)
    planes = [n.name for n in gl.nodes if n.mesh is not None and n.name == "ground"]
    assert planes == ["ground"]  # the garden's own ground plane left out
    cams = sorted(c.name for c in gl.cameras)
    assert cams == ["follow flock/boid3", "follow garden/b0_butterfly", "overview"]
    # the flock is scaled so that a bird is 0.2 m long: the bird's bones sit 0.2 m apart per agent length
    flock = next(p for p in parts if p.name == "flock")
    assert flock.scale == pytest.approx(0.2 / 0.7)
    world = _world(gl, blob, root.children[children.index("flock")], np.zeros(1))
    rig = flock.rigs[3]
    flight, tail = world[rig.name], world[f"{rig.name}/tail"]
    assert np.linalg.norm(flight[0] - tail[0]) == pytest.approx(0.3 * 0.2, rel=1e-3)  # tail bone at 0.3 L
    extras = gl.asset.extras
    assert extras["scene"]["units"] == "m" and set(extras["scene"]["parts"]) == {"garden", "pond", "flock"}
    assert extras["scene"]["parts"]["flock"]["parameters"]["bird_length_m"] == 0.2
    assert extras["frames"]["per_s"] == 30
    reports = _khronos([path])
    if reports is None:
        pytest.skip("the Khronos glTF-Validator is not installed (.ci/run installs it with npm into .ci/node)")
    assert reports[0]["errors"] == 0 and reports[0]["warnings"] == 0, reports[0]


def test_every_body_and_bone_plays_within_the_tolerance_in_scene_metres(scene):
    parts, _, gl, blob = scene
    root = gl.nodes[gl.scenes[0].nodes[0]]
    children = [gl.nodes[c].name for c in root.children]
    for part, spec in zip(parts, SCENE["parts"]):
        t = part.poses.t_s - part.poses.t_s[0]
        world = _world(gl, blob, root.children[children.index(part.name)], t)
        yaw = math.radians(spec.get("yaw_deg", 0.0))  # counter-clockwise seen from above
        Rz = np.array([[math.cos(yaw), -math.sin(yaw), 0.0], [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
        turn = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
        for rig in part.rigs[:4]:
            for b in rig.bones:
                p, q, s = world[b.name]
                assert s == pytest.approx(part.scale)
                want_p = np.array(spec["at_m"]) + part.scale * b.position_m @ Rz.T
                want_q = qmul(turn, b.quat_wxyz)
                if rig.cycle is not None and b.parent >= 0:  # a crowd's agent: keyed channel by channel
                    pb = rig.bones[b.parent]
                    pp, pq, _ = world[pb.name]
                    p, q = qrot(qconj(pq), p - pp), qmul(qconj(pq), q)
                    want_p = part.scale * qrot(qconj(pb.quat_wxyz), b.position_m - pb.position_m)
                    want_q = qmul(qconj(pb.quat_wxyz), b.quat_wxyz)
                assert np.max(np.linalg.norm(p - want_p, axis=1)) <= TOL_M, (part.name, b.name)
                assert np.max(_turn(q, want_q)) <= math.radians(TOL_DEG), (part.name, b.name)


def test_the_birds_bank_by_the_turn_relation_at_their_scene_speed(scene):
    """tan(bank) = a_lat / g with the lateral acceleration in scene metres per second squared: a flock shrunk to
    bird size flies slower in metres than in box units, and banks less."""
    parts, *_ = scene
    flock = next(p for p in parts if p.name == "flock")
    for rig in flock.rigs[:6]:
        flight = rig.bones[0]
        p = flock.to_scene(flight.position_m)
        v = np.gradient(p, flock.poses.t_s, axis=0)
        s = rig.secondary
        np.testing.assert_allclose(s["speed_m_s"], np.linalg.norm(v, axis=1), rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(np.tan(s["bank_rad"]), s["lateral_m_s2"] / 9.81, rtol=1e-6, atol=1e-9)
        scaled = look.drawn_flight(flock.poses.t_s, flight.position_m, 1.0, 0.0, look.TURN_SIGMA_STEPS)[2]
        np.testing.assert_allclose(s["lateral_m_s2"], flock.scale * scaled["lateral_m_s2"], rtol=1e-6, atol=1e-9)


def test_the_shipped_scene_is_a_valid_scene_file():
    from lifelike_mj.cli.scene import load_scene

    data = load_scene(GARDEN)
    assert {p["creature"] for p in data["parts"]} == {"butterfly3d", "fish", "boids"}


def _bad(tmp_path, change) -> str:
    data = json.loads(json.dumps(SCENE))
    change(data)
    f = tmp_path / "bad.json"
    f.write_text(json.dumps(data))
    return str(f)


BAD = {
    "an unknown key": (lambda d: d["parts"][0].update(colour="red"), "colour"),
    "an unknown creature": (lambda d: d["parts"][1].update(creature="whale"), "whale"),
    "a bad option": (lambda d: d["parts"][1]["options"].update(n=-3), "pond"),
    "an unknown option": (lambda d: d["parts"][1]["options"].update(wings=2), "wings"),
    "an option the scene sets": (lambda d: d["parts"][0]["options"].update(duration=3), "sets 'duration'"),
    "a creature not in the part": (lambda d: d["parts"][2].update(follow=["boid99"]), "boid99"),
    "a bird size for fish": (lambda d: d["parts"][1].update(bird_length_m=0.1), "bird_length_m"),
    "two parts of one name": (lambda d: d["parts"][1].update(name="garden"), "twice"),
    "one creature followed twice": (lambda d: d["parts"][0].update(follow=["b0_butterfly"] * 2), "follow"),
    "no parts": (lambda d: d.update(parts=[]), "parts"),
    "too long": (lambda d: d.update(duration_s=1e6), "duration_s"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_scene_is_refused_in_one_sentence_before_any_simulation(case, tmp_path, capsys, monkeypatch):
    change, words = BAD[case]
    from lifelike_mj.cli import export

    def never(self):
        raise AssertionError("a part was simulated")

    monkeypatch.setattr(export.Window, "record", never)
    out = tmp_path / "scene.glb"
    assert main(["export", "scene", _bad(tmp_path, change), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err and "Traceback" not in err, err
    assert not out.exists()


def test_a_scene_is_not_written_as_usd_and_an_existing_file_is_kept(tmp_path, capsys):
    assert main(["export", "scene", str(GARDEN), "--out", str(tmp_path / "s.usda")]) == 2
    assert "USD takes one run" in capsys.readouterr().err
    keep = tmp_path / "s.glb"
    keep.write_text("mine")
    assert main(["export", "scene", str(GARDEN), "--out", str(keep)]) == 2
    assert "--overwrite" in capsys.readouterr().err and keep.read_text() == "mine"


def test_a_scene_plays_in_a_web_page(scene, tmp_path):
    parts, *_ = scene
    page = write_scene(parts, tmp_path / "scene.html", ground_half_m=6).read_text()
    assert "<model-viewer" in page
    framing = json.loads(page.split('<script type="application/json" id="framing">')[1].split("</script>")[0]
                         .replace("<\\/", "</"))
    assert framing["follow_path"] and framing["span_s"] == pytest.approx(SCENE["duration_s"], abs=0.05)
