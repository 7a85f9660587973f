"""The network controller of Oe 2010 section 6 on both backends, and its evolution problem."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lifelike_mj.butterfly import ann, batch, controllers
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.evolution import PitchProblem, make_problem
from lifelike_mj.butterfly.flight import Condition
from lifelike_mj.cli import main
from lifelike_mj.errors import UserError


def _weights(seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-1.0, 1.0, ann.N_WEIGHTS)


def test_transfer_function_eq12():
    u = np.linspace(-3, 3, 601)
    g = np.array([ann.transfer(x) for x in u])
    assert ann.transfer(0.0) == pytest.approx(0.0, abs=1e-15)
    assert np.allclose(g, -g[::-1], atol=1e-15)  # odd
    assert np.all(g > -1) and np.all(g < 1) and np.all(np.diff(g) > 0)
    # flat near 0: much flatter than a plain tanh-like sigmoid with the same range
    assert abs(ann.transfer(0.1)) < 0.01
    ref = 1 / (1 + np.exp(-12 * (u + 0.5))) + 1 / (1 + np.exp(-12 * (u - 0.5))) - 1
    assert np.allclose(g, ref, atol=1e-15)


def test_pitch_step_limits():
    c = controllers.ann_controller(_weights())
    _, cp = c.compiled()
    big = cp.copy()
    big[ann.A_W + 42 : ann.A_W + 49] = 50.0  # output saturates at +1
    phi = 0.0
    for _ in range(20):
        new = ann.ann_pitch(big, 0.3, 10.0, 0.0, 0.0, 3.0, 0.0, 0.0, phi)
        assert new - phi <= math.radians(3.0) + 1e-12
        phi = new
    assert phi == pytest.approx(math.radians(30.0))  # clipped


def test_compiled_matches_naive_loop():
    c = controllers.ann_controller(_weights(1))
    for cond in (Condition(0.0), Condition(3.0, (1.0, -0.5))):
        tr = paper.simulate(c, conditions=cond, duration_s=1.0)[0]
        y, z, vy, vz = paper.simulate_naive(c, condition=cond, n_steps=1200)
        assert abs(y - tr.y[-1]) < 1e-9 and abs(vz - tr.vz[-1]) < 1e-9


def test_relative_and_ground_inputs_agree_without_wind_and_differ_with():
    c = controllers.ann_controller(_weights(2))
    g = c.with_inputs("ground")
    a, b = paper.simulate([c, g], duration_s=2.0)
    assert np.array_equal(a.y, b.y)
    a, b = paper.simulate([c, g], conditions=Condition(0.0, (2.0, 0.0)), duration_s=2.0)
    assert not np.array_equal(a.phi, b.phi)


def test_mujoco_backend_flies_the_network_like_the_paper_backend():
    c = controllers.ann_controller(_weights(3))
    ref = paper.simulate(c, duration_s=1.0)[0]
    mj = batch.simulate_mujoco(c, duration_s=1.0)[0]
    assert np.max(np.abs(ref.y - mj.y)) < 0.01
    assert mj.fitness == pytest.approx(ref.fitness, rel=0.01)
    py = batch.simulate_mujoco(c, duration_s=0.05, callback="python")[0]
    co = batch.simulate_mujoco(c, duration_s=0.05)[0]
    assert np.max(np.abs(py.y - co.y)) < 1e-12 and py.fitness == pytest.approx(co.fitness, abs=1e-12)


def test_fitness_is_eq13():
    c = controllers.ann_controller(_weights(4))
    tr = paper.simulate(c, duration_s=0.5)[0]
    expected = np.sum(tr.vz[1:] / 3.0 * 0.1 / (np.abs(tr.y[1:]) + 0.1))
    assert tr.fitness == pytest.approx(expected, rel=1e-12)


def test_problem_batches_equal_single_flights():
    prob = PitchProblem(duration_s=0.5)
    X = np.stack([_weights(s) for s in range(5)])
    f = prob.evaluate(X)
    for i in range(5):
        assert f[i] == prob.evaluate(X[i : i + 1])[0]
        assert f[i] == paper.simulate(prob.controller(X[i]), duration_s=0.5)[0].fitness
    two = PitchProblem(duration_s=0.5, conditions=(Condition(0.0), Condition(2.0, (1.0, 0.0))))
    single = [PitchProblem(duration_s=0.5, conditions=(cd,)).evaluate(X) for cd in two.conditions]
    assert np.allclose(two.evaluate(X), np.mean(single, axis=0), rtol=1e-14)


def test_mujoco_problem_batch_matches_fly_one():
    prob = PitchProblem(backend="mujoco", duration_s=0.25)
    X = np.stack([_weights(s) for s in range(3)])
    f = prob.evaluate(X)
    for i in range(3):
        assert f[i] == pytest.approx(batch.simulate_mujoco(prob.controller(X[i]), duration_s=0.25)[0].fitness, rel=1e-12)


def test_fingerprint_names_the_problem():
    assert make_problem("paper").fingerprint() == make_problem("paper").fingerprint()
    assert make_problem("paper").fingerprint() != make_problem("robust").fingerprint()
    assert make_problem("paper").fingerprint() != make_problem("paper", inputs="ground").fingerprint()
    with pytest.raises(UserError):
        make_problem("nonsense")


def test_controller_file_round_trip_and_bad_weight_count(tmp_path, capsys):
    c = controllers.ann_controller(_weights(5), provenance={"note": "test"})
    path = tmp_path / "net.json"
    path.write_text(json.dumps(c.to_dict()))
    back = controllers.load(path)
    assert np.array_equal(back.weights, c.weights) and back.type == "ann"
    data = c.to_dict()
    data["parameters"]["weights"] = data["parameters"]["weights"][:-3]
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(UserError, match="46 weights"):
        controllers.load(bad)
    assert main(["butterfly", "fly", "--controller", str(bad), "--duration", "0.1"]) == 2
    err = capsys.readouterr().err
    assert "46 weights" in err and "Traceback" not in err


@pytest.mark.parametrize("argv, needle", [
    (["butterfly", "evolve", "--optimizer", "nonsense", "--generations", "1"], "--optimizer 'nonsense' is not one of"),
    (["butterfly", "evolve", "--optimizer", "rcga", "--population", "2", "--generations", "1"], "minimum"),
    (["butterfly", "evolve", "--optimizer", "rcga", "--task", "elsewhere", "--generations", "1"], "unknown task"),
    (["butterfly", "windmap", "--controller", "simple_rule"], "network"),
])
def test_cli_bad_input_exit_2(argv, needle, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv + (["--executor", "serial"] if argv[1] == "evolve" else [])) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err


def test_checkpoint_of_another_problem_is_refused(tmp_path, capsys, monkeypatch):
    ck = tmp_path / "run.ckpt"
    args = ["butterfly", "evolve", "--optimizer", "rcga", "--population", "6", "--generations", "2", "--executor",
            "serial", "--quiet", "--checkpoint", str(ck), "--out", str(tmp_path / "a.json")]
    from lifelike_mj.butterfly import evolution

    def small(task, backend, inputs, params, hidden=None):
        return evolution.PitchProblem(duration_s=0.2, inputs="relative" if task == "paper" else "ground")

    monkeypatch.setattr(evolution, "make_problem", small)
    assert main(args) == 0
    assert main(args + ["--resume", "--task", "robust"]) == 2
    assert "different problem" in capsys.readouterr().err


def test_windmap_small_grid():
    from lifelike_mj.butterfly.ann_experiments import e11_windmap

    c = controllers.ann_controller(_weights(6))
    m = e11_windmap(c, "relative", step_m_s=1.0, max_m_s=1.0)
    assert m.total_cells == 9 and m.passed.shape == (3, 3)
    # each cell is the flight of that wind: the centre cell is the still-air flight
    tr = paper.simulate(c, conditions=Condition(0.0, (0.0, 0.0)))[0]
    s = tr.summary()
    ok = s["settled_altitude_min_m"] >= -1 and s["settled_altitude_max_m"] <= 1 and s["settled_forward_speed_cm_s"] >= 0
    assert bool(m.passed[1, 1]) == ok
    with pytest.raises(UserError):
        e11_windmap(c, step_m_s=0.3, max_m_s=1.0)


def test_robust_task_flies_windy_conditions_with_both_input_readings():
    prob = make_problem("robust")
    flights = prob.flights()
    windy = [c for c in prob.conditions if any(c.wind_from_m_s)]
    assert prob.inputs == "both" and len(flights) == len(prob.conditions) + len(windy)
    short = PitchProblem(duration_s=0.3, conditions=prob.conditions, inputs="both")
    x = _weights(7)
    c = short.controller(x)
    vals = [paper.simulate(c.with_inputs("relative" if rel else "ground"), conditions=cd, duration_s=0.3)[0].fitness
            for cd, rel in short.flights()]
    assert short.evaluate(x[None])[0] == pytest.approx(np.mean(vals), rel=1e-12)


def test_robust_map_task_weights_flights_by_ground_speed():
    """robust_map: each flight's H divided by its head-wind share of eq. 13's speed term
    (V_REF / max(V_REF - a, V_MIN)), weights summing to 1; unweighted tasks keep their fingerprints."""
    prob = make_problem("robust_map")
    assert prob.weighting == "ground_speed" and "weighting" in prob.describe()
    assert "weighting" not in make_problem("robust").describe()
    w = prob.weights()
    assert w.sum() == pytest.approx(1.0)
    heads = np.array([c.wind_from_m_s[0] for c, _ in prob.flights()])
    expected = 3.0 / np.maximum(3.0 - heads, 0.5)
    np.testing.assert_allclose(w, expected / expected.sum())
    assert w[heads == 3.0][0] == pytest.approx(6 * w[heads == 0.0][0])
    short = PitchProblem(duration_s=0.3, conditions=prob.conditions, inputs="both", weighting="ground_speed")
    x = _weights(3)
    c = short.controller(x)
    vals = [paper.simulate(c.with_inputs("relative" if rel else "ground"), conditions=cd, duration_s=0.3)[0].fitness
            for cd, rel in short.flights()]
    assert short.evaluate(x[None])[0] == pytest.approx(float(np.dot(short.weights(), vals)), rel=1e-12)
    with pytest.raises(UserError):
        PitchProblem(weighting="nonsense")


def test_cli_evolve_writes_a_controller_with_provenance_same_on_serial_and_process(tmp_path):
    outs = {}
    for ex in ("serial", "process"):
        out = tmp_path / f"{ex}.json"
        workers = ["--workers", "2"] if ex == "process" else []
        assert main(["butterfly", "evolve", "--optimizer", "rcga", "--population", "6", "--generations", "3", "--seed",
                     "5", "--executor", ex, *workers, "--quiet", "--out", str(out)]) == 0
        outs[ex] = json.loads(out.read_text())
        assert (tmp_path / f"{ex}.json.ckpt").exists()
    a, b = outs["serial"], outs["process"]
    assert a["parameters"]["weights"] == b["parameters"]["weights"]
    prov = a["provenance"]
    for key in ("optimizer", "seed", "budget", "fitness_history", "package_version", "wall_time_s", "problem"):
        assert key in prov
    assert prov["optimizer"] == "rcga" and prov["seed"] == 5 and len(prov["fitness_history"]) == 3
    c = controllers.load(tmp_path / "serial.json")
    tr = paper.simulate(c)[0]
    assert tr.fitness == pytest.approx(prov["best_fitness"], rel=1e-12)  # the file reproduces its fitness
