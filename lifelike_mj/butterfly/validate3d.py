"""Checks of the 3D butterfly against the planar one: the reduction to the paper's flight.

With both wings flapping alike, the paper's mass layout (all of the 0.319 g in the thorax), the paper's
tip-speed law (Oe 2010 eq. 7-9), body drag on the world's axes (eq. 10) and the body's pitch set once per
step by the paper's pitch law (section 5.1; roll and yaw held at 0), the 3D model must fly the planar
MuJoCo model's flight: the motion stays in the sagittal plane and the path is the same.
"""

from __future__ import annotations

import numpy as np

from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import pitch_command


def kinematics_of(controller: ButterflyController):
    """The :class:`~lifelike_mj.butterfly.kinematics3d.KinematicsCommand` of a planar controller's flap
    pattern (Oe 2010 section 4.3: ``theta_c + theta_a cos(2 pi f t)`` on both wings, no feathering)."""
    from lifelike_mj.butterfly.kinematics3d import KinematicsCommand

    fl = controller.flap
    return KinematicsCommand(frequency_hz=fl.frequency_hz, offset_left=fl.theta_c, offset_right=fl.theta_c,
                             amplitude_left=fl.theta_a, amplitude_right=fl.theta_a)


def reduction(controller: ButterflyController | str = "simple_rule", duration_s: float = 20.0,
              dt_s: float = 1.0 / 1200.0) -> dict:
    """Fly ``controller`` on the planar MuJoCo model (``config="paper"``, tip-speed law) and on the 3D
    model reduced to it (module docstring) for ``duration_s``; return the largest differences of the
    paths (m) and the largest sideways excursion of the 3D flight (m), with both end points."""
    from lifelike_mj.butterfly import controllers as _controllers
    from lifelike_mj.butterfly.sim import Flight
    from lifelike_mj.butterfly.sim3d import Flight3D

    ctrl = controller if isinstance(controller, ButterflyController) else _controllers.load(controller)
    planar = Flight(ctrl, backend="mujoco", config="paper", force_mode="tip", dt_s=dt_s).record(duration_s=duration_s)
    kind, cp = ctrl.compiled()
    kind = int(kind)
    last = [0.0]

    def law(f) -> float:
        # the planar loop's pitch law with the 3D state: flap reference, altitude, climb and forward speed
        ref = f.kinematics.joint_references()
        q, v = f.data.qpos, f.data.qvel
        last[0] = pitch_command(kind, cp, f.time, ref[0, 0], ref[0, 1], q[2], 0.0, v[2], v[0], 0.0, 0.0, last[0])
        return last[0]

    flight = Flight3D(kinematics_of(ctrl), masses="paper", force_law="tip", drag_frame="world", assist="hold",
                      pitch_law=law, dt_s=dt_s)
    path = np.empty((len(planar.t), 3))
    path[0] = flight.state()["position_m"]
    for k in range(1, len(planar.t)):
        flight.step(1)
        path[k] = flight.data.qpos[:3]
    return {"duration_s": float(planar.t[-1]),
            "max_forward_difference_m": float(np.abs(path[:, 0] - planar.z).max()),
            "max_altitude_difference_m": float(np.abs(path[:, 2] - planar.y).max()),
            "max_sideways_m": float(np.abs(path[:, 1]).max()),
            "planar_end_m": [float(planar.z[-1]), float(planar.y[-1])],
            "reduced_end_m": [float(path[-1, 0]), float(path[-1, 2])]}
