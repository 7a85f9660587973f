"""The virtual aquarium's two rules, scripted through the stepper: a tap startles the fish near it away from
it; a pellet is found and eaten. Without taps or food the tank swims exactly as before."""

import numpy as np
import pytest

from lifelike_mj.errors import UserError
from lifelike_mj.fish import Tank
from lifelike_mj.fish.aquarium import EAT_RADIUS_M, FOOD_SINK_M_S, TAP_RADIUS_M, Aquarium


def test_without_taps_or_food_the_tank_swims_as_before():
    a, b = Aquarium(Tank(n_fish=10, seed=3)), Tank(n_fish=10, seed=3)
    a.step(120)
    b.step(120)
    assert np.array_equal(a.tank.snapshot()[0], b.snapshot()[0])


def test_a_tap_startles_the_fish_near_it_away_from_it():
    a, b = Aquarium(Tank(n_fish=10, seed=3)), Tank(n_fish=10, seed=3)
    a.step(120)
    b.step(120)
    pos, _ = a.tank.snapshot()
    tap = np.array([pos[0, 0], -a.tank.scene.size[1] / 2, pos[0, 2]])  # the front glass, level with fish 0
    near = np.linalg.norm(pos - tap, axis=1) <= TAP_RADIUS_M
    assert a.tap(tap) == near.sum() and 0 < near.sum() < 10
    assert np.array_equal(a.startled, near)
    a.step(int(round(0.5 / a.dt)))
    b.step(int(round(0.5 / b.dt)))
    assert not a.startled.any()  # a startle lasts STARTLE_S
    d0 = np.linalg.norm(pos - tap, axis=1)
    moved = np.linalg.norm(a.tank.snapshot()[0] - tap, axis=1) - d0
    calm = np.linalg.norm(b.snapshot()[0] - tap, axis=1) - d0
    assert np.all(moved[near] > 0.02)  # every startled fish fled
    assert moved[near].mean() > calm[near].mean() + 0.05  # much farther than it would have swum


def test_a_pellet_is_found_and_eaten_where_no_fish_would_have_passed():
    a, b = Aquarium(Tank(n_fish=10, seed=3)), Tank(n_fish=10, seed=3)
    a.step(60)
    b.step(60)
    x = float(np.clip(a.tank.snapshot()[0][:, 0].mean(), -2.0, 2.0))
    a.drop_food(x, 0.0)
    H = a.tank.scene.size[2]
    closest = np.inf  # the untouched tank's closest fish to where the pellet would have been
    for k in range(1, 601):
        a.step(1)
        b.step(1)
        pellet = np.array([x, 0.0, max(H - FOOD_SINK_M_S * k * b.dt, 0.0)])
        closest = min(closest, float(np.min(np.linalg.norm(b.snapshot()[0] - pellet, axis=1))))
    assert a.eaten == 1 and len(a.pellets_m) == 0
    assert closest > EAT_RADIUS_M


def test_taps_and_food_outside_the_tank_are_refused():
    a = Aquarium(Tank(n_fish=2, seed=0))
    with pytest.raises(UserError, match="a tap is a point"):
        a.tap([10.0, 0.0, 0.5])
    with pytest.raises(UserError, match="food's x"):
        a.drop_food(9.0, 0.0)
    with pytest.raises(UserError, match="without policies"):
        Aquarium(Tank(n_fish=2, seed=0, mu_policy=lambda t: np.full(2, -1)))
