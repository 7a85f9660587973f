"""Clips that loop: the last frame joins the first.

Two ways, by what the motion is:

* **cut** (:func:`cut_loop`), for periodic motion such as a butterfly's level flight: the clip keeps a whole
  number of wing beats (the length asked for, or up to a fifth less) and ends on the sample where the state comes
  back closest to the first sample's (every body's turn relative to the root body, and the root's attitude); the root's travel
  over the clip is taken off linearly (the creature flies in place, as a game engine's locomotion cycle does)
  and given as the clip's root motion, so that playing it again and again and moving the root by that much per
  loop gives the flight;
* **blend** (:func:`blend_loop`), for motion that does not repeat (a tank, a flock): the run is recorded from
  ``blend_s`` before the clip starts; over the clip's last ``blend_s`` every body (and bone) fades from where it
  is to where it was ``duration`` earlier (linearly, and by slerp), so the last sample is the first. The blended
  stretch is not the simulation: the file says where it is.

Both report the seam: the largest jump of any body or bone in position (m) and angle (deg) from the clip's last
sample to its first, as a player looping it sees.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.rig import continuous, qconj, qmul


def _slerp(a: np.ndarray, b: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Rows of spherical interpolation from ``a`` to ``b`` by ``w`` (0 to 1)."""
    b = np.where((np.sum(a * b, axis=-1) < 0)[..., None], -b, b)
    dot = np.clip(np.sum(a * b, axis=-1), -1.0, 1.0)[..., None]
    th = np.arccos(dot)
    s = np.sin(th)
    small = s < 1e-9
    wa = np.where(small, 1.0 - w, np.sin((1.0 - w) * th) / np.where(small, 1.0, s))
    wb = np.where(small, w, np.sin(w * th) / np.where(small, 1.0, s))
    q = wa * a + wb * b
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def blend_series(t: np.ndarray, pos: np.ndarray, quat: np.ndarray, lead: int, blend: int):
    """One track ``pos`` ``(n, ..., 3)``, ``quat`` ``(n, ..., 4)`` at times ``t``, recorded with ``lead`` samples
    before the clip: the clip (samples ``lead`` on) with its last ``blend`` samples faded into the ``blend``
    samples before its start (module docstring). Returns the clip's times, positions and quaternions."""
    n = len(t) - lead
    clip_p, clip_q = pos[lead:].copy(), quat[lead:].copy()
    if blend > lead or blend >= n:
        raise UserError("a blended loop needs its blend recorded before the clip, and a clip longer than the blend.")
    w = np.linspace(0.0, 1.0, blend + 1)[1:]  # 0 just before the blend, 1 at the clip's last sample
    shape = (blend,) + (1,) * (pos.ndim - 1)
    early_p = pos[lead - blend + 1: lead + 1]  # where each was ``duration`` earlier: up to the clip's first sample
    early_q = quat[lead - blend + 1: lead + 1]
    clip_p[n - blend:] = (1.0 - w.reshape(shape)) * clip_p[n - blend:] + w.reshape(shape) * early_p
    clip_q[n - blend:] = _slerp(clip_q[n - blend:], early_q, w.reshape(shape))
    return t[lead:], clip_p, clip_q


def seam(pos: np.ndarray, quat: np.ndarray) -> tuple[float, float]:
    """The largest jump (m, deg) of any body from the last sample to the first: ``pos`` ``(n, bodies, 3)``."""
    jump = float(np.max(np.linalg.norm(pos[-1] - pos[0], axis=-1)))
    d = np.clip(np.abs(np.sum(quat[-1] * quat[0], axis=-1)), 0.0, 1.0)
    return jump, float(np.degrees(np.max(2.0 * np.arccos(d))))


