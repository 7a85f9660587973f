"""Tests of lifelike_mj.fish.metrics on synthetic signals whose answers are known by hand."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lifelike_mj.fish import metrics as m

# --------------------------------------------------------------------------------------------
# Tracks: side view, resampling, speed and acceleration
# --------------------------------------------------------------------------------------------


def test_side_view_keeps_x_and_z():
    p = np.arange(2 * 3 * 3, dtype=float).reshape(2, 3, 3)
    sv = m.side_view(p)
    assert sv.shape == (2, 3, 2)
    np.testing.assert_array_equal(sv[..., 0], p[..., 0])
    np.testing.assert_array_equal(sv[..., 1], p[..., 2])
    np.testing.assert_array_equal(m.side_view(p[:, 0, :]), sv[:, 0, :])
    with pytest.raises(ValueError):
        m.side_view(np.zeros((4, 2)))


def test_resample_is_exact_on_a_linear_track():
    rng = np.random.default_rng(1)
    t = np.concatenate(([0.1], 0.1 + np.cumsum(rng.uniform(0.005, 0.03, 400))))
    a = np.array([[0.3, -1.0, 2.0], [0.0, 0.5, -0.2]])  # (F=2, 3) offsets
    v = np.array([[0.7, 0.1, -0.4], [-0.2, 0.0, 0.9]])  # m/s
    p = a[None] + v[None] * t[:, None, None]
    tg, pg = m.resample(t, p, fps=24.0)
    assert tg[0] == t[0] and tg[-1] <= t[-1] and t[-1] - tg[-1] < 1 / 24
    np.testing.assert_allclose(np.diff(tg), 1 / 24, rtol=0, atol=1e-12)
    assert pg.shape == (tg.size, 2, 3)
    np.testing.assert_allclose(pg, a[None] + v[None] * tg[:, None, None], rtol=0, atol=1e-12)


def test_resample_includes_the_last_sample_when_on_the_grid():
    t = np.array([0.0, 0.3, 1.0])
    tg, pg = m.resample(t, 2.0 * t, fps=10.0)
    assert tg.size == 11
    np.testing.assert_allclose(pg, 2.0 * tg, atol=1e-12)
    with pytest.raises(ValueError):
        m.resample(np.array([0.0, 0.0, 1.0]), np.zeros(3))


def test_speed_and_accel_of_constant_acceleration():
    fps, acc = 24.0, 1.5
    t = np.arange(50) / fps
    u = np.array([0.6, 0.8])  # unit direction in the side view
    s = 0.5 * acc * t**2
    speed, accel = m.speed_and_accel(s[:, None] * u, fps)
    # Displacement over [t_i, t_i+1] / dt is the speed at the midpoint: acc * (i + 1/2) / fps.
    np.testing.assert_allclose(speed, acc * (np.arange(49) + 0.5) / fps, rtol=1e-12)
    np.testing.assert_allclose(accel, acc, rtol=1e-9)
    # Deceleration (still moving forward) is negative; several fish at once.
    s2 = 4.0 * t - 0.5 * acc * t**2  # stops at t = 8/3 s, after the last sample 49/24 s
    both = np.stack([s[:, None] * u, s2[:, None] * u], axis=1)  # (T, 2, 2)
    speed2, accel2 = m.speed_and_accel(both, fps)
    assert speed2.shape == (49, 2) and accel2.shape == (48, 2)
    np.testing.assert_allclose(accel2[:, 0], acc, rtol=1e-9)
    np.testing.assert_allclose(accel2[:, 1], -acc, rtol=1e-9)


# --------------------------------------------------------------------------------------------
# Acceleration distribution
# --------------------------------------------------------------------------------------------


def test_accel_histogram_is_symmetric_and_summary_is_right():
    a = np.concatenate([np.full(50, -0.3), np.full(10, 2.0), [0.0, 0.1]])
    counts, edges = m.accel_histogram(a, bins=21, limit=2.1)
    assert counts.size == 21 and edges[0] == -edges[-1] == -2.1
    assert counts.sum() == a.size
    s = m.histogram_summary(a, bins=21, limit=2.1)
    assert s["mode"] == pytest.approx(-0.2)  # bin [-0.3, -0.1) centre -0.2 holds the 50 samples
    assert s["fraction_positive"] == pytest.approx(11 / 62)
    assert s["mean"] == pytest.approx(a.mean())
    assert s["median"] == pytest.approx(-0.3)
    assert s["p5"] == pytest.approx(-0.3) and s["p95"] == pytest.approx(2.0)
    assert s["skewness"] > 1.0  # rare large positive bursts, many small decelerations
    assert all(type(v) is float for v in s.values())
    # Skewness against the exponential's known value 2 (SE ~ sqrt(6*... )): big sample, loose tol.
    x = np.random.default_rng(3).exponential(size=200_000)
    assert m.histogram_summary(x)["skewness"] == pytest.approx(2.0, abs=0.1)


def test_kurtosis_hand_values_and_known_distributions():
    assert m.kurtosis([0.0, 0.0, 0.0, 1.0]) == pytest.approx(7 / 3 - 3)  # m4/m2^2 = 2.333...
    assert m.kurtosis([-1.0, 1.0, -1.0, 1.0]) == pytest.approx(-2.0)
    assert math.isnan(m.kurtosis([1.0, 2.0, 3.0])) and math.isnan(m.kurtosis(np.ones(10)))
    rng = np.random.default_rng(7)
    # n = 200k: the sample excess kurtosis has SD ~ sqrt(24/n) = 0.011 (normal) and ~0.065
    # (Laplace, measured over 200 replicates); tolerances are > 4.5 SD.
    assert m.kurtosis(rng.standard_normal(200_000)) == pytest.approx(0.0, abs=0.05)
    assert m.kurtosis(rng.laplace(size=200_000)) == pytest.approx(3.0, abs=0.3)


# --------------------------------------------------------------------------------------------
# Bursts and burstiness
# --------------------------------------------------------------------------------------------


def test_bursts_onsets_of_a_hand_made_series():
    a = np.array([2.0, 3.0, 0.0, 1.0, 0.0, 5.0, 6.0, 1.0, 7.0, 0.0, 8.0, 8.0, 8.0])
    # Runs above 1.0 (strictly): [0,1], [5,6], [8], [10,12]; samples 3 and 7 equal the threshold.
    np.testing.assert_allclose(m.bursts(a, fps=10.0, threshold=1.0), [0.0, 0.5, 0.8, 1.0])
    np.testing.assert_allclose(m.bursts(a, fps=10.0, threshold=1.0, t0=2.0), [2.0, 2.5, 2.8, 3.0])
    # Above 0.5: [0,1], [3], [5,8], [10,12].
    np.testing.assert_allclose(m.bursts(a, fps=10.0, threshold=0.5), [0.0, 0.3, 0.5, 1.0])
    np.testing.assert_allclose(m.bursts(a, fps=10.0, threshold=-1.0), [0.0])  # one run
    assert m.bursts(a, fps=10.0, threshold=9.0).size == 0
    b = a.copy()
    b[11] = np.nan  # a non-finite sample ends a run
    np.testing.assert_allclose(m.bursts(b, fps=10.0, threshold=1.0), [0.0, 0.5, 0.8, 1.0, 1.2])


def test_accel_events_are_the_samples_above_threshold():
    a = np.array([0.0, 5.0, 5.0, 1.0, 4.0, 4.000001, np.nan, 9.0])
    np.testing.assert_allclose(m.accel_events(a, fps=2.0, threshold=4.0), [0.5, 1.0, 2.5, 3.5])
    np.testing.assert_allclose(m.accel_events(a, fps=2.0, threshold=4.0, t0=10.0), [10.5, 11.0, 12.5, 13.5])
    with pytest.raises(ValueError):
        m.accel_events(np.zeros((2, 2)), 1.0, 0.0)


def test_burstiness_periodic_is_minus_one():
    assert m.burstiness(np.full(10, 0.7)) == pytest.approx(-1.0)
    assert m.burstiness(np.full(10, 0.7), finite_size_correction=False) == pytest.approx(-1.0)


def test_burstiness_kim_jo_small_case_by_hand():
    # Intervals 1, 2, 3: mu = 2, population sigma = sqrt(2/3), r = sqrt(2/3)/2 = 1/sqrt(6).
    # n = 3 intervals: sqrt(n+1) = 2, so A_3 = (2r - sqrt2) / sqrt2 = sqrt2 * r - 1 = 1/sqrt3 - 1.
    assert m.burstiness([1.0, 2.0, 3.0]) == pytest.approx(1 / math.sqrt(3) - 1, rel=1e-12)
    r = 1 / math.sqrt(6)
    assert m.burstiness([1.0, 2.0, 3.0], finite_size_correction=False) == pytest.approx((r - 1) / (r + 1))
    # With n = 4 (intervals + 1, the other reading) the value would differ: guard the choice.
    a4 = (math.sqrt(5) * r - math.sqrt(3)) / ((math.sqrt(5) - 2) * r + math.sqrt(3))
    assert abs(m.burstiness([1.0, 2.0, 3.0]) - a4) > 0.01


def test_burstiness_extreme_sequence_reaches_one():
    # All time in one interval: r = sqrt(n - 1) with population sigma, and A_n = 1 exactly.
    assert m.burstiness([0.0, 0.0, 0.0, 0.0, 5.0]) == pytest.approx(1.0)
    assert m.burstiness([0.0, 0.0, 0.0, 0.0, 5.0], finite_size_correction=False) < 0.5


def test_burstiness_zero_point_is_the_poisson_mean_of_r_squared():
    # The Kim-Jo zero is r0^2 = (n-1)/(n+1); for n i.i.d. exponential intervals E[r^2] equals it
    # exactly when n counts intervals and sigma is the population SD. 100k replicates give
    # SE ~ 0.001 on the mean of r^2; the alternative n = intervals + 1 gives 5/7 = 0.714 for n=5.
    n = 5
    x = np.random.default_rng(11).exponential(size=(100_000, n))
    r2 = np.mean((x.std(axis=1) / x.mean(axis=1)) ** 2)
    assert r2 == pytest.approx((n - 1) / (n + 1), abs=0.005)
    # Intervals 1-c, 1-c, 1, 1+c, 1+c have r = 2c/sqrt5; choose r = r0 and A_5 must vanish.
    c = math.sqrt((n - 1) / (n + 1)) * math.sqrt(5) / 2
    assert m.burstiness([1 - c, 1 - c, 1.0, 1 + c, 1 + c]) == pytest.approx(0.0, abs=1e-12)


def test_burstiness_poisson_is_near_zero():
    # 20k exponential intervals: A_n has SD 0.0036 over 500 replicates (measured), so |A| < 0.02
    # is > 5 SD; a periodic or bursty process is far outside.
    iv = np.random.default_rng(5).exponential(0.8, size=20_000)
    assert m.burstiness(iv) == pytest.approx(0.0, abs=0.02)


def test_burstiness_clustered_events_is_clearly_positive():
    # Trains of 10 events 0.01 s apart, trains 10 s apart: r ~ 3, B ~ 0.5.
    rng = np.random.default_rng(2)
    iv = np.tile(np.r_[np.full(9, 0.01), 10.0], 30) * rng.uniform(0.9, 1.1, 300)
    assert m.burstiness(iv) > 0.4
    assert m.burstiness(iv) > m.burstiness(rng.exponential(size=300)) + 0.3


def test_burstiness_edge_cases():
    assert math.isnan(m.burstiness([1.0, 2.0]))
    assert math.isnan(m.burstiness([0.0, 0.0, 0.0]))
    with pytest.raises(ValueError):
        m.burstiness([1.0, -1.0, 2.0])


intervals_st = st.lists(st.floats(min_value=0.0, max_value=1e3, allow_nan=False), min_size=3, max_size=60).filter(
    lambda v: sum(v) > 1e-6
)


@settings(max_examples=150, deadline=None)
@given(intervals_st)
def test_burstiness_is_within_minus_one_one(iv):
    for corrected in (True, False):
        b = m.burstiness(iv, finite_size_correction=corrected)
        assert -1.0 <= b <= 1.0


@settings(max_examples=150, deadline=None)
@given(intervals_st, st.floats(min_value=1e-3, max_value=1e3))
def test_burstiness_is_invariant_to_scaling_intervals(iv, c):
    b = m.burstiness(iv)
    assert m.burstiness(np.asarray(iv) * c) == pytest.approx(b, abs=1e-9)


# --------------------------------------------------------------------------------------------
# Turning
# --------------------------------------------------------------------------------------------


def test_straight_track_has_zero_turning_entropy():
    # Diagonal line at uneven speed, 2-D and 3-D: every angle is 0 up to rounding, one bin.
    s = np.cumsum(np.random.default_rng(4).uniform(0.01, 0.05, 500))
    p = np.c_[0.1 + 0.6 * s, -0.2 + 0.8 * s]
    ang = m.turning_angles(p, min_speed=0.0, fps=24.0)
    assert ang.size == 498 and np.all(np.abs(ang) < 1e-6)
    assert m.turn_entropy(ang) == 0.0
    p3 = np.c_[p, 0.3 * s]
    assert m.turn_entropy(m.turning_angles(p3, 0.0, 24.0, window=6)) == 0.0


def test_turning_angles_are_unsigned_and_windowed():
    # +x then +z: a quarter turn; then back along -z: a reversal (pi); then +x: a quarter turn.
    p = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [1.0, 0.0], [2.0, 0.0]])
    np.testing.assert_allclose(m.turning_angles(p, min_speed=0.0, fps=1.0), [np.pi / 2, np.pi, np.pi / 2])
    q2 = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, -1.0]])  # a right turn is also +pi/2
    np.testing.assert_allclose(m.turning_angles(q2, 0.0, 1.0), [np.pi / 2])
    # window 2 on a square path in steps of 0.5: displacements over 2 frames are (1, 0), (.5, .5),
    # (0, 1), (-.5, .5), (-1, 0); each is 90 deg from the one 2 frames later (frame to frame: 0 or 90)
    sq = np.array([[0, 0], [0.5, 0], [1, 0], [1, 0.5], [1, 1], [0.5, 1], [0, 1]], dtype=float)
    np.testing.assert_allclose(m.turning_angles(sq, 0.0, 1.0, window=2), [np.pi / 2] * 3)
    np.testing.assert_allclose(m.turning_angles(sq, 0.0, 1.0), [0, np.pi / 2, 0, np.pi / 2, 0], atol=1e-12)
    with pytest.raises(ValueError):
        m.turning_angles(sq, 0.0, 1.0, window=0)
    assert m.turning_angles(sq[:4], 0.0, 1.0, window=2).size == 0


def test_turning_angles_skip_slow_steps():
    # Steps of 1 m at 1 fps (1 m/s) with a near stop (0.01 m/s) in the middle: the two pairs
    # that touch the slow step are skipped.
    p = np.cumsum(np.array([[0, 0], [1, 0], [0, 1], [0.01, 0], [1, 0], [0, 1]], dtype=float), axis=0)
    assert m.turning_angles(p, min_speed=0.0, fps=1.0).size == 4
    np.testing.assert_allclose(m.turning_angles(p, min_speed=0.5, fps=1.0), [np.pi / 2, np.pi / 2])
    assert m.turning_angles(p, min_speed=0.5, fps=0.1).size == 0  # now every step is 0.1 m/s or less


def test_random_walk_turning_entropy_is_near_log2_bins():
    # Uniform random headings in the plane: the unsigned angle between two of them is uniform on
    # [0, pi]. 20k angles, 36 bins: plug-in bias ~ -0.0013 bits, SD ~ 0.002 bits.
    rng = np.random.default_rng(9)
    th = rng.uniform(-np.pi, np.pi, 20_001)
    p = np.cumsum(np.c_[np.cos(th), np.sin(th)] * rng.uniform(0.5, 1.5, (20_001, 1)), axis=0)
    h = m.turn_entropy(m.turning_angles(p, min_speed=0.0, fps=24.0), bins=36)
    assert h == pytest.approx(math.log2(36), abs=0.02)
    assert m.turn_entropy(np.zeros(0)) != m.turn_entropy(np.zeros(0))  # nan without angles


def test_turn_entropy_hand_values():
    assert m.turn_entropy(np.array([0.1, 0.1, 2.0, 2.0]), bins=36) == pytest.approx(1.0)
    assert m.turn_entropy(np.array([0.0, np.pi, 0.1, 1.0]), bins=4) == pytest.approx(1.5)


# --------------------------------------------------------------------------------------------
# Motion-unit log
# --------------------------------------------------------------------------------------------


def test_mu_entropy_rate_cycle_and_iid():
    cycle = np.tile([0, 1, 2, 3], 500)
    assert m.mu_entropy_rate(cycle) == pytest.approx(0.0, abs=1e-12)
    # i.i.d. uniform: 2 bits/step; with 60k transitions the plug-in bias is ~ -12/(2 N ln2)
    # = -1.4e-4 and the SD ~ 0.001.
    iid = np.random.default_rng(0).integers(0, 4, size=(20_001, 3))
    assert m.mu_entropy_rate(iid) == pytest.approx(2.0, abs=0.01)


def test_mu_entropy_rate_hand_value_and_pooling():
    # 0,0,0,1,1,0: from 0: 0->0 x2, 0->1 x1; from 1: 1->1, 1->0. H = 3/5 H(2/3,1/3) + 2/5 * 1.
    h = 3 / 5 * -(2 / 3 * math.log2(2 / 3) + 1 / 3 * math.log2(1 / 3)) + 2 / 5
    seq = np.array([0, 0, 0, 1, 1, 0])
    assert m.mu_entropy_rate(seq) == pytest.approx(h)
    # Two fish: transitions pooled, never from the end of one column into the next.
    two = np.stack([np.tile([0, 1], 50), np.tile([2, 3], 50)], axis=1)
    assert m.mu_entropy_rate(two) == pytest.approx(0.0, abs=1e-12)
    assert m.mu_entropy_rate(two.T.ravel()) > 0.0  # joined: 0->2 or so breaks determinism
    with pytest.raises(ValueError):
        m.mu_entropy_rate(np.array([0, 4, 1]))


def test_mu_dwell_times():
    d = m.mu_dwell_times(np.array([0, 0, 0, 1, 1, 0]), dt=0.5)
    assert set(d) == {0, 1, 2, 3}
    np.testing.assert_allclose(d[0], [1.5, 0.5])
    np.testing.assert_allclose(d[1], [1.0])
    assert d[2].size == 0 and d[3].size == 0
    two = np.array([[2, 2], [2, 3], [3, 3]])  # per column: fish 0 = 2,2,3; fish 1 = 2,3,3
    d2 = m.mu_dwell_times(two, dt=1.0)
    np.testing.assert_allclose(d2[2], [2.0, 1.0])
    np.testing.assert_allclose(d2[3], [1.0, 2.0])
    d3 = m.mu_dwell_times(np.array([0, 1, 1, 2, 2, 2, 0]), dt=1.0, drop_censored=True)
    np.testing.assert_allclose(d3[1], [2.0])
    np.testing.assert_allclose(d3[2], [3.0])
    assert d3[0].size == 0


# --------------------------------------------------------------------------------------------
# The whole analysis on a small synthetic tank
# --------------------------------------------------------------------------------------------

EXPECTED_KEYS = {
    "burst_interval_mean_s",
    "burst_interval_median_s",
    "bursts_per_s",
    "burstiness",
    "accel_kurtosis",
    "accel_skewness",
    "accel_mode_bl_s2",
    "turn_entropy",
    "mean_speed_body_lengths_s",
    "max_speed_body_lengths_s",
    "n_bursts",
}


U_LOW, U_HIGH, T_KICK, TAU = 0.05, 0.3, 0.125, 0.3
U_END = U_LOW + (U_HIGH - U_LOW) * math.exp(-(1.0 - T_KICK) / TAU)


def _speed_profile(ph):
    """Speed (m/s) at phase ``ph`` (s, in [0, 1)) of a 1 s kick cycle: linear push U_END -> U_HIGH
    in T_KICK s, then exponential coast toward U_LOW (time constant TAU) until the next kick."""
    push = U_END + (U_HIGH - U_END) * ph / T_KICK
    coast = U_LOW + (U_HIGH - U_LOW) * np.exp(-(ph - T_KICK) / TAU)
    return np.where(ph < T_KICK, push, coast)


def _kick_tank(n_fish=3, duration=20.0, seed=0):
    """Fish swimming along +x with a kick every 1 s (:func:`_speed_profile`), wiggling a lot in depth y (invisible from the side),
    sampled at uneven times near 60 Hz. Kick phases lie in (0.3, 0.7) s: no cut-off kick."""
    rng = np.random.default_rng(seed)
    fine = np.arange(0.0, duration + 1e-9, 1e-4)
    t = np.concatenate(([0.0], np.cumsum(rng.uniform(0.8, 1.2, int(duration * 60)) / 60)))
    t = t[t <= duration]
    pos = np.zeros((t.size, n_fish, 3))
    for f in range(n_fish):
        u = _speed_profile(np.mod(fine - rng.uniform(0.3, 0.7), 1.0))
        x = np.concatenate(([0.0], np.cumsum(0.5 * (u[1:] + u[:-1]) * 1e-4)))
        pos[:, f, 0] = np.interp(t, fine, x) + 0.1 * f
        pos[:, f, 1] = 0.2 * np.sin(2 * np.pi * 0.7 * t + f)  # depth: ignored by the side view
        pos[:, f, 2] = 0.3 + 0.05 * f
    return t, pos


def test_track_measures_keys_types_and_values():
    t, pos = _kick_tank()
    bl = 0.05
    mu = np.random.default_rng(1).integers(0, 4, size=(600, 3))
    out = m.track_measures(t, pos, body_length_m=bl, mu_log=mu, control_dt=1 / 60)
    assert set(out) == EXPECTED_KEYS | {"mu_entropy_rate", "mu_dwell_mean_s"}
    for k in EXPECTED_KEYS - {"n_bursts"}:
        assert type(out[k]) is float, k
    assert type(out["n_bursts"]) is int and type(out["mu_entropy_rate"]) is float
    assert set(out["mu_dwell_mean_s"]) == {"accelerate", "coast", "cruise", "brake"}
    assert all(type(v) is float for v in out["mu_dwell_mean_s"].values())
    json.loads(json.dumps(out))
    # Known answers: one burst (a train of 2-3 frames above 4 BL/s^2: the push lasts 0.125 s) per
    # kick, 20 per fish, exactly periodic at 24 fps. Event intervals: 1/24 s inside a train, ~0.9 s
    # between trains -> clustered events, B > 0 (by hand, trains of 3 give B = 0.106).
    assert out["n_bursts"] == 60
    assert out["bursts_per_s"] == pytest.approx(60 / (3 * (t[-1] - t[0])))
    assert out["burst_interval_mean_s"] == pytest.approx(1.0, abs=1e-9)
    assert out["burst_interval_median_s"] == pytest.approx(1.0, abs=1e-9)
    assert 0.05 < out["burstiness"] < 0.35
    assert out["turn_entropy"] == 0.0  # straight along x in the side view despite the y wiggle
    assert out["accel_skewness"] > 0  # short strong pushes, long gentle coasts
    assert out["accel_mode_bl_s2"] < 0  # most of the time the fish decelerates (coasts)
    # Speeds: 0.05..0.3 m/s = 1..6 BL/s; mean of the profile over a period.
    u_mean = _speed_profile(np.linspace(0, 1, 100_001)[:-1]).mean()
    assert out["mean_speed_body_lengths_s"] == pytest.approx(u_mean / bl, rel=0.02)
    # The peak U_HIGH is sharp; a 1/24 s frame averages it down by a few percent at most.
    assert 0.9 * U_HIGH / bl < out["max_speed_body_lengths_s"] <= U_HIGH / bl
    assert 0.0 < out["mu_entropy_rate"] <= 2.0
    with pytest.raises(ValueError):
        m.track_measures(t, pos, body_length_m=bl, mu_log=mu)  # control_dt missing


def test_track_measures_is_scale_free_and_ignores_depth():
    t, pos = _kick_tank(n_fish=2, duration=10.0, seed=3)
    a = m.track_measures(t, pos, body_length_m=0.05)
    assert set(a) == EXPECTED_KEYS
    big = m.track_measures(t, pos * 2.0, body_length_m=0.10)  # everything twice as large
    for k in ("burstiness", "accel_kurtosis", "accel_skewness", "accel_mode_bl_s2", "mean_speed_body_lengths_s"):
        assert big[k] == pytest.approx(a[k], rel=1e-9, abs=1e-12), k
    assert big["n_bursts"] == a["n_bursts"]
    flat = pos.copy()
    flat[..., 1] = 0.0
    b = m.track_measures(t, flat, body_length_m=0.05)
    assert json.dumps(b, sort_keys=True) == json.dumps(a, sort_keys=True)
    # A single fish given as (T, 3) equals the same fish as (T, 1, 3).
    one = m.track_measures(t, pos[:, 0, :], body_length_m=0.05)
    assert json.dumps(one, sort_keys=True) == json.dumps(m.track_measures(t, pos[:, :1, :], 0.05), sort_keys=True)
