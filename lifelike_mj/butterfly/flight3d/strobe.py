"""Stroboscopic pictures of one wing beat: the butterfly drawn at ``n`` moments of a beat in one image, as a
chronophotograph shows it.

* **side**: the moments where they happened, seen from the butterfly's left: the path through the beat, the body's
  pitching and bobbing, each wing position along it;
* **front**: the moments drawn around the body's first position, seen from ahead: the stroke's envelope, the
  dorsal gap at the top and the wings' lowest reach.

:func:`strobe` flies a :class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D` on through one beat and returns
the image; ``lifelike-mj butterfly strobe3d`` writes it.
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
    span = float(np.max(m.geom_rbound)) if m.ngeom else 0.06
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
            cam = mujoco.MjvCamera()
            cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            cam.lookat[:] = centre
            cam.azimuth, cam.elevation = VIEWS[view]
            cam.distance = 1.6 * max(reach, 2.2 * span) / math.tan(math.radians(m.vis.global_.fovy) / 2.0) / 2.0
            r.update(m, shown[0], cam)
            for e in shown[1:]:
                r.add(m, e)
            panels.append(r.draw().copy())
    return np.concatenate(panels, axis=1)
