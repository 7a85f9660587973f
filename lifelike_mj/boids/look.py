"""How a bird of the flock looks when its motion leaves the project: a rig (:mod:`lifelike_mj.export.rig`) per
agent, a textured bird (body, head, beak, two-segment wings, tail) made here, with wing beats and banking
computed from the flock's recorded motion afterwards (the flock itself is untouched).

Bones of agent ``boidN``:

* ``boidN``: the MuJoCo body, exactly as the flock has it (the paper's agent: its drawn heading is its velocity
  at that step, which in many patterns turns by tens of degrees from one step to the next);
* ``boidN/flight``: the bird as it flies, which the mesh follows: at the agent's path smoothed over
  :data:`SMOOTH_STEPS` steps (a Gaussian), heading along that path, pitched with its climb, and banked into
  turns by the coordinated-turn relation ``tan(bank) = v * yaw rate / g`` (v and the yaw rate of the smoothed
  path in the file's units: box units as metres and playback seconds; g = 9.81 m/s^2);
* ``boidN/wing_left_inner``, ``.../wing_left_outer`` (and right): the wing beat, a flap about the body's
  long axis at the shoulder, the outer wing lagging and folding on the upstroke;
* ``boidN/tail``: spread and lifted a little in turns and climbs.

The wing beat follows the flight's effort: frequency :data:`FLAP_HZ` (about 10 Hz: Pennycuick's 1996 formula
for a starling, derived) rising to :data:`FLAP_HZ_MAX` with climb and acceleration, amplitude from
:data:`FLAP_DEG` to :data:`FLAP_DEG_MAX`; when the bird slows or sinks the wings stop spread in a glide (flap
and glide: Tobalske 1995, J Exp Biol 198:1259). How effort maps to frequency and amplitude is a look: no
starling figure gives it.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj.export.meshes import Piece, assemble, loft, rigid, sheet, sphere
from lifelike_mj.export.rig import Bone, Look, Rig, body_bone, continuous, creatures, extra_bone, qaxis, qmul, smooth

#: The path is smoothed over this many steps (a Gaussian's sigma) for the flight bone.
SMOOTH_STEPS = 10.0
#: Wing beat: frequency (Hz) and amplitude (deg, each side of the mid stroke) at rest effort and at full effort.
FLAP_HZ, FLAP_HZ_MAX, FLAP_DEG, FLAP_DEG_MAX = 9.0, 13.0, 35.0, 55.0
#: Below this effort (0-1) the bird glides, wings spread.
GLIDE_BELOW = 0.25
G = 9.81


def flight_frame(t: np.ndarray, pos: np.ndarray, sigma: float = SMOOTH_STEPS, metres_per_unit: float = 1.0):
    """The flight bone's world pose at every sample (module docstring) and what it came from: ``(position,
    quat_wxyz, series)`` with ``series`` holding speed (m/s), yaw rate (rad/s), bank (rad), climb (m/s) and
    acceleration (m/s^2) along the path; ``pos`` in units of ``metres_per_unit`` metres (the series in m/s)."""
    p = smooth(pos, sigma)
    n = len(t)
    v = metres_per_unit * np.gradient(p, t, axis=0) if n > 2 else np.tile(np.array([1e-9, 0.0, 0.0]), (n, 1))
    speed = np.linalg.norm(v, axis=1)
    horiz = np.linalg.norm(v[:, :2], axis=1)
    yaw = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
    pitch = np.arctan2(v[:, 2], np.maximum(horiz, 1e-12))
    yaw_rate = np.gradient(yaw, t) if n > 2 else np.zeros(n)
    bank = np.arctan(horiz * yaw_rate / G)  # coordinated turn: tan(bank) = v * yaw rate / g
    accel = np.gradient(speed, t) if n > 2 else np.zeros(n)
    # heading, then climb (nose up: a negative turn about y), then bank (into a left turn, a positive yaw rate,
    # the left wing goes down: a negative turn about the forward axis)
    q = qmul(qmul(qaxis((0.0, 0.0, 1.0), yaw), qaxis((0.0, 1.0, 0.0), -pitch)), qaxis((1.0, 0.0, 0.0), -bank))
    series = {"speed_m_s": speed, "yaw_rate_rad_s": yaw_rate, "bank_rad": bank, "climb_m_s": v[:, 2],
              "accel_m_s2": accel, "horizontal_m_s": horiz}
    return p, continuous(q), series


def effort(series: dict) -> np.ndarray:
    """How hard the bird works its wings (0 glide .. 1 full): half at level, steady flight, more with climb
    (per unit of speed) and acceleration (per g), less when slowing or sinking."""
    v = np.maximum(series["speed_m_s"], 1e-9)
    e = 0.5 + 1.5 * series["climb_m_s"] / v + 2.0 * series["accel_m_s2"] / G
    return np.clip(smooth(e[:, None], 4.0)[:, 0], 0.0, 1.0)


def _plumage(px: int = 128) -> np.ndarray:
    """A starling's plumage (u along the body or wing, v across): dark glossy with pale speckles."""
    u, v = np.meshgrid((np.arange(px) + 0.5) / px, (np.arange(px) + 0.5) / px)
    rng = np.random.default_rng(7)  # the texture's own speckles: the same in every file
    speck = rng.random((px, px)) > 0.93
    base = np.array([38, 40, 48]) * (0.85 + 0.3 * np.sin(np.pi * v))[..., None]
    gloss = np.array([30, 70, 60]) * (0.5 + 0.5 * np.sin(6 * np.pi * u))[..., None] * 0.25
    img = base + gloss
    img[speck] = [215, 205, 180]
    return np.concatenate([np.clip(img, 0, 255), np.full((px, px, 1), 255.0)], axis=-1).astype(np.uint8)