def cut_loop(t: np.ndarray, pos: np.ndarray, quat: np.ndarray, period_s: float, duration_s: float,
             root: int = 0):
    """The cut (module docstring) of bodies ``pos`` ``(n, bodies, 3)``, ``quat`` ``(n, bodies, 4)`` sampled at
    ``t``: a whole number of ``period_s`` from ``duration_s`` down to a fifth less, ending on the best-matching sample, the root
    body's (index ``root``) travel taken off. Returns ``(last sample index, positions, quaternions, travel
    (m, 3-vector), beats)``."""
    if not period_s > 0 or not math.isfinite(period_s):
        raise UserError(f"a looped cut needs a positive period, got {period_s!r} s.")
    most = max(1, int(round(duration_s / period_s)))
    dt = float(np.median(np.diff(t)))
    if t[0] + most * period_s > t[-1] + dt / 2:
        most = int((t[-1] - t[0]) // period_s)
        if most < 1:
            raise UserError(f"a looped clip needs at least one whole beat of {period_s:g} s; record longer.")
    rel = qmul(qconj(quat[:, root:root + 1]), quat)  # each body's turn in the root's frame (wings, abdomen)

    def mismatch(k: int) -> float:
        a = np.clip(np.abs(np.sum(rel[k] * rel[0], axis=-1)), 0.0, 1.0)
        b = min(1.0, abs(float(np.sum(quat[k, root] * quat[0, root]))))
        return float(np.max(2.0 * np.arccos(a))) + 2.0 * math.acos(b)

    # the beat counts from a fifth fewer up to the length asked: a flight's slower swings (its body's, over a few
    # beats) come back better after some counts than others; each ends on its best-matching sample
    best = None
    for n in range(most, max(1, most - most // 5) - 1, -1):
        target = t[0] + n * period_s
        near = np.nonzero(np.abs(t - target) <= max(2.5 * dt, 0.1 * period_s))[0]
        k = int(min(near, key=mismatch)) if len(near) else int(np.argmin(np.abs(t - target)))
        miss = mismatch(k)
        if best is None or miss < best[0] - 1e-12:
            best = (miss, k, n)
    _, end, beats = best
    travel = pos[end, root] - pos[0, root]
    u = ((t[: end + 1] - t[0]) / (t[end] - t[0]))[:, None, None]
    p = pos[: end + 1] - u * travel
    return end, p, continuous(quat[: end + 1]), travel, beats


def beat_period(t: np.ndarray, quat: np.ndarray, root_quat: np.ndarray) -> float:
    """The period (s) of a body's beat relative to its root (a wing's flap): the median time between the
    upward crossings of its mean by the turn's main component (the quaternion's vector part projected on its
    principal direction)."""
    rel = continuous(qmul(qconj(root_quat), quat))[:, 1:]
    rel = rel - rel.mean(axis=0)
    _, _, vt = np.linalg.svd(rel, full_matrices=False)
    x = rel @ vt[0]
    up = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    if len(up) < 3:
        raise UserError("the run holds fewer than two wing beats to find a loop in; record longer.")
    tc = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    return float(np.median(np.diff(tc)))


def _frames(t: np.ndarray, fps: float) -> np.ndarray:
    n = int(np.floor((t[-1] - t[0]) * fps + 1e-9)) + 1
    return np.clip(np.searchsorted(t, t[0] + np.arange(n) / fps - 1e-9), 0, len(t) - 1)


def loop_cut(poses, rigs: list | None, period_s: float, lead_s: float = 0.0):
    """:func:`cut_loop` on a run's :class:`~lifelike_mj.export.poses.Poses` recorded ``lead_s`` before the clip
    (so that the secondary motion of ``rigs``, built on the whole recording, has its history at the clip's
    start and joins up at its end): the clip's poses and rigs, and what the file records of the loop."""
    from lifelike_mj.export.poses import Poses

    t = poses.t_s
    lead = int(np.searchsorted(t, t[0] + lead_s - 1e-9)) if lead_s > 0 else 0
    end, p, q, travel, beats = cut_loop(t[lead:], poses.position_m[lead:], poses.quat_wxyz[lead:], period_s,
                                        float(t[-1] - t[lead]))
    tt = t[lead: lead + end + 1]
    u = ((tt - tt[0]) / (tt[-1] - tt[0]))[:, None]
    out = Poses(poses.model, poses.body_ids, poses.body_names, tt, p, q, _frames(tt, poses.fps), poses.fps)
    jumps = [seam(p, q)]
    for rig in rigs or []:
        for b in rig.bones:
            b.position_m = b.position_m[lead: lead + end + 1] - u * travel
            b.quat_wxyz = continuous(b.quat_wxyz[lead: lead + end + 1])
            jumps.append(seam(b.position_m[:, None], b.quat_wxyz[:, None]))
        rig.secondary = {k: v[lead: lead + end + 1] if isinstance(v, np.ndarray) and len(v) == len(t) else v
                         for k, v in rig.secondary.items()}
    return out, rigs, {"mode": "cut", "beats": beats, "period_s": period_s, "span_s": float(tt[-1] - tt[0]),
                       "root_motion_m": [float(v) for v in travel], "seam_m": max(j[0] for j in jumps),
                       "seam_deg": max(j[1] for j in jumps)}


def loop_blend(poses, rigs: list | None, blend_s: float):
    """:func:`blend_series` on a run recorded ``blend_s`` longer than its clip (the first ``blend_s`` the lead-in),
    on its bodies and on every bone of ``rigs`` (built on the whole recording, so their secondary motion joins
    too). Returns the clip's poses, rigs and what the file records of the loop."""
    from lifelike_mj.export.poses import Poses

    t = poses.t_s
    lead = int(np.searchsorted(t, t[0] + blend_s - 1e-9))
    if lead < 1 or lead >= len(t) - 1:
        raise UserError(f"a blend of {blend_s:g} s needs a longer run; give a longer --duration or a shorter "
                        "--loop-blend.")
    tt, p, q = blend_series(t, poses.position_m, poses.quat_wxyz, lead, lead)
    out = Poses(poses.model, poses.body_ids, poses.body_names, tt, p, continuous(q), _frames(tt, poses.fps),
                poses.fps)
    jumps = [seam(p, q)]
    for rig in rigs or []:
        for b in rig.bones:
            _, bp, bq = blend_series(t, b.position_m, b.quat_wxyz, lead, lead)
            b.position_m, b.quat_wxyz = bp, continuous(bq)
            jumps.append(seam(bp[:, None], bq[:, None]))
        rig.secondary = {k: v[lead:] if isinstance(v, np.ndarray) and len(v) == len(t) else v
                         for k, v in rig.secondary.items()}
    return out, rigs, {"mode": "blend", "blend_s": float(t[lead] - t[0]),
                       "blended_from_s": float(tt[-1 - lead] - tt[0]), "span_s": float(tt[-1] - tt[0]),
                       "seam_m": max(j[0] for j in jumps), "seam_deg": max(j[1] for j in jumps)}
