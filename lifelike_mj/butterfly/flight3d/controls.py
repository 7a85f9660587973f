"""The controls of the averaged butterfly and its designed controller, and the small geometry both use: the state and
control names, the natural envelope the controls move in, the kinematics changed by controls and read back as controls,
and rotations (issue 42). Kept apart from :mod:`~lifelike_mj.butterfly.flight3d.averaged` (which builds the model by
flying the simulator) so that the controller, low in the slice, needs nothing above it.

The state is the body-axis velocity ``u, v, w`` (x forward, y left, z up; m/s), the body-axis rates ``p, q, r``
(rad/s) and a small rotation ``(a_x, a_y, a_z)`` of the body from the trim attitude, about its own axes (rad; ``a_y >
0`` lowers the nose). The controls (:data:`CONTROLS`) are the symmetric and antisymmetric changes of the kinematics a
controller makes: the flap frequency (Hz), the stroke's offset and amplitude (both wings, and left less right), the
feathering's mean (both, and left less right), the feathering amplitude and the abdomen's angle (rad).
"""

from __future__ import annotations

import math

import numpy as np

#: State names (module docstring).
STATES = ("u", "v", "w", "p", "q", "r", "a_x", "a_y", "a_z")
#: Longitudinal and lateral states (indices into :data:`STATES`).
LONGITUDINAL, LATERAL = (0, 2, 4, 7), (1, 3, 5, 6, 8)
#: Controls (module docstring; Hz or rad).
CONTROLS = ("frequency_hz", "offset", "amplitude", "offset_difference", "amplitude_difference", "feather_mean",
            "feather_mean_difference", "feather_amplitude", "abdomen_mean")
#: The symmetric controls trim may move, and how far from the filmed gait each is allowed (the natural envelope:
#: 9.5-11 Hz, strokes of 110-130 deg, the top of the stroke where the wing tips stop 35-50 deg apart, feathering within
#: 45 deg, the abdomen within its filmed swing around its filmed mean).
ENVELOPE = {"frequency_hz": (9.5, 11.0), "offset": (math.radians(2.0), math.radians(17.0)),
            "amplitude": (math.radians(55.0), math.radians(65.0)), "feather_mean": (math.radians(-20.0), math.radians(20.0)),
            "feather_amplitude": (math.radians(25.0), math.radians(45.0)),
            "abdomen_mean": (math.radians(-31.0), math.radians(-3.0))}
#: The top of the stroke (offset plus amplitude, rad) inside the natural envelope: the wing tips stop 35-50 deg apart
#: above the body (the filmed gait's top at 68 deg leaves them 48.5 deg apart, and each degree higher about 1.7 deg
#: less, measured in the simulator, :func:`~lifelike_mj.butterfly.flight3d.averaged.flown`): the range the designed
#: controller's stroke offset may move the top in (its lowest at the largest amplitude); trims keep above
#: :func:`~lifelike_mj.butterfly.flight3d.averaged.top_floor`.
TOP_RANGE = (math.radians(69.0), math.radians(75.0))


def command_from_controls(base, u) -> np.ndarray:
    """The kinematics parameters (``KinematicsCommand.as_array`` order) of ``base`` changed by the controls ``u``
    (:data:`CONTROLS`, additions to the base's values; differences split half to each wing)."""
    p = base.as_array().copy() if hasattr(base, "as_array") else np.array(base, float)
    f, off, amp, doff, damp, fm, dfm, fa, ab = (float(x) for x in u)
    p[0] += f
    p[1] += off + 0.5 * doff
    p[2] += off - 0.5 * doff
    p[3] += amp + 0.5 * damp
    p[4] += amp - 0.5 * damp
    p[5] += fm + 0.5 * dfm
    p[6] += fm - 0.5 * dfm
    p[7] += fa
    p[8] += fa
    p[10] += ab
    return p


def controls_of(p: np.ndarray) -> np.ndarray:
    """The controls' values (:data:`CONTROLS`) of the kinematics ``p``: the two wings' means and their differences
    (left less right); :func:`command_from_controls` adds changes of them back."""
    return np.array([p[0], 0.5 * (p[1] + p[2]), 0.5 * (p[3] + p[4]), p[1] - p[2], p[3] - p[4], 0.5 * (p[5] + p[6]),
                     p[5] - p[6], 0.5 * (p[7] + p[8]), p[10]])


def rotation(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """The body's axes in the world (columns) for ``roll`` (right wing down > 0), ``pitch`` (nose up > 0) and ``yaw``
    (left > 0), composed yaw, pitch, roll (:func:`~lifelike_mj.butterfly.flight3d.flight.euler_from_quat`)."""
    cr, sr, cp, sp, cy, sy = (math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw),
                              math.sin(yaw))
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])  # nose up about -y
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


def exp_rotation(a: np.ndarray) -> np.ndarray:
    """The rotation matrix of the rotation vector ``a`` (rad)."""
    t = float(np.linalg.norm(a))
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    if t < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + math.sin(t) / t * k + (1.0 - math.cos(t)) / t ** 2 * (k @ k)
