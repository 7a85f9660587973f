"""Watching a 3D butterfly live: the MuJoCo viewer (or its web viewer) on a flight, with keys that steer it
and change the wind."""

from __future__ import annotations

import math

import mujoco

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.tasks import level
from lifelike_mj.render.viewer import Control, require_display, view

#: The 3D viewer's keys: the altitude step (m), the heading step (rad) and the wind (m/s) of keys 1-4.
ALTITUDE_STEP_M = 0.5
HEADING_STEP_RAD = math.pi / 4
WIND_KEY_M_S = 1.0


#: The 3D viewer's keys and what each does (none of them is one of MuJoCo's viewer's own).
FLIGHT3D_KEYS = (("Up", "climb 0.5 m"), ("Down", "descend 0.5 m"), ("Left", "turn left 45 deg"),
                 ("Right", "turn right 45 deg"), ("6", "wind 1 m/s toward +x"), ("7", "wind 1 m/s toward +y"),
                 ("8", "wind 1 m/s toward -x"), ("9", "wind 1 m/s toward -y"), ("Space", "calm"))


def flight3d_controls(flight) -> list:
    """The 3D butterfly's keys (:data:`FLIGHT3D_KEYS`; buttons in the web viewer;
    :class:`~lifelike_mj.render.viewer.Control`): the arrows raise or lower the target altitude by
    :data:`ALTITUDE_STEP_M` and turn the course left or right by 45 deg, ``6``-``9`` blow a :data:`WIND_KEY_M_S`
    wind toward +x, +y, -x, -y and Space calms it (:meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.set_reference`,
    :meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.set_wind`)."""
    def climb(dz: float):
        return lambda: flight.set_reference(altitude_m=flight.reference[1] + dz)

    def turn(da: float):
        return lambda: flight.set_reference(heading_rad=flight.reference[0] + da)

    def blow(x: float, y: float):
        return lambda: flight.set_wind((x, y, 0.0))

    w = WIND_KEY_M_S
    acts = (climb(ALTITUDE_STEP_M), climb(-ALTITUDE_STEP_M), turn(HEADING_STEP_RAD), turn(-HEADING_STEP_RAD),
            blow(w, 0.0), blow(0.0, w), blow(-w, 0.0), blow(0.0, -w), blow(0.0, 0.0))
    return [Control(key, label, act) for (key, label), act in zip(FLIGHT3D_KEYS, acts, strict=True)]


def view_flight3d(controller="designed", speed_m_s: float = 1.5, duration_s: float | None = None, flight=None,
                  web=None) -> None:
    """Fly a 3D butterfly in the MuJoCo viewer in about real time, level at ``speed_m_s``, the camera following
    it, with the keys of :func:`flight3d_controls` (steer it, change the wind).
    ``controller``: a 3D controller of either kind, or its name or file (default ``designed``);
    ``flight``: a :class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D` of your own instead; ``web``:
    :class:`~lifelike_mj.render.web.WebOptions` to serve MuJoCo's web viewer (no display needed)."""
    if web is None:
        require_display("butterfly3d")
    if duration_s is not None:
        duration_s = checks.positive("duration", duration_s, "s")
    if flight is None:
        flight = Flight3D(controller=controller, task=level(checks.positive("speed_m_s", speed_m_s, "m/s")))
    flight.step(1)  # compiles the flight loop before the window opens
    end = None if duration_s is None else flight.steps + int(round(duration_s / flight.dt))
    body = flight.model.body("butterfly").id

    def setup(viewer) -> None:
        viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
        viewer.cam.trackbodyid = body
        viewer.cam.distance, viewer.cam.azimuth, viewer.cam.elevation = 1.0, 200.0, -15.0

    flight.sync()
    view(flight, 1.0 / flight.dt, end, setup, web=web, controls=flight3d_controls(flight))
