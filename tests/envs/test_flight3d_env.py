"""ButterflyFlight3D-v0: Gymnasium's checker, the return against the evolution's fitness, the vector form against
single environments, rendering, and bad input."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import lifelike_mj.envs  # noqa: E402,F401  (registers the environments)
from lifelike_mj.butterfly import flight3d  # noqa: E402
from lifelike_mj.butterfly.flight3d.loop import network  # noqa: E402
from lifelike_mj.envs.butterfly3d import (  # noqa: E402
    TASKS,
    ButterflyFlight3DEnv,
    ButterflyFlight3DVectorEnv,
    NetworkActions3D,
    NetworkInputs3D,
    network_controller3d,
)
from lifelike_mj.errors import UserError  # noqa: E402


@pytest.mark.parametrize("task", TASKS)
def test_gymnasiums_checker_passes(task):
    from gymnasium.utils.env_checker import check_env

    env = gym.make("lifelike_mj/ButterflyFlight3D-v0", task=task, duration_s=0.1, every=12, flutter=0.1).unwrapped
    check_env(env, skip_render_check=True)
    obs, info = env.reset(seed=0)
    assert info["observation_names"] == flight3d.OBS_NAMES and env.observation_space.contains(obs)


def _network_policy(ctl):
    u, scratch = np.zeros(flight3d.N_ACT), np.zeros(2 * int(max(ctl.layers)))

    def policy(obs):
        network(ctl.layers, ctl.weights, obs, u, scratch)
        return u.copy()

    return policy


@pytest.mark.parametrize("name", ["steer", "wind"])
def test_an_evolved_controllers_return_is_its_evolution_fitness(name):
    """Flown through the env by its own network, an evolved controller's (the swallowtail's, since withdrawn) mean
    return over its task set is the fitness ``evolve3d`` computes for it (the wind set has gusts and wind: the env
    draws them as the evolution does)."""
    ctl = flight3d.load_controller(flight3d.withdrawn_file(name))
    tasks = flight3d.TASK_SETS[name]()
    problem = flight3d.FlightProblem3D(tuple(tasks), ctl, duration_s=4.0)
    fitness = float(problem.evaluate(np.zeros((1, problem.dim)))[0])
    env = gym.make("lifelike_mj/ButterflyFlight3D-v0", controller=ctl, duration_s=4.0)
    policy = _network_policy(ctl)
    returns = []
    for task in tasks:
        obs, _ = env.reset(options={"task": task})
        total, done = 0.0, False
        while not done:
            obs, r, term, trunc, _ = env.step(policy(obs))
            total, done = total + r, term or trunc
        returns.append(total)
    assert np.mean(returns) == pytest.approx(fitness, rel=1e-9, abs=1e-12)
    assert fitness > 0.7  # the shipped controllers fly their tasks well: a return of 0 would not pass


def test_the_vector_env_is_single_envs_in_one_call_bit_for_bit():
    """Copy i of the vector env seeded s flies as a single env seeded s + i, through autoresets (NEXT_STEP)."""
    n, kw = 3, {"task": "wind", "duration_s": 0.2, "every": 12, "flutter": 0.1}
    env = gym.make_vec("lifelike_mj/ButterflyFlight3D-v0", num_envs=n, vectorization_mode="vector_entry_point", **kw)
    assert isinstance(env.unwrapped, ButterflyFlight3DVectorEnv)
    singles = [ButterflyFlight3DEnv(**kw) for _ in range(n)]
    obs, _ = env.reset(seed=5)
    assert np.array_equal(obs, [s.reset(seed=5 + i)[0] for i, s in enumerate(singles)])
    actions = np.random.default_rng(0).uniform(-1.0, 1.0, (45, n, flight3d.N_ACT))
    ended, resets = [False] * n, 0
    for a in actions:
        obs, rewards, term, trunc, _ = env.step(a)
        for i, s in enumerate(singles):
            if ended[i]:
                (o, _), r, t, tr = s.reset(), 0.0, False, False
                resets += 1
            else:
                o, r, t, tr, _ = s.step(a[i])
            ended[i] = t or tr
            assert np.array_equal(obs[i], o) and rewards[i] == r and (term[i], trunc[i]) == (t, tr)
    assert resets >= n  # every copy went through an autoreset


def test_a_trained_network_leaves_the_env_as_a_controller_file_fly3d_flies(tmp_path):
    """A policy of NetworkInputs3D -> tanh layers -> NetworkActions3D is written out by network_controller3d; the
    controller flies the same flight (same rewards) as the policy in the env."""
    rng = np.random.default_rng(3)
    shapes = [(16, flight3d.N_OBS), (9, 16)]
    layers = [(0.3 * rng.standard_normal(s), 0.1 * rng.standard_normal(s[0])) for s in shapes]

    def policy(x):  # numpy stand-in for a trained torch actor: tanh hidden layer, linear mean
        h = np.tanh(layers[0][0] @ x + layers[0][1])
        return layers[1][0] @ h + layers[1][1]

    env = NetworkActions3D(NetworkInputs3D(ButterflyFlight3DEnv(task="turn", duration_s=1.0, every=12)))
    obs, _ = env.reset(seed=2)
    total, done = 0.0, False
    while not done:
        obs, r, term, trunc, _ = env.step(policy(obs))
        total, done = total + r, term or trunc
    ctl = network_controller3d(layers, env.unwrapped.controller)
    path = tmp_path / "rl.json"
    from lifelike_mj.io import write_json

    write_json(path, ctl.to_dict())
    flight = flight3d.Flight3D(controller=str(path), task=env.unwrapped.episode_task, end_on_tumble=True)
    flight.step(round(1.0 / flight.dt))
    assert flight.reward == pytest.approx(total * 1.0, rel=1e-12)


def test_a_network_written_out_keeps_the_butterfly_and_wing_law_it_was_trained_on():
    """A policy trained on the calibrated monarch is written out for the calibrated monarch (it once came out as
    the default swallowtail on the exact law, a butterfly it never flew)."""
    template = flight3d.Controller3D([flight3d.N_OBS, flight3d.N_ACT],
                                     np.zeros(flight3d.n_weights([flight3d.N_OBS, flight3d.N_ACT])),
                                     animal="monarch", force_law="calibrated", every=12)
    env = ButterflyFlight3DEnv(task="level", duration_s=0.1, controller=template)
    layers = [(np.zeros((flight3d.N_ACT, flight3d.N_OBS)), np.zeros(flight3d.N_ACT))]
    ctl = network_controller3d(layers, env.controller)
    assert (ctl.animal, ctl.force_law, ctl.every) == ("monarch", "calibrated", 12)
    assert flight3d.controller_from_dict(ctl.to_dict()).force_law == "calibrated"


def test_rgb_array_draws_the_butterfly():
    env = gym.make("lifelike_mj/ButterflyFlight3D-v0", render_mode="rgb_array", width=160, height=120)
    env.reset(seed=0)
    env.step(np.zeros(flight3d.N_ACT))
    img = env.render()
    assert img.shape == (120, 160, 3) and img.dtype == np.uint8
    centre = img[40:80, 50:110].reshape(-1, 3).astype(int)
    assert (np.abs(centre - np.median(centre, axis=0)).sum(axis=1) > 60).mean() > 0.01  # the wings stand out
    env.close()


@pytest.mark.parametrize("kw", [{"task": "swim"}, {"speed_m_s": 0}, {"duration_s": -1}, {"render_mode": "movie"},
                                {"controller": "no_such"}, {"every": 0}, {"inputs": "water"}, {"flutter": 2},
                                {"task": [flight3d.course(1, 11)]}])
def test_bad_arguments_are_one_sentence(kw):
    with pytest.raises(UserError):
        ButterflyFlight3DEnv(**kw)


def test_bad_actions_are_one_sentence():
    env = ButterflyFlight3DEnv(duration_s=0.1)
    env.reset(seed=0)
    for bad, says in ((np.zeros(8), r"an action must have shape \(9,\)"),
                      (np.full(9, np.nan), r"the action's entry 0 \(offset_sym\) is nan, not a finite number"),
                      (np.array(["a"] * 9), "an action must be real numbers")):
        with pytest.raises(UserError, match=says):
            env.step(bad)
    with pytest.raises(UserError, match="unknown reset option"):
        env.reset(options={"tasks": "level"})


def test_the_monarch_flies_through_the_env_with_its_own_wings_and_law():
    """The shipped monarch as the env's controller: the env's flights are the monarch's (its measured wings and the
    quasi-steady law the controller keeps), single and vectorised alike."""
    env = gym.make("lifelike_mj/ButterflyFlight3D-v0", controller="monarch", duration_s=0.2)
    obs, _ = env.reset(seed=0)
    flight = env.unwrapped.flight
    assert flight.animal == "monarch" and flight.options["force_law"] == "quasi_steady"
    for _ in range(20):
        obs, *_ = env.step(np.zeros(flight3d.N_ACT))
    assert np.isfinite(obs).all()
    venv = gym.make_vec("lifelike_mj/ButterflyFlight3D-v0", num_envs=2, vectorization_mode="vector_entry_point",
                        controller="monarch", duration_s=0.2)
    vobs, _ = venv.reset(seed=0)
    assert np.isfinite(vobs).all()
    from lifelike_mj.butterfly.flight3d import model as mj3d

    d = venv.unwrapped._new_data()
    assert d.userdata[mj3d.U_MODE] == mj3d.FORCE_LAWS["quasi_steady"]
    assert venv.unwrapped._model.body_subtreemass[1] == pytest.approx(flight.model.body_subtreemass[1])


@pytest.fixture(scope="module")
def designed_controller():
    import json
    from pathlib import Path

    from lifelike_mj.butterfly.flight3d import designed

    model = json.loads((Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "monarch_model.json")
                       .read_text())
    return designed.DesignedController(designed.design(model), name="designed")


def test_the_designed_controller_is_a_baseline_a_residual_policy_acts_on(designed_controller):
    """With a designed controller the env flies it as the baseline (its command in info) and the actions are a
    residual: zeros give the flight Flight3D flies alone, bit for bit; the vector form is single envs; Gymnasium's
    checker passes; a network's every, inputs or animal are refused."""
    from gymnasium.utils.env_checker import check_env

    from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned

    kw = {"task": "wind", "duration_s": 0.5, "controller": designed_controller}
    check_env(ButterflyFlight3DEnv(**kw), skip_render_check=True)
    env = ButterflyFlight3DEnv(**kw)
    obs, info = env.reset(seed=3)
    assert info["baseline_command"].shape == (13,) and env.observation_space.contains(obs)
    total, done, steps = 0.0, False, 0
    while not done:
        obs, r, term, trunc, info = env.step(np.zeros(flight3d.N_ACT))
        total, done, steps = total + r, term or trunc, steps + 1
    assert steps == 50  # 0.5 s at the controller's 100 decisions per second
    alone = flight3d.Flight3D(controller=CompiledDesigned.of(designed_controller), task=env.episode_task,
                              end_on_tumble=True)
    alone.step(env.n_steps)
    assert np.array_equal(alone.data.qpos, env.flight.data.qpos)
    assert total == pytest.approx(alone.reward / 0.5, rel=1e-12) and total > 0.1
    n = 3
    vec = ButterflyFlight3DVectorEnv(num_envs=n, **kw)
    singles = [ButterflyFlight3DEnv(**kw) for _ in range(n)]
    obs, info = vec.reset(seed=7)
    assert np.array_equal(obs, [s.reset(seed=7 + i)[0] for i, s in enumerate(singles)])
    actions = np.random.default_rng(1).uniform(-1.0, 1.0, (60, n, flight3d.N_ACT))
    ended = [False] * n
    for a in actions:
        obs, rewards, term, trunc, info = vec.step(a)
        for i, s in enumerate(singles):
            if ended[i]:
                (o, si), r, t, tr = s.reset(), 0.0, False, False
            else:
                o, r, t, tr, si = s.step(a[i])
            ended[i] = t or tr
            assert np.array_equal(obs[i], o) and rewards[i] == r and (term[i], trunc[i]) == (t, tr)
            assert np.array_equal(info["baseline_command"][i], si["baseline_command"])
    for bad in ({"every": 4}, {"inputs": "air"}, {"animal": "swallowtail"}):
        with pytest.raises(UserError, match="designed controller keeps its own rate"):
            ButterflyFlight3DEnv(controller=designed_controller, **bad)
