"""N butterflies stepped in one native call: the vector form of ``ButterflyPitch-v0`` and
``ButterflyPitchWind-v0`` on the paper and MuJoCo backends."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space
from numba import njit

from lifelike_mj.butterfly import PAPER_FLAP, ButterflyParams, Condition
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.envs.butterfly import (
    OBSERVATION_NAMES,
    ButterflyPitchEnv,
    ButterflyPitchWindEnv,
    as_condition,
    check_actions,
    check_num_envs,
    check_options,
    copy_rngs,
)
from lifelike_mj.errors import UserError


@njit(cache=True, error_model="numpy")
def _set_pitch(a, phis, live, dphi_mode, max_dphi, phi_limit):
    """The pitch of each live copy after its action (rad): the change clipped to ``max_dphi`` (action
    mode ``dphi``) or the pitch itself, then clipped to ``phi_limit``, as the single environment does."""
    for b in range(len(a)):
        if live[b]:
            t = phis[b] + min(max(a[b], -max_dphi), max_dphi) if dphi_mode else a[b]
            phis[b] = min(max(t, -phi_limit), phi_limit)


@njit(cache=True, error_model="numpy")
def _observe(cols, phis, airs, relative, obs):
    """Every copy's observation, as the single environment builds it: ``cols`` rows ``y, v_y, v_z,
    theta, omega``; velocities made air-relative if ``relative``; anything not finite shown as 0."""
    for b in range(len(phis)):
        vy = cols[b, 1]
        vz = cols[b, 2]
        if relative:
            vz -= airs[b, 0]
            vy -= airs[b, 1]
        o = obs[b]
        o[0] = phis[b]
        o[1] = cols[b, 4]
        o[2] = cols[b, 3]
        o[3] = vy
        o[4] = cols[b, 0]
        o[5] = vz
        for j in range(6):
            if not math.isfinite(o[j]):
                o[j] = 0.0


@njit(cache=True, error_model="numpy")
def _finish(live, cols, phis, airs, relative, before, after, reset, diverged, ks, n_steps, ground,
            obs, rewards, terminated, truncated):
    """Observation (:func:`_observe`), reward and episode end of every copy after a step, as the single
    environment computes them; a copy that was reset this step (not ``live``) gets reward 0 and no
    episode end."""
    _observe(cols, phis, airs, relative, obs)
    for b in range(len(phis)):
        r = after[b] - before[b]
        rewards[b] = r if live[b] and reset[b] == 0 and math.isfinite(r) else 0.0
        term = live[b] and (diverged[b] >= 0 or (ground > 0.0 and obs[b, 4] < -ground))
        terminated[b] = term
        truncated[b] = live[b] and not term and ks[b] >= n_steps


#: The options ``reset`` takes.
RESET_OPTIONS = ("conditions",)
#: The most copies of the vector form.
MAX_NUM_ENVS = 1_000_000
#: Butterfly-steps per call from which the paper backend's batch runs on threads (measured crossover).
PARALLEL_FROM = 256


class _PaperBatch:
    """The paper backend's butterflies (eq. 7-11, RK4) as rows of arrays: :func:`paper.step_batch`."""

    def __init__(self, n: int, params: ButterflyParams, dt_s: float) -> None:
        self.dt = dt_s
        self.consts = np.tile(paper.constants_row(params), (n, 1))
        self.flaps = np.tile(PAPER_FLAP.as_array(), (n, 1))
        self.states = np.zeros((n, paper.N_STATE))
        self.airs = np.zeros((n, 2))
        self.ks = np.zeros(n, dtype=np.int64)
        self.diverged = np.full(n, -1, dtype=np.int64)
        self.reset = np.zeros(n, dtype=np.int64)  # never set: the paper backend has no solver to reset
        self.cols = np.zeros((n, 5))

    def reset_row(self, i: int, cond: Condition) -> None:
        self.states[i] = paper.initial_state(cond.y0_m)
        self.airs[i] = cond.air_velocity()
        self.ks[i] = 0
        self.diverged[i] = -1

    def step(self, idx: np.ndarray, phis: np.ndarray, n: int) -> None:
        # threads pay off from a few hundred butterfly-steps per call (starting them costs tens of us)
        kernel = paper.step_batch if len(idx) * n >= PARALLEL_FROM else paper.step_batch_serial
        if len(idx) == len(self.ks):
            kernel(phis, self.flaps, self.airs, self.consts, self.states, self.ks, n, self.dt, self.diverged)
            return
        st, ks, dv = self.states[idx], self.ks[idx], self.diverged[idx]
        kernel(phis[idx], self.flaps[idx], self.airs[idx], self.consts[idx], st, ks, n, self.dt, dv)
        self.states[idx], self.ks[idx], self.diverged[idx] = st, ks, dv

    def fitness(self) -> np.ndarray:
        return self.states[:, paper.S_FIT].copy()

    def columns(self) -> np.ndarray:
        """``y, v_y, v_z, theta, omega`` of every row (m, m/s, rad, rad/s)."""
        s, f, c = self.states, self.flaps[0], self.cols
        c[:, 0], c[:, 1], c[:, 2] = s[:, paper.S_Y], s[:, paper.S_VY], s[:, paper.S_VZ]
        c[:, 3] = f[0] + f[1] * s[:, paper.S_CW]
        c[:, 4] = -f[1] * f[2] * s[:, paper.S_SW]
        return c


