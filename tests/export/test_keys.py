"""Keys that resolve the motion (lifelike_mj.export.keys): within the tolerance at every sample, few, and
recorded without touching the simulation."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lifelike_mj.errors import UserError
from lifelike_mj.export.keys import MAX_KEY_TURN_DEG, lerp_keys, slerp_keys, tolerance_of
from lifelike_mj.export.poses import record_poses


def _lerp(t, keys, x):
    return np.stack([np.interp(t, t[keys], x[keys, j]) for j in range(x.shape[1])], axis=1)


def _slerp_at(t, keys, q):
    out = np.empty_like(q)
    for i, ti in enumerate(t):
        k = min(np.searchsorted(t[keys], ti, side="right") - 1, len(keys) - 2)
        a, b = q[keys[k]], q[keys[k + 1]]
        u = (ti - t[keys[k]]) / (t[keys[k + 1]] - t[keys[k]])
        if np.dot(a, b) < 0:
            b = -b
        th = math.acos(min(1.0, np.dot(a, b)))
        s = (1 - u) * a + u * b if th < 1e-9 else (math.sin((1 - u) * th) * a + math.sin(u * th) * b) / math.sin(th)
        out[i] = s / np.linalg.norm(s)
    return out


def _angles(p, q):
    return 2.0 * np.arccos(np.clip(np.abs(np.sum(p * q, axis=1)), 0.0, 1.0))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**31), tol_mm=st.floats(0.01, 5.0), hz=st.floats(0.1, 20.0))
def test_positions_stay_within_the_tolerance_between_their_keys(seed, tol_mm, hz):
    rng = np.random.default_rng(seed)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 2000))  # uneven steps
    x = np.stack([0.05 * np.sin(2 * np.pi * hz * t + p) for p in rng.uniform(0, 6, 3)], axis=1)
    x += rng.normal(0.0, 1e-5, x.shape)
    keys = lerp_keys(t, x, tol_mm * 1e-3)
    assert keys[0] == 0 and keys[-1] == len(t) - 1 and np.all(np.diff(keys) > 0)
    assert np.max(np.linalg.norm(_lerp(t, keys, x) - x, axis=1)) <= tol_mm * 1e-3 + 1e-12
    assert len(lerp_keys(t, x, 2 * tol_mm * 1e-3)) <= len(keys)  # looser, fewer


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31), tol_deg=st.floats(0.05, 5.0), amp_deg=st.floats(1.0, 170.0))
def test_rotations_stay_within_the_tolerance_and_turn_at_most_20_degrees_between_keys(seed, tol_deg, amp_deg):
    rng = np.random.default_rng(seed)
    t = np.arange(1500) / 1200.0
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    angle = np.radians(amp_deg) * np.sin(2 * np.pi * 10.7 * t)  # a wing beat
    q = np.concatenate([np.cos(angle / 2)[:, None], np.sin(angle / 2)[:, None] * axis], axis=1)
    q[1::2] *= -1.0  # either sign of each sample is the same rotation
    keys = slerp_keys(t, q, np.radians(tol_deg))
    assert keys[0] == 0 and keys[-1] == len(t) - 1
    assert np.max(_angles(_slerp_at(t, keys, q), q)) <= np.radians(tol_deg) + 1e-9
    assert np.max(_angles(q[keys[1:]], q[keys[:-1]])) <= np.radians(MAX_KEY_TURN_DEG) + 1e-9
    assert len(keys) < len(t)


def test_tolerances_read_with_units_and_bad_ones_get_one_sentence():
    assert tolerance_of("0.5mm,0.5deg") == (0.0005, 0.5)
    assert tolerance_of("20um, 0.01rad") == pytest.approx((2e-5, math.degrees(0.01)))
    assert tolerance_of("1,2") == (0.001, 2.0)  # bare numbers: mm and deg
    assert tolerance_of((0.001, 1.0)) == (0.001, 1.0)
    for bad, match in (("0.5mm", "a distance and an angle"), ("fast,0.5deg", "not a number"),
                       ("0mm,0.5deg", "distance"), ("1mm,90deg", "angle"), ("nanmm,1deg", "distance"),
                       ((1.0,), "metres, degrees")):
        with pytest.raises(UserError, match=match):
            tolerance_of(bad)


@pytest.mark.parametrize("creature", ["butterfly3d", "fish", "boids"])
def test_sampling_every_step_leaves_the_run_bit_for_bit_as_it_was(runs, fresh, creature):
    """The frames of a run recorded at every step are the frames recorded alone, bit for bit (stepping one step
    at a time or many changes nothing)."""
    _, poses = runs(creature)
    sim, fps, scale, duration = fresh(creature)
    alone = record_poses(sim, duration, fps, scale, every_step=False)
    frames = poses.frames()
    assert alone.n_samples == frames.n_samples == poses.n_frames
    np.testing.assert_array_equal(alone.position_m, frames.position_m)
    side = np.sign(np.sum(alone.quat_wxyz * frames.quat_wxyz, axis=2, keepdims=True))  # q and -q: one rotation,
    np.testing.assert_array_equal(alone.quat_wxyz * side, frames.quat_wxyz)  # kept on one side sample to sample
    np.testing.assert_array_equal(alone.t_s, frames.t_s)
    assert poses.n_samples > poses.n_frames
