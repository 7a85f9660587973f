"""How a bird of the flock looks when its motion leaves the project: a crowd (:mod:`lifelike_mj.export.rig`),
each agent a textured bird (body, head, beak, two-segment wings, tail) on a small skeleton, drawn along a path
smoothed from the flock's recorded motion afterwards (the flock itself is untouched), its wings playing one wing
beat that every bird shares, each at its own phase.

**The render path** (bone ``boidN``, the drawn bird; the simulated agent is not a bone): the paper's agents
zigzag, their heading turning a median 105-113 degrees from one step to the next, so the bird is drawn along

* the agent's positions smoothed by a Gaussian of :data:`PATH_SIGMA_STEPS` steps (sigma), narrowed in proportion
  where the agent moves faster than :data:`FAST_BL_PER_STEP` body lengths a step (some patterns, 5b among them,
  have spells of agents crossing the box in a few steps, bouncing off its walls: a wide smoothing would draw the
  bird metres from its agent there); :func:`drawn_flight` reports the distance from the simulated positions;
* its heading and climb from the drawn velocity, averaged by a Gaussian of :data:`TURN_SIGMA_STEPS` steps (the
  slow stretches weigh less, so the bird does not spin where it hovers);
* its bank from the drawn lateral acceleration, averaged alike: ``tan(bank) = a_lat / g``, the coordinated
  turn (Reynolds 1987 banks a boid the same way), which for a steady turn is ``v * yaw rate / g`` (g =
  9.81 m/s^2; lengths in the file's units as metres, times in playback seconds).

The paper's box has reflecting walls, not periodic ones: an agent never leaves it through one side and enters
through the other, so there is no wrap to hide; at a wall the drawn path rounds the agent's reflection.

**The wing beat** (bones ``boidN/wing_left_inner``, ``.../wing_left_outer`` and the right ones): one cycle of
:data:`FLAP_HZ` (about 10 Hz: Pennycuick's 1996 formula for a starling, derived), a flap of :data:`FLAP_DEG`
each side about the body's long axis at the shoulder, the outer wing folding on the upstroke. Every bird plays
the same cycle (:func:`wing_cycle`, a :class:`~lifelike_mj.export.rig.Cycle`), stored once in a file, at one of
:data:`PHASES` phases, spread over the flock by the golden ratio so that neighbours do not beat in step.

What a flock file cannot carry: each bird's own flap and glide, or a frequency that follows its effort. Those
change along each bird's flight, so they cannot be one cycle shared by all; a bird of the flock flaps steadily.
``boidN/tail`` (keyed per bird): spread and lifted a little in turns and climbs.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj.export.meshes import Piece, assemble, loft, rigid, sheet, sphere
from lifelike_mj.export.rig import Bone, Cycle, Look, Rig, adaptive_smooth, continuous, creatures, extra_bone, qaxis, qmul, smooth

#: The drawn path: the agent's positions smoothed by a Gaussian of this many steps (sigma), narrowed where the agent
#: moves faster than :data:`FAST_BL_PER_STEP` (in proportion), so that a fast agent is drawn near where it is.
PATH_SIGMA_STEPS = 10.0
#: An agent's speed (body lengths per step, over 5 steps) above which its path's smoothing narrows (the paper's 5a
#: moves a median 0.05).
FAST_BL_PER_STEP = 0.05
#: The drawn heading, climb and bank: the drawn velocity and lateral acceleration averaged over this many steps.
TURN_SIGMA_STEPS = 30.0
#: The shared wing beat: frequency (Hz), flap amplitude each side of the mid stroke (deg), the outer wing's fold on
#: the upstroke (deg) and a little dihedral (deg).
FLAP_HZ, FLAP_DEG, FOLD_DEG, DIHEDRAL_DEG = 10.0, 45.0, 25.0, 8.0
#: The cycle's samples per beat and the phases birds play it at (the samples a multiple of them).
CYCLE_SAMPLES, PHASES = 48, 16
G = 9.81
#: The golden ratio's conjugate: bird i plays phase group floor(frac(i * GOLDEN) * PHASES).
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def drawn_flight(t: np.ndarray, pos: np.ndarray, metres_per_unit: float = 1.0, path_sigma: float = PATH_SIGMA_STEPS,
                 turn_sigma: float = TURN_SIGMA_STEPS, length: float | None = None):
    """The drawn bird's world pose at every sample (module docstring) and what it came from: ``(position,
    quat_wxyz, series)`` with ``series`` holding speed (m/s), yaw rate (rad/s), lateral acceleration (m/s^2), bank
    (rad), climb (m/s) along the drawn path, and the distance from the simulated positions (the file's units);
    ``pos`` in units of ``metres_per_unit`` metres (the series in m/s); ``length``: the agent's body length (the
    file's units), which narrows the path's smoothing where the agent is fast (:data:`FAST_BL_PER_STEP`; None: a
    fixed ``path_sigma``)."""
    if length is None or len(pos) < 3:
        p = smooth(pos, path_sigma)
    else:
        step = smooth(np.linalg.norm(np.gradient(pos, axis=0), axis=1)[:, None], 5.0)[:, 0] / length
        p = adaptive_smooth(pos, path_sigma * np.minimum(1.0, FAST_BL_PER_STEP / np.maximum(step, 1e-12)))
    n = len(t)
    if n > 2:
        v = metres_per_unit * np.gradient(p, t, axis=0)
        acc = np.gradient(v, t, axis=0)
    else:
        v, acc = np.tile(np.array([1e-9, 0.0, 0.0]), (n, 1)), np.zeros((n, 3))
    h = smooth(v, turn_sigma)  # the heading: the drawn velocity, averaged
    horiz = np.linalg.norm(h[:, :2], axis=1)
    yaw = np.unwrap(np.arctan2(h[:, 1], h[:, 0]))
    pitch = np.arctan2(h[:, 2], np.maximum(horiz, 1e-12))
    left = np.stack([-np.sin(yaw), np.cos(yaw), np.zeros(n)], axis=1)
    a_lat = smooth(np.sum(acc * left, axis=1)[:, None], turn_sigma)[:, 0]
    bank = np.arctan(a_lat / G)  # coordinated turn: tan(bank) = a_lat / g
    # heading, then climb (nose up: a negative turn about y), then bank (into a left turn, a positive lateral
    # acceleration, the left wing goes down: a negative turn about the forward axis)
    q = qmul(qmul(qaxis((0.0, 0.0, 1.0), yaw), qaxis((0.0, 1.0, 0.0), -pitch)), qaxis((1.0, 0.0, 0.0), -bank))
    speed = np.linalg.norm(v, axis=1)
    series = {"speed_m_s": speed, "horizontal_m_s": np.linalg.norm(v[:, :2], axis=1),
              "yaw_rate_rad_s": np.gradient(yaw, t) if n > 2 else np.zeros(n), "lateral_m_s2": a_lat,
              "bank_rad": bank, "climb_m_s": v[:, 2], "off_path": np.linalg.norm(p - pos, axis=1)}
    return p, continuous(q), series


def wing_cycle(hz: float = FLAP_HZ, samples: int = CYCLE_SAMPLES, phases: int = PHASES) -> Cycle:
    """The shared wing beat (module docstring): each wing's inner and outer bone over one beat."""
    phase = 2.0 * np.pi * np.arange(samples + 1) / samples
    stroke = math.radians(FLAP_DEG) * np.sin(phase) + math.radians(DIHEDRAL_DEG)
    fold = math.radians(FOLD_DEG) * np.clip(np.cos(phase), 0.0, None)  # the outer wing folds going up
    x = (1.0, 0.0, 0.0)
    quats = {}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        quats[f"wing_{side}_inner"] = continuous(qaxis(x, sign * stroke))
        quats[f"wing_{side}_outer"] = continuous(qaxis(x, -sign * fold))
    return Cycle("bird wingbeat", 1.0 / hz, quats, phases)


def phase_group(i: int, phases: int = PHASES) -> int:
    """The phase group of the flock's ``i``-th bird: spread by the golden ratio (module docstring)."""
    return int(math.floor(((i * GOLDEN) % 1.0) * phases)) % phases


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


def bird_rig(poses, i: int, length: float, looks: dict, meshes: dict, cycle: Cycle, metres_per_unit: float = 1.0
             ) -> Rig:
    """The rig of the flock's ``i``-th body (module docstring); ``metres_per_unit``: the flock's unit in metres
    (its speeds, climbs and accelerations in m/s for the turn relation)."""
    t = poses.t_s
    body = poses.body_names[i]
    p, q, series = drawn_flight(t, poses.position_m[:, i], metres_per_unit, length=length)
    bones: list[Bone] = [Bone(body, -1, np.eye(4), p, q, body, drawn=True)]
    group = phase_group(i)
    wings = {}
    for side, sign in (("left", 1.0), ("right", -1.0)):
        inner = cycle.play(f"wing_{side}_inner", group, t - t[0])
        bones.append(extra_bone(f"{body}/wing_{side}_inner", 0, bones, (0.15 * length, sign * 0.1 * length,
                                                                         0.06 * length), inner))
        k = len(bones) - 1
        bones.append(extra_bone(f"{body}/wing_{side}_outer", k, bones, (0.0, sign * 0.405 * length, 0.0),
                                cycle.play(f"wing_{side}_outer", group, t - t[0])))
        wings[side] = (k, len(bones) - 1)
    lift = np.radians(10.0) * np.clip(np.abs(series["bank_rad"]) + series["climb_m_s"] /
                                      np.maximum(series["speed_m_s"], 1e-9), 0.0, 1.0)
    bones.append(extra_bone(f"{body}/tail", 0, bones, (-0.3 * length, 0.0, 0.0), qaxis((0.0, 1.0, 0.0), -lift)))
    if "mesh" not in meshes:
        meshes["mesh"] = assemble("bird", bird_mesh(length, looks, 0, wings, len(bones) - 1))
    # phase: where in the beat (a fraction) the bird is at the clip's start; rate: the beat's speed against the cycle's
    extras = {"cycle": {"name": cycle.name, "period_s": cycle.period_s, "phase": group / cycle.groups, "rate": 1.0}}
    return Rig(body, bones, meshes["mesh"], extras, series, cycle=cycle, group=group)


def agent_length(poses) -> float:
    """The agents' drawn body length (the flock's units): twice the first agent's geom's half length."""
    m = poses.model
    g = int(np.nonzero(m.geom_bodyid == poses.body_ids[0])[0][0])
    return 2.0 * float(m.geom_size[g, 0])


def rigs(poses, length: float | None = None, metres_per_unit: float = 1.0) -> list[Rig]:
    """One rig per agent of the flock, all sharing one bird mesh and one wing beat (``length``: the bird's, default the agents'
    drawn body length, :func:`agent_length`); ``metres_per_unit``: the flock's unit in metres, 1 unless the flock
    is scaled to a bird size (a scene), for the turn relation and the effort, which are in m/s."""
    if length is None:
        length = agent_length(poses)
    looks = {"plumage": Look("plumage", (1, 1, 1, 1), _plumage(), double_sided=False, roughness=0.5),
             "wing": Look("wing", (1, 1, 1, 1), _plumage(), double_sided=True, roughness=0.6),
             "beak": Look("beak", (0.85, 0.7, 0.2, 1.0), roughness=0.4)}
    meshes: dict = {}
    cycle = wing_cycle()
    return [bird_rig(poses, idx[0], length, looks, meshes, cycle, metres_per_unit)
            for idx in creatures(poses).values()]

