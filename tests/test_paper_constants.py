"""The papers' constants, written out here from the papers (not read from the modules that define
them), and the "which reading" choices that a formula test cannot see: a changed constant or a
swapped reading must fail here."""

import math

import numpy as np
import pytest

# ---- Oe 2010 (butterfly) -----------------------------------------------------------------------


def test_butterfly_constants_are_the_papers():
    from lifelike_mj.butterfly.params import ButterflyParams

    p = ButterflyParams()
    assert p.mass_kg == 0.319e-3  # section 4.2: m = 0.319 g (a swallowtail)
    assert p.span_m == 0.055 and p.width_m == 0.050  # section 4.3: L = 5.5 cm, W = 5.0 cm
    assert p.rho == 1.28 and p.cd == 2.2  # section 3: air at about 5 deg C, C_d = 2.2
    assert p.gravity == 9.8


def test_the_papers_flight_settings():
    from lifelike_mj.butterfly import controllers
    from lifelike_mj.butterfly.experiments import E5_STEPS_PER_S

    rule = controllers.load("simple_rule")
    assert rule.flap.frequency_hz == 10.0  # section 5: f = 10 Hz
    assert (rule.flap.theta_min_deg, rule.flap.theta_max_deg) == (-90.0, 90.0)
    assert rule.parameters == {"phi_up_deg": 12.77, "phi_down_deg": 0.0}  # section 5.1: the level angle
    assert E5_STEPS_PER_S == {"1/12000": 12000, "1/1200": 1200, "1/360": 360, "1/120": 120}  # Fig. 5


def test_the_papers_ga():
    """Oe 2010 section 6.2: N = 40, BLX-alpha with alpha = 0.45, mutation x U[-2, 2] with probability 0.01."""
    from lifelike_mj.evolve import rcga

    assert rcga.DEFAULT_POPULATION == 40
    assert rcga.ALPHA == 0.45 and rcga.MUTATION_RATE == 0.01 and rcga.MUTATION_SCALE == 2.0
    rng = np.random.default_rng(0)
    # crossover with its default alpha: children of (0, 1) fill U[-0.45, 1.45]
    Q = np.array([[0.0], [0.0], [1.0]] * 1 + [[0.0], [1.0]] * 2000)
    C, pairs = rcga.crossover(Q, rng)
    kids = C[1:, 0]
    assert kids.min() == pytest.approx(-0.45, abs=0.01) and kids.max() == pytest.approx(1.45, abs=0.01)
    # mutation with its default scale and rate: factors fill U[-2, 2] on about 1 % of the genes
    ones = np.ones((20001, 50))
    M, mask = rcga.mutate(ones, rng)
    assert mask.mean() == pytest.approx(0.01, rel=0.05)
    f = M[mask]
    assert f.min() == pytest.approx(-2.0, abs=0.01) and f.max() == pytest.approx(2.0, abs=0.01)


@pytest.mark.parametrize("inputs", ["relative", "ground"])
def test_network_inputs_in_a_known_wind_by_hand(inputs):
    """Section 7.2: the network sees velocities relative to the air or to the ground. In a wind from the
    front of 2 m/s (the air moves at -2 m/s forward) a butterfly flying at 3 m/s forward and 0.5 m/s up
    reads 5 m/s (air) or 3 m/s (ground) forward."""
    from lifelike_mj.butterfly import ann, controllers

    c = controllers.load("ann_paper").with_inputs(inputs)
    s = c.input_scale()
    _, cp = c.compiled()
    theta, omega, y, vy, vz, phi_prev = 0.3, 5.0, -0.2, 0.5, 3.0, 0.1
    air_y, air_z = 0.0, -2.0  # Condition(0, (2, 0)).air_velocity() in (up, forward)
    got = ann.scaled_inputs.py_func(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev)
    rel_vy, rel_vz = (vy - air_y, vz - air_z) if inputs == "relative" else (vy, vz)
    want = (phi_prev / math.radians(s["phi_deg"]), omega / s["omega_rad_s"],
            (theta - math.radians(s["theta_center_deg"])) / math.radians(s["theta_half_range_deg"]),
            rel_vy / s["vy_m_s"], y / s["y_m"], rel_vz / s["vz_m_s"])
    np.testing.assert_allclose(got, want, rtol=1e-15)
    assert (rel_vz == 5.0) == (inputs == "relative")
    from lifelike_mj.butterfly.flight import Condition

    assert Condition(0.0, (2.0, 0.0)).air_velocity() == (-2.0, 0.0)  # (forward, up): from the front


# ---- Nakamura 2013 (boids) ---------------------------------------------------------------------


def test_boids_constants_are_the_papers():
    from lifelike_mj.boids.engine import BoidParams

    p = BoidParams(wa=((0.5,),), wc=((0.01,),))
    assert (p.r_s, p.r_a, p.r_c) == (1.0, 2.5, 4.5)  # section 2: zone radii
    assert p.w_s == 0.05  # section 2: separation weight
    assert p.box == 20.0 and p.dt == 1.0
    from lifelike_mj.boids.engine import N_AGENTS

    assert N_AGENTS == 300


@pytest.mark.parametrize("name, wa, wc", [  # Nakamura 2013 Fig. 4-5 (section 3.2)
    ("4a", [[0.5, 0.01], [0.01, 0.5]], [[0.01, 0.001], [0.001, 0.01]]),
    ("4b", [[0.0, 0.5], [0.5, 0.0]], [[0.01, 0.0], [0.0, 0.01]]),
    ("4c", [[0.5, 0.0], [0.0, 0.5]], [[0.01, 0.1], [0.01, 0.01]]),
    ("4d", [[0.5, -0.15], [-0.15, 0.5]], [[0.01, 0.01], [0.01, 0.01]]),
    ("5a", [[0.5, 0.5], [0.5, 0.5]], [[0.01, 0.01], [0.01, 0.01]]),
    ("5b", [[0.5, -0.2], [-0.2, 0.5]], [[0.01, 0.01], [0.01, 0.01]]),
    ("5c", [[0.5, 0.5], [0.5, 0.5]], [[0.01, -0.005], [-0.005, 0.01]]),
    ("5d", [[0.01, 0.0], [0.0, 0.01]], [[0.001, 0.0], [0.0, 0.001]]),
])
def test_boids_presets_are_the_papers(name, wa, wc):
    from lifelike_mj.boids.presets import load_preset

    p = load_preset(name)
    assert [list(r) for r in p.wa] == wa and [list(r) for r in p.wc] == wc


# ---- Satoi 2015 (fish) -------------------------------------------------------------------------


def test_fish_control_rate_is_the_papers():
    from lifelike_mj.fish.params import FishParams

    assert FishParams().control_hz == 60.0  # section 5: 60 frames per second
