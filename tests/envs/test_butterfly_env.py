"""ButterflyPitch-v0: Gymnasium's checker, determinism, pickling, and the reward against eq. 13."""

import pickle

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import lifelike_mj.envs  # noqa: E402,F401  (registers the environments)
from lifelike_mj.envs.butterfly import OBSERVATION_NAMES, ButterflyPitchEnv  # noqa: E402


@pytest.mark.parametrize("env_id", ["lifelike_mj/ButterflyPitch-v0", "lifelike_mj/ButterflyPitchWind-v0"])
@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_gymnasiums_checker_passes(backend, env_id):
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id, backend=backend, duration_s=0.5).unwrapped
    check_env(env, skip_render_check=True)


def test_make_with_the_module_prefix_and_spaces():
    env = gym.make("lifelike_mj.envs:lifelike_mj/ButterflyPitch-v0")
    obs, info = env.reset(seed=0)
    assert obs.shape == (6,) and info["observation_names"] == OBSERVATION_NAMES
    assert env.action_space.high[0] == pytest.approx(np.radians(3.0))


def _rollout(env, actions):
    env.reset(seed=1)
    out = []
    for a in actions:
        obs, r, term, trunc, _ = env.step(np.array([a]))
        out.append((obs.copy(), r, term, trunc))
    return out


def test_same_actions_same_episode_and_pickling():
    rng = np.random.default_rng(0)
    actions = rng.uniform(-0.05, 0.05, 300)
    env = ButterflyPitchEnv(duration_s=0.25)
    a = _rollout(env, actions)
    b = _rollout(pickle.loads(pickle.dumps(env)), actions)
    assert len(a) == len(b) == 300
    for (oa, ra, ta, ua), (ob, rb, tb, ub) in zip(a, b):
        np.testing.assert_array_equal(oa, ob)
        assert (ra, ta, ua) == (rb, tb, ub)
    assert a[-1][3] and not any(t[3] for t in a[:-1])  # truncated exactly at 0.25 s = 300 steps


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_episode_reward_is_the_evolution_fitness(backend):
    """The shipped network flown through the env (action = its pitch): the summed reward equals the eq. 13
    fitness H that `butterfly evolve` computes for the same weights (1e-9 relative)."""
    from lifelike_mj.butterfly import ann, controllers
    from lifelike_mj.butterfly.evolution import PitchProblem

    ctrl = controllers.load("ann_paper")
    weights = np.array(ctrl.parameters["weights"])
    problem = PitchProblem(backend=backend, duration_s=4.0)
    h = float(problem.evaluate(weights[None, :])[0])
    _, cp = problem.controller(weights).compiled()
    env = ButterflyPitchEnv(backend=backend, action_mode="phi", duration_s=4.0)
    env.reset()
    total, done = 0.0, False
    while not done:
        o = env.flight.observation()
        phi = ann.ann_pitch(cp, o.theta_rad, o.omega_rad_s, o.altitude_m, o.climb_m_s, o.forward_m_s, o.air_up_m_s,
                            o.air_forward_m_s, o.phi_rad)
        _, r, term, trunc, _ = env.step(np.array([phi]))
        total += r
        done = term or trunc
    assert total == pytest.approx(h, rel=1e-9)


def test_bad_arguments_are_one_sentence():
    from lifelike_mj.errors import UserError

    for kw in ({"backend": "jax"}, {"backend": "mujoco", "config": "wide"},
               {"inputs": "water"}, {"action_mode": "angle"}, {"frame_skip": 0}, {"duration_s": -1},
               {"wind_from_m_s": (100.0, 0.0)}, {"render_mode": "movie"}, {"camera": "top"}, {"width": 0}):
        with pytest.raises(UserError):
            ButterflyPitchEnv(**kw)


def test_the_wind_env_draws_its_condition_from_the_seed():
    from gymnasium.utils.env_checker import check_env

    from lifelike_mj.butterfly.evolution import robust_map_conditions

    env = gym.make("lifelike_mj/ButterflyPitchWind-v0", duration_s=0.5).unwrapped
    check_env(env, skip_render_check=True)
    drawn = [env.reset(seed=s)[1] for s in range(40)]
    conds = {(c.y0_m, tuple(c.wind_from_m_s)) for c in robust_map_conditions()}
    got = {(d["y0_m"], d["wind_from_m_s"]) for d in drawn}
    assert got <= conds and len(got) >= 10  # 40 draws over the 17 conditions
    assert env.reset(seed=7)[1] == env.reset(seed=7)[1]
    obs, info = env.reset(seed=3)
    assert obs[4] == info["y0_m"] and info["flight_weight"] > 0
    fixed = gym.make("lifelike_mj/ButterflyPitchWind-v0", conditions=[(5.0, (0.0, 1.0))]).unwrapped
    assert fixed.reset(seed=0)[1]["wind_from_m_s"] == (0.0, 1.0)


@pytest.mark.parametrize("backend", ["paper", "mujoco"])
def test_rgb_array_frames_headless(backend, gl_backend):
    env = gym.make("lifelike_mj/ButterflyPitch-v0", backend=backend, render_mode="rgb_array", width=160, height=120)
    env.reset(seed=0)
    first = env.render()
    assert first.shape == (120, 160, 3) and first.dtype == np.uint8
    for _ in range(30):
        env.step(np.array([0.01]))
    later = env.render()
    assert np.abs(later.astype(int) - first.astype(int)).sum() > 0  # the wings moved
    env.close()


