"""MuJoCo's own instability warnings, read after every chunk of steps.

When an acceleration, position or velocity becomes NaN, infinite or huge, ``mj_step`` prints a
warning, writes ``MUJOCO_LOG.TXT`` into the working directory and *resets* the simulation to its
initial state, so that a NaN check after the step sees nothing wrong. :func:`watching` catches those
warnings instead (no print, no log file); :func:`was_reset` (the clock went back) or :class:`Watch`
(MuJoCo's warning counters, for batches) finds a reset after each chunk, and :func:`describe` says
what MuJoCo found, for a :class:`~lifelike_mj.errors.Diverged` error that the caller completes with
the likely cause.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence

import mujoco

_BAD = {
    int(mujoco.mjtWarning.mjWARN_BADQACC): "accelerations",
    int(mujoco.mjtWarning.mjWARN_BADQPOS): "positions",
    int(mujoco.mjtWarning.mjWARN_BADQVEL): "velocities",
}
_lock = threading.Lock()
_depth = 0
_saved: object = None
_messages: list[str] = []


def bad_counts(data: mujoco.MjData) -> tuple[int, ...]:
    """How often ``data`` has had NaN/huge accelerations, positions, velocities (MuJoCo's counters)."""
    return tuple(int(data.warning[w].number) for w in _BAD)


class _Watching:
    """The context manager of :func:`watching` (a class: it runs around every chunk of steps)."""

    __slots__ = ()

    def __enter__(self) -> list[str]:
        global _depth, _saved
        with _lock:
            if _depth == 0:
                _saved = mujoco.get_mju_user_warning()
                _messages.clear()
                mujoco.set_mju_user_warning(_messages.append)
            _depth += 1
        return _messages

    def __exit__(self, *exc: object) -> None:
        global _depth
        with _lock:
            _depth -= 1
            if _depth == 0:
                mujoco.set_mju_user_warning(_saved)


_WATCHING = _Watching()


def watching() -> _Watching:
    """While active (``with watching() as messages:``), MuJoCo's warnings are collected in ``messages``
    instead of printed and logged to ``MUJOCO_LOG.TXT``; the previous handler comes back at the end.
    Re-entrant."""
    return _WATCHING


def was_reset(data: mujoco.MjData, time_before: float, n_steps: int, dt: float) -> bool:
    """Whether MuJoCo reset ``data`` during the last ``n_steps`` steps of ``dt`` seconds begun at
    ``time_before``: a reset sets the clock back to 0, so the clock then disagrees with the steps taken.
    (Two float reads: cheap enough to run after every call, where :class:`Watch` costs tens of us.)"""
    return abs(float(data.time) - (time_before + n_steps * dt)) > 0.5 * dt


class Watch:
    """Counts of MuJoCo's instability warnings on some ``mjData``, to compare after each chunk."""

    def __init__(self, datas: Sequence[mujoco.MjData]) -> None:
        self.datas = list(datas)
        self.before = [bad_counts(d) for d in self.datas]

    def new(self) -> list[int]:
        """Indices of the datas with a new instability warning since the last call."""
        hit = []
        for i, d in enumerate(self.datas):
            now = bad_counts(d)
            if now != self.before[i]:
                hit.append(i)
            self.before[i] = now
        return hit


def describe(data: mujoco.MjData, where: str = "the simulation") -> str:
    """One clause: what MuJoCo found unstable in ``data``, and when (from its warning record)."""
    kinds = [name for w, name in _BAD.items() if data.warning[w].number > 0]
    last = [int(data.warning[w].lastinfo) for w in _BAD if data.warning[w].number > 0]
    dof = f" (degree of freedom {last[0]})" if last else ""
    t = reset_time()
    when = f" at t = {t:.4g} s" if t is not None else ""
    return (f"{where} became unstable{when}: MuJoCo found NaN, infinite or huge {' and '.join(kinds) or 'values'}"
            f"{dof} and reset it, so no result from it is valid;")


def reset_time() -> float | None:
    """The simulation time (s) MuJoCo reported with its last warning inside :func:`watching`, if any."""
    for m in reversed(_messages):
        if "Time = " in m:
            try:
                t = float(m.rsplit("Time = ", 1)[1].rstrip(". "))
                return t if math.isfinite(t) else None
            except ValueError:
                return None
    return None


def likely_cause(current: object, default: object, names: Sequence[str] | None = None, top: int = 2) -> str:
    """The parameters of ``current`` that differ most from ``default`` (by ratio), as
    ``"r_max_N = 20 (default 0.03)"`` phrases, for the "likely cause" part of a divergence message.
    ``names``: the parameters to compare (default: every field of the dataclass ``current``; fields that
    are not numbers are skipped)."""
    if names is None:
        from dataclasses import fields

        names = [f.name for f in fields(current)]
    scored = []
    for n in names:
        a, b = getattr(current, n), getattr(default, n)
        if isinstance(a, (int, float)) and isinstance(b, (int, float)) and a != b:
            ratio = abs(math.log(abs(a) / abs(b))) if a and b else math.inf
            scored.append((ratio, f"{n} = {a:g} (default {b:g})"))
    scored.sort(key=lambda s: -s[0])
    return ", ".join(s for _, s in scored[:top])
