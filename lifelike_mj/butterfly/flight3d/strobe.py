"""Stroboscopic pictures of one wing beat: the butterfly drawn at ``n`` moments of a beat in one image, as a
chronophotograph shows it.

* **side**: the moments where they happened, seen from the butterfly's left: the path through the beat, the body's
  pitching and bobbing, each wing position along it;
* **front**: the moments drawn around the body's first position, seen from ahead: the stroke's envelope, the
  dorsal gap at the top and the wings' lowest reach.

:func:`strobe` flies a :class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D` on through one beat and returns
the image; ``lifelike-mj butterfly strobe3d`` writes it. :func:`landing_strobe` draws a landing on a flower and the
take-off from it the same way, seen from the side (``lifelike-mj butterfly land3d --picture``).
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj import checks

#: The views :func:`strobe` draws: camera azimuth and elevation (deg) about the beat's middle.
VIEWS = {"side": (90.0, -5.0), "front": (180.0, -5.0), "top": (90.0, -89.0)}


def strobe(flight, n: int = 8, views=("side", "front"), width: int = 480, height: int = 360) -> np.ndarray:
    """Fly ``flight`` on through one wing beat (``1 / f`` of its command's frequency) and draw it at ``n`` evenly
    spaced moments (the first at the current state) in each of ``views`` (:data:`VIEWS`), side by side:
    an ``(height, width * len(views), 3)`` RGB image."""
    import mujoco

    from lifelike_mj.butterfly.render import dress
    from lifelike_mj.render.offscreen import Offscreen

    n = checks.whole("n (moments of the beat)", n, 2, 64)
    for v in views:
        if v not in VIEWS:
            from lifelike_mj.errors import unknown_name

            raise unknown_name("unknown view", v, VIEWS)
    m = flight.model
    period = 1.0 / float(flight.kinematics.p[0])
    steps = max(1, int(round(period / n / flight.dt)))
    states = []
    for k in range(n):
        if k:
            flight.step(steps)
        d = mujoco.MjData(m)
        mujoco.mj_copyData(d, m, flight.data)
        mujoco.mj_kinematics(m, d)  # the places of this moment (a step leaves them at its start)
        states.append(d)
    root = int(m.jnt_qposadr[m.joint("root").id])
    first = states[0].qpos[root : root + 3].copy()
    path = np.array([d.qpos[root : root + 3] for d in states])
    span = float(np.max(m.geom_rbound[m.geom_bodyid > 0])) if m.ngeom else 0.06
    panels = []
    dress(m)
    with Offscreen(m, width, height) as r:
        for view in views:
            shown = states
            if view != "side":  # around the body: the stroke's envelope
                shown = []
                for d in states:
                    e = mujoco.MjData(m)
                    mujoco.mj_copyData(e, m, d)
                    e.qpos[root : root + 3] = first
                    mujoco.mj_kinematics(m, e)
                    shown.append(e)
            centre = path.mean(axis=0) if view == "side" else first
            reach = float(np.ptp(path[:, 0])) if view == "side" else 0.0
            panels.append(_exposures(r, m, shown, centre, *VIEWS[view], 1.6 * max(reach, 2.2 * span)))
    return np.concatenate(panels, axis=1)


def _exposures(r, m, states, centre, azimuth: float, elevation: float, extent_m: float) -> np.ndarray:
    """One picture of all ``states`` of model ``m`` at once (a multiple exposure) with the renderer ``r``, a free
    camera looking at ``centre`` from ``azimuth``, ``elevation`` (deg), far enough to see ``extent_m`` across."""
    import mujoco

    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = centre
    cam.azimuth, cam.elevation = azimuth, elevation
    cam.distance = extent_m / math.tan(math.radians(m.vis.global_.fovy) / 2.0) / 2.0
    r.update(m, states[0], cam)
    for e in states[1:]:
        r.add(m, e)
    return r.draw().copy()


def landing_strobe(controller, flowers=((0.0, 0.0, -0.1), (1.2, 0.4, -0.25)), every_s: float = 0.04,
                   before_s: float = 0.6, after_s: float = 0.4, perch_s: float = 1.0, width: int = 640,
                   height: int = 420, land: bool = True) -> tuple[np.ndarray, dict]:
    """A landing and a take-off, each in one picture of moments ``every_s`` apart, seen from the side of the path:
    the butterfly ``controller`` starts perched on ``flowers[0]``, takes off and lands on ``flowers[1]``; the left
    panel shows its last ``before_s`` before touchdown and the perch after ``perch_s`` (the wings closed), the right
    panel the take-off back towards ``flowers[0]``, its first ``after_s``. Returns the ``(height, 2 width, 3)`` image
    and what happened (``touchdown``: time and speed; ``landed``). Without ``land``: the take-off from ``flowers[0]``
    towards ``flowers[1]`` only, its perch first (one panel)."""
    from collections import deque

    import mujoco

    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.landing import MAX_LANDING_S
    from lifelike_mj.butterfly.flight3d.parts import World
    from lifelike_mj.butterfly.render import dress
    from lifelike_mj.render.offscreen import Offscreen

    f = Flight3D(controller=controller, world=World(flowers=flowers))
    m = f.model
    f.perch_on(0)
    f.step(int(round(0.3 / f.dt)))
    every = max(1, int(round(checks.positive("every_s", every_s, "s") / f.dt)))

    def copy():
        d = mujoco.MjData(m)
        mujoco.mj_copyData(d, m, f.data)
        mujoco.mj_kinematics(m, d)
        return d

    before: deque = deque(maxlen=max(1, int(round(before_s / every_s))))
    touchdown, back = None, 1
    if land:
        f.take_off(f.land_on(1))
        t0 = f.time
        while not f.perched and f.time - t0 < MAX_LANDING_S:
            f.step(every)
            before.append(copy())
        touchdown, back = f.touchdown, 0
        if touchdown is None:
            from lifelike_mj.errors import UserError

            raise UserError(f"the butterfly did not land on the flower within {MAX_LANDING_S:g} s, so there is no "
                            "landing to draw; a controller that lands (with a land network, or evolved on the garden "
                            "task set) draws one.")
        f.step(int(round(perch_s / f.dt)))
    perched = copy()
    f.take_off(f.land_on(back))
    after = [perched]
    for _ in range(max(1, int(round(after_s / every_s)))):
        f.step(every)
        after.append(copy())
    root = int(m.jnt_qposadr[m.joint("root").id])
    a, b = np.asarray(flowers[0], dtype=float), np.asarray(flowers[1], dtype=float)
    heading = math.degrees(math.atan2(b[1] - a[1], b[0] - a[0]))
    dress(m)
    panels = []
    with Offscreen(m, width, height) as r:
        for states in ((list(before) + [perched], after) if land else (after,)):
            path = np.array([d.qpos[root : root + 3] for d in states])
            reach = float(np.max(np.ptp(path, axis=0)))
            panels.append(_exposures(r, m, states, path.mean(axis=0), heading + 90.0, -5.0, 1.3 * max(reach, 0.12)))
    return np.concatenate(panels, axis=1), {"touchdown": touchdown, "landed": touchdown is not None, "drew_landing": land}
