"""Cameras for :class:`~lifelike_mj.render.offscreen.Offscreen` and the viewer (``MjvCamera``).

``mujoco`` is imported only inside the functions (see :mod:`lifelike_mj.render.gl`).
"""

from __future__ import annotations

from lifelike_mj.errors import UserError


def tracking(body: int, distance_m: float, azimuth_deg: float, elevation_deg: float):
    """A camera that follows body ``body`` at ``distance_m`` metres, from azimuth and elevation (deg)."""
    import mujoco

    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    cam.trackbodyid = body
    cam.fixedcamid = -1
    cam.distance = distance_m
    cam.azimuth = azimuth_deg
    cam.elevation = elevation_deg
    return cam


def camera_names(m) -> list[str]:
    """Names of the cameras of model ``m``, in order."""
    return [m.camera(i).name for i in range(m.ncam)]


def fixed(m, name: str, others: tuple[str, ...] = ()):
    """The model's camera ``name``; a :class:`UserError` naming the choices (``others`` first) if it
    has none of that name."""
    import mujoco

    names = camera_names(m)
    if name not in names:
        raise UserError(f"unknown camera {name!r}; choose one of {', '.join((*others, *names))}.")
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
    cam.fixedcamid = m.camera(name).id
    return cam


def free(lookat, distance_m: float, azimuth_deg: float, elevation_deg: float, orthographic: bool = False):
    """A free camera looking at the point ``lookat`` (m) from ``distance_m``, azimuth and elevation (deg)."""
    import mujoco

    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = lookat
    cam.distance = distance_m
    cam.azimuth = azimuth_deg
    cam.elevation = elevation_deg
    cam.orthographic = int(orthographic)
    return cam