def test_reset_starts_the_same_flight_again():
    env = ButterflyPitchEnv(duration_s=0.1)
    a = _rollout(env, [0.02] * 120)
    b = _rollout(env, [0.02] * 120)
    for (oa, ra, *_), (ob, rb, *_) in zip(a, b):
        np.testing.assert_array_equal(oa, ob)
        assert ra == rb


def test_reset_options_choose_one_episodes_condition():
    from lifelike_mj.envs.vector import ButterflyPitchVectorEnv
    from lifelike_mj.errors import UserError

    env = ButterflyPitchEnv(duration_s=0.1, y0_m=1.0)
    obs, _ = env.reset(options={"condition": (5.0, (2.0, 0.0))})
    assert obs[4] == 5.0 and obs[5] == 2.0  # at rest in a 2 m/s head wind: 2 m/s forward through the air
    obs, _ = env.reset()
    assert obs[4] == 1.0 and obs[5] == 0.0  # the next plain reset: the env's own condition again
    vec = ButterflyPitchVectorEnv(2, duration_s=0.1)
    obs, _ = vec.reset(options={"conditions": [(3.0, (0.0, 0.0)), (-3.0, (0.0, 1.0))]})
    assert list(obs[:, 4]) == [3.0, -3.0] and list(obs[:, 3]) == [0.0, 1.0]  # wind from above: air moves down
    for bad, words in (({"condition": "high"}, r"\(y0_m, \(a, b\)\) pair"), ({"condition": (0.0, (99.0, 0.0))}, "wind")):
        with pytest.raises(UserError, match=words):
            env.reset(options=bad)
    with pytest.raises(UserError, match="one .* pair per copy"):
        vec.reset(options={"conditions": [(0.0, (0.0, 0.0))]})


def test_controller_policy_checks_the_env():
    from lifelike_mj.envs.policies import controller_policy
    from lifelike_mj.errors import UserError

    with pytest.raises(UserError, match="action_mode='phi'"):
        controller_policy("ann_paper", ButterflyPitchEnv())
    with pytest.raises(UserError, match="reads relative velocities .* ground"):
        controller_policy("ann_paper", ButterflyPitchEnv(action_mode="phi", inputs="ground"))
    env = ButterflyPitchEnv(action_mode="phi", duration_s=0.05)
    policy = controller_policy("simple_rule", env)
    obs, _ = env.reset()
    assert policy(obs).shape == (1,)
    env.step(policy(obs))


def test_the_envs_inputs_are_named_as_a_pitch_laws_and_the_old_names_still_work_one_release():
    """A law written from the env's table runs as a pitch law: the six names are PitchObservation's fields, and
    with ground inputs the values are the same; the names of before 0.3 still work, each with a note."""
    import warnings

    from lifelike_mj import checks
    from lifelike_mj.butterfly.flight import PitchObservation
    from lifelike_mj.envs.butterfly import OLD_OBSERVATION_NAMES, observation_index

    checks._RENAMED.clear()  # the note comes once per process: let this test see it

    assert set(OBSERVATION_NAMES) <= set(PitchObservation._fields)
    env = ButterflyPitchEnv(inputs="ground")
    obs, _ = env.reset()
    for _ in range(30):
        obs, *_ = env.step(env.action_space.sample() * 0.0)
    law_obs = env.flight.observation()
    for i, name in enumerate(OBSERVATION_NAMES):
        assert obs[i] == pytest.approx(getattr(law_obs, name)), name
    for old, new in OLD_OBSERVATION_NAMES.items():
        with pytest.warns(DeprecationWarning, match=new):
            assert observation_index(old) == OBSERVATION_NAMES.index(new)
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        with pytest.warns(DeprecationWarning, match="altitude_m"):
            assert law_obs.y_m == law_obs.altitude_m


def test_wind_and_inputs_are_named_by_their_meaning_and_the_old_words_still_work():
    """``wind_from_m_s`` and ``wind_to_m_s`` are one wind seen from its two ends; ``wind_m_s`` (where it comes from)
    and ``inputs="relative"`` (through the air) are taken this release, each with a note."""
    import warnings

    from lifelike_mj.butterfly import Condition
    from lifelike_mj.errors import UserError

    a = ButterflyPitchEnv(wind_from_m_s=(1.0, 0.5))
    b = ButterflyPitchEnv(wind_to_m_s=(-1.0, -0.5))
    assert a.condition == b.condition and a.condition.wind_to_m_s == (-1.0, -0.5)
    with pytest.warns(DeprecationWarning):
        old = ButterflyPitchEnv(wind_m_s=(1.0, 0.5), inputs="relative")
    assert old.condition == a.condition and old.inputs == "air"
    with pytest.raises(UserError, match="give the wind once"):
        ButterflyPitchEnv(wind_from_m_s=(1.0, 0.0), wind_to_m_s=(1.0, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the new names give no note
        assert Condition(wind_to_m_s=(2.0, 0.0)).wind_from_m_s == (-2.0, 0.0)
        assert Condition(3.0, (2.0, 0.0)).air_velocity() == (-2.0, -0.0)
