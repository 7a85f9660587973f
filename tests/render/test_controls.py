"""The live scenes' keys and buttons act on the stepper: the 3D butterfly's course, altitude and wind, the
boids' weights, the aquarium's tap and food (each scripted here through the controls, as the viewers run
them between two steps)."""

import math

import numpy as np

from lifelike_mj.boids import Flock
from lifelike_mj.boids.presets import load_preset
from lifelike_mj.boids.render import weight_controls
from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.view import flight3d_controls
from lifelike_mj.fish import Tank
from lifelike_mj.fish.aquarium import Aquarium, controls


def test_no_scene_key_is_one_of_mujocos_viewers_own():
    """MuJoCo's viewer takes every letter (its flags' shortcuts) and 0-5 (the geom groups): a scene key on one of
    them would change the viewer too, so a Control refuses it; the shipped scenes' keys are all free."""
    import pytest

    from lifelike_mj.errors import UserError
    from lifelike_mj.render.viewer import Control, mujoco_viewer_keys

    taken = mujoco_viewer_keys()
    assert all(ord(c) in taken for c in "ABCDEFGHIJKLMNOPQRSTUVWXYZ012345")
    for key in ("0", "3", "5"):
        with pytest.raises(UserError, match="MuJoCo's geom group"):
            Control(key, "x", lambda: None)
    with pytest.raises(UserError, match="a scene key is one of"):
        Control("T", "x", lambda: None)
    f = Flight3D(controller=flight3d.withdrawn_file("wind"), task=flight3d.level(1.5))
    scenes = [flight3d_controls(f), weight_controls(Flock(load_preset("5a"), n=10, seed=0)),
              controls(Aquarium(Tank(n_fish=2, seed=0)))]
    for scene in scenes:
        assert all(c.code not in taken for c in scene if c.key)


def _press(controls, key):
    next(c for c in controls if c.key == key).act()


def test_the_butterflys_keys_change_its_course_altitude_and_wind():
    f = Flight3D(controller=flight3d.withdrawn_file("wind"), task=flight3d.level(1.5))
    keys = flight3d_controls(f)
    assert [c.key for c in keys] == ["Up", "Down", "Left", "Right", "6", "7", "8", "9", "Space"]
    _press(keys, "Up")
    _press(keys, "Up")
    _press(keys, "Left")
    assert f.reference == (math.pi / 4, 1.0, 1.5)
    _press(keys, "7")
    np.testing.assert_array_equal(f.wind_to_m_s, [0.0, 1.0, 0.0])
    f.step(int(4.0 / f.dt))
    s = f.state()
    assert abs(s["position_m"][2] - 1.0) < 0.15 and abs(math.degrees(s["attitude_rad"][2]) - 45.0) < 15.0
    _press(keys, "Space")
    np.testing.assert_array_equal(f.wind_to_m_s, [0.0, 0.0, 0.0])


def test_the_boids_keys_switch_the_weights_live():
    flock = Flock(load_preset("5a"), n=50, seed=1)
    flock.step(10)
    keys = weight_controls(flock)
    assert [c.key for c in keys if c.key] == ["Right", "Left", "Enter"] and len(keys) == 11  # and a button per pattern
    _press(keys, "Right")
    _press(keys, "Right")  # pattern 4b
    p = load_preset("4b")
    np.testing.assert_array_equal(flock.params.wa, p.wa)
    np.testing.assert_array_equal(flock.params.wc, p.wc)
    assert flock.steps == 10  # the agents stay where they are
    flock.step(5)
    before = flock.state()
    _press(keys, "Enter")  # scattered afresh: new places, the same types, weights and step count
    after = flock.state()
    assert not np.allclose(after["position_box"], before["position_box"])
    np.testing.assert_array_equal(after["type"], before["type"])
    np.testing.assert_array_equal(flock.params.wa, p.wa)
    assert flock.steps == 15 and flock.model is not None
    x = after["position_box"]
    assert x.min() >= flock.params.r_c - 1e-12 and x.max() <= flock.params.box - flock.params.r_c + 1e-12


def test_the_aquariums_keys_tap_and_feed():
    a = Aquarium(Tank(n_fish=10, seed=2))
    keys = controls(a, seed=0)
    _press(keys, "Space")
    assert a.startled.any()
    _press(keys, "Enter")
    assert len(a.pellets_m) == 1 and len(a.marks()) == 1


def test_the_aquariums_right_key_startles_one_fish_alone():
    a = Aquarium(Tank(n_fish=10, seed=2))
    _press(controls(a, seed=0), "Right")
    assert a.startled.sum() == 1
    a.step(1)
    assert a.startled.sum() == 1  # without the cascade no neighbour follows
