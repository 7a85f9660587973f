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


def test_the_viewers_key_for_5b_shows_it_only_after_a_fresh_start():
    """docs/models/boids.md's table of what the viewer's keys show (benchmarks/viewer_patterns.py, seeds 20-39),
    recomputed for one entry: the viewer's flock (5a for 1,500 steps) given 5b's weights at seed 22 forms 4d's
    picture, and 5b's own once scattered afresh (the Enter key); the benchmark's file holds the same labels."""
    import importlib.util
    import json
    from pathlib import Path

    bench = Path(__file__).resolve().parents[2] / "benchmarks"
    spec = importlib.util.spec_from_file_location("viewer_patterns", bench / "viewer_patterns.py")
    vp = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(vp)
    table = json.loads((bench / "results" / "viewer_patterns.json").read_text())
    i = table["seeds"].index(22)
    got = (vp.switched("5b", 22, 1500), vp.switched("5b", 22, 1500, scatter=True))
    assert got == ("4d", "5b") == (table["patterns"]["5b"]["viewer_labels"][i], table["patterns"]["5b"]["enter_labels"][i])
