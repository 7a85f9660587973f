"""Every creature's simulation has the one stepper shape (lifelike_mj/stepper.py)."""

from __future__ import annotations

import numpy as np
import pytest

from lifelike_mj import boids, butterfly, fish
from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d import garden
from lifelike_mj.stepper import Stepper

FACTORIES = {
    "flight-paper": lambda seed: butterfly.Flight("simple_rule"),
    "flight-mujoco": lambda seed: butterfly.Flight("ann_paper", backend="mujoco", config="rich"),
    "tank": lambda seed: fish.Tank(fish.load_preset("B-D"), n_fish=3, seed=seed, size=(1.0, 0.3, 0.5)),
    "flock": lambda seed: boids.Flock(boids.load_preset("4c"), n=40, seed=seed),
    "flight3d": lambda seed: flight3d.Flight3D(controller=flight3d.withdrawn_file("wind"), task=flight3d.course(seed)),
    "garden": lambda seed: flight3d.Garden(3, flight3d.withdrawn_file("steer"), seed=seed),
}
UNITS = {"flight-paper": butterfly.STATE_UNITS, "flight-mujoco": butterfly.STATE_UNITS, "tank": fish.STATE_UNITS,
         "flock": boids.STATE_UNITS, "flight3d": flight3d.STATE_UNITS, "garden": garden.STATE_UNITS}


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(np.array_equal(a[k], b[k]) for k in a)


@pytest.mark.parametrize("name", sorted(FACTORIES))
def test_stepper_shape(name):
    s = FACTORIES[name](3)
    assert isinstance(s, Stepper)
    start = s.state()
    assert set(start) == set(UNITS[name])
    s.step(2)
    s.step(3)
    assert s.steps == 5 and s.time == pytest.approx(5 * s.dt)
    moved = s.state()
    assert not _same(start, moved)
    s.sync()
    assert s.model is not None and s.data is not None
    s.reset()
    assert s.steps == 0 and _same(s.state(), start)
    s.step(5)
    assert _same(s.state(), moved)  # same seed, same run
    twin = FACTORIES[name](3)
    twin.step(5)
    assert _same(twin.state(), moved)


@pytest.mark.parametrize("name", ["tank", "flock"])
def test_a_new_seed_is_a_new_start(name):
    s = FACTORIES[name](3)
    a = s.state()
    s.reset(seed=4)
    assert not _same(a, s.state())
    s.reset(seed=3)
    assert _same(a, s.state())
