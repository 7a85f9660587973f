"""The paper's patterns and Fig. 2's regimes, computed: every preset run at the classifier's full
length (n = 300, 10,000 steps, seed 0) and classified; the homogeneous grid likewise."""

import concurrent.futures
import multiprocessing

import pytest

from lifelike_mj.boids.presets import PATTERNS


def _label(name):
    from lifelike_mj.boids.experiments import classified_run
    from lifelike_mj.boids.presets import load_preset

    _, _, label, reasons = classified_run(load_preset(name), 300, 0)
    return name, label, bool(reasons.get("paper_picture"))


@pytest.fixture(scope="module")
def labels():
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        return {name: (label, pic) for name, label, pic in pool.map(_label, PATTERNS)}


def test_seven_of_the_eight_presets_make_their_own_pattern(labels):
    """Nakamura 2013 Fig. 4-5 at seed 0: every preset but 4d is classified as itself, in the paper's
    picture. 4d (one flock split into hemispheres, which the paper says needs fine tuning) comes out
    as 4a here (docs/results.md, the confusion table over seeds)."""
    for name in PATTERNS:
        label, picture = labels[name]
        if name == "4d":
            assert label == "4a"
        else:
            assert (label, picture) == (name, True), name


def test_fig2_regimes_of_one_type():
    """Fig. 2's grid at seed 0, classified into one type's regimes (docs/results.md)."""
    from lifelike_mj.boids.experiments import Sweep, run_sweep
    from lifelike_mj.boids.presets import homogeneous, load_grid

    g = load_grid()
    res = run_sweep(Sweep(homogeneous(1.0, 0.0), ("wa", "wc")), [g["w_a"], g["w_c"]], [0], executor="process",
                    workers=2)
    got = {(r["wa"], r["wc"]): r["label"] for r in res["rows"]}
    want = {}
    for wa in (1.0, 0.1, 0.01, 0.001):
        want[(wa, 0.0)] = "aligned lattice" if wa >= 0.1 else "spread"
        want[(wa, 0.001)] = "lattice" if wa >= 0.1 else "spread"
        want[(wa, 0.01)] = "swarm" if wa >= 0.01 else "spread"
        want[(wa, 0.1)] = "compact flock" if wa >= 0.01 else "spread"
    assert got == want
