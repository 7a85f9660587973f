"""The naturalness measures of a 3D flight (flight3d.measures): each computed from the simulation, each checked
on a flight whose answer is known."""

import math
from dataclasses import replace

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import measures as M
from lifelike_mj.butterfly.flight3d.controllers import default_base
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.errors import UserError

MONARCH_BASE = default_base("monarch")


def _held(command, pitch_deg=20.0, **kw):
    """A flight whose attitude is held (the reduction's assist): roll 0, the body angle ``pitch_deg``."""
    return Flight3D(command, animal="monarch", assist="hold", pitch_law=lambda f: math.radians(pitch_deg), **kw)


@pytest.fixture(scope="module")
def held_monarch():
    f = _held(MONARCH_BASE)
    f.step(400)
    return M.measures(M.sample(f, 0.5), **M.body_numbers(f))


def test_the_monarch_envelope_measures_as_commanded(held_monarch):
    """The monarch's base kinematics (120 deg strokes about +8 deg, the abdomen at -17 +- 14 deg, most flexed
    0.1 beat after the top) flown with the body held: the measures read back what was commanded, and the wings
    stop 44 deg apart at the top (the tips, seen from between the hinges)."""
    m = held_monarch
    assert m["flap_frequency_hz"] == pytest.approx(10.2, rel=2e-3)
    assert m["stroke_left_deg"] == pytest.approx(120.0, abs=0.2) and m["stroke_difference_deg"] < 1e-6
    assert 35.0 <= m["dorsal_gap_deg"] <= 50.0
    assert abs(m["roll_mean_deg"]) < 1e-9 and m["body_angle_deg"] == pytest.approx(20.0, abs=1e-6)
    assert m["abdomen_mean_deg"] == pytest.approx(-17.0, abs=0.5)
    assert m["abdomen_swing_deg"] == pytest.approx(14.0, abs=0.2)
    assert m["abdomen_lowest_after_top"] == pytest.approx(0.6 / (2 * math.pi), abs=0.02)


def test_the_strokes_and_the_advance_ratio_count_both_wings():
    """Lopsided strokes (the left 20 deg shorter): each wing's stroke is measured, and J divides by the mean of
    the two (not by one wing's)."""
    cmd = replace(MONARCH_BASE, amplitude_left=MONARCH_BASE.amplitude_left - math.radians(10.0))
    f = _held(cmd)
    f.step(400)
    m = M.measures(M.sample(f, 0.5), **M.body_numbers(f))
    assert m["stroke_left_deg"] == pytest.approx(100.0, abs=0.3) and m["stroke_right_deg"] == pytest.approx(120.0, abs=0.3)
    assert m["stroke_difference_deg"] == pytest.approx(20.0, abs=0.5)
    phi = math.radians(0.5 * (m["stroke_left_deg"] + m["stroke_right_deg"]))
    assert m["advance_ratio"] == pytest.approx(m["air_speed_m_s"] / (2 * phi * m["flap_frequency_hz"] * 0.060997),
                                               rel=1e-9)


def test_in_a_vacuum_the_drive_does_no_net_work_over_whole_beats():
    """Without air and gravity the joints' drive only trades energy with the wings' motion: over whole beats its
    net work is the change of kinetic energy (the start and end of a beat alike: about none), while each joint
    still does positive work against the wings' inertia. This is what the power measure integrates:
    ``tau dq/dt`` at every step."""
    f = Flight3D(MONARCH_BASE, animal="monarch", force_law="none")
    f.model.opt.gravity[:] = 0.0
    f.step(200)
    m = M.measures(M.sample(f, 0.6), **M.body_numbers(f))
    assert m["power_W_kg"] > 5.0  # the wings' inertia: work in, work out, every beat
    assert abs(m["power_net_W_kg"]) < 0.03 * m["power_W_kg"]


def test_air_and_gravity_cost_power():
    """Flying in air costs net work (the air takes it), far above the vacuum's."""
    f = _held(MONARCH_BASE)
    f.step(400)
    m = M.measures(M.sample(f, 0.5), **M.body_numbers(f))
    assert m["power_net_W_kg"] > 5.0 and m["power_W_kg"] >= m["power_net_W_kg"]


def test_too_short_a_flight_is_one_sentence():
    f = _held(MONARCH_BASE)
    with pytest.raises(UserError, match="whole wing beats"):
        M.measures(M.sample(f, 0.15), **M.body_numbers(f))
    with pytest.raises(UserError, match="at least"):
        M.level_measures("monarch", settle_s=5.0, window_s=0.1)
    assert np.isfinite(M.body_numbers(f)["mass_kg"])


