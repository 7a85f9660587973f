"""Measures of fish living together (fish/shoal.py): each on tracks whose answer is known."""

import math

import numpy as np
import pytest

from lifelike_mj import fish
from lifelike_mj.fish import shoal
from lifelike_mj.fish.scene import BODY_LENGTH_M


def _circle(n_fish: int, tangential: bool, radius=1.0, omega=1.0):
    """Fish spread evenly round a circle, all turning about its centre (tangential) or swimming outward, for 2 s."""
    t = np.linspace(0.0, 2.0, 201)
    phase = 2 * math.pi * np.arange(n_fish) / n_fish
    if tangential:
        a = omega * t[:, None] + phase[None, :]
        r = np.full_like(a, radius)
    else:
        a = np.broadcast_to(phase, (t.size, n_fish))
        r = radius + 0.5 * t[:, None] * np.ones(n_fish)
    return t, np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(a)], axis=-1)


def test_order_parameters_tell_a_school_a_mill_and_a_burst_apart():
    t = np.linspace(0.0, 1.0, 11)
    school = np.stack([np.stack([0.3 * t + 0.1 * i, 0.05 * i + 0 * t, 0 * t], -1) for i in range(6)], axis=1)
    h = shoal.headings(shoal.velocities(t, school))
    np.testing.assert_allclose(shoal.polarisation(h), 1.0)
    t, mill = _circle(8, tangential=True)
    h = shoal.headings(shoal.velocities(t, mill))
    np.testing.assert_allclose(shoal.milling(mill, h), 1.0, atol=1e-3)
    assert shoal.polarisation(h).max() < 1e-9
    t, burst = _circle(8, tangential=False)
    h = shoal.headings(shoal.velocities(t, burst))
    assert shoal.milling(burst, h).max() < 1e-9 and shoal.polarisation(h).max() < 1e-9
    # a fish standing still has no heading and does not count
    still = np.concatenate([school[:, :1], np.zeros((11, 1, 3))], axis=1)
    h = shoal.headings(shoal.velocities(np.linspace(0.0, 1.0, 11), still), min_speed_m_s=0.01)
    assert np.isnan(h[:, 1]).all() and np.allclose(shoal.polarisation(h), 1.0)


def test_distances_in_the_fish_frame_and_to_the_walls():
    p = np.array([[[0.0, 0.0, 0.5], [0.0, 0.2, 0.5], [2.0, 0.0, 0.1]]])
    np.testing.assert_allclose(shoal.nearest_neighbour_m(p), [[0.2, 0.2, math.hypot(2.0, 0.4)]])
    np.testing.assert_allclose(shoal.cohesion_m(p), np.linalg.norm(p[0] - p[0].mean(0), axis=1).mean())
    np.testing.assert_allclose(shoal.wall_distance_m(p, (5.0, 0.5, 1.0)), [[0.25, 0.05, 0.25]])
    # fish 0 heads +y: fish 1 (at +y) is 0.2 m ahead, fish 2 (at +x) 2 m to its right; fish 2 heads -x: opposite
    head = np.array([[[0.0, 1.0], [0.0, 1.0], [-1.0, 0.0]]])
    rel, dphi = shoal.neighbour_frame(p, head)
    np.testing.assert_allclose(rel[0], [0.2, 0.0], atol=1e-12)
    np.testing.assert_allclose(rel[1], [0.0, -2.0], atol=1e-12)
    assert dphi[0] == 0.0 and dphi[1] == pytest.approx(math.pi / 2)


def test_kicks_are_the_onsets_of_speed_rises_beyond_the_threshold():
    t = np.arange(0.0, 5.0, 1 / 60)
    kicks = np.array([0.5, 1.1, 1.5, 2.4, 3.0, 4.1])
    v = np.full_like(t, 0.02)
    for k in kicks:  # a push over 50 ms to 0.2 m/s, then a glide decaying as exp(-t / 0.8 s)
        after = t >= k
        rise = np.clip((t - k) / 0.05, 0.0, 1.0)
        v = np.where(after, np.maximum(v * (1 - rise), 0.0) + rise * 0.2 * np.exp(-np.clip(t - k - 0.05, 0, None) / 0.8),
                     v)
    v = v + 0.002 * np.sin(2 * math.pi * 7.0 * t)  # a ripple far below the threshold
    found = shoal.kick_times(t, v, rise_m_s=0.05)
    assert len(found) == len(kicks)
    np.testing.assert_allclose(found, kicks, atol=1.5 / 60)
    assert len(shoal.kick_times(t, v, rise_m_s=0.5)) == 0


def test_independent_fish_of_the_paper_are_neither_a_school_nor_a_shoal():
    """Ten B-D fish of Satoi 2015 (which ignore each other): the measures of fish that swim independently."""
    r = fish.Tank(fish.load_preset("B-D"), n_fish=10, seed=3).record(duration_s=40.0)
    m = fish.swim_summary(r)["group"]
    # independent headings: |mean of 10 unit vectors| is about sqrt(pi / 40) = 0.28
    assert 0.15 < m["polarisation"] < 0.4
    assert m["nn_distance_bl"]["median"] > 3.0 and m["near_fraction_2bl"] < 0.15
    assert m["state_fractions"]["polarised"] < 0.05
    k = m["kick_interval_s"]
    assert k["count"] > 200 and 0.3 < k["mean"] < 1.5 and k["cv"] > 0.5  # the paper's chain: near memoryless
    assert m["wall_distance_bl"]["p5"] > 0.0 and m["speed_bl_s"]["median"] > 0.5
    assert m == shoal.group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m)


def test_the_group_figure_is_written(tmp_path):
    from lifelike_mj.fish.figures import group_figure

    r = fish.Tank(fish.load_preset("B-D"), n_fish=4, seed=0).record(duration_s=3.0)
    out = tmp_path / "group.png"
    group_figure(r, out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
