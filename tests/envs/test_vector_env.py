"""The vector environment gives the episodes of N single environments, bit for bit."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import lifelike_mj.envs  # noqa: E402,F401
from lifelike_mj.envs.butterfly import ButterflyPitchEnv, ButterflyPitchWindEnv  # noqa: E402
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv  # noqa: E402


@pytest.mark.parametrize("backend,wind,action_mode", [("paper", False, "dphi"), ("paper", False, "phi"),
                                                     ("paper", True, "dphi"), ("paper", True, "phi"),
                                                     ("mujoco", False, "dphi"), ("mujoco", True, "phi")])
def test_vector_equals_single_envs_with_next_step_autoreset(backend, wind, action_mode):
    n, kw = 5, {"duration_s": 0.1, "action_mode": action_mode, "frame_skip": 3, "backend": backend}
    vec = ButterflyPitchVectorEnv(n, wind=wind, **kw)
    singles = [(ButterflyPitchWindEnv if wind else ButterflyPitchEnv)(**kw) for _ in range(n)]
    vobs, vinfo = vec.reset(seed=10)
    sobs = [e.reset(seed=10 + i)[0] for i, e in enumerate(singles)]
    np.testing.assert_array_equal(vobs, np.array(sobs))
    rng = np.random.default_rng(1)
    ended = [False] * n
    autoresets = 0
    for _ in range(130):  # 40 steps per episode (0.1 s at 1/1200 s, frame skip 3): three episodes each
        actions = rng.uniform(-0.1, 0.1, (n, 1))
        vobs, vrew, vterm, vtrunc, _ = vec.step(actions)
        for i, e in enumerate(singles):
            if ended[i]:  # NEXT_STEP autoreset: this step resets the copy and ignores its action
                obs, r, term, trunc = e.reset()[0], 0.0, False, False
                autoresets += 1
            else:
                obs, r, term, trunc, _ = e.step(actions[i])
            np.testing.assert_array_equal(vobs[i], obs)
            assert (vrew[i], vterm[i], vtrunc[i]) == (r, term, trunc)
            ended[i] = term or trunc
    assert autoresets >= 2 * n


def test_gymnasium_make_vec_and_its_checker():
    from gymnasium.utils.env_checker import check_env  # noqa: F401  (the single env is checked elsewhere)

    vec = gym.make_vec("lifelike_mj/ButterflyPitch-v0", num_envs=8, vectorization_mode="vector_entry_point",
                       duration_s=0.05)
    obs, _ = vec.reset(seed=0)
    assert obs.shape == (8, 6) and vec.observation_space.contains(obs)
    obs, rew, term, trunc, _ = vec.step(vec.action_space.sample())
    assert rew.shape == (8,) and rew.dtype == np.float64 and not term.any()


def test_vector_env_refuses_what_it_does_not_do():
    from lifelike_mj.errors import UserError

    with pytest.raises(UserError, match="does not render"):
        ButterflyPitchVectorEnv(4, render_mode="rgb_array")
    with pytest.raises(UserError, match="num_envs"):
        ButterflyPitchVectorEnv(0)


def test_a_mujoco_reset_ends_that_copy_alone_with_no_reward(tmp_path, monkeypatch):
    """MuJoCo resets a copy whose state is huge: that copy's episode ends (terminated, diverged, reward 0:
    nothing after a reset is valid) and starts again on the next step; the others fly on undisturbed."""
    monkeypatch.chdir(tmp_path)
    vec = ButterflyPitchVectorEnv(3, backend="mujoco", duration_s=0.1)
    single = ButterflyPitchEnv(backend="mujoco", duration_s=0.1)
    vec.reset(seed=0)
    single.reset(seed=0)
    a = np.full((3, 1), 0.01)
    for _ in range(5):
        vec.step(a)
        single.step(a[0])
    b = vec._batch
    b.datas[1].qpos[int(b.lay[2])] = 1e11  # an altitude of 1e11 m: MuJoCo resets this copy inside mj_step
    obs, rew, term, trunc, info = vec.step(a)
    sobs, srew, *_ = single.step(a[0])
    assert list(term) == [False, True, False] and not trunc.any() and list(info["diverged"]) == [False, True, False]
    assert rew[1] == 0.0 and rew[0] == rew[2] == srew
    np.testing.assert_array_equal(obs[0], sobs)
    obs, rew, term, trunc, _ = vec.step(a)  # NEXT_STEP: copy 1 starts again
    assert rew[1] == 0.0 and not term.any() and obs[1][4] == 0.0 and obs[1][3] == 0.0
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