def test_the_compiled_style_integrals_agree_with_the_measures():
    """What the evolution's naturalness reads (the style integrals the compiled loop adds up at every step) is
    what ``measures`` computes from the states: a symmetric monarch flight (no network, the attitude held) shows
    no stroke or offset difference, the commanded top of the stroke, and the drive's positive power within a few
    per cent (the loop takes each step's torques at its last Runge-Kutta stage)."""
    from lifelike_mj.butterfly.flight3d import evolution as E
    from lifelike_mj.butterfly.flight3d.tasks import N_STYLE, R_STYLE, STYLE_NAMES

    f = _held(MONARCH_BASE)
    f.step(400)
    assert not f._rec[R_STYLE : R_STYLE + N_STYLE].any()  # nothing in the first second (the start from rest)
    f.step(400)
    f._rec[R_STYLE : R_STYLE + N_STYLE] = 0.0
    s = M.sample(f, 0.6)
    rec = f._rec.copy()
    assert rec[R_STYLE + STYLE_NAMES.index("time_s")] == pytest.approx(0.6, abs=1.5 * f.dt)  # (the 1 s boundary within a step)
    mass = float(f.model.body_subtreemass[1])
    st = E.style(rec, f.dt, mass)
    m = M.measures(s, **M.body_numbers(f))
    assert st["stroke_difference_deg"] < 1e-9 and st["offset_difference_deg"] < 1e-9
    flown = np.degrees(np.max(s["joints_rad"][:, :2], axis=1))
    tops = [flown[a:b].max() for a, b in M.beats(0.5 * (s["joints_rad"][:, 0] + s["joints_rad"][:, 1]))]
    assert st["stroke_top_deg"] == pytest.approx(np.mean(tops), abs=0.3)  # the top as flown, beat by beat
    assert 60.0 < st["stroke_top_deg"] < 68.5  # the drive follows the 68 deg command a little short
    assert st["power_W_kg"] == pytest.approx(m["power_W_kg"], rel=0.05)
    assert st["stroke_frequency_rad_s"] == pytest.approx(2 * math.radians(60.0) * 10.2, rel=1e-9)


def test_unnatural_flight_costs_and_natural_flight_does_not():
    from lifelike_mj.butterfly.flight3d import evolution as E
    from lifelike_mj.butterfly.flight3d.tasks import level, turn

    natural = {"roll_deg": 1.0, "pitch_deg": E.body_angle_target_deg(1.5), "stroke_difference_deg": 2.0,
               "offset_difference_deg": 1.0, "stroke_top_deg": 70.0, "power_W_kg": 15.0}
    assert E.unnatural(natural, level(1.5)) == 0.0
    banked = dict(natural, roll_deg=13.0)
    assert E.unnatural(banked, level(1.5)) == pytest.approx(0.5)  # 10 deg beyond 3, 0.05 per deg
    assert E.unnatural(banked, turn(90.0, 1.5, 1.5)) == 0.0  # a turn banks
    assert E.unnatural(dict(natural, power_W_kg=40.2), level(1.5)) == pytest.approx(0.4)
    assert E.unnatural(dict(natural, stroke_top_deg=80.0), level(1.5)) == pytest.approx(0.3)
    assert E.body_angle_target_deg(1.0) == 20.0 and E.body_angle_target_deg(2.0) == 10.0
    assert E.body_angle_target_deg(3.0) == 5.0
    # slow flight (before a landing) is asked for level wings and even strokes only: no cruise power, gap or body angle
    slow = dict(natural, power_W_kg=40.2, stroke_top_deg=88.0, pitch_deg=50.0)
    assert E.unnatural(slow, level(0.4)) == 0.0
    assert E.unnatural(dict(slow, roll_deg=13.0), level(0.4)) == pytest.approx(0.5)
    assert E.unnatural(slow, level(1.0)) > 1.0


def test_falling_is_no_way_out_of_looking_unnatural():
    """With naturalness asked, a flight's score is its reward times exp(-cost): never above the reward, so a
    candidate that tumbles (little reward) cannot beat one that flies by escaping the cost."""
    from lifelike_mj.butterfly.flight3d import evolution as E
    from lifelike_mj.butterfly.flight3d.controllers import Controller3D
    from lifelike_mj.butterfly.flight3d.tasks import level

    c = Controller3D([10, 9], E.pd_prior([10, 9], "monarch"), MONARCH_BASE, animal="monarch")
    plain = E.FlightProblem3D((level(1.0),), c, duration_s=1.0)
    natural = E.FlightProblem3D((level(1.0),), c, duration_s=1.0, natural=True)
    x = np.zeros((2, plain.dim))
    x[1] = 0.5  # a worse candidate
    a, b = plain.evaluate(x), natural.evaluate(x)
    assert (b <= a + 1e-12).all() and (b > 0).all()
    assert plain.fingerprint() != natural.fingerprint()
