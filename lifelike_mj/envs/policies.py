"""The library's butterfly controllers as policies of ``ButterflyPitch-v0`` (action mode ``"phi"``).

A controller file's pitch law (simple rule, the paper's network, a deeper network, a constant pitch)
reads the environment's observation and returns the pitch to set: ``controller_policy`` for one
controller, :func:`pitch_actions` for a batch of compiled controllers (one per copy of a vector
environment, as an evolution strategy asks for them), all in one compiled loop.

The other way round, a network trained by a reinforcement-learning library becomes a controller file:
train it on :class:`NetworkInputs` and :class:`NetworkActions` over the environment, with eq. 12's
transfer function as its activation, then :func:`network_controller` (``examples/gym_sb3_ppo.py``).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numba import njit

from lifelike_mj.butterfly import PAPER_FLAP, ButterflyController, ann, ann_controller
from lifelike_mj.butterfly import controllers as _controllers
from lifelike_mj.butterfly.flight import pitch_command
from lifelike_mj.errors import UserError


@njit(cache=True)
def _actions(kinds, cparams, obs, out):
    for i in range(obs.shape[0]):
        o = obs[i]
        # observation: phi_prev, omega, theta, v_y, y, v_z; its velocities are already those the
        # controller reads (air-relative or ground), so the air velocity passed on is 0
        out[i, 0] = pitch_command(kinds[i], cparams[i], 0.0, o[2], o[1], o[4], 0.0, o[3], o[5], 0.0, 0.0, o[0])


#: The environment's word for the speed inputs (``air``, ``ground``) and the planar controller file's (``relative``,
#: ``ground``; the files keep their word).
FILE_WORD = {"air": "relative", "ground": "ground"}
ENV_WORD = {"relative": "air", "ground": "ground"}


def pitch_actions(kinds: np.ndarray, cparams: np.ndarray, obs: np.ndarray) -> np.ndarray:
    """The pitch (rad) each compiled controller chooses from its copy's observation: ``kinds[i]`` and
    ``cparams[i]`` (rows of :meth:`~lifelike_mj.butterfly.ButterflyController.compiled`, padded to one
    length) read ``obs[i]`` (the six inputs of Oe 2010 section 6.1, SI units). Returns an ``(N, 1)``
    action array for ``action_mode="phi"``. The controllers' velocity inputs must be the environment's
    (``inputs``): the observation is passed on as it is."""
    obs = np.ascontiguousarray(np.atleast_2d(obs), dtype=np.float64)
    out = np.empty((obs.shape[0], 1))
    _actions(np.ascontiguousarray(kinds, dtype=np.int64), np.ascontiguousarray(np.atleast_2d(cparams), dtype=np.float64),
             obs, out)
    return out


def episode_returns(env, kinds: np.ndarray, cparams: np.ndarray, *, seed: int | None = None,
                    options: dict | None = None) -> np.ndarray:
    """One episode of each copy of the vector environment ``env`` (``action_mode="phi"``) flown by its
    compiled controller (:func:`pitch_actions`), from ``env.reset(seed=seed, options=options)``: the
    summed rewards, eq. 13's H of each flight. The steps after a copy's episode ends (its autoreset)
    are not counted."""
    obs, _ = env.reset(seed=seed, options=options)
    total, done = np.zeros(env.num_envs), np.zeros(env.num_envs, dtype=bool)
    while not done.all():
        obs, reward, term, trunc, _ = env.step(pitch_actions(kinds, cparams, obs))
        total += np.where(done, 0.0, reward)
        done |= term | trunc
    return total


def controller_policy(controller: ButterflyController | str | Path, env) -> Callable[[np.ndarray], np.ndarray]:
    """``policy(obs) -> action`` that flies ``controller`` (an object, or a controller file's name or
    path) through ``env`` (a single or vector ``ButterflyPitch`` environment with ``action_mode="phi"``):
    the action is an ``(1,)`` array for one observation, ``(N, 1)`` for a batch. A network controller
    reads velocities of the kind the environment observes (``inputs``); a mismatch is refused."""
    ctrl = controller if isinstance(controller, ButterflyController) else _controllers.load(controller)
    single = getattr(env, "single", getattr(env, "unwrapped", env))
    if single.action_mode != "phi":
        raise UserError("a controller sets the pitch itself: make the environment with action_mode='phi'.")
    wants = ctrl.parameters.get("inputs")
    if wants is not None and wants != FILE_WORD[single.inputs]:
        raise UserError(f"the controller reads {wants} velocities but the environment observes {single.inputs} ones; "
                        f"make it with inputs={ENV_WORD[wants]!r} (or use "
                        f"controller.with_inputs({FILE_WORD[single.inputs]!r})).")
    kind, cp = ctrl.compiled()
    kinds, cps = np.array([kind], dtype=np.int64), np.ascontiguousarray(cp, dtype=np.float64)[None, :]

    def policy(obs: np.ndarray) -> np.ndarray:
        o = np.asarray(obs, dtype=np.float64)
        n = 1 if o.ndim == 1 else o.shape[0]
        act = pitch_actions(np.repeat(kinds, n), np.repeat(cps, n, axis=0), o)
        return act[0] if o.ndim == 1 else act

    return policy


# ---- a network trained elsewhere (RL), in the controller file's form -------------------------------


class NetworkInputs(gym.ObservationWrapper):
    """The observation scaled as a network controller's inputs (Oe 2010 section 6.1, the scales of
    :mod:`lifelike_mj.butterfly.ann`): ``phi / 30 deg``, ``omega / peak rate``, ``(theta - centre) /
    half range``, ``v_y / 2 m/s``, ``y / 10 m``, ``v_z / 3 m/s`` (dimensionless, about [-1, 1]). A policy
    that reads these and acts through :class:`NetworkActions` is a network of the controller file's kind
    (:func:`network_controller` writes it out)."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        u = env.unwrapped
        cp = ann.compile_params(FILE_WORD[u.inputs], ann.default_scales(PAPER_FLAP), np.zeros(ann.N_WEIGHTS))
        self._scale = cp[ann.A_SCALE : ann.A_W].copy()
        self._shift = np.array([0.0, 0.0, cp[ann.A_THETA_C], 0.0, 0.0, 0.0])
        box = env.observation_space
        self.observation_space = spaces.Box((box.low - self._shift) * self._scale, (box.high - self._shift) * self._scale,
                                            (6,), dtype=np.float64)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        return (np.asarray(observation, dtype=np.float64) - self._shift) * self._scale