def bird_mesh(length: float, looks: dict, flight: int, wings: dict, tail: int) -> list[Piece]:
    """A bird ``length`` long (x forward, z up): body, head, beak, inner and outer wings on their bones, tail."""
    L = length
    s = np.linspace(0.0, 1.0, 18)
    x = L * (0.45 - 0.75 * s)
    prof = np.sqrt(np.clip(np.sin(np.pi * np.clip(s, 0.0, 1.0)), 0.0, 1.0))
    pieces = [loft(x, 0.13 * L * prof, 0.12 * L * prof, looks["plumage"], rigid(1, flight),
                   centre_z=0.02 * L * np.sin(np.pi * s))]
    pieces.append(sphere((0.42 * L, 0.0, 0.05 * L), (0.1 * L, 0.085 * L, 0.085 * L), looks["plumage"], rigid(1, flight)))
    sb = np.linspace(0.0, 1.0, 5)
    pieces.append(loft(L * (0.5 + 0.13 * sb), 0.025 * L * (1 - sb) + 1e-5, 0.02 * L * (1 - sb) + 1e-5, looks["beak"],
                       rigid(1, flight), centre_z=np.full(5, 0.04 * L)))
    span = 0.9 * L  # one wing, shoulder to tip (a starling's span is about twice its length)
    n = 8
    for side, sign in (("left", 1.0), ("right", -1.0)):
        inner, outer = wings[side]
        c = np.linspace(0.0, 1.0, n)[:, None]  # chord, leading edge (0) to trailing edge (1)
        a = np.linspace(0.0, 1.0, 6)[None, :]  # along the span
        # inner wing: broad, from the shoulder to the wrist (0.45 of the span)
        chord_in = 0.32 * L * (1.0 - 0.25 * a)
        pts = np.stack(np.broadcast_arrays(-c * chord_in, sign * 0.45 * span * a, 0.0 * a + 0.0 * c), axis=-1)
        pieces.append(sheet(pts, np.stack(np.broadcast_arrays(a * 0.45, c), axis=-1), looks["wing"], rigid(1, inner)))
        # outer wing: from the wrist, tapering to a pointed tip swept back
        chord_out = 0.24 * L * (1.0 - 0.85 * a)
        sweep = -0.12 * L * a
        pts = np.stack(np.broadcast_arrays(sweep - c * chord_out, sign * (0.45 + 0.55 * a) * span,
                                           0.0 * a + 0.0 * c), axis=-1)
        piece = sheet(pts, np.stack(np.broadcast_arrays(0.45 + 0.55 * a, c), axis=-1), looks["wing"],
                      rigid(1, outer))
        pieces.append(piece)
    st = np.linspace(-1.0, 1.0, 7)[None, :]
    r = np.linspace(0.0, 1.0, 6)[:, None]
    pts = np.stack(np.broadcast_arrays(-0.3 * L * r, 0.07 * L * st * (0.6 + r), 0.0 * r + 0.0 * st), axis=-1)
    pieces.append(sheet(pts, np.stack(np.broadcast_arrays((st + 1) / 2, r), axis=-1), looks["wing"], rigid(1, tail)))
    return pieces


