"""Rigged creatures for the exporters: a skeleton whose bones are the MuJoCo bodies (named as in the MJCF) and
the extra bones of secondary motion, with a skinned, textured mesh bound to it.

A creature's slice builds its :class:`Rig` from a run's :class:`~lifelike_mj.export.poses.Poses` (its mesh,
texture and secondary motion are its own business); this module holds what every rig shares and turns the
bones' world poses into keys:

* the **bind pose** is the creature at rest, its root bone at the origin (x forward, z up, metres), so that a
  flock of hundreds binds one mesh with one set of inverse bind matrices;
* each bone's **world pose** is given at every sample of the run; its keys are local to its parent bone
  (what a glTF node or a UsdSkel joint holds), chosen parent first: a child's local target is taken against its
  parent's pose *as the keys will play it*, so the child's keys also absorb the parent's interpolation and
  storage error. Every bone then stays within the key tolerance of its world pose at every sample, however
  deep the chain (:func:`bone_keys`).

Quaternions here are (w, x, y, z), as MuJoCo's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.keys import SHORT_ROTATION_RAD, lerp_keys, slerp_keys, tolerance_of

# ---- quaternions (w, x, y, z), row by row ------------------------------------------------------------


def qmul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product ``a b`` (either may be one quaternion or rows of them)."""
    aw, ax, ay, az = np.moveaxis(np.asarray(a, dtype=float), -1, 0)
    bw, bx, by, bz = np.moveaxis(np.asarray(b, dtype=float), -1, 0)
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=-1)


def qconj(q: np.ndarray) -> np.ndarray:
    return np.asarray(q, dtype=float) * np.array([1.0, -1.0, -1.0, -1.0])


