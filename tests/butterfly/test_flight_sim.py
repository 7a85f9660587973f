"""The butterfly's stepper (butterfly/sim.py): chunks, pitch laws of your own, networks of any shape."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numba import njit

from lifelike_mj import butterfly
from lifelike_mj.butterfly import ann, batch, controllers
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.flight import Condition
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.butterfly.sim import STATE_UNITS, Flight
from lifelike_mj.errors import Diverged, UserError

RULE = controllers.load("simple_rule")
UP, DOWN = np.radians([RULE.parameters["phi_up_deg"], RULE.parameters["phi_down_deg"]])


def py_rule(obs):
    """The simple rule of Oe 2010 section 5.1, written by a user."""
    return UP if obs.omega_rad_s > 1e-9 else DOWN


@njit
def nb_rule(obs):
    return UP if obs.omega_rad_s > 1e-9 else DOWN


def _reference(backend: str, duration_s: float, cond=None):
    if backend == "paper":
        return paper.simulate(RULE, conditions=cond, duration_s=duration_s)[0]
    return batch.simulate_mujoco(RULE, conditions=cond, duration_s=duration_s)[0]


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_record_in_chunks_is_the_batch_flight(backend):
    cond = Condition(2.0, (1.0, 0.5))
    ref = _reference(backend, 1.0, cond)
    f = Flight(RULE, condition=cond, backend=backend)
    f.step(1)
    f.step(299)
    part = f.record(n_steps=900)
    assert f.steps == 1200 and f.time == pytest.approx(1.0)
    for k in ("y", "z", "vy", "vz", "phi"):
        np.testing.assert_array_equal(getattr(part, k), getattr(ref, k)[300:], err_msg=k)
    assert part.fitness == ref.fitness


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
@pytest.mark.parametrize("law", [py_rule, nb_rule], ids=["python", "numba"])
def test_own_simple_rule_flies_the_built_in_one(backend, law):
    ref = _reference(backend, 2.0)
    got = Flight(RULE, backend=backend, pitch_law=law).record(duration_s=2.0)
    for k in ("y", "z", "vy", "vz", "phi"):
        np.testing.assert_allclose(getattr(got, k), getattr(ref, k), rtol=0, atol=1e-12, err_msg=k)
    assert got.fitness == pytest.approx(ref.fitness, rel=1e-12)


def test_a_different_law_flies_differently():
    def always_up(obs):
        return UP

    a = Flight(RULE, pitch_law=always_up).record(duration_s=1.0)
    assert np.max(np.abs(a.y - _reference("paper", 1.0).y)) > 1e-3


def test_the_law_sees_the_observation_in_si_units():
    seen = []

    def law(obs):
        seen.append(obs)
        return 0.0

    f = Flight(RULE, condition=Condition(3.0, (2.0, -1.0)), pitch_law=law)
    f.step(3)
    first = seen[0]
    assert first.t_s == 0.0 and first.altitude_m == 3.0 and first.theta_rad == pytest.approx(np.pi / 2)
    assert (first.air_forward_m_s, first.air_up_m_s) == (-2.0, 1.0)
    assert seen[2].t_s == pytest.approx(2 / 1200)


def test_bad_laws_are_one_sentence():
    with pytest.raises(UserError, match="finite angle"):
        Flight(RULE, pitch_law=lambda obs: float("nan")).step(1)
    with pytest.raises(UserError, match="did not return a number"):
        Flight(RULE, pitch_law=lambda obs: "up").step(1)
    with pytest.raises(UserError, match="pitch_law"):
        Flight(RULE, pitch_law=3.0)


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_a_runaway_is_an_error_naming_the_step(backend):
    light = ButterflyParams().with_overrides(mass_g=0.001)  # a 1 mg butterfly: the wing forces fling it away
    f = Flight(RULE, light, backend=backend)
    with pytest.raises(Diverged, match=r"diverged at step \d+ .*ran away.*likely cause is mass_kg = 1e-06") as info:
        f.step(100)
    assert 1 <= info.value.step <= 100
    with pytest.raises(Diverged):
        f.step(1)  # stays diverged
    f.reset()
    assert f.steps == 0


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_state_is_named_with_units(backend):
    f = Flight(RULE, condition=Condition(1.5), backend=backend)
    s = f.state()
    assert set(s) == set(STATE_UNITS)
    np.testing.assert_array_equal(s["position_m"], [0.0, 1.5])
    f.step(10)
    f.sync()
    assert f.model.body("butterfly").id == f.body_id
    z, y = f.state()["position_m"]
    assert f.data.xpos[f.body_id][2] == pytest.approx(y, abs=0.01)  # the drawing follows the state


def test_mlp_of_the_paper_shape_computes_the_6_6_1_network_bit_for_bit():
    c = controllers.load("ann_paper")
    p = c.parameters
    cp_mlp = ann.compile_mlp(p["inputs"], c.input_scale(), p["weights"], (6, 6, 1), p["max_dphi_deg"],
                             p["phi_limit_deg"])
    kind, cp_ann = c.compiled()
    cps = np.zeros((2, max(len(cp_ann), len(cp_mlp))))
    cps[0, : len(cp_ann)], cps[1, : len(cp_mlp)] = cp_ann, cp_mlp
    kinds = np.array([kind, controllers.KIND_MLP])
    out, _, fit = paper.run_batch(kinds, cps, np.repeat(c.flap.as_array()[None], 2, 0), np.array([[1.0, 0.5]] * 2),
                                  np.array([10.0, 10.0]), np.repeat(paper.constants_row(butterfly.ButterflyParams())[None],
                                                                    2, 0), 6000, 1 / 1200, 1)
    np.testing.assert_array_equal(out[0], out[1])
    assert fit[0] == fit[1]


def test_a_linear_policy_is_the_output_neuron_alone():
    """``"layers": [6, 1]``: the pitch changes by max_dphi G(w . x + b), x the scaled inputs (eq. 12)."""
    w = np.array([0.3, -0.2, 0.5, 1.1, -2.0, 0.4, 0.05])
    c = butterfly.ann_controller(w, layers=[6, 1])
    kind, cp = c.compiled()
    assert kind == controllers.KIND_MLP and c.parameters["layers"] == [6, 1]
    theta, omega, y, vy, vz, phi = 0.4, -3.0, 0.7, -0.2, 1.5, 0.1
    x = np.array(ann.scaled_inputs(cp, theta, omega, y, vy, vz, 0.0, 0.0, phi))
    want = phi + np.radians(3.0) * ann.transfer(float(w[:6] @ x + w[6]))
    assert ann.mlp_pitch(cp, theta, omega, y, vy, vz, 0.0, 0.0, phi) == pytest.approx(want, rel=1e-12)
    assert Flight(c).record(duration_s=0.5).finite


def test_an_8_8_network_evolves_and_flies(tmp_path, capsys):
    from lifelike_mj.cli import main

    out = tmp_path / "net88.json"
    assert main(["butterfly", "evolve", "--optimizer", "rcga", "--hidden", "8,8", "--population", "10",
                 "--generations", "3", "--executor", "serial", "--quiet", "--out", str(out), "--json"]) == 0
    data = json.loads(out.read_text())
    assert data["parameters"]["layers"] == [6, 8, 8, 1] and len(data["parameters"]["weights"]) == 137
    hist = data["provenance"]["fitness_history"]
    assert hist[-1]["best"] >= hist[0]["best"]
    ctrl = controllers.load(out)
    assert ctrl.compiled()[0] == controllers.KIND_MLP
    capsys.readouterr()
    assert main(["butterfly", "fly", "--controller", str(out), "--duration", "2", "--json"]) == 0
    assert main(["butterfly", "fly", "--controller", str(out), "--backend", "mujoco", "--duration", "0.5",
                 "--json"]) == 0
    # the file's best fitness is what the problem computes for its weights
    prob = butterfly.make_problem("paper", hidden=[8, 8])
    assert prob.evaluate(ctrl.weights[None])[0] == pytest.approx(data["provenance"]["best_fitness"], rel=1e-12)


def test_network_files_are_checked():
    c = controllers.load("ann_paper").to_dict()
    c["parameters"]["layers"] = [6, 8, 1]
    with pytest.raises(UserError, match="needs 65"):
        controllers.from_dict(c)
    c["parameters"]["layers"] = [5, 6, 1]
    with pytest.raises(UserError, match="start with 6"):
        controllers.from_dict(c)
    with pytest.raises(UserError, match="--hidden"):
        butterfly.make_problem("paper", hidden="8,x")


@pytest.mark.parametrize("record", [False, True])
def test_a_mujoco_reset_is_an_error_not_a_fresh_start(record, tmp_path, monkeypatch):
    """MuJoCo resets a simulation whose state is NaN or huge (here: an altitude of 1e11 m) inside mj_step;
    the flight must stop with the cause, not fly on from the start, and MuJoCo must not litter the folder."""
    monkeypatch.chdir(tmp_path)
    f = Flight(RULE, backend="mujoco")
    f.step(12)
    f.data.qpos[f._lay.q_height] = 1e11
    if record:
        tr = f.record(24, every=4)
        assert tr.diverged_step == 13 and "became unstable" in tr.diverged_cause
        assert np.all(np.isfinite(tr.y[:1])) and np.all(np.isnan(tr.y[1:]))
    else:
        with pytest.raises(Diverged, match="became unstable.*huge positions.*reset it") as info:
            f.step(24)
        assert info.value.step == 13
    with pytest.raises(Diverged, match="became unstable"):
        f.step(1)
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()


def test_conditions_are_checked():
    for bad in (math.nan, math.inf, 1e6):
        with pytest.raises(UserError, match="start altitude"):
            Condition(bad)
    with pytest.raises(UserError, match="wind component a"):
        Condition(0.0, (math.nan, 0.0))
    with pytest.raises(UserError, match="does not resolve the wing beat"):
        Flight(RULE, dt_s=0.05)
