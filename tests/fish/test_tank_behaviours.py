"""Behaviours of your own in the fish tank: a motion-unit policy, a push policy, a Markov matrix."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from lifelike_mj import fish
from lifelike_mj.errors import UserError

P = fish.load_preset("B-D")
SIZE = (1.0, 0.3, 0.5)


def _swim(**kw):
    return fish.Tank(kw.pop("params", P), 4, seed=1, size=SIZE, **kw).record(n_steps=90)


def test_a_matrix_in_the_preset_equal_to_the_chain_swims_the_same():
    own = replace(P, transition=tuple(map(tuple, P.transition_matrix())))
    np.testing.assert_array_equal(_swim(params=own).positions, _swim().positions)
    other = replace(P, transition=((1, 1, 1, 1),) * 4)
    assert not np.array_equal(_swim(params=other).mu, _swim().mu)


def test_mu_policy_drives_one_fish_and_leaves_the_others():
    ref = _swim()

    def policy(tank):
        mu = np.full(tank.n_fish, -1)
        mu[0] = 1  # fish 0 only coasts
        return mu

    got = _swim(mu_policy=policy)
    assert set((got.mu[1:, 0] % 4).tolist()) == {1}
    np.testing.assert_array_equal(got.positions[:, 1:], ref.positions[:, 1:])


def test_push_policy_sets_the_push_of_accelerating_fish():
    ref = _swim()

    def push(tank):
        out = np.full((tank.n_fish, 3), np.nan)
        out[2] = (0.03, 90.0, 90.0)  # straight ahead, the strongest push of the preset
        return out

    got = _swim(push_policy=push)
    assert not np.array_equal(got.positions[:, 2], ref.positions[:, 2])
    np.testing.assert_array_equal(got.positions[:, 0], ref.positions[:, 0])


def test_bad_policies_and_matrices_are_one_sentence():
    with pytest.raises(UserError, match="motion units"):
        fish.Tank(P, 2, size=SIZE, mu_policy=lambda t: [7, 7]).step(1)
    with pytest.raises(UserError, match=r"\(2, 3\)"):
        fish.Tank(P, 2, size=SIZE, push_policy=lambda t: np.zeros((2, 2))).step(1)
    with pytest.raises(UserError, match="4 x 4"):
        replace(P, transition=((1, 2), (3, 4)))
    with pytest.raises(UserError, match="4 x 4"):
        replace(P, transition=((1, -1, 0, 0),) * 4)
