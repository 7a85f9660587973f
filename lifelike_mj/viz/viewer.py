"""The MuJoCo viewer on a flying butterfly (interactive inspection).

:func:`view_butterfly` opens ``mujoco.viewer.launch_passive`` on the real simulation (compiled
wing-force callback, controller once per step, see :mod:`lifelike_mj.viz.video`) and steps it
in about real time. Without a display ``launch_passive`` kills the whole process, so the display
is checked first and its absence reported as a :class:`~lifelike_mj.errors.UserError`.
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import TYPE_CHECKING

from lifelike_mj.errors import UserError

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.butterfly.controllers import ButterflyController
    from lifelike_mj.butterfly.paper import Condition
    from lifelike_mj.butterfly.params import ButterflyParams

#: Wall-clock interval between viewer refreshes, s (about 60 Hz).
FRAME_S = 1.0 / 60.0
#: At most this much simulated time (s) is stepped between two refreshes; if the simulation falls
#: further behind the wall clock (a slow machine, a window drag), the viewer slows down instead of
#: freezing while it catches up.
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


def view_butterfly(controller: ButterflyController, params: ButterflyParams | None = None,
                   condition: Condition | None = None, config: str = "paper", force_mode: str = "tip",
                   duration_s: float | None = None) -> None:
    """Fly the butterfly in the MuJoCo viewer in about real time, until the window is closed or
    ``duration_s`` seconds of simulated flight have passed (``None``: until closed).

    The camera tracks the butterfly from the side, slightly behind (drag to orbit, as usual).
    Time step 1/1200 s. Raises :class:`UserError` when there is no display; on macOS run it under
    ``mjpython``.
    """
    require_display("butterfly")
    if duration_s is not None and (isinstance(duration_s, bool) or not isinstance(duration_s, (int, float))
                                   or not (math.isfinite(duration_s) and duration_s > 0)):
        raise UserError(f"duration must be a positive number of seconds, got {duration_s!r}.")

    import mujoco

    from lifelike_mj.viz.video import FOLLOW_AZIMUTH_DEG, FOLLOW_DISTANCE_M, FOLLOW_ELEVATION_DEG, _Flight

    flight = _Flight(controller, params, condition, config, force_mode)  # compiles the loop (about 1 s)
    with launch_viewer(flight.m, flight.d) as viewer:
        with viewer.lock():
            viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
            viewer.cam.trackbodyid = flight.body
            viewer.cam.distance = FOLLOW_DISTANCE_M
            viewer.cam.azimuth = FOLLOW_AZIMUTH_DEG
            viewer.cam.elevation = FOLLOW_ELEVATION_DEG
            viewer.opt.sitegroup[:] = 0
        end_step = None if duration_s is None else int(round(duration_s / flight.dt))
        max_chunk = max(1, int(round(MAX_CATCH_UP_S / flight.dt)))
        start = time.perf_counter()
        sim_at_start = 0
        while viewer.is_running():
            target = sim_at_start + int((time.perf_counter() - start) / flight.dt)
            if target - flight.k > max_chunk:  # fell behind: re-anchor the clock, run slower than real time
                target = flight.k + max_chunk
                sim_at_start, start = target, time.perf_counter()
            if end_step is not None:
                target = min(target, end_step)
            with viewer.lock():
                flight.advance_to(target)
            viewer.sync()
            if end_step is not None and flight.k >= end_step:
                break
            time.sleep(FRAME_S)
