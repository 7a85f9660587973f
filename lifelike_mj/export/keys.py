"""Keys that resolve the motion: from poses sampled at the simulation's rate, the few keys that linear
interpolation of positions and spherical interpolation (slerp) of rotations need to stay within a stated
tolerance of every sample.

A body's track is sampled at every step of its simulation (:func:`~lifelike_mj.export.poses.record_poses`),
so a wing beating at 10.7 Hz is seen 112 times per beat at 1,200 steps/s. The keys are chosen by the
Ramer-Douglas-Peucker scheme (Ramer 1972; Douglas and Peucker 1973) on each channel on its own: start with
the first and last samples, find the sample the interpolation between two neighbouring keys misses most, and
keep it as a key while that miss exceeds the tolerance. Every sample is then within the tolerance of the
interpolated track, whatever the playback frame rate; key times fall where the motion needs them, between
frames. A rotation is also split wherever two neighbouring keys are more than :data:`MAX_KEY_TURN_DEG`
apart, so that a player's interpolation (slerp, or Blender's per-component interpolation of quaternions)
always takes the short way and a motion blur follows the arc.

The tolerance is spent honestly: the part that storing the keys may cost (16-bit rotations: 6e-5 rad;
32-bit positions: 6e-8 of the largest coordinate) is taken off before the keys are chosen.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: Default tolerance: 0.5 mm and 0.5 deg.
DEFAULT_TOLERANCE = (0.0005, 0.5)
#: No two neighbouring rotation keys are further apart than this (deg).
MAX_KEY_TURN_DEG = 20.0
#: What 16-bit rotation keys may cost (rad): half a step of 1/32767 in each component, as an angle, rounded up.
SHORT_ROTATION_RAD = 1e-4
#: The smallest tolerances taken: 1 micrometre and 0.01 deg (16-bit keys are good to 0.0034 deg).
MIN_TOLERANCE = (1e-6, 0.01)


def tolerance_of(text_or_pair) -> tuple[float, float]:
    """``(metres, degrees)`` from ``"0.5mm,0.5deg"``-like text (``mm``, ``m``, ``um``; ``deg``, ``rad``; bare
    numbers are mm and deg) or a pair, checked (at least :data:`MIN_TOLERANCE`, at most 1 m and 45 deg)."""
    if isinstance(text_or_pair, str):
        parts = [p.strip() for p in text_or_pair.split(",")]
        if len(parts) != 2 or not all(parts):
            raise UserError(f"a key tolerance is a distance and an angle, like '0.5mm,0.5deg', got {text_or_pair!r}.")
        units_m = {"um": 1e-6, "mm": 1e-3, "cm": 1e-2, "m": 1.0, "": 1e-3}
        units_deg = {"deg": 1.0, "rad": 180.0 / math.pi, "": 1.0}
        vals = []
        for part, units, what in ((parts[0], units_m, "distance"), (parts[1], units_deg, "angle")):
            unit = next((u for u in sorted(units, key=len, reverse=True) if u and part.endswith(u)), "")
            try:
                v = float(part[: len(part) - len(unit)])
            except ValueError:
                raise UserError(f"the key tolerance's {what} {part!r} is not a number with a unit "
                                f"({', '.join(u for u in units if u)}).") from None
            vals.append(v * units[unit])
        pair = tuple(vals)
    else:
        try:
            pair = tuple(text_or_pair)
        except TypeError:
            raise UserError(f"a key tolerance is (metres, degrees), got {text_or_pair!r}.") from None
        if len(pair) != 2:
            raise UserError(f"a key tolerance is (metres, degrees), got {text_or_pair!r}.")
    m = checks.number("the key tolerance's distance", pair[0], MIN_TOLERANCE[0], 1.0, unit="m")
    deg = checks.number("the key tolerance's angle", pair[1], MIN_TOLERANCE[1], 45.0, unit="deg")
    return float(m), float(deg)


@njit(cache=True)
def _lerp_miss(t, x, a, b):
    """The sample between ``a`` and ``b`` that linear interpolation misses most, and the miss (m)."""
    worst, at = -1.0, -1
    span = t[b] - t[a]
    for i in range(a + 1, b):
        u = (t[i] - t[a]) / span
        e = 0.0
        for j in range(x.shape[1]):
            d = x[a, j] + u * (x[b, j] - x[a, j]) - x[i, j]
            e += d * d
        if e > worst:
            worst, at = e, i
    return at, math.sqrt(max(worst, 0.0))


@njit(cache=True)
def _angle(p, q):
    """The angle (rad) between the rotations of unit quaternions ``p`` and ``q`` (either sign):
    ``4 asin(|p - q| / 2)`` with ``q`` on ``p``'s side, accurate for tiny angles too."""
    sign = 1.0 if p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3] >= 0.0 else -1.0
    s = 0.0
    for j in range(4):
        v = p[j] - sign * q[j]
        s += v * v
    return 4.0 * math.asin(min(1.0, math.sqrt(s) / 2.0))


