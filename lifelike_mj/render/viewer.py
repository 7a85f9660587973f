"""The MuJoCo viewer on a live simulation: one real-time loop for every creature.

:func:`view` opens ``mujoco.viewer.launch_passive`` on a stepper's model and data (the shape of
:mod:`lifelike_mj.stepper`) and steps it in about real time, until the window is closed or a
number of steps has been shown. Without a display ``launch_passive`` kills the whole process, so
:func:`require_display` checks first and reports its absence as a
:class:`~lifelike_mj.errors.UserError`.
"""

from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable
from typing import Any

from lifelike_mj.errors import UserError

#: Wall-clock interval between viewer refreshes, s (about 60 Hz).
FRAME_S = 1.0 / 60.0
#: At most this much wall-clock time's worth of steps is run between two refreshes; if the
#: simulation falls further behind the wall clock (a slow machine, a window drag), the viewer slows
#: down instead of freezing while it catches up.
MAX_CATCH_UP_S = 0.1


def has_display() -> bool:
    """Whether a window can be opened: on Linux, ``DISPLAY`` or ``WAYLAND_DISPLAY`` is set;
    assumed true on macOS and Windows."""
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def require_display(creature: str) -> None:
    """Raise :class:`UserError` (pointing to ``lifelike-mj render CREATURE``) when :func:`has_display`
    says no window can be opened: ``launch_passive`` would kill the whole process."""
    if not has_display():
        raise UserError("no display found (DISPLAY and WAYLAND_DISPLAY are unset), so the viewer cannot open a "
                        f"window; use `lifelike-mj render {creature} --out FILE.mp4` instead.")


def launch_viewer(m, d):
    """``mujoco.viewer.launch_passive`` on model ``m`` and data ``d``, side panels hidden; a viewer
    that cannot start (macOS outside ``mjpython``) is a :class:`UserError`."""
    import mujoco.viewer

    try:
        return mujoco.viewer.launch_passive(m, d, show_left_ui=False, show_right_ui=False)
    except RuntimeError as exc:
        raise UserError(f"the MuJoCo viewer cannot start here ({str(exc).strip()}).") from None


def view(stepper: Any, steps_per_s: float, end_step: int | None = None,
         setup: Callable[[Any], None] | None = None, web: Any = None) -> None:
    """Show ``stepper`` in the MuJoCo viewer, ``steps_per_s`` steps per wall-clock second, until the
    window is closed or the stepper reaches step ``end_step`` (``None``: until closed).

    ``setup(viewer)`` places the viewer's camera (called under the viewer's lock before the first
    refresh). The stepper is advanced with ``step(n)`` and drawn after ``sync()``; when it cannot keep
    up, the clock is re-anchored and the view runs slower than asked rather than freezing.

    ``web``: :class:`~lifelike_mj.render.web.WebOptions` to show it in MuJoCo's web viewer instead (no display
    needed; :func:`~lifelike_mj.render.web.launch_web`), until the stepper reaches ``end_step`` or Ctrl+C.
    """
    if web is not None:
        from lifelike_mj.render.web import launch_web

        opened = launch_web(stepper.model, stepper.data, web, setup=setup)
    else:
        opened = launch_viewer(stepper.model, stepper.data)
    with opened as viewer:
        with viewer.lock():
            viewer.opt.sitegroup[:] = 0
            if setup is not None:
                setup(viewer)
        max_chunk = max(1, int(round(MAX_CATCH_UP_S * steps_per_s)))
        start = time.perf_counter()
        at_start = int(stepper.steps)
        while viewer.is_running():
            target = at_start + int((time.perf_counter() - start) * steps_per_s)
            if target - stepper.steps > max_chunk:  # fell behind: re-anchor the clock, run slower than asked
                target = int(stepper.steps) + max_chunk
                at_start, start = target, time.perf_counter()
            if end_step is not None:
                target = min(target, end_step)
            with viewer.lock():
                if target > stepper.steps:
                    stepper.step(target - int(stepper.steps))
                stepper.sync()
            viewer.sync()
            if end_step is not None and stepper.steps >= end_step:
                break
            time.sleep(FRAME_S)
