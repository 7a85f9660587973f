"""The designed controller (issue 42, point 2), as far as it is built: gains from the averaged model hold level flight
in calm air with the filmed monarch's gait; the wind triangle of its guidance."""

import math

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import averaged as A
from lifelike_mj.butterfly.flight3d import designed as D
from lifelike_mj.butterfly.flight3d import measures as M
from lifelike_mj.butterfly.flight3d.flight import Flight3D, quat_from_pitch
from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
from lifelike_mj.butterfly.flight3d.tasks import level


def test_the_wind_triangle_crabs_into_a_cross_wind_and_speeds_up_into_a_head_wind():
    d = np.array([1.0, 0.0])
    heading, air = D.DesignedController.wind_triangle(d, 1.5, np.array([0.0, -1.0]))  # wind blowing to the right
    assert heading > 0.0 and air == pytest.approx(math.hypot(1.5, 1.0))  # nose to the left, into the wind
    heading, air = D.DesignedController.wind_triangle(d, 1.5, np.array([-2.0, 0.0]))  # 2 m/s head wind
    assert heading == pytest.approx(0.0) and air == pytest.approx(D.MAX_AIRSPEED_M_S)  # as fast as the envelope goes
    heading, air = D.DesignedController.wind_triangle(d, 1.5, np.array([-1.2, -1.2]))
    ground = air * np.array([math.cos(heading), math.sin(heading)]) + np.array([-1.2, -1.2])
    assert abs(ground[1]) < 1e-9 and ground[0] > 0.0  # the track held, the ground speed what is left


@pytest.mark.slow
def test_the_designed_controller_holds_level_flight_in_calm_air_with_a_natural_gait():
    model = A.build(speeds=(1.25, 1.5, 1.75), climbs=(0.0,))
    spec = D.design(model)
    V = 1.5
    fl = Flight3D(KinematicsCommand(*D._interp(spec["schedule"], V, "command")), animal="monarch",
                  force_law="calibrated", controller=D.DesignedController(spec), task=level(V))
    fl.data.qpos[3:7] = quat_from_pitch(float(D._interp(spec["schedule"], V, "body_angle_rad")))
    fl.data.qvel[0:3] = (V, 0.0, 0.0)
    fl.step(2400)
    s = M.sample(fl, 4.0)
    m = M.measures(s, **M.body_numbers(fl))
    assert np.sqrt(np.mean(s["position_m"][:, 2] ** 2)) < 0.05  # altitude within 5 cm rms
    assert abs(m["roll_mean_deg"]) <= 3.0 and abs(m["air_speed_m_s"] - V) < 0.15
    assert 110.0 <= m["stroke_left_deg"] <= 130.0 and m["stroke_difference_deg"] <= 5.0
    assert 9.5 <= m["flap_frequency_hz"] <= 11.0 and 35.0 <= m["dorsal_gap_deg"] <= 50.5