class NetworkActions(gym.ActionWrapper):
    """The action as a network controller's output neuron (Oe 2010 eq. 12): the agent gives the neuron's
    sum ``u`` in [-2, 2] (``G`` is flat beyond, ``G(2) = 1 - 1.5e-8``) and the environment changes the
    pitch by ``max_dphi G(u)``, as the network does. Needs ``action_mode="dphi"``."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        if env.unwrapped.action_mode != "dphi":
            raise UserError("NetworkActions changes the pitch by max_dphi G(u): make the env with action_mode='dphi'.")
        self._max = float(env.unwrapped.max_dphi)
        self.action_space = spaces.Box(-2.0, 2.0, (1,), dtype=np.float64)

    def action(self, action: np.ndarray) -> np.ndarray:
        u = float(np.clip(np.asarray(action, dtype=np.float64).reshape(-1)[0], -2.0, 2.0))
        return np.array([self._max * ann.transfer(u)])


def network_controller(layers: list[tuple[np.ndarray, np.ndarray]], inputs: str = "air",
                       provenance: dict | None = None) -> ButterflyController:
    """A network controller (the controller file's ``ann`` type) from a trained network's layers
    ``[(W, b), ...]`` (``W`` of shape (outputs, inputs), as ``torch.nn.Linear`` keeps it): hidden layers
    with eq. 12's ``G``, a single output neuron, inputs as :class:`NetworkInputs` gives them and the
    output as :class:`NetworkActions` uses it. ``butterfly fly`` and the viewer fly the result."""
    sizes = [int(np.asarray(layers[0][0]).shape[1])] + [int(np.asarray(w).shape[0]) for w, _ in layers]
    flat = []
    for w, b in layers:
        w, b = np.asarray(w, dtype=np.float64), np.asarray(b, dtype=np.float64).reshape(-1)
        for j in range(w.shape[0]):  # per neuron: its input weights, then its bias
            flat.extend(w[j].tolist())
            flat.append(float(b[j]))
    return ann_controller(np.array(flat), PAPER_FLAP, FILE_WORD.get(inputs, inputs), provenance=provenance, layers=sizes)
