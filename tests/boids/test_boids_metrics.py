"""Measures of heterogeneous boids and the pattern classifier (spec/boids.md section 3): synthetic
configurations with known answers, the classifier's rules at both sides of each threshold, and one
short real run."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lifelike_mj.boids import metrics as M


def ball(rng, n, radius, centre=(10.0, 10.0, 10.0)):
    """``n`` points uniform in a ball."""
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = radius * rng.uniform(size=n) ** (1 / 3)
    return np.asarray(centre) + d * r[:, None]


def shell(rng, n, r0, r1, centre=(10.0, 10.0, 10.0)):
    """``n`` points uniform in the shell ``r0 < r < r1``."""
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    r = (r0 ** 3 + (r1 ** 3 - r0 ** 3) * rng.uniform(size=n)) ** (1 / 3)
    return np.asarray(centre) + d * r[:, None]


def random_v(rng, n, speed=0.05):
    return speed * rng.normal(size=(n, 3))


@pytest.fixture
def rng():
    return np.random.default_rng(7)


# ---- neighbour search ------------------------------------------------------------------------------


def test_knn_pairs_and_components_match_brute_force(rng):
    x = rng.uniform(0, 10, size=(230, 3))
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    np.fill_diagonal(d, np.inf)
    idx, dist = M.knn(x, 6)
    assert np.allclose(np.sort(dist, axis=1), np.sort(d, axis=1)[:, :6])
    assert np.allclose(np.sort(d[np.arange(230)[:, None], idx], axis=1), np.sort(d, axis=1)[:, :6])
    i, j = M.pairs_within(x, 1.3)
    want = {(a, b) for a, b in zip(*np.nonzero(d < 1.3)) if a < b}
    assert set(zip(i.tolist(), j.tolist())) == want
    # components: a chain 0-1-2, a pair 3-4, a single 5
    lab = M.components(6, np.array([1, 0, 4]), np.array([2, 1, 3]))
    assert lab.tolist() == [0, 0, 0, 3, 3, 5]


# ---- synthetic configurations ----------------------------------------------------------------------


def test_two_separated_blobs_are_segregated_into_two_groups(rng):
    x = np.concatenate([ball(rng, 150, 2.0, (5, 10, 10)), ball(rng, 150, 2.0, (15, 10, 10))])
    t = np.repeat([0, 1], 150)
    m = M.frame_measures(x, random_v(rng, 300), t)
    assert m["segregation_index"] > 0.99
    assert m["contact_ratio"] == 0.0
    assert m["n_groups"] == 2 and m["n_groups_0"] == 1 and m["n_groups_1"] == 1
    assert m["plane_split"] == 1.0
    assert m["centroid_distance"] == pytest.approx(10.0, abs=0.5)
    assert m["centroid_distance_rel"] > 1.8


def test_random_mix_is_not_segregated(rng):
    x = ball(rng, 300, 3.0)
    t = rng.integers(0, 2, size=300)
    m = M.frame_measures(x, random_v(rng, 300), t)
    assert abs(m["segregation_index"]) < 0.1
    assert m["contact_ratio"] == pytest.approx(1.0, abs=0.1)
    assert m["plane_split"] < 0.65
    assert m["n_groups"] == 1
    assert m["radial_sorting_error"] > 0.7 and m["radius_ratio"] > 0.9


def test_segregation_index_is_zero_for_the_random_expectation_with_unequal_types(rng):
    """With 3 types in proportions 1:2:3, the expected same-type fraction E is the random-mix
    baseline, so a shuffle of a segregated configuration gives ~0 whatever the proportions."""
    x = ball(rng, 600, 4.0)
    t = np.repeat([0, 1, 2], [100, 200, 300])
    E = (100 * 99 + 200 * 199 + 300 * 299) / (600 * 599)
    shuffled = M.frame_measures(x, random_v(rng, 600), rng.permutation(t))
    assert shuffled["same_type_expected"] == pytest.approx(E)
    assert abs(shuffled["segregation_index"]) < 0.08
    sorted_by_x = t[np.argsort(np.argsort(x[:, 0]))]  # slabs along x: segregated
    assert M.frame_measures(x, random_v(rng, 600), sorted_by_x)["segregation_index"] > 0.75


def test_shell_around_core_has_small_radial_sorting_error_and_clear_radius_ratio(rng):
    x = np.concatenate([ball(rng, 150, 2.0), shell(rng, 150, 2.4, 3.2)])
    t = np.repeat([0, 1], 150)
    m = M.frame_measures(x, random_v(rng, 300), t)
    assert m["radial_sorting_error"] == 0.0
    assert m["radius_ratio"] < 0.7
    assert m["inner_type"] == 0
    assert m["centroid_distance"] < 0.5
    swapped = M.frame_measures(x, random_v(rng, 300), 1 - t)  # the other type inside
    assert swapped["inner_type"] == 1 and swapped["radius_ratio"] == pytest.approx(m["radius_ratio"])


def test_hemispheres_of_one_sphere_split_by_a_plane_with_close_centroids(rng):
    x = ball(rng, 300, 3.0)
    t = (x[:, 2] < 10.0).astype(int)
    m = M.frame_measures(x, random_v(rng, 300), t)
    assert m["plane_split"] > 0.95  # the plane goes through the sample's centroid, not exactly z = 10
    assert m["centroid_distance_rel"] < 1.1  # 3R/4 over sqrt(3/5) R = 0.97 for a full ball
    assert m["elongation"] < 1.3  # the whole is round
    assert m["radial_sorting_error"] > 0.7
    # two touching balls: as well split, but the centroids are farther apart and the whole is long
    x2 = np.concatenate([ball(rng, 150, 2.4, (7.6, 10, 10)), ball(rng, 150, 2.4, (12.4, 10, 10))])
    m2 = M.frame_measures(x2, random_v(rng, 300), np.repeat([0, 1], 150))
    assert m2["plane_split"] > 0.98 and m2["centroid_distance_rel"] > 1.4 and m2["elongation"] > 1.6


def test_plane_split_finds_a_tilted_plane(rng):
    x = ball(rng, 400, 3.0)
    normal = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    t = ((x - 10.0) @ normal > 0).astype(int)
    assert M.frame_measures(x, random_v(rng, 400), t)["plane_split"] > 0.95


def test_polarisation_aligned_random_and_opposite(rng):
    x = ball(rng, 300, 3.0)
    t = np.repeat([0, 1], 150)
    v = np.tile([0.03, 0.04, 0.0], (300, 1)) * rng.uniform(0.5, 2.0, size=(300, 1))
    m = M.frame_measures(x, v, t)
    assert m["polarisation"] == pytest.approx(1.0) and m["polarisation_0"] == pytest.approx(1.0)
    assert m["heading_cos"] == pytest.approx(1.0)
    assert m["contact_alignment_same"] == pytest.approx(1.0)
    mr = M.frame_measures(x, random_v(rng, 300), t)
    assert mr["polarisation"] < 0.15 and abs(mr["contact_alignment_same"]) < 0.1
    v2 = v.copy()
    v2[t == 1] *= -1
    mo = M.frame_measures(x, v2, t)
    assert mo["heading_cos"] == pytest.approx(-1.0) and mo["polarisation"] < 0.2
    assert mo["speed"] == pytest.approx(float(np.linalg.norm(v, axis=1).mean()))


def test_radial_sorting_error_is_twice_the_mann_whitney_overlap():
    ra = np.array([1.0, 2.0, 3.0])
    rb = np.array([2.5, 4.0])
    # pairs (a, b) with r_b > r_a: 5 of 6 -> P = 5/6, error = 2 * 1/6
    assert M._radial_sorting_error(ra, rb) == pytest.approx(1 / 3)
    assert M._radial_sorting_error(rb, ra) == pytest.approx(1 / 3)
    assert M._radial_sorting_error(np.array([1.0, 1.0]), np.array([1.0])) == pytest.approx(1.0)  # ties: no order


def test_groups_ignore_small_stragglers_and_count_per_type(rng):
    x = np.concatenate([ball(rng, 140, 2.0, (5, 10, 10)), ball(rng, 140, 2.0, (15, 10, 10)),
                        np.array([[10.0, 2.0, 2.0], [10.0, 18.0, 18.0]])])
    t = np.concatenate([np.repeat([0, 1], 70), np.repeat([0, 1], 70), [0, 1]])  # both blobs mixed
    m = M.frame_measures(x, random_v(rng, 282), t)
    assert m["n_groups"] == 2  # the two stragglers are below 5 % of the agents
    assert m["n_groups_0"] == 2 and m["n_groups_1"] == 2
    assert m["largest_group_fraction"] == pytest.approx(140 / 282)


def test_wall_fraction(rng):
    x = ball(rng, 100, 3.0)
    x[:10, 0] = 0.5  # within R_s = 1 of the wall x = 0
    assert M.frame_measures(x, random_v(rng, 100), np.repeat([0, 1], 50))["wall_fraction"] == pytest.approx(0.1)


def test_one_type_only_gives_undefined_mixing_measures_as_none(rng):
    x = ball(rng, 50, 2.0)
    m = M.measures_from_frames(x[None], random_v(rng, 50)[None], np.zeros(50, dtype=int))
    assert m["segregation_index"] is None and m["plane_split"] is None and m["n_groups"] == 1
    json.dumps(m, allow_nan=False)


# ---- the classifier: each rule at both sides of its threshold ----------------------------------------

EPS = 1e-3
#: Typical averaged measures of each pattern (values the presets reach at n = 300).
TYPICAL = {
    "4a": dict(segregation_index=0.87, contact_ratio=0.28, radial_sorting_error=0.9, radius_ratio=0.95,
               nn_distance=0.975, n_groups=1, speed=0.05, elongation=1.55, centroid_distance_rel=1.26),
    "4b": dict(segregation_index=0.89, contact_ratio=0.27, radial_sorting_error=0.95, radius_ratio=0.98,
               nn_distance=0.92, n_groups=1, speed=0.10, elongation=1.46, centroid_distance_rel=1.21),
    "4c": dict(segregation_index=0.61, contact_ratio=0.63, radial_sorting_error=0.0, radius_ratio=0.59,
               nn_distance=0.65, n_groups=1, speed=0.095, elongation=1.07, centroid_distance_rel=0.01, inner_type=0),
    "4d": dict(segregation_index=0.15, contact_ratio=0.97, radial_sorting_error=0.95, radius_ratio=0.98,
               nn_distance=0.94, n_groups=1, speed=0.064, elongation=1.05, centroid_distance_rel=0.2),
    "5a": dict(segregation_index=0.0, contact_ratio=1.0, radial_sorting_error=0.97, radius_ratio=0.98,
               nn_distance=0.95, n_groups=1, speed=0.054, elongation=1.04, centroid_distance_rel=0.1),
    "5b": dict(segregation_index=0.95, contact_ratio=0.05, radial_sorting_error=0.6, radius_ratio=0.9,
               nn_distance=0.8, n_groups=2, speed=0.4, elongation=7.0, centroid_distance_rel=1.8),
    "5c": dict(segregation_index=1.0, contact_ratio=0.0, radial_sorting_error=0.7, radius_ratio=0.88,
               nn_distance=0.97, n_groups=2, speed=0.053, elongation=4.4, centroid_distance_rel=1.85),
    "5d": dict(segregation_index=0.69, contact_ratio=0.23, radial_sorting_error=0.87, radius_ratio=0.92,
               nn_distance=1.32, n_groups=1, speed=0.06, elongation=1.54, centroid_distance_rel=0.96),
}


@pytest.mark.parametrize("label", sorted(TYPICAL))
def test_typical_measures_get_their_label(label):
    got, reasons = M.classify(TYPICAL[label])
    assert got == label, reasons
    assert reasons["tests"] and all(len(x) == 5 for x in reasons["tests"])
    json.dumps(reasons)


# (start from, measure, threshold, label at threshold + EPS, label at threshold - EPS, other changes)
FLIPS = [
    ("4b", "speed", M.FAST_SPEED, "5b", "4b", {}),
    ("4c", "radial_sorting_error", M.SHELL_SORTING_ERROR, "5b", "4c", {}),
    ("4c", "radius_ratio", M.SHELL_RADIUS_RATIO, "5b", "4c", {}),
    ("4c", "centroid_distance_rel", M.SHELL_CENTROID_REL, "5b", "4c", {}),
    ("5c", "centroid_distance_rel", M.SHELL_CENTROID_REL, "5c", "4c", {"radial_sorting_error": 0.03, "radius_ratio": 0.67}),
    ("5c", "contact_ratio", M.SEPARATE_CONTACT_RATIO, "other", "5c", {}),
    ("5c", "segregation_index", M.SEPARATE_SEGREGATION, "5c", "other", {}),
    ("5c", "contact_ratio", M.SEPARATE_CONTACT_RATIO, "4a", "5c", {"n_groups": 1}),
    ("5d", "nn_distance", M.LOOSE_NN_DISTANCE, "5d", "5b", {}),
    ("5d", "segregation_index", M.HALF_SEGREGATED, "5d", "other", {}),
    ("4a", "segregation_index", M.SEGREGATED, "4a", "5b", {"speed": 0.06}),
    ("4b", "segregation_index", M.SEGREGATED, "4b", "5b", {}),
    ("4a", "speed", M.SWARM_SPEED, "4b", "4a", {}),
    ("4a", "elongation", M.ROUND_ELONGATION, "4a", "4d", {"centroid_distance_rel": 1.0}),
    ("4a", "centroid_distance_rel", M.HEMISPHERE_CENTROID_REL, "4a", "4d", {"elongation": 1.1}),
    ("4d", "speed", M.AGITATED_SPEED, "4d", "4a", {}),
    ("4d", "segregation_index", M.PARTLY_SEGREGATED, "4d", "5a", {}),
    ("4d", "segregation_index", M.HALF_SEGREGATED, "5b", "4d", {}),
    ("5a", "segregation_index", M.PARTLY_SEGREGATED, "4a", "5a", {}),
    ("5a", "speed", M.AGITATED_SPEED, "5a", "5a", {}),  # a mix is a mix, agitated or not
]


@pytest.mark.parametrize("start, key, thr, above, below, extra", FLIPS,
                         ids=[f"{f[0]}-{f[1]}-{f[3]}-{f[4]}" for f in FLIPS])
def test_classifier_threshold_sides(start, key, thr, above, below, extra):
    m = {**TYPICAL[start], **extra}
    hi, r_hi = M.classify({**m, key: thr + EPS})
    lo, r_lo = M.classify({**m, key: thr - EPS})
    assert (hi, lo) == (above, below), (r_hi, r_lo)
    assert any(x[0] == key for x in r_hi["tests"])  # the measure is among the reasons


def test_classifier_several_groups_not_sorted_by_type_is_other():
    m = {**TYPICAL["5a"], "n_groups": 2}
    assert M.classify(m)[0] == "other"
    assert M.classify({**m, "n_groups": 1})[0] == "5a"


def test_classifier_without_two_types_is_other():
    label, reasons = M.classify({**TYPICAL["5a"], "segregation_index": None})
    assert label == "other" and reasons["rule"] == "0"


def test_classifier_marks_kinematic_decisions():
    """Labels decided by agitation rather than shape say so (paper_picture False)."""
    assert M.classify(TYPICAL["4d"])[1]["paper_picture"] is False
    assert M.classify(TYPICAL["5c"])[1]["paper_picture"] is True


def test_window_frames_and_majority():
    steps = np.arange(0, 1001, 20)
    sel = M.window_frames(steps, 200)
    assert steps[sel].tolist() == list(range(820, 1001, 20))
    assert len(M.window_frames(steps, None)) == len(steps)
    assert M._majority(np.array([1, 2, 2, 1, 3])) == 1  # a tie goes to the smaller count


# ---- one short real run ------------------------------------------------------------------------------


def test_short_real_run_of_5a_is_a_mixed_flock():
    """Preset 5a (the mixed flock settles within ~500 steps): 1500 steps of 300 agents, measures over
    the last 1000 steps."""
    from lifelike_mj.boids.presets import load_preset
    from lifelike_mj.boids.sim import simulate

    run = simulate(load_preset("5a"), n=300, n_steps=1500, seed=3, record_every=25, record_from=500)
    m = M.measures(run, window=1000)
    json.dumps(m, allow_nan=False)
    assert m["n_frames"] == 40 and m["window_steps"] == [525, 1500]
    assert abs(m["segregation_index"]) < M.PARTLY_SEGREGATED
    assert m["n_groups"] == 1 and m["nn_distance"] < 1.1
    label, reasons = M.classify(m)
    assert label == "5a", reasons


def test_measures_work_in_2d(rng):
    """The paper's 2D check: the same measures on (n, 2) positions."""
    x = np.concatenate([rng.uniform([4, 8], [8, 12], size=(100, 2)), rng.uniform([14, 8], [18, 12], size=(100, 2))])
    m = M.frame_measures(x, rng.normal(size=(200, 2)), np.repeat([0, 1], 100))
    assert m["segregation_index"] > 0.99 and m["n_groups"] == 2 and m["plane_split"] == 1.0
    assert m["elongation"] > 2.0


