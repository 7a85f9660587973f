"""The library's butterfly controllers as policies of ``ButterflyPitch-v0`` (action mode ``"phi"``).

A controller file's pitch law (simple rule, the paper's network, a deeper network, a constant pitch)
reads the environment's observation and returns the pitch to set: ``controller_policy`` for one
controller, :func:`pitch_actions` for a batch of compiled controllers (one per copy of a vector
environment, as an evolution strategy asks for them), all in one compiled loop.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
from numba import njit

from lifelike_mj.butterfly import ButterflyController
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
    if wants is not None and wants != single.inputs:
        raise UserError(f"the controller reads {wants} velocities but the environment observes {single.inputs} ones; "
                        f"make it with inputs={wants!r} (or use controller.with_inputs({single.inputs!r})).")
    kind, cp = ctrl.compiled()
    kinds, cps = np.array([kind], dtype=np.int64), np.ascontiguousarray(cp, dtype=np.float64)[None, :]

    def policy(obs: np.ndarray) -> np.ndarray:
        o = np.asarray(obs, dtype=np.float64)
        n = 1 if o.ndim == 1 else o.shape[0]
        act = pitch_actions(np.repeat(kinds, n), np.repeat(cps, n, axis=0), o)
        return act[0] if o.ndim == 1 else act

    return policy