class _MujocoBatch:
    """The MuJoCo backend's butterflies: one ``mjData`` per row on one model, stepped together by
    :func:`lifelike_mj.butterfly.backends.mj.step_batch` with the compiled wing-force callback."""

    def __init__(self, n: int, params: ButterflyParams, dt_s: float, config: str, force_mode: str | None,
                 controller) -> None:
        from lifelike_mj.butterfly.backends import mj, mujoco_options
        from lifelike_mj.physics.callbacks import passive_callback
        from lifelike_mj.physics.stability import watching

        self.mj, self._passive_callback, self._watching = mj, passive_callback, watching
        self.dt = dt_s
        self.params = params
        self.options = mujoco_options(config, force_mode)
        self.model = mj.build_model(params, self.options["config"])
        self.model.opt.timestep = dt_s
        self.lay = mj.layout(self.model).as_array()
        self.flap = controller.flap.as_array()
        self._controller = controller  # setup_data reads its flap pattern
        self.datas: list = [None] * n
        self.dptrs = np.zeros(n, dtype=np.int64)
        self.ks = np.zeros(n, dtype=np.int64)
        self.diverged = np.full(n, -1, dtype=np.int64)
        self.reset = np.zeros(n, dtype=np.int64)
        self.fits = np.zeros(n)
        self.cols = np.zeros((n, 5))

    def reset_row(self, i: int, cond: Condition) -> None:
        d = self.mj.setup_data(self.model, self._controller, self.params, cond, self.options["force_mode"])
        self.datas[i] = d
        self.dptrs[i] = d._address
        self.ks[i] = 0
        self.diverged[i] = -1
        self.reset[i] = 0
        self.fits[i] = 0.0
        f = self.flap
        self.cols[i] = (d.qpos[self.lay[2]], d.qvel[self.lay[4]], d.qvel[self.lay[3]], f[0] + f[1] * math.cos(0.0),
                        -f[1] * f[2] * math.sin(0.0))

    def step(self, idx: np.ndarray, phis: np.ndarray, n: int) -> None:
        mj = self.mj
        with self._passive_callback(mj.COMPILED_PASSIVE), self._watching():
            mj.step_batch(self.model._address, self.dptrs, idx, phis, self.ks, n, self.flap, self.lay, self.dt,
                          self.diverged, self.reset, self.fits, self.cols, mj._OFFSETS)

    def fitness(self) -> np.ndarray:
        return self.fits.copy()

    def columns(self) -> np.ndarray:
        """``y, v_y, v_z, theta, omega`` of every row (m, m/s, rad, rad/s), written by each step."""
        return self.cols


class ButterflyPitchVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`~lifelike_mj.envs.butterfly.ButterflyPitchEnv` (or, with
    ``wind=True``, of :class:`~lifelike_mj.envs.butterfly.ButterflyPitchWindEnv`) as one Gymnasium
    :class:`~gymnasium.vector.VectorEnv`, all stepped together by one compiled, multi-threaded call:
    :func:`lifelike_mj.butterfly.backends.paper.step_batch` on the paper backend (eq. 7-11),
    :func:`lifelike_mj.butterfly.backends.mj.step_batch` on the MuJoCo backend (one ``mjData`` per copy,
    ``mj_step`` called from native code on every core).

    Spaces, reward and episode end are those of the single environment, batched. Gymnasium 1.x
    semantics: ``reset(seed=s)`` seeds copy ``i`` with ``s + i`` (the wind variant then draws the same
    condition as a single env reset with that seed), and autoreset is ``NEXT_STEP``: the step after an
    episode ends resets that copy, ignores its action and returns its first observation with reward 0.
    ``reset(options={"conditions": [(y0_m, (a, b)), ...]})`` starts copy ``i`` from the ``i``-th start
    altitude and wind (m; m/s, where the wind comes from) for that episode, for instance to fly one
    controller over a grid of winds; autoresets go back to the environment's own conditions.
    The episodes are those of ``num_envs`` single environments, bit for bit (tested, both backends).

    Keyword arguments are the single environment's (``render_mode`` is not offered: render a single
    environment); ``num_envs`` is a whole number from 1 to 1,000,000. ``info["diverged"]`` marks the copies whose
    episode ended by divergence. Made by ``gymnasium.make_vec("lifelike_mj/ButterflyPitch-v0", num_envs=N,
    vectorization_mode="vector_entry_point")`` (or ``ButterflyPitchWind-v0``).
    """

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 64, wind: bool = False, **kwargs: Any) -> None:
        if kwargs.get("render_mode") is not None:
            raise UserError("the vector environment does not render; render a single ButterflyPitch-v0.")
        num_envs = check_num_envs(num_envs, MAX_NUM_ENVS)
        self.single = (ButterflyPitchWindEnv if wind else ButterflyPitchEnv)(**kwargs)
        self.num_envs = num_envs
        self.single_observation_space = self.single.observation_space
        self.single_action_space = self.single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        s = self.single
        if s.backend == "paper":
            self._batch: _PaperBatch | _MujocoBatch = _PaperBatch(num_envs, s.params, s.dt_s)
        else:
            opts = s._flight_options
            self._batch = _MujocoBatch(num_envs, s.params, s.dt_s, opts["config"], opts["force_mode"], s._controller)
        self._phis = np.zeros(num_envs)
        self._every = np.arange(num_envs)
        self._all_live = np.ones(num_envs, dtype=bool)
        self._airs = np.zeros((num_envs, 2))
        self._ended = np.zeros(num_envs, dtype=bool)
        self._rngs: list[np.random.Generator] = [np.random.default_rng() for _ in range(num_envs)]
        self._conditions: list[Condition] = [s.condition] * num_envs

    # ---- the VectorEnv API ----------------------------------------------------------------------

    def reset(self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None):
        check_options(options, RESET_OPTIONS)
        if seed is not None:
            self._rngs = copy_rngs(seed, self.num_envs)
        chosen = (options or {}).get("conditions")
        if chosen is not None:
            chosen = [as_condition(c) for c in chosen]
            if len(chosen) != self.num_envs:
                raise UserError(f"options['conditions'] needs one (y0_m, (a, b)) pair per copy ({self.num_envs}), "
                                f"got {len(chosen)}.")
        for i in range(self.num_envs):
            self._reset_one(i, None if chosen is None else chosen[i])
        return self._observations(), self._reset_info(np.ones(self.num_envs, dtype=bool))

    def step(self, actions):
        n, s, b = self.num_envs, self.single, self._batch
        a = check_actions(actions, n)
        live, all_live = self._all_live, True
        if self._ended.any():  # NEXT_STEP autoreset of the copies whose episode ended on the last step
            live, all_live = ~self._ended, False
            for i in np.flatnonzero(self._ended):
                self._reset_one(i)
        _set_pitch(a, self._phis, live, s.action_mode == "dphi", s.max_dphi, s.phi_limit)
        before = b.fitness()
        left = s.n_steps - b.ks
        if all_live and left.min() >= s.frame_skip:
            b.step(self._every, self._phis, s.frame_skip)  # one native call for all copies
        else:
            steps = np.minimum(s.frame_skip, left)
            for k in np.unique(steps[live]):  # one call per distinct step count (near an episode's end)
                if k > 0:
                    b.step(np.flatnonzero(live & (steps == k)), self._phis, int(k))
        obs, rewards = np.empty((n, 6)), np.empty(n)
        terminated, truncated = np.empty(n, dtype=bool), np.empty(n, dtype=bool)
        _finish(live, b.columns(), self._phis, self._airs, s.inputs == "air", before, b.fitness(), b.reset,
                b.diverged, b.ks, s.n_steps, -1.0 if s.ground_m is None else s.ground_m, obs, rewards, terminated,
                truncated)
        self._ended = terminated | truncated
        info = {} if all_live else self._reset_info(~live)
        diverged = live & (b.diverged >= 0)
        if diverged.any():
            info["diverged"] = diverged
        return obs, rewards, terminated, truncated, info

    # ---- internals ------------------------------------------------------------------------------

    def _reset_one(self, i: int, condition: Condition | None = None) -> None:
        s = self.single
        if condition is not None:
            self._conditions[i] = condition
        elif isinstance(s, ButterflyPitchWindEnv):
            self._conditions[i] = s.conditions[int(self._rngs[i].integers(len(s.conditions)))]
        else:
            self._conditions[i] = s._own_condition
        self._batch.reset_row(i, self._conditions[i])
        self._airs[i] = self._conditions[i].air_velocity()
        self._phis[i] = 0.0
        self._ended[i] = False

    def _observations(self) -> np.ndarray:
        obs = np.empty((self.num_envs, 6))
        _observe(self._batch.columns(), self._phis, self._airs, self.single.inputs == "air", obs)
        return obs

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
