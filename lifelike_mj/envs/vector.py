"""N butterflies stepped in one native call: the vector form of ``ButterflyPitch-v0`` and
``ButterflyPitchWind-v0`` on the paper backend."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from lifelike_mj.butterfly import PAPER_FLAP, Condition
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.envs.butterfly import OBSERVATION_NAMES, ButterflyPitchEnv, ButterflyPitchWindEnv
from lifelike_mj.errors import UserError


class ButterflyPitchVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`~lifelike_mj.envs.butterfly.ButterflyPitchEnv` (or, with
    ``wind=True``, of :class:`~lifelike_mj.envs.butterfly.ButterflyPitchWindEnv`) as one Gymnasium
    :class:`~gymnasium.vector.VectorEnv`, all stepped together by one compiled, multi-threaded call
    (:func:`lifelike_mj.butterfly.backends.paper.step_batch`).

    Spaces, reward and episode end are those of the single environment, batched. Gymnasium 1.x
    semantics: ``reset(seed=s)`` seeds copy ``i`` with ``s + i`` (the wind variant then draws the same
    condition as a single env reset with that seed), and autoreset is ``NEXT_STEP``: the step after an
    episode ends resets that copy, ignores its action and returns its first observation with reward 0.
    The episodes are those of ``num_envs`` single environments, bit for bit (tested).

    Only the paper backend (eq. 7-11) is batched; keyword arguments are the single environment's
    (``backend`` must be ``"paper"``; ``render_mode`` is not offered).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 64, wind: bool = False, **kwargs: Any) -> None:
        if kwargs.get("backend", "paper") != "paper":
            raise UserError("the vector environment steps the paper backend; use gymnasium's SyncVectorEnv over "
                            "ButterflyPitch-v0 for the MuJoCo backend.")
        if kwargs.get("render_mode") is not None:
            raise UserError("the vector environment does not render; render a single ButterflyPitch-v0.")
        if not (isinstance(num_envs, int) and 1 <= num_envs <= 1_000_000):
            raise UserError(f"num_envs must be a whole number from 1 to 1,000,000, got {num_envs!r}.")
        self.single = (ButterflyPitchWindEnv if wind else ButterflyPitchEnv)(**kwargs)
        self.num_envs = num_envs
        self.single_observation_space = self.single.observation_space
        self.single_action_space = self.single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        s = self.single
        self._consts = np.tile(paper.constants_row(s.params), (num_envs, 1))
        self._flaps = np.tile(PAPER_FLAP.as_array(), (num_envs, 1))
        self._states = np.zeros((num_envs, paper.N_STATE))
        self._airs = np.zeros((num_envs, 2))
        self._ks = np.zeros(num_envs, dtype=np.int64)
        self._diverged = np.full(num_envs, -1, dtype=np.int64)
        self._phis = np.zeros(num_envs)
        self._ended = np.zeros(num_envs, dtype=bool)
        self._rngs: list[np.random.Generator] = [np.random.default_rng() for _ in range(num_envs)]
        self._conditions: list[Condition] = [s.condition] * num_envs

    # ---- the VectorEnv API ----------------------------------------------------------------------

    def reset(self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None):
        if seed is not None:
            seeds = list(seed) if isinstance(seed, (list, tuple)) else [int(seed) + i for i in range(self.num_envs)]
            if len(seeds) != self.num_envs:
                raise UserError(f"give one seed or {self.num_envs} seeds, got {len(seeds)}.")
            self._rngs = [gym.utils.seeding.np_random(sd)[0] for sd in seeds]
        for i in range(self.num_envs):
            self._reset_one(i)
        return self._observations(), self._reset_info(np.ones(self.num_envs, dtype=bool))

    def step(self, actions):
        a = np.asarray(actions, dtype=np.float64).reshape(self.num_envs, -1)[:, 0]
        if not np.all(np.isfinite(a)):
            raise ValueError("every action must be a finite number")
        s = self.single
        resetting = self._ended.copy()
        for i in np.flatnonzero(resetting):
            self._reset_one(i)
        live = ~resetting
        if s.action_mode == "dphi":
            target = self._phis + np.clip(a, -s.max_dphi, s.max_dphi)
        else:
            target = a
        self._phis = np.where(live, np.clip(target, -s.phi_limit, s.phi_limit), self._phis)
        before = self._states[:, paper.S_FIT].copy()
        n = min(s.frame_skip, s.n_steps)  # every live copy has at least frame_skip steps left, or fewer at the end
        left = s.n_steps - self._ks
        steps = np.minimum(n, left)
        diverged_before = self._diverged.copy()
        for k in np.unique(steps[live]):  # one native call per distinct step count (one, but at an episode's end)
            idx = np.flatnonzero(live & (steps == k))
            self._step_rows(idx, int(k))
        rewards = np.where(live, self._states[:, paper.S_FIT] - before, 0.0)
        rewards = np.where(np.isfinite(rewards), rewards, 0.0)
        obs = self._observations()
        terminated = live & (self._diverged >= 0) & (diverged_before < 0)
        if s.ground_m is not None:
            terminated |= live & (obs[:, 4] < -s.ground_m)
        truncated = live & ~terminated & (self._ks >= s.n_steps)
        self._ended = terminated | truncated
        info = self._reset_info(resetting)
        if terminated.any():
            info["diverged"] = terminated & (self._diverged >= 0)
        return obs, rewards, terminated, truncated, info

    # ---- internals ------------------------------------------------------------------------------

    def _reset_one(self, i: int) -> None:
        s = self.single
        if isinstance(s, ButterflyPitchWindEnv):
            self._conditions[i] = s.conditions[int(self._rngs[i].integers(len(s.conditions)))]
        cond = self._conditions[i]
        self._states[i] = paper.initial_state(cond.y0_m)
        self._airs[i] = cond.air_velocity()
        self._ks[i] = 0
        self._diverged[i] = -1
        self._phis[i] = 0.0
        self._ended[i] = False

    def _step_rows(self, idx: np.ndarray, n: int) -> None:
        if n <= 0 or not len(idx):
            return
        if len(idx) == self.num_envs:
            paper.step_batch(self._phis, self._flaps, self._airs, self._consts, self._states, self._ks, n,
                             self.single.dt_s, self._diverged)
            return
        st, ks, dv = self._states[idx], self._ks[idx], self._diverged[idx]
        paper.step_batch(self._phis[idx], self._flaps[idx], self._airs[idx], self._consts[idx], st, ks, n,
                         self.single.dt_s, dv)
        self._states[idx], self._ks[idx], self._diverged[idx] = st, ks, dv

    def _observations(self) -> np.ndarray:
        s, f = self._states, PAPER_FLAP.as_array()
        vy, vz = s[:, paper.S_VY].copy(), s[:, paper.S_VZ].copy()
        if self.single.inputs == "relative":
            vz -= self._airs[:, 0]
            vy -= self._airs[:, 1]
        out = np.stack([s[:, paper.S_PHI], -f[1] * f[2] * s[:, paper.S_SW], f[0] + f[1] * s[:, paper.S_CW], vy,
                        s[:, paper.S_Y], vz], axis=1)
        return np.where(np.isfinite(out), out, 0.0)

    def _reset_info(self, which: np.ndarray) -> dict:
        info: dict[str, Any] = {}
        if which.any():
            info["observation_names"] = OBSERVATION_NAMES
            info["y0_m"] = np.array([c.y0_m for c in self._conditions])
            info["_y0_m"] = which.copy()
        return info


def ButterflyPitchWindVectorEnv(num_envs: int = 64, **kwargs: Any) -> ButterflyPitchVectorEnv:  # noqa: N802
    """The vector form of ``ButterflyPitchWind-v0`` (``ButterflyPitchVectorEnv(wind=True)``)."""
    return ButterflyPitchVectorEnv(num_envs, wind=True, **kwargs)
