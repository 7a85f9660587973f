"""A run's body poses sampled at every step of the simulation, with the frames of its playback: what every
exporter writes (keyed by :mod:`lifelike_mj.export.keys`).

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
from lifelike_mj.export.keys import DEFAULT_TOLERANCE, Track, body_tracks, tolerance_of

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


def geom_looks(model: mujoco.MjModel) -> tuple[np.ndarray, list[str]]:
    """Each geom's look: an index shared by the geoms that look alike (the same MJCF material and colour, or,
    without a material, the same colour) and each look's name: its MJCF material's (``wing``, ``body``,
    ``fish_blue``; the prefix of an attached copy, ``s0/f3/``, left off, so that every fish wears one
    ``fish_blue``), else the name of the first geom that wears it (``geom7`` where that has none)."""
    rgba = np.round(geom_rgba(model), 6)
    index = np.empty(model.ngeom, dtype=np.int64)
    seen: dict[tuple, int] = {}
    names: list[str] = []
    for g in range(model.ngeom):
        mat = int(model.geom_matid[g])
        material = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_MATERIAL, mat) if mat >= 0 else None
        material = material.rsplit("/", 1)[-1] if material else None
        key = (material, tuple(rgba[g].tolist()))
        if key not in seen:
            seen[key] = len(names)
            names.append(material or mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or f"geom{g}")
        index[g] = seen[key]
    return index, names


@dataclass
class Poses:
    """Body poses over time, in MuJoCo's world frame (m, Z up): ``t_s`` (the samples' playback times, s),
    ``position_m`` ``(samples, bodies, 3)``, ``quat_wxyz`` ``(samples, bodies, 4)`` (unit, sign-continuous from
    sample to sample) of the bodies ``body_ids`` (names ``body_names``); ``model``: the MuJoCo model they belong
    to. The samples are the simulation's steps (or only its frames, when recorded so); ``frame_samples``: the
    sample shown by each playback frame, ``fps`` frames per second of playback."""

    model: mujoco.MjModel
    body_ids: np.ndarray
    body_names: list[str]
    t_s: np.ndarray
    position_m: np.ndarray
    quat_wxyz: np.ndarray
    frame_samples: np.ndarray | None = None
    fps: float = 0.0

    def __post_init__(self) -> None:
        if self.frame_samples is None:  # every sample is a frame
            self.frame_samples = np.arange(len(self.t_s))
        if not self.fps:
            span = float(self.t_s[-1] - self.t_s[0]) if len(self.t_s) else 0.0
            self.fps = (self.n_frames - 1) / span if span > 0 else 0.0

    @property
    def n_frames(self) -> int:
        """Playback frames."""
        return len(self.frame_samples)

    @property
    def n_samples(self) -> int:
        return len(self.t_s)

    def tracks(self, tolerance=DEFAULT_TOLERANCE, rotations: str = "short") -> list[Track]:
        """Each body's keys within ``tolerance`` (m, deg) for ``rotations`` ("short" or "float") storage
        (:func:`~lifelike_mj.export.keys.body_tracks`), computed once per tolerance."""
        key = (tolerance_of(tolerance), rotations)
        cache = self.__dict__.setdefault("_tracks", {})
        if key not in cache:
            cache[key] = body_tracks(self.t_s, self.position_m, self.quat_wxyz, key[0], rotations)
        return cache[key]

    def frames(self) -> Poses:
        """The same run at its playback frames only."""
        k = self.frame_samples
        return Poses(self.model, self.body_ids, self.body_names, self.t_s[k], self.position_m[k], self.quat_wxyz[k],
                     None, self.fps)


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
    # MAX_FRAMES frames of playback: ten minutes at 60 per second, whose first and last frames both count
    return checks.work(f"a window of {duration_s:g} {unit} at {fps:g} frames per {unit}", n, checks.MAX_FRAMES + 1,
                       "frames", "a shorter window or fewer frames per second")


def plan_recording(stepper, duration_s: float, fps: float, every_step: bool = True):
    """What :func:`record_poses` will record, checked before any simulation: the exported bodies, each frame's
    step and the steps sampled (at most :data:`~lifelike_mj.checks.MAX_RECORD_ROWS` body poses)."""
    n_frames = frames_of(duration_s, fps)
    dt = float(stepper.dt)
    frame_steps = np.array([int(round(k / fps / dt)) for k in range(n_frames)])
    bodies = animated_bodies(stepper.model)
    if len(bodies) == 0:
        raise UserError("the model has no drawn body to export (no geom in groups 0-2).")
    targets = np.arange(frame_steps[-1] + 1) if every_step else frame_steps
    checks.work(f"recording {len(targets):,} poses of {len(bodies):,} bodies", float(len(targets)) * len(bodies),
                checks.MAX_RECORD_ROWS, "body poses", "a shorter window, fewer frames per second or fewer creatures")
    return bodies, frame_steps, targets


def record_poses(stepper, duration_s: float, fps: float = 30.0, time_scale: float = 1.0,
                 every_step: bool = True) -> Poses:
    """Run ``stepper`` on for ``duration_s`` of its time from where it is, recording its drawn bodies' poses at
    every step (``every_step``; else only at the frames), with playback frames ``fps`` times per unit of its
    time (the first is the state now). Each frame lies on the nearest whole step; a sample's time is its step's,
    times ``time_scale``: the seconds of playback per unit of the stepper's time (1 for the creatures that live
    in seconds; a flock's time is counted in steps, so ``time_scale = 1 / (steps per frame x frames per
    second)`` plays it at a frame rate). Stepping one step at a time or many changes nothing in the run.
    ``stepper``: anything in the stepper shape (``model``, ``data``, ``step``, ``sync``, ``dt``, ``time``)."""
    time_scale = checks.positive("time_scale", time_scale, "s per unit")
    bodies, frame_steps, targets = plan_recording(stepper, duration_s, fps, every_step)
    m = stepper.model
    dt = float(stepper.dt)
    t0 = float(stepper.time)
    done = 0
    n = len(targets)
    pos = np.empty((n, len(bodies), 3))
    quat = np.empty((n, len(bodies), 4))
    for k, target in enumerate(targets):
        if target > done:
            stepper.step(int(target - done))
            done = int(target)
        stepper.sync()
        d = stepper.data
        pos[k] = d.xpos[bodies]
        quat[k] = d.xquat[bodies]
    q = quat / np.linalg.norm(quat, axis=2, keepdims=True)
    flip = np.cumsum(np.sum(q[1:] * q[:-1], axis=2) < 0.0, axis=0) % 2 == 1  # q and -q are one rotation:
    q[1:][flip] *= -1.0  # keep neighbours on one side for slerp
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, int(b)) or f"body{int(b)}" for b in bodies]
    frames = np.searchsorted(targets, frame_steps)
    return Poses(m, bodies, names, (t0 + targets * dt) * time_scale, pos, q, frames, fps / time_scale)
