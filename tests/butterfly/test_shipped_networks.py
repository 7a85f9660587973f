"""The shipped evolved controllers meet the issue's acceptance numbers (computed, not stored)."""

from __future__ import annotations

import numpy as np
import pytest

from lifelike_mj.butterfly import ann_experiments as ax
from lifelike_mj.butterfly import batch, controllers
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.evolution import make_problem
from lifelike_mj.butterfly.flight import Condition


@pytest.fixture(scope="module")
def ann_paper():
    return controllers.load("ann_paper")


@pytest.fixture(scope="module")
def ann_robust():
    return controllers.load("ann_robust")


def test_ann_paper_reproduces_its_recorded_fitness(ann_paper):
    prov = ann_paper.provenance
    assert prov["optimizer"] == "rcga" and prov["population"] == 40 and prov["generations_done"] == 1000
    prob = make_problem("paper")
    assert prov["problem_fingerprint"] == prob.fingerprint()
    assert prob.evaluate(ann_paper.weights[None])[0] == pytest.approx(prov["best_fitness"], rel=1e-12)


def test_ann_paper_level_flight_e6(ann_paper):
    s = ax.e6_level(ann_paper).numbers
    assert s["initial_drop_m"] <= 1.0
    assert -0.25 <= s["settled_altitude_min_m"] and s["settled_altitude_max_m"] <= 0.25
    assert s["settled_forward_speed_cm_s"] > 200.0


def test_ann_paper_from_plus_10m_descends_and_holds_e7(ann_paper):
    s = ax.e7_from_above(ann_paper).flights["+10 m"]
    assert s["holds_level"], s


def test_ann_paper_fails_from_minus_10m_like_the_paper_e9(ann_paper):
    assert not ax.e9_from_below(ann_paper, starts=(-10.0,)).flights["-10 m"]["reaches_target"]


def test_ann_paper_on_mujoco_matches_the_paper_backend(ann_paper):
    ref = paper.simulate(ann_paper)[0]
    mj = batch.simulate_mujoco(ann_paper)[0]
    assert np.max(np.abs(ref.y - mj.y)) < 0.02


def test_ann_robust_climbs_back_from_minus_10m(ann_robust):
    s = ax.e9_from_below(ann_robust, starts=(-10.0,)).flights["-10 m"]
    assert s["time_to_within_0_5m_s"] is not None and s["time_to_within_0_5m_s"] < 20.0
    assert s["reaches_target"]


def test_ann_robust_survives_the_tail_wind(ann_robust):
    tr = paper.simulate(ann_robust, conditions=Condition(0.0, (-2.0, 0.0)))[0]
    s = ax.flight_numbers(tr, 0.5)
    assert s["initial_drop_m"] <= 2.0 and s["holds_level"]


def test_ann_robust_holds_level_in_still_air(ann_robust):
    s = ax.e6_level(ann_robust).numbers
    assert s["holds_level"] and s["settled_forward_speed_cm_s"] > 200.0


def test_ann_robust_reproduces_its_recorded_fitness(ann_robust):
    prov = ann_robust.provenance
    assert prov["task"] == "robust_map" and prov["optimizer"] == "cmaes"
    prob = make_problem("robust_map")
    assert prov["problem_fingerprint"] == prob.fingerprint()
    assert prob.evaluate(ann_robust.weights[None])[0] == pytest.approx(prov["best_fitness"], rel=1e-12)


@pytest.mark.parametrize("inputs", ["relative", "ground"])
def test_ann_robust_passes_more_wind_cells(ann_paper, ann_robust, inputs):
    # E11 on a 0.25 m/s grid here (625 cells, to keep the suite fast); the 0.1 m/s map of the issue
    # (3721 cells) is in docs/results.md and `lifelike-mj butterfly assess --controller ann_robust`
    a = ax.e11_windmap(ann_paper, inputs, step_m_s=0.25)
    b = ax.e11_windmap(ann_robust, inputs, step_m_s=0.25)
    assert b.pass_cells > a.pass_cells


def test_e8_the_glide_sinks_at_its_closed_form_terminal_speed(ann_paper):
    """E8: gliding with the wings held at 75 deg and phi = 0, the wings meet the air edge-on (eq. 7:
    v' = -v_z sin(phi) = 0), so only the body's drag (eq. 10) holds the weight: the sink speed tends to
    v_t = sqrt(2 m g / (rho C_d A_b)) = 4.712 m/s."""
    import math

    from lifelike_mj.butterfly.params import ButterflyParams

    p = ButterflyParams()
    v_t = math.sqrt(2 * p.mass_kg * p.gravity / (p.rho * p.cd * p.body_area_m2))
    assert v_t == pytest.approx(4.712, abs=5e-4)
    e8 = ax.e8_glide(ann_paper)
    assert e8.max_sink_gliding_m_s <= v_t and e8.max_sink_gliding_m_s == pytest.approx(v_t, rel=1e-3)
    # the paper: the glide sinks about twice as fast as the network's descent; ours computes 0.79
    # (docs/results.md: our network descends at 5.9 m/s, it dives rather than flaps down)
    assert e8.ratio == pytest.approx(0.793, abs=0.005)


def test_e10_the_winds_as_computed(ann_paper):
    """E10 (Fig. 14, 15), computed: each flight's end altitude (m) in the four 2 m/s winds, both input
    readings. Paper: relative inputs hold in a head wind and level at an offset from above and below;
    a tail wind crashes. Ours, pinned at what the code computes (docs/results.md says where it differs)."""
    e10 = ax.e10_winds(ann_paper)
    final = {(k, w): v["final_altitude_m"] for k, d in e10.flights.items() for w, v in d.items()}
    want = {("relative", "front (2,0)"): 0.0002, ("relative", "above (0,2)"): -3.377,
            ("relative", "behind (-2,0)"): 0.0002, ("relative", "below (0,-2)"): -51.789,
            ("ground", "front (2,0)"): -0.584, ("ground", "above (0,2)"): -0.120,
            ("ground", "behind (-2,0)"): -1.371, ("ground", "below (0,-2)"): 0.081}
    assert set(final) == set(want)
    for key, value in want.items():
        assert final[key] == pytest.approx(value, abs=0.002), key
    # the levelled flights have settled; the one from below falls all the way
    rates = {(k, w): v["settled_climb_rate_cm_s"] for k, d in e10.flights.items() for w, v in d.items()}
    assert abs(rates[("relative", "above (0,2)")]) < 5 and rates[("relative", "below (0,-2)")] < -100