def qrot(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The vectors ``v`` turned by the unit quaternions ``q``."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    u = q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + q[..., :1] * t + np.cross(u, t)


def qaxis(axis, angle_rad) -> np.ndarray:
    """Rotations by ``angle_rad`` (scalar or array) about the unit ``axis``."""
    a = np.asarray(angle_rad, dtype=float)[..., None] / 2.0
    return np.concatenate([np.cos(a), np.sin(a) * np.asarray(axis, dtype=float)], axis=-1)


def continuous(q: np.ndarray) -> np.ndarray:
    """Rows of quaternions with their signs chosen so that neighbours lie on one side (for slerp)."""
    q = np.array(q, dtype=float)
    flip = np.cumsum(np.sum(q[1:] * q[:-1], axis=-1) < 0.0, axis=0) % 2 == 1
    q[1:][flip] *= -1.0
    return q


def lerp_at(t: np.ndarray, keys: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Linear interpolation of the key rows ``x`` (at the sample indices ``keys``) at every time of ``t``."""
    tk = t[keys]
    return np.stack([np.interp(t, tk, x[:, j]) for j in range(x.shape[1])], axis=1)


def slerp_at(t: np.ndarray, keys: np.ndarray, q: np.ndarray, key_times: np.ndarray | None = None) -> np.ndarray:
    """Spherical interpolation of the unit key quaternions ``q`` (at the sample indices ``keys`` of ``t``, or at
    ``key_times``) at every time of ``t``."""
    tk = t[keys] if key_times is None else np.asarray(key_times, dtype=float)
    k = np.clip(np.searchsorted(tk, t, side="right") - 1, 0, len(tk) - 2)
    u = np.clip((t - tk[k]) / (tk[k + 1] - tk[k]), 0.0, 1.0)[:, None]
    a, b = q[k], q[k + 1].copy()
    dot = np.sum(a * b, axis=1)
    b[dot < 0] *= -1.0
    theta = np.arccos(np.clip(np.abs(dot), 0.0, 1.0))[:, None]
    small = theta < 1e-9
    s = np.where(small, 1.0, np.sin(theta))
    out = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / s) * a + np.where(small, u, np.sin(u * theta) / s) * b
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def matrix(pos: np.ndarray, quat_wxyz: np.ndarray) -> np.ndarray:
    """The 4x4 transform of a position and a unit quaternion."""
    w, x, y, z = quat_wxyz
    R = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    M = np.eye(4)
    M[:3, :3], M[:3, 3] = R, pos
    return M


# ---- what a rig is -----------------------------------------------------------------------------------


@dataclass
class Look:
    """A material: its name (the MJCF's where it has one), base colour (RGBA, 0-1), optional texture image
    (``(H, W, 4)`` uint8 RGBA, embedded as PNG), and how it is drawn."""

    name: str
    rgba: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    image: np.ndarray | None = None
    double_sided: bool = True
    roughness: float = 0.7


@dataclass
class Mesh:
    """A skinned mesh in its rig's bind pose (m; x forward, z up): ``positions``, ``normals`` ``(V, 3)``, ``uv``
    ``(V, 2)`` (texture coordinates, v down as glTF's), ``joints`` ``(V, 4)`` bone indices, ``weights``
    ``(V, 4)`` (summing to 1); ``parts``: ``(look, triangles (T, 3))`` per material."""

    name: str
    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    joints: np.ndarray
    weights: np.ndarray
    parts: list[tuple[Look, np.ndarray]]


@dataclass
class Bone:
    """One bone: ``name`` (a MuJoCo body's, or ``body/extra`` for a bone of secondary motion), ``parent``
    (index in the rig's bones, -1 for the root), ``bind`` (4x4 pose at rest in the rig's frame), and its world
    pose at every sample: ``position_m`` ``(n, 3)``, ``quat_wxyz`` ``(n, 4)``; ``body``: the MuJoCo body it is
    (``None`` for an extra bone)."""

    name: str
    parent: int
    bind: np.ndarray
    position_m: np.ndarray
    quat_wxyz: np.ndarray
    body: str | None = None
    #: The bone follows a path drawn from ``body`` (smoothed: a crowd's agent), not the body itself.
    drawn: bool = False


@dataclass
class Cycle:
    """A looping motion that rigs share (a flock's wing beat): ``name``; ``period_s`` (s); ``quat_wxyz``: per
    part (a bone's name after its creature's, ``wing_left_inner``), the bone's rotation in its parent's frame at
    ``samples`` instants evenly spread over one period, and the first again at the end (``(samples + 1, 4)``);
    ``groups``: the phases a rig may play it at, ``k / groups`` of a period (``samples`` a multiple of it, so
    that each phase's values are the same samples, shifted).

    A player plays it as glTF does: slerp between neighbouring samples, looping (:meth:`play`)."""

    name: str
    period_s: float
    quat_wxyz: dict[str, np.ndarray]
    groups: int

    @property
    def samples(self) -> int:
        return len(next(iter(self.quat_wxyz.values()))) - 1

    def shifted(self, part: str, group: int) -> np.ndarray:
        """The samples of ``part`` as phase ``group`` plays them (one period, the first again at the end)."""
        q = self.quat_wxyz[part][:-1]
        q = np.roll(q, -group * (self.samples // self.groups), axis=0)
        return continuous(np.concatenate([q, q[:1]]))

    def play(self, part: str, group: int, t_s: np.ndarray) -> np.ndarray:
        """``part``'s local rotation at the times ``t_s`` (s from the clip's start) in phase ``group``."""
        m = self.samples
        times = np.arange(m + 1) * (self.period_s / m)
        return slerp_at(np.mod(np.asarray(t_s, dtype=float), self.period_s), np.arange(m + 1), self.shifted(part, group),
                        times)


@dataclass
class Rig:
    """One creature: ``name`` (its root body's), its ``bones`` (parents before children) and its ``mesh``
    (shared, by identity, between the rigs that look alike); ``extras``: written with it (strict JSON);
    ``secondary``: the series its secondary motion was computed from (for reports and tests, not written)."""

    name: str
    bones: list[Bone]
    mesh: Mesh
    extras: dict = field(default_factory=dict)
    secondary: dict = field(default_factory=dict)
    #: A crowd's agent: the bones that ``cycle`` names play it (in phase ``group``) instead of keys of their own,
    #: and every bone's keys are taken against its parent's pose as drawn (not as the parent's keys play it), so
    #: that a child needs no keys to absorb its parent's interpolation (:func:`bone_keys`).
    cycle: Cycle | None = None
    group: int = 0

    def cycle_part(self, bone: Bone) -> str | None:
        """The part of :attr:`cycle` that ``bone`` plays, or None."""
        if self.cycle is None:
            return None
        part = bone.name.rsplit("/", 1)[-1]
        return part if part in self.cycle.quat_wxyz else None

    def keys(self, t: np.ndarray, tolerance=(0.0005, 0.5), rotations: str = "short", cycles: bool = True
             ) -> list[BoneKeys]:
        """The bones' keys (:func:`bone_keys`), computed once per tolerance, storage and ``cycles``."""
        key = (tolerance_of(tolerance), rotations, len(t), cycles)
        cache = self.__dict__.setdefault("_keys", {})
        if key not in cache:
            cache[key] = bone_keys(t, self, key[0], rotations, cycles)
        return cache[key]

    def key_counts(self, t: np.ndarray, tolerance=(0.0005, 0.5), rotations: str = "short", cycles: bool = True
                   ) -> dict:
        """Keys kept per bone and channel (a still channel has 1: its node's value; a bone's rotation that plays the
        shared cycle has none of its own, 0, and ``cycle``: the cycle's name and the phase group)."""
        out: dict = {}
        for b, k in zip(self.bones, self.keys(t, tolerance, rotations, cycles)):
            out[b.name] = {"translation": 1 if k.translation is None else len(k.translation),
                           "rotation": 0 if k.cycle is not None else 1 if k.rotation is None else len(k.rotation)}
            if k.cycle is not None:
                out[b.name]["cycle"] = {"name": k.cycle, "group": self.group}
        return out

    def check(self) -> None:
        for i, b in enumerate(self.bones):
            if not -1 <= b.parent < i:
                raise UserError(f"bone {b.name!r} of {self.name} must come after its parent.")
        if self.mesh.joints.max(initial=0) >= len(self.bones):
            raise UserError(f"the mesh of {self.name} is bound to a bone it does not have.")


# ---- keys, parent first --------------------------------------------------------------------------------


@dataclass
class BoneKeys:
    """A bone's local keys: ``translation``/``rotation`` sample indices (``None``: still, ``still_*`` holds
    the value) and the stored values at them (rotations as quaternions w, x, y, z)."""

    translation: np.ndarray | None
    rotation: np.ndarray | None
    translation_values: np.ndarray
    rotation_values: np.ndarray
    still_translation: np.ndarray
    still_rotation: np.ndarray
    #: The shared cycle whose part this bone's rotation plays (its rig's ``cycle``), or None.
    cycle: str | None = None


def _stored(q: np.ndarray, rotations: str) -> np.ndarray:
    """Quaternions as a reader gets them back from the file."""
    if rotations == "short":
        q = np.round(np.clip(q, -1.0, 1.0) * 32767.0) / 32767.0
    else:
        q = q.astype(np.float32).astype(float)
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def bone_keys(t: np.ndarray, rig: Rig, tolerance=(0.0005, 0.5), rotations: str = "short", cycles: bool = True
              ) -> list[BoneKeys]:
    """Each bone's local keys (module docstring): within ``tolerance`` (m, deg) of its world pose at every
    sample of ``t``, less what storing costs (``rotations``: ``"short"`` 16-bit or ``"float"``).

    A crowd's agent (a rig with a ``cycle``) is keyed channel by channel instead: its root within the tolerance
    of its world pose, every other bone within it of its pose in its parent's frame as drawn; the bones that play
    the cycle get no keys (``cycles``; with ``cycles=False``, for a writer that cannot share a cycle, they are
    keyed as the others, and every bone as a rig's that has no cycle, within the tolerance in the world)."""
    tol_m, tol_deg = tolerance_of(tolerance)
    span = max(float(np.max(np.abs(b.position_m))) for b in rig.bones)
    tol_m -= 6e-8 * span + 1e-9
    tol_rad = math.radians(tol_deg) - (SHORT_ROTATION_RAD if rotations == "short" else 1e-6)
    if tol_m <= 0:
        raise UserError(f"a key tolerance of {tolerance_of(tolerance)[0]:g} m is below what 32-bit positions "
                        f"{span:g} m from the origin can hold; give a larger one.")
    played: list[tuple[np.ndarray, np.ndarray]] = []  # each bone's world pose as its keys play it
    out = []
    crowd = rig.cycle is not None and cycles
    margin = 1.0 if crowd else 0.75  # a chain's keys leave a quarter for what a child absorbs of its parent's
    for b in rig.bones:
        if b.parent < 0:
            p_local, q_local = b.position_m, continuous(b.quat_wxyz)
        else:
            pb = rig.bones[b.parent]
            pp, pq = (pb.position_m, pb.quat_wxyz) if crowd else played[b.parent]
            p_local = qrot(qconj(pq), b.position_m - pp)
            q_local = continuous(qmul(qconj(pq), b.quat_wxyz))
        part = rig.cycle_part(b) if cycles else None
        if part is not None:  # plays the shared cycle: its still values are where the cycle starts
            tv = p_local[:1].astype(np.float32).astype(float)
            rv = _stored(rig.cycle.shifted(part, rig.group)[:1], "float")
            played.append((b.position_m, b.quat_wxyz))
            out.append(BoneKeys(None, None, tv, rv, tv[0], rv[0], rig.cycle.name))
            continue
        # translation: still where every sample is within a quarter of the tolerance of the first
        if np.max(np.linalg.norm(p_local - p_local[0], axis=1)) <= tol_m / 4:
            tk, tv = None, p_local[:1].astype(np.float32).astype(float)
            p_play = np.repeat(tv, len(t), axis=0)
        else:
            tk = lerp_keys(t, p_local, tol_m * margin)
            tv = p_local[tk].astype(np.float32).astype(float)
            p_play = lerp_at(t, tk, tv)
        if np.max(2.0 * np.arccos(np.clip(np.abs(q_local @ q_local[0]), 0.0, 1.0))) <= tol_rad / 4:
            rk, rv = None, _stored(q_local[:1], "float")
            q_play = np.repeat(rv, len(t), axis=0)
        else:
            rk = slerp_keys(t, q_local, tol_rad * margin)
            rv = _stored(q_local[rk], rotations)
            q_play = slerp_at(t, rk, rv)
        if b.parent < 0:
            played.append((p_play, q_play))
        else:
            pp, pq = played[b.parent]
            played.append((pp + qrot(pq, p_play), qmul(pq, q_play)))
        out.append(BoneKeys(tk, rk, tv, rv, tv[0], rv[0]))
    return out


def bone_play(t: np.ndarray, rig: Rig, keys: list[BoneKeys]) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each bone's pose in its parent's frame (its root's: the world's) as a player plays ``keys`` at the samples
    ``t``: ``(position (n, 3), quat_wxyz (n, 4))``; a bone of the shared cycle as the cycle plays, looping from
    the file's start."""
    out = []
    for b, k in zip(rig.bones, keys):
        p = np.repeat(k.still_translation[None], len(t), axis=0) if k.translation is None else \
            lerp_at(t, k.translation, k.translation_values)
        if k.cycle is not None:
            q = rig.cycle.play(rig.cycle_part(b), rig.group, t - t[0])
        elif k.rotation is None:
            q = np.repeat(k.still_rotation[None], len(t), axis=0)
        else:
            q = slerp_at(t, k.rotation, k.rotation_values)
        out.append((p, q))
    return out


def check_bone_keys(t: np.ndarray, rig: Rig, keys: list[BoneKeys]) -> tuple[float, float]:
    """The largest miss (m, rad) of the keys over every sample, what the tolerance bounds: the bones' world poses
    as a player composes them against the rig's; for a crowd's agent keyed with its ``cycle``, channel by channel,
    each bone's pose in its parent's frame against the same as drawn (:func:`bone_keys`)."""
    worst_m, worst_rad = 0.0, 0.0
    played: list[tuple[np.ndarray, np.ndarray]] = []
    crowd = any(k.cycle is not None for k in keys)  # keyed as a crowd (bone_keys with its cycle)
    for b, (p, q) in zip(rig.bones, bone_play(t, rig, keys)):
        want_p, want_q = b.position_m, b.quat_wxyz
        if b.parent >= 0 and crowd:
            pb = rig.bones[b.parent]
            want_p = qrot(qconj(pb.quat_wxyz), b.position_m - pb.position_m)
            want_q = qmul(qconj(pb.quat_wxyz), b.quat_wxyz)
        elif b.parent >= 0:
            pp, pq = played[b.parent]
            p, q = pp + qrot(pq, p), qmul(pq, q)
        played.append((p, q))
        worst_m = max(worst_m, float(np.max(np.linalg.norm(p - want_p, axis=1))))
        d = np.clip(np.abs(np.sum(q * want_q, axis=1)), 0.0, 1.0)
        worst_rad = max(worst_rad, float(np.max(2.0 * np.arccos(d))))
    return worst_m, worst_rad


# ---- building rigs from a run ---------------------------------------------------------------------------


def rest_pose(model, body: int) -> np.ndarray:
    """The 4x4 pose of ``body`` at rest (its joints at zero) in the frame of its root body (the body below the
    world that carries it): the bind pose of its bone."""
    M = np.eye(4)
    b = int(body)
    root = int(model.body_rootid[b])
    while b != root:
        M = matrix(model.body_pos[b], model.body_quat[b]) @ M
        b = int(model.body_parentid[b])
    return M


def creatures(poses) -> dict[int, list[int]]:
    """The run's bodies grouped by creature: each root body's id -> the indices (in ``poses``) of its bodies,
    the root first, parents before children."""
    m = poses.model
    out: dict[int, list[int]] = {}
    for i, b in enumerate(poses.body_ids):
        out.setdefault(int(m.body_rootid[b]), []).append(i)
    for root, idx in out.items():
        idx.sort(key=lambda i: (int(poses.body_ids[i]) != root, int(poses.body_ids[i])))  # MJCF order: parents first
    return out


def body_bone(poses, i: int, parent: int, name: str | None = None) -> Bone:
    """The bone of the run's ``i``-th body (its world pose at every sample, its rest pose as bind)."""
    body = poses.body_names[i]
    return Bone(name or body, parent, rest_pose(poses.model, poses.body_ids[i]), poses.position_m[:, i],
                poses.quat_wxyz[:, i], body)


def extra_bone(name: str, parent: int, bones: list[Bone], offset_m, turn_wxyz: np.ndarray | None = None,
               rest_wxyz=(1.0, 0.0, 0.0, 0.0)) -> Bone:
    """A bone of secondary motion: at ``offset_m`` in its parent bone's frame, turned there by ``rest_wxyz``
    and then by ``turn_wxyz`` (rows, one per sample; ``None``: still)."""
    p = bones[parent]
    rest = np.asarray(rest_wxyz, dtype=float)
    local = np.broadcast_to(rest, p.quat_wxyz.shape) if turn_wxyz is None else qmul(rest, turn_wxyz)
    pos = p.position_m + qrot(p.quat_wxyz, np.broadcast_to(np.asarray(offset_m, dtype=float), p.position_m.shape))
    quat = qmul(p.quat_wxyz, local)
    return Bone(name, parent, p.bind @ matrix(np.asarray(offset_m, dtype=float), rest), pos, continuous(quat))


def smooth(x: np.ndarray, sigma: float) -> np.ndarray:
    """``x`` (samples along its first axis: ``(n,)`` or ``(n, k)``) smoothed by a Gaussian of ``sigma`` samples,
    its ends held; returned as it is where ``sigma`` is under half a sample or there are fewer than 3 samples."""
    x = np.asarray(x, dtype=float)
    if sigma < 0.5 or len(x) < 3:
        return x.copy()
    r = int(math.ceil(3 * sigma))
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    cols = x.reshape(len(x), -1)
    pad = np.concatenate([np.repeat(cols[:1], r, 0), cols, np.repeat(cols[-1:], r, 0)])
    out = np.stack([np.convolve(pad[:, j], k, mode="valid") for j in range(cols.shape[1])], axis=1)
    return out.reshape(x.shape)


def adaptive_smooth(x: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """``x`` ``(n, k)`` smoothed by a Gaussian whose sigma (samples) is ``sigma[i]`` at sample ``i`` (its weights
    normalised there; the ends held): where sigma is under half a sample, ``x`` as it is."""
    n = len(x)
    r = int(math.ceil(3.0 * float(np.max(sigma, initial=0.0))))
    if r < 1 or n < 3:
        return np.array(x, dtype=float)
    j = np.arange(-r, r + 1)
    idx = np.clip(np.arange(n)[:, None] + j[None, :], 0, n - 1)
    s = np.maximum(sigma, 1e-9)[:, None]
    w = np.exp(-0.5 * (j[None, :] / s) ** 2)
    w[np.abs(j)[None, :] > np.ceil(3.0 * s)] = 0.0
    w /= w.sum(axis=1, keepdims=True)
    return np.einsum("ij,ijk->ik", w, np.asarray(x, dtype=float)[idx])


def damped(signal: np.ndarray, dt: float, hz: float, zeta: float) -> np.ndarray:
    """The response of a damped oscillator (natural frequency ``hz``, damping ratio ``zeta``, unit static gain)
    to ``signal`` ``(n, k)`` sampled every ``dt`` s, from rest at the first sample's value: a lagging follower
    (semi-implicit Euler, sub-stepped to stay stable)."""
    w = 2.0 * math.pi * hz
    sub = max(1, int(math.ceil(dt * w / 0.2)))
    h = dt / sub
    y = np.array(signal[0], dtype=float)
    v = np.zeros_like(y)
    out = np.empty_like(signal, dtype=float)
    for k in range(len(signal)):
        for _ in range(sub):
            v += h * (w * w * (signal[k] - y) - 2.0 * zeta * w * v)
            y = y + h * v
        out[k] = y
    return out
