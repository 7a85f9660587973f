"""The flock stepper: a script changes weights or adds agents between steps (boids/sim.py)."""

from __future__ import annotations

import numpy as np
import pytest

from lifelike_mj.boids import Flock, load_preset, simulate
from lifelike_mj.errors import Diverged, UserError


def test_record_is_simulate():
    p = load_preset("5a")
    ref = simulate(p, n=60, n_steps=40, seed=1, record_every=10)
    f = Flock(p, 60, 1)
    f.step(15)
    run = f.record(25, every=5)
    np.testing.assert_array_equal(run.positions[-1], ref.positions[-1])
    assert list(run.steps) == [15, 20, 25, 30, 35, 40]


def test_set_weights_changes_the_run_from_then_on():
    p = load_preset("5a")
    a, b = Flock(p, 60, 0), Flock(p, 60, 0)
    a.step(10)
    b.step(10)
    b.set_weights(wa=((0.5, -0.2), (-0.2, 0.5)))
    a.step(1)
    b.step(1)
    assert not np.array_equal(a.state()["velocity_box_per_step"], b.state()["velocity_box_per_step"])
    with pytest.raises(UserError, match="types"):
        b.set_weights(wa=((1.0,),), wc=((0.01,),))


def test_add_agents_joins_the_flock_and_the_scene():
    f = Flock(load_preset("4c"), 40, 0)
    f.step(5)
    f.add_agents([[10.0, 10.0, 10.0], [11.0, 10.0, 10.0]], types=[1, 1])
    assert f.n == 42
    f.step(5)
    f.sync()
    assert f.layout.n == 42 and np.all(np.isfinite(f.state()["position_box"]))
    with pytest.raises(UserError, match="inside the box"):
        f.add_agents([[30.0, 1.0, 1.0]])
    with pytest.raises(UserError, match="types"):
        f.add_agents([[1.0, 1.0, 1.0]], types=[5])


def test_divergence_is_an_error_naming_the_step():
    f = Flock(load_preset("5a"), 60, 0)
    f.set_weights(wa=((20.0, 20.0), (20.0, 20.0)))
    with pytest.raises(Diverged, match="too large") as info:
        f.step(200)
    assert info.value.step == f.steps