@njit(cache=True)
def _slerp_miss(t, q, a, b):
    """The sample between ``a`` and ``b`` that slerp misses most, and the miss (rad)."""
    worst, at = -1.0, -1
    span = t[b] - t[a]
    qa, qb = q[a], q[b].copy()
    dot = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3]
    if dot < 0.0:
        qb = -qb
        dot = -dot
    theta = math.acos(min(1.0, dot))
    s = np.empty(4)
    for i in range(a + 1, b):
        u = (t[i] - t[a]) / span
        if theta < 1e-9:
            wa, wb = 1.0 - u, u
        else:
            wa, wb = math.sin((1.0 - u) * theta) / math.sin(theta), math.sin(u * theta) / math.sin(theta)
        n = 0.0
        for j in range(4):
            s[j] = wa * qa[j] + wb * qb[j]
            n += s[j] * s[j]
        s /= math.sqrt(n)
        e = _angle(s, q[i])
        if e > worst:
            worst, at = e, i
    return at, worst


@njit(cache=True)
def _reduce(t, x, rotation, tol, max_turn):
    """Which samples are keys (module docstring): ``x`` positions ``(n, 3)`` or unit quaternions ``(n, 4)``
    (``rotation``), ``tol`` in m or rad, ``max_turn`` (rad) between neighbouring rotation keys."""
    n = len(t)
    keep = np.zeros(n, dtype=np.bool_)
    keep[0] = True
    keep[n - 1] = True
    stack = [(0, n - 1)]
    while len(stack) > 0:
        a, b = stack.pop()
        if b - a < 2:
            continue
        if rotation:
            at, miss = _slerp_miss(t, x, a, b)
            if miss <= tol and _angle(x[a], x[b]) > max_turn:
                at, miss = (a + b) // 2, 2.0 * tol + 1.0
        else:
            at, miss = _lerp_miss(t, x, a, b)
        if miss > tol:
            keep[at] = True
            stack.append((a, at))
            stack.append((at, b))
    return np.nonzero(keep)[0]


def lerp_keys(t: np.ndarray, x: np.ndarray, tol_m: float) -> np.ndarray:
    """Indices of the samples of ``x`` ``(n, k)`` at times ``t`` (increasing) kept as keys so that linear
    interpolation between them is within ``tol_m`` (Euclidean) of every sample; the first and last always."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    return _reduce(np.ascontiguousarray(t, dtype=np.float64), x, False, float(tol_m), 0.0)


def slerp_keys(t: np.ndarray, q: np.ndarray, tol_rad: float, max_turn_rad: float = math.radians(MAX_KEY_TURN_DEG)
               ) -> np.ndarray:
    """Indices of the unit quaternions ``q`` ``(n, 4)`` kept as keys so that slerp between them is within
    ``tol_rad`` of every sample and no two neighbouring keys are more than ``max_turn_rad`` apart."""
    q = np.ascontiguousarray(q, dtype=np.float64)
    return _reduce(np.ascontiguousarray(t, dtype=np.float64), q, True, float(tol_rad), float(max_turn_rad))


@dataclass
class Track:
    """One body's keys: sample indices of its translation and rotation keys (``None``: the channel never
    changes, and the node's still value says it)."""

    translation: np.ndarray | None
    rotation: np.ndarray | None


def body_tracks(t: np.ndarray, position_m: np.ndarray, quat_wxyz: np.ndarray, tolerance=DEFAULT_TOLERANCE,
                rotations: str = "short") -> list[Track]:
    """The keys of every body (``position_m`` ``(n, bodies, 3)``, ``quat_wxyz`` ``(n, bodies, 4)`` sampled at
    ``t``) within ``tolerance`` (m, deg), less what the storage costs (module docstring; ``rotations``:
    ``"short"`` or ``"float"`` keys)."""
    tol_m, tol_deg = tolerance_of(tolerance)
    span = float(np.max(np.abs(position_m))) if position_m.size else 0.0
    tol_m -= 6e-8 * span + 1e-9  # float32 positions
    tol_rad = math.radians(tol_deg) - (SHORT_ROTATION_RAD if rotations == "short" else 1e-6)
    if tol_m <= 0:
        raise UserError(f"a key tolerance of {tolerance_of(tolerance)[0]:g} m is below what 32-bit positions "
                        f"{span:g} m from the origin can hold; give a larger one.")
    out = []
    for b in range(position_m.shape[1]):
        p, q = position_m[:, b], quat_wxyz[:, b]
        out.append(Track(None if np.all(p == p[0]) else lerp_keys(t, p, tol_m),
                         None if np.all(q == q[0]) else slerp_keys(t, q, tol_rad)))
    return out


def key_counts(tracks: list[Track], names: list[str]) -> dict[str, dict[str, int]]:
    """Keys kept per body and channel (a still channel has 1: its node's value)."""
    return {name: {"translation": 1 if tr.translation is None else len(tr.translation),
                   "rotation": 1 if tr.rotation is None else len(tr.rotation)} for name, tr in zip(names, tracks)}
