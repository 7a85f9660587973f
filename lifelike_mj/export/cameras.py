"""Where to look at a run from: the framing every exporter shares (glTF cameras, the web page's view).

* **overview**: a still camera that sees the whole run, every body at every frame and the world's still
  geoms other than a ground plane (a tank, a box, flowers), from the front left
  and above (azimuth -60 deg, elevation 25 deg, vertical field of view 45 deg);
* **follow**: where the run has one creature (one body tree under the world), a camera that keeps the same
  direction and moves with the creature's root body, at a distance of 8 times the creature's size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from lifelike_mj.export.poses import Poses, drawn_geoms

#: The cameras' vertical field of view (deg), azimuth and elevation (deg, MuJoCo's world: Z up).
FOV_DEG = 45.0
AZIMUTH_DEG = -60.0
ELEVATION_DEG = 25.0
#: The follow camera's distance in creature sizes, and its least distance (m).
FOLLOW_SIZES = 8.0
FOLLOW_MIN_M = 0.3
#: The world's still geoms smaller than this (m, bounding radius) are kept in the overview.
MAX_STILL_M = 100.0
#: The picture's width over height that the overview is framed for.
ASPECT = 4.0 / 3.0


@dataclass
class Framing:
    """``centre_m``: the centre of the box around every body at every frame (m, MuJoCo's world);
    ``direction``: unit vector from what is looked at to the camera; ``follow``: index (into the poses'
    bodies) of the one creature's root body, or None; ``follow_m``: the follow camera's distance;
    ``overview_m``: the overview camera's distance from ``centre_m``, the nearest that keeps the box around
    everything in a picture of aspect :data:`ASPECT`."""

    centre_m: np.ndarray
    direction: np.ndarray
    follow: int | None
    follow_m: float
    overview_m: float

    def axes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The cameras' right, up and back unit vectors in MuJoCo's world (back = ``direction``)."""
        return _axes(self.direction)

    def look_quat_wxyz(self) -> np.ndarray:
        """The cameras' orientation (:func:`look_quat_wxyz` of ``direction``)."""
        return look_quat_wxyz(self.direction)


def look_quat_wxyz(direction: np.ndarray) -> np.ndarray:
    """A camera's orientation (w, x, y, z) in MuJoCo's world, for a glTF camera (it looks along its own -Z, with
    +Y up): looking along ``-direction`` with the world's Z up in the picture."""
    R = np.column_stack(_axes(direction))
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, R.reshape(-1))
    return q


def _axes(back: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    right = np.cross(np.array([0.0, 0.0, 1.0]), back)
    right /= np.linalg.norm(right)
    return right, np.cross(back, right), back


def bounds(poses: Poses) -> tuple[np.ndarray, np.ndarray, float]:
    """``(lo, hi, size)``: the box (m, MuJoCo's world) around every body at every sample, grown by ``size`` (the
    farthest a drawn geom of a body reaches from the body's origin), and around the world's still geoms other
    than a ground plane (a tank, a box, flowers)."""
    m = poses.model
    drawn = drawn_geoms(m)
    size = 0.0
    for g in drawn[m.geom_bodyid[drawn] > 0]:
        size = max(size, float(np.linalg.norm(m.geom_pos[g]) + m.geom_rbound[g]))
    pts = poses.position_m.reshape(-1, 3)
    lo, hi = pts.min(axis=0) - size, pts.max(axis=0) + size
    for g in still_geoms(m):
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, m.geom_quat[g])
        R = R.reshape(3, 3)
        centre_g = m.geom_pos[g] + R @ m.geom_aabb[g, :3]  # the geom's own box, turned into the world
        half = np.abs(R) @ m.geom_aabb[g, 3:]
        lo, hi = np.minimum(lo, centre_g - half), np.maximum(hi, centre_g + half)
    return lo, hi, size


def still_geoms(m: mujoco.MjModel) -> list[int]:
    """The world's drawn still geoms that frame a view: not a ground plane, nothing :data:`MAX_STILL_M` or
    larger."""
    drawn = drawn_geoms(m)
    return [int(g) for g in drawn[m.geom_bodyid[drawn] == 0]
            if 0.0 < m.geom_rbound[g] < MAX_STILL_M and m.geom_type[g] != mujoco.mjtGeom.mjGEOM_PLANE]


def view_direction() -> np.ndarray:
    """The unit vector from what the cameras look at to the cameras (:data:`AZIMUTH_DEG`, :data:`ELEVATION_DEG`)."""
    az, el = math.radians(AZIMUTH_DEG), math.radians(ELEVATION_DEG)
    return np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


def overview(lo: np.ndarray, hi: np.ndarray, direction: np.ndarray) -> tuple[np.ndarray, float]:
    """``(centre, distance)``: the centre of the box ``lo``-``hi`` and the nearest distance from it along
    ``direction`` that keeps the whole box in a picture of aspect :data:`ASPECT` (with 5 % to spare)."""
    centre = (lo + hi) / 2.0
    right, up, back = _axes(direction)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]) - centre
    tan_v = math.tan(math.radians(FOV_DEG) / 2.0)
    need = corners @ back + np.maximum(np.abs(corners @ up) / tan_v, np.abs(corners @ right) / (tan_v * ASPECT))
    return centre, 1.05 * float(need.max())


def framing(poses: Poses) -> Framing:
    """The framing (module docstring) of ``poses``."""
    m = poses.model
    lo, hi, size = bounds(poses)
    direction = view_direction()
    roots = {int(m.body_rootid[b]) for b in poses.body_ids}
    follow, follow_m = None, 0.0
    if len(roots) == 1:
        root = roots.pop()
        ids = [int(b) for b in poses.body_ids]
        if root in ids:
            follow = ids.index(root)
            reach = np.linalg.norm(poses.position_m[0] - poses.position_m[0, follow], axis=1).max() + size
            follow_m = max(FOLLOW_SIZES * float(reach), FOLLOW_MIN_M)
    centre, distance = overview(lo, hi, direction)
    return Framing(centre, direction, follow, follow_m, distance)
