"""A run's body poses sampled at a frame rate: what every exporter writes.

A body is exported when it carries a geom that is drawn by default (MuJoCo's visible groups 0, 1 and 2,
and not fully transparent): the looks of the creature, not its mass or fluid geoms. The world body's
drawn geoms (ground, tank, flowers) are exported as still objects.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: Geom groups drawn by default (MuJoCo's ``mjvOption.geomgroup`` starts with groups 0, 1 and 2 on).
DRAWN_GROUPS = (0, 1, 2)


def drawn_geoms(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the geoms drawn by default: in a drawn group and not fully transparent."""
    rgba = geom_rgba(model)
    keep = np.isin(model.geom_group, DRAWN_GROUPS) & (rgba[:, 3] > 0.0)
    return np.nonzero(keep)[0]


def geom_rgba(model: mujoco.MjModel) -> np.ndarray:
    """Each geom's colour (RGBA in [0, 1]): its material's where it has one, else its own."""
    rgba = model.geom_rgba.copy()
    has_mat = model.geom_matid >= 0
    rgba[has_mat] = model.mat_rgba[model.geom_matid[has_mat]]
    return rgba


@dataclass
class Poses:
    """Body poses over time, in MuJoCo's world frame (m, Z up): ``t_s`` (frames), ``position_m``
    ``(frames, bodies, 3)``, ``quat_wxyz`` ``(frames, bodies, 4)`` (unit, sign-continuous from frame to frame)
    of the bodies ``body_ids`` (names ``body_names``); ``model``: the MuJoCo model they belong to."""

    model: mujoco.MjModel
    body_ids: np.ndarray
    body_names: list[str]
    t_s: np.ndarray
    position_m: np.ndarray
    quat_wxyz: np.ndarray

    @property
    def n_frames(self) -> int:
        return len(self.t_s)


def animated_bodies(model: mujoco.MjModel) -> np.ndarray:
    """Ids of the bodies other than the world that carry a drawn geom (:func:`drawn_geoms`)."""
    bodies = np.unique(model.geom_bodyid[drawn_geoms(model)])
    return bodies[bodies > 0]


def frames_of(duration_s: float, fps: float, unit: str = "s") -> int:
    """The frames :func:`record_poses` samples over ``duration_s`` (of the stepper's time unit ``unit``) at ``fps``
    frames per unit, the first and the last included: checked before any simulation (at least 2, at most
    :data:`~lifelike_mj.checks.MAX_FRAMES`)."""
    fps = checks.positive("fps", fps, f"frames/{unit}")
    duration_s = checks.positive("the duration", duration_s, unit)
    n = float(np.floor(duration_s * fps + 1e-9)) + 1
    if n < 2:
        raise UserError(f"a window of {duration_s:g} {unit} at {fps:g} frames per {unit} holds a single frame; give "
                        "more time or frames.")
    return checks.work(f"a window of {duration_s:g} {unit} at {fps:g} frames per {unit}", n, checks.MAX_FRAMES,
                       "frames", "a shorter window or fewer frames per second")


def record_poses(stepper, duration_s: float, fps: float = 30.0, time_scale: float = 1.0) -> Poses:
    """Run ``stepper`` on for ``duration_s`` of its time from where it is, sampling its drawn bodies' poses
    ``fps`` times per unit of its time (the first frame is the state now). Each frame lies on the nearest
    whole step; its time is that step's, times ``time_scale``: the seconds of playback per unit of the
    stepper's time (1 for the creatures that live in seconds; a flock's time is counted in steps, so
    ``time_scale = 1 / (steps per frame x frames per second)`` plays it at a frame rate). ``stepper``: anything
    in the stepper shape (``model``, ``data``, ``step``, ``sync``, ``dt``, ``time``)."""
    time_scale = checks.positive("time_scale", time_scale, "s per unit")
    n_frames = frames_of(duration_s, fps)
    dt = float(stepper.dt)
    t0 = float(stepper.time)
    done = 0
    times, pos, quat = [], [], []
    bodies = None
    for k in range(n_frames):
        target = int(round(k / fps / dt))
        if target > done:
            stepper.step(target - done)
            done = target
        stepper.sync()
        m, d = stepper.model, stepper.data
        if bodies is None:
            bodies = animated_bodies(m)
            if len(bodies) == 0:
                raise UserError("the model has no drawn body to export (no geom in groups 0-2).")
        times.append(t0 + done * dt)
        pos.append(d.xpos[bodies].copy())
        quat.append(d.xquat[bodies].copy())
    q = np.array(quat)
    q /= np.linalg.norm(q, axis=2, keepdims=True)
    for k in range(1, len(q)):  # q and -q are the same rotation: keep neighbours on one side for slerp
        flip = np.sum(q[k] * q[k - 1], axis=1) < 0.0
        q[k, flip] *= -1.0
    m = stepper.model
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(b)) or f"body{int(b)}" for b in bodies]
    return Poses(m, bodies, names, np.array(times) * time_scale, np.array(pos), q)
