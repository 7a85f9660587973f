"""What the Python API and the Gymnasium environments take (issue 24): every physical option finite and in range
(a ``UserError`` naming it, before anything is simulated), unknown option and parameter names refused with the
nearest valid one (``UnknownName``, a ``TypeError`` as Python's own), env actions of the wrong shape or dtype refused
with the expected shape, reset options checked."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lifelike_mj.errors import UnknownName, UserError

NAN = math.nan


def _flight3d(**kw):
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    return Flight3D(**kw)


def _garden(**kw):
    from lifelike_mj.butterfly import flight3d
    from lifelike_mj.butterfly.flight3d.garden import Garden

    return Garden(2, flight3d.withdrawn_file("steer"), **kw)


def _tank(**kw):
    from lifelike_mj.fish import Tank

    return Tank(n_fish=2, **kw)


def _flock(**kw):
    from lifelike_mj.boids import Flock

    return Flock(n=10, **kw)


def _flight(**kw):
    from lifelike_mj.butterfly import Flight

    return Flight("simple_rule", **kw)


def _params(**kw):
    from lifelike_mj.butterfly import ButterflyParams

    return ButterflyParams(**kw)


def _overrides(**kw):
    from lifelike_mj.butterfly import ButterflyParams

    return ButterflyParams().with_overrides(**kw)


def _evolve3d(**kw):
    from lifelike_mj.butterfly import flight3d

    return flight3d.evolve(**kw)


def _optimize(**kw):
    from lifelike_mj.evolve import optimize
    from lifelike_mj.evolve.testproblems import Sphere

    return optimize(Sphere(dim=2), "rcga", seed=0, **kw)


def _env(**kw):
    import gymnasium as gym

    import lifelike_mj.envs  # noqa: F401

    return gym.make("lifelike_mj/ButterflyPitch-v0", **kw)


def _task(**kw):
    from lifelike_mj.butterfly import flight3d

    return flight3d.Task3D(**{"kind": "schedule", "rows": ((0.0, 0.0, 0.0, 1.5),), **kw})


def _record3d(dt_s, duration_s):
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    f = Flight3D(dt_s=dt_s, command=None)
    return f.record(duration_s=duration_s)


BAD = [
    # physical options: NaN, infinite, negative, too large, the wrong type
    (_flight3d, {"body_areas_m2": [NAN] * 3}, UserError, "body_areas_m2"),
    (_flight3d, {"body_areas_m2": [1e-4, -1e-4, 1e-4]}, UserError, "body_areas_m2 must be a number in [0, 1]"),
    (_flight3d, {"body_areas_m2": "abc"}, UserError, "body_areas_m2"),
    (_flight3d, {"drive_hz": math.inf}, UserError, "drive_hz"),
    (_flight3d, {"omega_c": NAN}, UserError, "omega_c"),
    (_flight3d, {"start_m": (NAN, 0, 0)}, UserError, "start_m"),
    (_flight3d, {"wind_to_m_s": (0, 0, NAN)}, UserError, "wind_to_m_s"),
    (_flight3d, {"n_strips": 0, "force_law": "strip"}, UserError, "n_strips (strips per wing) must be a whole number"),
    (_flight3d, {"n_chord": 10**9, "force_law": "strip"}, UserError, "n_chord (chordwise panels per strip)"),
    (_flight3d, {"n_strips": 30, "n_chord": 3, "force_law": "strip"}, UserError, "make 270"),
    (_flight3d, {"dt_s": NAN}, UserError, "dt_s"),
    (_flight3d, {"force_law": "exactt"}, UserError, "unknown wing-force law 'exactt'"),
    (_params, {"mass_kg": NAN}, UserError, "mass_kg"),
    (_params, {"rho": 1e9}, UserError, "rho must be a number in (0, 2000]"),
    (_params, {"cd": "2.2"}, UserError, "cd"),
    (_overrides, {"body_area_cm2": NAN}, UserError, "body_area_cm2"),
    (_overrides, {"mass_g": "0.3"}, UserError, "mass_g"),
    (_garden, {"wind_from_m_s": (NAN, 0, 0)}, UserError, "wind_from_m_s"),
    (_garden, {"flutter": 2.0}, UserError, "flutter"),
    (_garden, {"dt_s": -1.0}, UserError, "dt_s"),
    (_tank, {"seed": -1}, UserError, "seed"),
    (lambda **kw: __import__("lifelike_mj.fish", fromlist=["Tank"]).Tank(n_fish=10**7), {}, UserError,
     "the number of fish must be a whole number from 1 to 5,000"),
    (lambda **kw: __import__("lifelike_mj.boids", fromlist=["Flock"]).Flock(n=10**8), {}, UserError,
     "the number of agents must be a whole number from 2 to 1000000, got 100000000"),
    (_flock, {"seed": 1.5}, UserError, "seed"),
    (_flight, {"dt_s": 1e-12}, UserError, "at most 1,000,000,000"),
    (lambda **kw: _task(speed_m_s=1e300), {}, UserError, "speed_m_s must be a number in (0, 100]"),
    (lambda **kw: _task(wind_to_m_s=(1e9, 0, 0)), {}, UserError, r"the wind must be a number in [-100, 100]"),
    (lambda **kw: _task(rows=((0.0, 0.0, 1e300, 1.5),)), {}, UserError, "a task's number must be a number in"),
    (lambda **kw: _record3d(1e-9, 100.0), {}, UserError, "asks for 100,000,000,000 time steps"),
    # unknown names: the closest one is named
    (_flight3d, {"forcelaw": "exact"}, UnknownName, "did you mean 'force_law'"),
    (_garden, {"flutterr": 0.1}, UnknownName, "did you mean 'flutter'"),
    (_tank, {"n_fsh": 3}, UnknownName, "did you mean 'n_fish'"),
    (_flock, {"sed": 3}, UnknownName, "did you mean 'seed'"),
    (_flight, {"backnd": "paper"}, UnknownName, "did you mean 'backend'"),
    (_overrides, {"body_area": 1.0}, UnknownName, "did you mean 'body_area_cm2'"),
    (_evolve3d, {"generation": 3}, UnknownName, "did you mean 'generations'"),
    (_optimize, {"populaton": 8}, UnknownName, "did you mean 'population'"),
    (_env, {"backnd": "paper"}, UnknownName, "did you mean 'backend'"),
    (_env, {"params": {"body_area": 1.0}}, UnknownName, "did you mean 'body_area_cm2'"),
    (_env, {"params": {"body_area_cm2": NAN}}, UserError, "body_area_cm2"),
    (_env, {"wind_from_m_s": ("1", 0)}, UserError, "wind component"),
    (_env, {"y0_m": NAN}, UserError, "y0"),
    (_env, {"frame_skip": 0}, UserError, "frame_skip"),
]


@pytest.mark.parametrize("make, kw, kind, words", BAD, ids=[f"{m.__name__}-{sorted(k)}" for m, k, _e, _w in BAD])
def test_a_bad_option_is_one_sentence_naming_it(make, kw, kind, words):
    with pytest.raises(kind) as info:
        make(**kw)
    assert words in str(info.value) and "\n" not in str(info.value), str(info.value)
    if kind is UnknownName:
        assert isinstance(info.value, TypeError)


@pytest.fixture(scope="module")
def env():
    e = _env()
    yield e
    e.close()


@pytest.mark.parametrize("action, words", [
    (np.array([0.1, 0.2, 0.3]), "shape (1,), got shape (3,)"),
    (np.array([]), "got shape (0,)"),
    (np.zeros((2, 2)), "got shape (2, 2)"),
    ("a", "dtype <U1"),
    (np.array([True]), "dtype bool"),
    (np.array([1 + 2j]), "dtype complex128"),
    (np.array([NAN]), "finite"),
    ([None], "dtype object"),
])
def test_an_env_action_of_the_wrong_shape_or_dtype_is_refused(env, action, words):
    env.reset(seed=0)
    with pytest.raises(UserError) as info:
        env.step(action)
    assert words in str(info.value), str(info.value)


def test_an_env_action_of_the_right_shape_steps(env):
    env.reset(seed=0)
    for a in (np.array([0.01]), np.array([[0.01]]), np.array([1], dtype=np.int64), 0.01):
        obs, *_ = env.step(a)
        assert obs.shape == (6,)


def test_reset_options_are_checked(env):
    with pytest.raises(UnknownName, match="did you mean 'condition'"):
        env.reset(options={"conditon": (0.0, (1.0, 0.0))})
    with pytest.raises(UserError, match="must be a dict"):
        env.reset(options=[("condition", 1)])
    obs, info = env.reset(options={"condition": (1.0, (0.0, 0.0))})
    assert obs[4] == 1.0


def test_the_vector_env_checks_its_actions_and_options():
    from lifelike_mj.envs.vector import ButterflyPitchVectorEnv

    v = ButterflyPitchVectorEnv(4)
    v.reset(seed=0)
    for bad, words in ((np.zeros((2, 2)), "(4,) or (4, 1)"), (np.zeros(5), "got shape (5,)"),
                       (np.zeros(4, dtype=bool), "dtype bool")):
        with pytest.raises(UserError, match=words.replace("(", r"\(").replace(")", r"\)")):
            v.step(bad)
    v.step(np.zeros((4, 1)))
    with pytest.raises(UnknownName, match="did you mean 'conditions'"):
        v.reset(options={"condition": [(0.0, (0.0, 0.0))] * 4})