@pytest.mark.parametrize("dims", [3, 2])
def test_the_tree_finds_the_neighbours_the_all_pairs_path_finds(dims, monkeypatch, rng):
    """Above DENSE_MAX agents the measures search a k-d tree; on the same positions (clumped, with twins at one point)
    it finds the same k nearest neighbours, distances and pairs within a radius as the all-pairs path, in the same
    order; and without ties, every measure of a frame agrees to rounding."""
    x = np.concatenate([rng.uniform(0, 20, size=(3000, dims)), rng.normal(10, 0.3, size=(2000, dims))])
    x[4000:4003] = x[4003]  # four agents at one point
    v, types = rng.normal(size=x.shape), rng.integers(0, 2, len(x))
    monkeypatch.setattr(M, "DENSE_MAX", 100)
    i_tree, d_tree = M.knn(x, 7)
    p_tree = M.pairs_within(x, 1.0)
    monkeypatch.setattr(M, "DENSE_MAX", 10**9)
    i_all, d_all = M.knn(x, 7)
    p_all = M.pairs_within(x, 1.0)
    np.testing.assert_allclose(np.sort(d_tree, axis=1), np.sort(d_all, axis=1), atol=1e-9)
    far = np.sort(d_all, axis=1)
    unique = far[:, -1] < np.partition(np.sqrt(((x[:, None] - x[None]) ** 2).sum(-1))[:, :], 8, axis=1)[:, 8] - 1e-9
    assert np.array_equal(np.sort(i_tree, axis=1)[unique], np.sort(i_all, axis=1)[unique])  # no tie at the k-th
    assert len(p_tree[0]) > 1000 and all(np.array_equal(a, b) for a, b in zip(p_tree, p_all))
    x[4000:4003] += 1e-6 * rng.normal(size=(3, dims))  # no ties among neighbours: either would be a k-th one
    m_tree = M.frame_measures(x, v, types)
    monkeypatch.setattr(M, "DENSE_MAX", 100)
    m_all, m_tree = m_tree, M.frame_measures(x, v, types)
    assert m_tree.keys() == m_all.keys()
    for k in m_all:
        assert m_tree[k] == pytest.approx(m_all[k], rel=1e-9, abs=1e-12, nan_ok=True), k
