"""Loops (``export --loop``): a level flight cut at whole wing beats, flying in place; a tank or a flock
blended into its start. The seam is measured on the written file."""

import json

import numpy as np
import pygltflib
import pytest
from test_gltf import _blob, _khronos, _turn
from test_rigs import world_poses

from lifelike_mj.butterfly.flight3d import DT_S
from lifelike_mj.cli import main


def _export(tmp_path, capsys, *argv):
    out = tmp_path / "loop.glb"
    assert main(["export", *argv, "--loop", "--out", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    gl = pygltflib.GLTF2().load(str(out))
    return out, gl, info


def _seam_in_file(gl, info):
    """Every node's largest jump from the clip's last sample to its first, as a player looping it sees."""
    t = np.array([0.0, info["span_s"]])
    world = world_poses(gl, _blob(gl), t)
    jumps = [(float(np.linalg.norm(p[1] - p[0])), float(np.degrees(_turn(q[1:], q[:1])[0]))) for p, q in world.values()]
    return max(j[0] for j in jumps), max(j[1] for j in jumps)


def test_a_level_flight_loops_at_whole_wing_beats_in_place(tmp_path, capsys):
    out, gl, info = _export(tmp_path, capsys, "butterfly3d", "--task", "level", "--start", "5", "--duration", "2")
    loop = info["loop"]
    assert loop["mode"] == "cut" and 0.8 * 2.0 / loop["period_s"] - 1 <= loop["beats"] <= 2.0 / loop["period_s"] + 1
    assert loop["span_s"] == pytest.approx(loop["beats"] * loop["period_s"], abs=1.5 * DT_S)  # whole beats
    assert 1.0 / loop["period_s"] == pytest.approx(8.9, abs=0.5)  # the monarch's flap frequency (8.7-9.0 Hz, measure3d)
    assert np.linalg.norm(loop["root_motion_m"]) / loop["span_s"] == pytest.approx(1.5, rel=0.2)  # its speed
    m, deg = _seam_in_file(gl, info)
    assert m <= 0.002 and deg <= 1.0, (m, deg)
    assert m == pytest.approx(loop["seam_m"], abs=0.0006) and deg == pytest.approx(loop["seam_deg"], abs=0.6)
    assert gl.asset.extras["parameters"]["loop"] == loop
    reports = _khronos([out])
    if reports is not None:
        assert reports[0]["errors"] == 0 and reports[0]["warnings"] == 0, reports[0]


@pytest.mark.parametrize("creature, argv", [("fish", ["--duration", "3", "--n", "5"]),
                                            ("boids", ["--steps", "300", "--n", "40"])])
def test_a_tank_and_a_flock_blend_their_end_into_their_start(creature, argv, tmp_path, capsys):
    _, gl, info = _export(tmp_path, capsys, creature, *argv, "--loop-blend", "0.5")
    loop = info["loop"]
    assert loop["mode"] == "blend" and loop["blend_s"] == pytest.approx(0.5, abs=0.04)
    assert loop["span_s"] == pytest.approx(3.0 if creature == "fish" else 300 / 150, abs=0.02)
    m, deg = _seam_in_file(gl, info)  # every body and bone, the fins and wings too, joins up
    assert m <= 0.0006 and deg <= 0.6, (m, deg)
