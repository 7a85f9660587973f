"""The 3D butterfly's interactive scene, scripted through the stepper: a new altitude, a new course and a
wind, set mid-flight, are flown to (the shipped `wind` controller measures its speeds through the air)."""

import math

import numpy as np
import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.errors import UserError


def _fly(f, seconds):
    f.step(int(round(seconds / f.dt)))
    return f.state()


def test_a_new_altitude_course_and_wind_are_flown_to():
    f = Flight3D(controller=flight3d.withdrawn_file("wind"), task=flight3d.level(1.5))
    _fly(f, 3.0)
    f.set_reference(altitude_m=1.0)
    assert f.reference == (0.0, 1.0, 1.5)
    assert abs(_fly(f, 3.0)["position_m"][2] - 1.0) < 0.1  # climbed the metre within 3 s
    alts = [_fly(f, 0.5)["position_m"][2] for _ in range(4)]
    assert max(abs(a - 1.0) for a in alts) < 0.1  # and holds it
    f.set_reference(heading_rad=math.pi / 2)
    s = _fly(f, 2.0)
    assert abs(math.degrees(s["attitude_rad"][2]) - 90.0) < 10.0  # turned left within 2 s
    f.set_wind((1.0, 0.0, 0.0))
    np.testing.assert_array_equal(f.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3], [1.0, 0.0, 0.0])
    s = _fly(f, 3.0)
    assert abs(math.degrees(s["attitude_rad"][2]) - 90.0) < 10.0 and abs(s["position_m"][2] - 1.0) < 0.15
    assert 0.8 < s["velocity_m_s"][0] < 1.2  # carried along by the cross wind, through which it flies its course


def test_the_default_designed_controller_follows_the_viewers_keys():
    """``view butterfly3d`` flies the designed controller: a new altitude is climbed to at its guidance's 0.3 m/s and
    held, a new course turned to, a cross wind carries it along while it keeps its heading through the air."""
    f = Flight3D(controller="designed", task=flight3d.level(1.5))
    _fly(f, 3.0)
    f.set_reference(altitude_m=1.0)
    assert abs(_fly(f, 3.0)["position_m"][2] - 1.0) > 0.05  # a climb at 0.3 m/s, not a jump
    assert abs(_fly(f, 2.5)["position_m"][2] - 1.0) < 0.1
    alts = [_fly(f, 0.5)["position_m"][2] for _ in range(4)]
    assert max(abs(a - 1.0) for a in alts) < 0.05  # and holds it
    f.set_reference(heading_rad=math.pi / 2)
    s = _fly(f, 2.0)
    assert abs(math.degrees(s["attitude_rad"][2]) - 90.0) < 10.0  # turned left within 2 s
    f.set_wind((1.0, 0.0, 0.0))
    _fly(f, 4.0)  # the step of cross wind swings the heading by +-20-35 deg for about 3 s (the wind estimate catching up)
    late = [_fly(f, 0.1) for _ in range(10)]  # then, over the fifth second:
    assert max(abs(math.degrees(s["attitude_rad"][2]) - 90.0) for s in late) < 10.0
    assert max(abs(s["position_m"][2] - 1.0) for s in late) < 0.15
    assert 0.8 < np.mean([s["velocity_m_s"][0] for s in late]) < 1.2


def test_bad_references_are_refused():
    f = Flight3D(controller=flight3d.withdrawn_file("wind"))
    with pytest.raises(UserError, match="altitude_m"):
        f.set_reference(altitude_m=float("nan"))
    with pytest.raises(UserError, match="wind_to_m_s"):
        f.set_wind((1.0, 2.0))


def test_the_wind_is_named_by_its_meaning_and_the_old_name_still_works():
    """``wind_to_m_s`` (the air's velocity) and ``wind_from_m_s`` are one wind; ``wind_m_s`` (where it blows to, as
    before) is taken this release with a note, on the flight, the garden, the task and ``set_wind``."""
    import warnings

    from lifelike_mj.butterfly import flight3d

    to = Flight3D(controller=flight3d.withdrawn_file("wind"), wind_to_m_s=(1.0, 0.5, 0.0))
    fro = Flight3D(controller=flight3d.withdrawn_file("wind"), wind_from_m_s=(-1.0, -0.5, 0.0))
    assert to.task == fro.task and to.task.wind_from_m_s == (-1.0, -0.5, 0.0)
    to.step(600)
    fro.step(600)
    np.testing.assert_array_equal(to.state()["position_m"], fro.state()["position_m"])
    with pytest.warns(DeprecationWarning):
        old = Flight3D(controller=flight3d.withdrawn_file("wind"), wind_m_s=(1.0, 0.5, 0.0))
    assert old.task == to.task
    with pytest.warns(DeprecationWarning):
        assert old.wind_m_s.tolist() == [1.0, 0.5, 0.0]
    with pytest.warns(DeprecationWarning):
        assert flight3d.level(1.5).with_weather(wind_m_s=(0.0, 1.0, 0.0)).wind_to_m_s == (0.0, 1.0, 0.0)
    with pytest.raises(UserError, match="give the wind once"):
        flight3d.Garden(2, wind_to_m_s=(1.0, 0.0, 0.0), wind_from_m_s=(1.0, 0.0, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new names give no note
        to.set_wind(wind_from_m_s=(0.0, 2.0, 0.0))
        assert to.wind_to_m_s.tolist() == [0.0, -2.0, 0.0]
        assert flight3d.Garden(2, wind_from_m_s=(1.0, 0.0, 0.0)).tasks[0].wind_to_m_s == (-1.0, 0.0, 0.0)
