"""The boids engine (Nakamura 2013 eq. 1-9): the cell-list engine equals the plain all-pairs
reference, same seed same run, walls hold, divergence is an error, bad input is one sentence."""

from __future__ import annotations

import numpy as np
import pytest

from lifelike_mj.boids.engine import BoidParams, initial_state, parse_matrix, simulate, step_grid, step_reference
from lifelike_mj.boids.presets import PATTERNS, homogeneous, load_grid, load_preset
from lifelike_mj.errors import UserError


@pytest.mark.parametrize("dims", [3, 2])
def test_grid_engine_equals_all_pairs_reference_over_100_steps(dims):
    p = load_preset("4a", dims=dims)
    x, v, t = initial_state(p, 120, seed=3)
    x2, v2 = x.copy(), v.copy()
    worst = 0.0
    for _ in range(100):
        step_grid(x, v, t, p)
        step_reference(x2, v2, t, p)
        worst = max(worst, float(np.max(np.abs(x - x2))), float(np.max(np.abs(v - v2))))
    # the issue asks for 1e-12; both sum each force in ascending neighbour index, so they agree exactly
    assert worst == 0.0


@pytest.mark.parametrize("dims", [3, 2])
def test_sparse_path_equals_the_reference(dims):
    """Sparse cells (a few agents each) take the engine's other path (plain loops, separation summed
    in the same pass); it too equals the reference bit for bit."""
    from dataclasses import replace

    from lifelike_mj.boids import engine

    p = replace(load_preset("5a", dims=dims), box=34.0)
    x, v, t = initial_state(p, 400, seed=5)
    wa, wc, c = p.arrays()
    assert engine._prepare(engine._as3(x), engine._as3(v), t, wa, wc, c, dims == 2, 1)[0]  # the sparse path
    x2, v2 = x.copy(), v.copy()
    for _ in range(12):
        step_grid(x, v, t, p)
        step_reference(x2, v2, t, p)
    assert np.array_equal(x, x2) and np.array_equal(v, v2)


def test_three_types_and_walls_equal_the_reference():
    """k = 3 types, agents started near the walls (wall avoidance and reflection both act)."""
    p = BoidParams(wa=((0.5, 0.1, 0.0), (0.1, 0.5, 0.2), (0.0, 0.3, 0.5)),
                   wc=((0.01, 0.0, 0.02), (0.005, 0.01, 0.0), (0.0, 0.01, 0.03)))
    x, v, t = initial_state(p, 90, seed=1, margin=0.2)
    v *= 50.0  # fast enough to cross walls
    x2, v2 = x.copy(), v.copy()
    for _ in range(40):
        step_grid(x, v, t, p)
        step_reference(x2, v2, t, p)
    assert np.array_equal(x, x2) and np.array_equal(v, v2) and set(np.unique(t)) == {0, 1, 2}


@pytest.mark.parametrize("dims,box", [(3, 20.0), (2, 20.0), (3, 40.0)])
def test_result_does_not_depend_on_the_number_of_threads(monkeypatch, dims, box):
    """The parallel path (chunks on all threads) gives the serial path's run bit for bit (box 40: the
    sparse path)."""
    from dataclasses import replace

    from lifelike_mj.boids import engine

    p = replace(load_preset("5a", dims=dims), box=box)
    runs = []
    for parallel_from in (10**9, 0):
        monkeypatch.setattr(engine, "PARALLEL_FROM", parallel_from)
        x, v, t = initial_state(p, 400, seed=2)
        step_grid(x, v, t, p, 120)
        runs.append((x, v))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])


def test_same_seed_same_run_and_recording():
    p = load_preset("5a")
    a = simulate(p, 200, 300, seed=4, record_every=50)
    b = simulate(p, 200, 300, seed=4, record_every=100)
    c = simulate(p, 200, 300, seed=5, record_every=100)
    assert list(a.steps) == [0, 50, 100, 150, 200, 250, 300] and list(b.steps) == [0, 100, 200, 300]
    assert np.array_equal(a.positions[-1], b.positions[-1]) and np.array_equal(a.types, b.types)
    assert not np.array_equal(a.positions[-1], c.positions[-1])


@pytest.mark.parametrize("name", PATTERNS)
def test_no_agent_ever_leaves_the_box(name):
    p = load_preset(name)
    r = simulate(p, 300, 600, seed=0, record_every=1)
    assert np.all(r.positions >= 0.0) and np.all(r.positions <= p.box)


def test_agents_are_a_or_b_with_probability_one_half():
    _, _, t = initial_state(load_preset("4a"), 20000, seed=0)
    assert abs(t.mean() - 0.5) < 0.02


@pytest.mark.parametrize("w_a, w_c", [(10.0, 0.01), (0.1, 1.0), (1.0, 1.0)])
def test_divergence_is_a_clear_error(w_a, w_c):
    with pytest.raises(UserError, match="diverged"):
        simulate(homogeneous(w_a, w_c), 300, 3000, seed=0, record_every=3000)


def test_homogeneous_grid_is_the_papers():
    g = load_grid()
    assert g["w_a"] == [1.0, 0.1, 0.01, 0.001] and g["w_c"] == [0.1, 0.01, 0.001, 0.0]


@pytest.mark.parametrize("kw, match", [
    (dict(wa=((0.5, 0.1),), wc=((0.01, 0.0),)), "square"),
    (dict(wa=((0.5, 0.1), (0.1, 0.5)), wc=((0.01,),)), "must match"),
    (dict(r_s=3.0), "nest"),
    (dict(dims=4), "dims"),
])
def test_bad_parameters_are_one_sentence(kw, match):
    with pytest.raises(UserError, match=match):
        BoidParams(**kw)


def test_bad_counts_and_matrices():
    with pytest.raises(UserError, match="at least 2"):
        initial_state(BoidParams(), 1, 0)
    with pytest.raises(UserError):
        parse_matrix("0.5,0.1;0.2", "W_a")
    assert parse_matrix("0.5,0.1;0.2,0.3") == ((0.5, 0.1), (0.2, 0.3))
    with pytest.raises(UserError, match="unknown boids preset"):
        load_preset("6z")


def test_numpy_all_pairs_peer_is_the_same_model():
    """The benchmark's NumPy peer computes the model of eq. 1-9 (to rounding, one step)."""
    from lifelike_mj.boids.bench import numpy_all_pairs_step

    p = load_preset("4c")
    x, v, t = initial_state(p, 150, seed=2, margin=0.5)
    x2, v2 = x.copy(), v.copy()
    numpy_all_pairs_step(x, v, t, p)
    step_reference(x2, v2, t, p)
    assert np.max(np.abs(v - v2)) < 1e-14 and np.max(np.abs(x - x2)) < 1e-13
