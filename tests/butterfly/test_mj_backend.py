"""MuJoCo backend: compiled callback equals its Python twin; agreement with the paper backend."""

import numpy as np
import pytest

from lifelike_mj.butterfly import batch, controllers
from lifelike_mj.butterfly.backends import mj as mjbackend
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.compare import compare
from lifelike_mj.butterfly.flight import Condition
from lifelike_mj.physics import mjabi


@pytest.fixture(scope="module")
def rule():
    return controllers.load("simple_rule")


def test_data_offsets_verified_against_bindings():
    m = mjbackend.build_model()
    d = mjbackend.setup_data(m, controllers.load("simple_rule"))
    mjabi.verify_offsets(d)  # raises on any mismatch
    assert mjabi.data_offsets()["qvel"] == mjabi.data_offsets()["qpos"] + 8


# the paper's whole 20 s flight for the tip formula; 5 s for the strip integration, whose Python reference costs
# the suite about 2 s per simulated second
@pytest.mark.parametrize("config,mode,duration", [("paper", "tip", 20.0), ("rich", "strip", 5.0)])
def test_compiled_callback_equals_python_reference_on_full_flight(rule, config, mode, duration):
    fast = batch.simulate_mujoco(rule, duration_s=duration, config=config, force_mode=mode)[0]
    ref = batch.simulate_mujoco(rule, duration_s=duration, config=config, force_mode=mode, callback="python")[0]
    assert fast.finite and ref.finite
    for name in ("y", "z", "vy", "vz", "phi", "theta"):
        np.testing.assert_allclose(getattr(fast, name), getattr(ref, name), rtol=0, atol=1e-12, err_msg=name)


def test_paper_equivalent_model_matches_paper_backend_at_level_angle(rule):
    r = compare(rule, "paper")
    assert r.max_altitude_excursion_m > 1.0
    assert r.max_altitude_diff_m < max(0.01 * r.max_altitude_excursion_m, 0.02)
    assert r.max_forward_diff_m < 0.02


def test_wind_and_start_altitude_agree_between_backends(rule):
    cond = Condition(3.0, (1.0, 0.5))
    a = paper.simulate(rule, conditions=cond, duration_s=3.0)[0]
    b = batch.simulate_mujoco(rule, conditions=cond, duration_s=3.0)[0]
    assert b.y[0] == pytest.approx(3.0)
    dy, dz = a.max_difference(b)
    assert dy < 2e-3 and dz < 2e-3


def test_wings_follow_flap_pattern(rule):
    tr = batch.simulate_mujoco(rule, duration_s=1.0)[0]
    np.testing.assert_allclose(tr.theta, rule.flap.theta(tr.t), atol=1e-5)  # 1e-5 rad = 0.0006 deg


def test_strip_mode_differs_from_tip_formula(rule):
    tip = batch.simulate_mujoco(rule, duration_s=5.0, force_mode="tip")[0]
    strip = batch.simulate_mujoco(rule, duration_s=5.0, force_mode="strip")[0]
    assert abs(tip.y[-1] - strip.y[-1]) > 0.05  # the paper's simplifications of eq. 7 matter


def test_callback_is_restored_after_flight(rule):
    import mujoco

    before = mujoco.get_mjcb_passive()
    batch.simulate_mujoco(rule, duration_s=0.01)
    assert mujoco.get_mjcb_passive() is before


def test_rich_model_pitch_servo_tracks_command(rule):
    tr = batch.simulate_mujoco(rule, duration_s=2.0, config="rich", force_mode="strip")[0]
    assert np.degrees(np.nanmax(tr.phi)) == pytest.approx(12.77, abs=1.0)
    assert np.degrees(np.nanmin(tr.phi)) > -2.0