def bird_rig(poses, i: int, length: float, looks: dict, meshes: dict, sigma: float = SMOOTH_STEPS,
             metres_per_unit: float = 1.0) -> Rig:
    """The rig of the flock's ``i``-th body (module docstring); ``metres_per_unit``: the flock's unit in metres
    (its speeds, climbs and accelerations in m/s for the turn relation and the effort)."""
    t = poses.t_s
    body = body_bone(poses, i, -1)
    p, q, series = flight_frame(t, body.position_m, sigma, metres_per_unit)
    bones: list[Bone] = [body, Bone(f"{body.name}/flight", -1, np.eye(4), p, q)]
    e = effort(series)
    glide = e < GLIDE_BELOW
    f = FLAP_HZ + (FLAP_HZ_MAX - FLAP_HZ) * e
    phase = 2 * np.pi * np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))]) if len(t) > 1 \
        else np.zeros(len(t))
    amp = np.radians(FLAP_DEG + (FLAP_DEG_MAX - FLAP_DEG) * e) * np.where(glide, 0.0, 1.0)
    amp = smooth(amp[:, None], 3.0)[:, 0]  # into and out of a glide smoothly
    stroke = amp * np.sin(phase) + math.radians(8.0)  # a little dihedral
    fold = np.radians(25.0) * np.clip(np.cos(phase), 0.0, None) * (amp > 0.05)  # the outer wing folds going up
    wings = {}
    x = (1.0, 0.0, 0.0)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        bones.append(extra_bone(f"{body.name}/wing_{side}_inner", 1, bones, (0.15 * length, sign * 0.1 * length,
                                                                             0.06 * length), qaxis(x, sign * stroke)))
        inner = len(bones) - 1
        bones.append(extra_bone(f"{body.name}/wing_{side}_outer", inner, bones, (0.0, sign * 0.405 * length, 0.0),
                                qaxis(x, -sign * fold)))
        wings[side] = (inner, len(bones) - 1)
    lift = np.radians(10.0) * np.clip(np.abs(series["bank_rad"]) + series["climb_m_s"] /
                                      np.maximum(series["speed_m_s"], 1e-9), 0.0, 1.0)
    bones.append(extra_bone(f"{body.name}/tail", 1, bones, (-0.3 * length, 0.0, 0.0), qaxis((0.0, 1.0, 0.0), -lift)))
    if "mesh" not in meshes:
        meshes["mesh"] = assemble("bird", bird_mesh(length, looks, 1, wings, len(bones) - 1))
    return Rig(body.name, bones, meshes["mesh"], {}, {**series, "effort": e, "flap_hz": f, "glide": glide})


def agent_length(poses) -> float:
    """The agents' drawn body length (the flock's units): twice the first agent's geom's half length."""
    m = poses.model
    g = int(np.nonzero(m.geom_bodyid == poses.body_ids[0])[0][0])
    return 2.0 * float(m.geom_size[g, 0])


def rigs(poses, length: float | None = None, metres_per_unit: float = 1.0) -> list[Rig]:
    """One rig per agent of the flock, all sharing one bird mesh (``length``: the bird's, default the agents'
    drawn body length, :func:`agent_length`); ``metres_per_unit``: the flock's unit in metres, 1 unless the flock
    is scaled to a bird size (a scene), for the turn relation and the effort, which are in m/s."""
    if length is None:
        length = agent_length(poses)
    looks = {"plumage": Look("plumage", (1, 1, 1, 1), _plumage(), double_sided=False, roughness=0.5),
             "wing": Look("wing", (1, 1, 1, 1), _plumage(), double_sided=True, roughness=0.6),
             "beak": Look("beak", (0.85, 0.7, 0.2, 1.0), roughness=0.4)}
    meshes: dict = {}
    return [bird_rig(poses, idx[0], length, looks, meshes, metres_per_unit=metres_per_unit)
            for idx in creatures(poses).values()]

