"""How a fish looks when its motion leaves the project: a rig (:mod:`lifelike_mj.export.rig`) per fish of a
tank, its root bone the fish's MuJoCo body (named as in the MJCF), a chain of spine bones down to the caudal
fin and two pectoral fins, with a textured damselfish mesh made here. The swim itself is the tank's, untouched:
the bones' secondary motion is computed from the recorded poses afterwards.

Secondary motion, as damselfish swim (Hale, Day, Thorsen and Westneat 2006, J Exp Biol 209:3708: pectoral
strokes at routine speeds, body and caudal fin in bursts; Gerstner 1999: body and tail join in fast turns):

* **Body wave** in bursts, sharp turns and escapes: a lateral wave ``y(s, t) = A(s) sin(phi(t) - 2 pi s / lambda)``
  travels from head to tail (``s`` the distance from the snout), its phase advancing at the tail-beat frequency
  of Bainbridge's relation (1958, J Exp Biol 35:109), ``U = L (3 f - 4) / 4``, so ``f = (4 U / L + 4) / 3``
  with ``U`` the fish's forward speed and ``L`` its length; tail amplitude :data:`TAIL_AMPLITUDE_L` L (his
  amplitude of about L/5, taken as peak to peak), growing from the head as ``(0.1 + 0.9 (s/L)^2)``; wave length
  :data:`WAVELENGTH_L` L (0.76 L in trout, Webb 1971; about 1 L in carangiform swimmers). The wave is on while
  the fish speeds up faster than :data:`BURST_ACCEL_BL_S2` body lengths/s^2 or, swimming, turns faster than
  :data:`TURN_DEG_S` (:func:`activity`), and fades over :data:`COAST_FADE_S` once it coasts.
* **Turning bend**: the spine follows the path's curvature (yaw rate / speed), so the body bends toward the
  side of a turn, a C-bend in an escape (at most :data:`MAX_BEND_DEG` over the spine).
* **Pectoral fins** beat while the body wave is off, at a frequency rising with speed
  (:data:`PECTORAL_HZ` plus :data:`PECTORAL_HZ_PER_BL_S` per body length/s, a look: no damselfish figure is at
  hand), and fold while it runs.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj.export.meshes import Piece, assemble, blend, loft, rigid, sheet, sphere
from lifelike_mj.export.rig import Bone, Look, Rig, body_bone, creatures, extra_bone, qaxis, qconj, qmul, qrot, smooth

#: Tail amplitude (one side) as a fraction of the body length, and the body wave's length (body lengths).
TAIL_AMPLITUDE_L, WAVELENGTH_L = 0.1, 0.9
#: When the body wave runs: forward acceleration (BL/s^2) or yaw rate (deg/s) above these; it fades over
#: COAST_FADE_S (s) once both fall below.
BURST_ACCEL_BL_S2, TURN_DEG_S, COAST_FADE_S = 4.0, 150.0, 0.25
#: The wave rises over this time (s) and a turn starts it only above this speed (BL/s).
WAVE_RISE_S, TURN_WAVE_BL_S = 0.04, 1.5
#: The largest bend of the spine in a turn (deg, head to tail), and the time (s, a Gaussian's sigma) over which
#: the yaw rate and speed that set it are smoothed (their differences from one step to the next are jittery).
MAX_BEND_DEG, BEND_SMOOTH_S = 70.0, 0.06
#: Pectoral fin beat: Hz at rest, plus Hz per body length/s; stroke amplitude (deg).
PECTORAL_HZ, PECTORAL_HZ_PER_BL_S, PECTORAL_DEG = 2.5, 1.2, 35.0
#: The spine's joints, as fractions of the length from the snout (the last carries the caudal fin).
SPINE_AT = (0.45, 0.58, 0.70, 0.80, 0.88)


def bainbridge_hz(speed_m_s, length_m: float) -> np.ndarray:
    """Tail-beat frequency (Hz) from Bainbridge 1958: ``U = L (3 f - 4) / 4``, so ``f = (4 U / L + 4) / 3``."""
    return (4.0 * np.asarray(speed_m_s, dtype=float) / length_m + 4.0) / 3.0


def kinematics(t: np.ndarray, pos: np.ndarray, quat: np.ndarray):
    """Forward speed (m/s), forward acceleration (m/s^2) and yaw rate (rad/s, about the body's up axis) of a
    body's recorded track, by central differences."""
    if len(t) < 3:
        z = np.zeros(len(t))
        return z, z, z
    vel = np.gradient(pos, t, axis=0)
    fwd = qrot(quat, np.array([1.0, 0.0, 0.0]))
    speed = np.sum(vel * fwd, axis=1)
    accel = np.gradient(speed, t)
    q = quat
    dq = np.gradient(q, t, axis=0)
    omega_body = 2.0 * qmul(qconj(q), dq)[:, 1:]  # body-frame angular velocity
    return speed, accel, omega_body[:, 2]


def activity(t: np.ndarray, accel_bl: np.ndarray, yaw_deg_s: np.ndarray, speed_bl: np.ndarray) -> np.ndarray:
    """The body wave's weight (0 to 1): rising within :data:`WAVE_RISE_S` while the fish bursts (speeds up
    faster than :data:`BURST_ACCEL_BL_S2`) or turns sharply (faster than :data:`TURN_DEG_S` while swimming
    faster than :data:`TURN_WAVE_BL_S`: a slow turn on the spot is a bend, not a wave), fading over
    :data:`COAST_FADE_S` once it coasts."""
    on = (accel_bl > BURST_ACCEL_BL_S2) | ((np.abs(yaw_deg_s) > TURN_DEG_S) & (speed_bl > TURN_WAVE_BL_S))
    out = np.zeros(len(t))
    level = 0.0
    for k in range(1, len(t)):
        dt = t[k] - t[k - 1]
        level = 1.0 - (1.0 - level) * math.exp(-dt / WAVE_RISE_S) if on[k] else level * math.exp(-dt / COAST_FADE_S)
        out[k] = level
    return out


def spine_angles(t, speed, yaw_rate, weight, length_m: float):
    """Each spine joint's yaw (rad, rows per sample, one column per joint of :data:`SPINE_AT`) and the
    wave's phase: the travelling wave and the turning bend (module docstring)."""
    f = bainbridge_hz(np.maximum(speed, 0.0), length_m)
    phase = 2.0 * np.pi * np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))])
    s = np.array((0.0,) + SPINE_AT + (1.0,))  # snout, joints, tail tip (fractions of L)
    amp = TAIL_AMPLITUDE_L * length_m * (0.1 + 0.9 * s ** 2)
    y = weight[:, None] * amp[None, :] * np.sin(phase[:, None] - 2 * np.pi * s[None, :] / WAVELENGTH_L)
    # heading of each segment (from one station to the next) against the front of the body (the root bone)
    heading = np.arctan2(np.diff(y, axis=1), np.diff(s) * length_m)
    # the bend that follows the path's curvature (yaw rate over speed): on a curved path each segment points
    # back along the curve, turned by the curvature times its distance behind the root (the centre of mass)
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    kappa = smooth(yaw_rate, BEND_SMOOTH_S / dt) / np.maximum(np.abs(smooth(speed, BEND_SMOOTH_S / dt)), 0.5 * length_m)
    mid = 0.5 * (s[1:] + s[:-1])
    bend = -kappa[:, None] * length_m * (mid[None, :] - mid[0])
    cap = math.radians(MAX_BEND_DEG)
    total = np.abs(bend[:, -1])
    bend *= np.where(total > cap, cap / np.maximum(total, 1e-12), 1.0)[:, None]
    joints = np.diff(heading + bend, axis=1)  # each joint turns its segment from the one before
    return joints, phase, f


def _texture(px: int = 256) -> np.ndarray:
    """The body's colours (u along the body from the snout, v around it from the back): the paper's blue
    (its fish_blue) darker on the back, paler on the belly, with rows of scales."""
    u, v = np.meshgrid((np.arange(px) + 0.5) / px, (np.arange(px) + 0.5) / px)
    blue = np.array([0.16, 0.38, 0.95]) * 255
    belly = np.cos(2 * np.pi * v)  # +1 on the back, -1 on the belly
    shade = 0.75 + 0.25 * (-belly) * 0.5 + 0.1
    scales = 0.92 + 0.08 * (np.sin(u * 90) * np.sin(v * 120 * np.pi / 2) > 0.2)
    img = blue[None, None, :] * (shade * scales)[..., None]
    img = img * (1.0 - 0.25 * np.clip(belly, 0, 1))[..., None] + np.array([60, 70, 40]) * np.clip(-belly - 0.5, 0, 1)[..., None]
    return np.concatenate([np.clip(img, 0, 255), np.full((px, px, 1), 255.0)], axis=-1).astype(np.uint8)


def _fin_texture(px: int = 64) -> np.ndarray:
    """Fins: the paper's fin blue (fish_fin), translucent toward the edge, with rays."""
    u, v = np.meshgrid((np.arange(px) + 0.5) / px, (np.arange(px) + 0.5) / px)
    rays = 0.85 + 0.15 * (np.abs(np.sin(u * 14 * np.pi)) > 0.6)
    rgb = np.array([0.2, 0.45, 1.0]) * 255 * rays[..., None]
    alpha = 255 * (0.9 - 0.45 * v)
    return np.concatenate([np.clip(rgb, 0, 255), alpha[..., None]], axis=-1).astype(np.uint8)


class _Looks:
    """The looks shared by every fish of a tank (one texture each in the file)."""

    def __init__(self) -> None:
        self.body = Look("fish_blue", (1.0, 1.0, 1.0, 1.0), _texture(), double_sided=False, roughness=0.4)
        self.fin = Look("fish_fin", (1.0, 1.0, 1.0, 0.75), _fin_texture(), double_sided=True, roughness=0.5)
        self.eye = Look("fish_eye", (0.02, 0.02, 0.02, 1.0), roughness=0.2)


def fish_mesh(length_m: float, looks: _Looks, spine_bones: list[int], pectorals: tuple[int, int],
              snout_x: float) -> list[Piece]:
    """A damselfish: a deep, laterally compressed body, forked caudal fin, long dorsal and anal fins, two
    pectoral fins and eyes, weighted along the spine (module docstring)."""
    L = length_m
    s = np.linspace(0.0, 0.80, 28)  # snout to caudal peduncle, fractions of L
    x = snout_x - s * L
    nose = np.sqrt(np.clip(s / 0.12, 0.0, 1.0))
    height = L * 0.17 * nose * np.clip(1.0 - ((s - 0.38) / 0.48) ** 2, 0.14, 1.0)
    width = L * 0.075 * nose * np.clip(1.0 - ((s - 0.3) / 0.55) ** 2, 0.12, 1.0)
    stations = snout_x - np.array((0.30,) + SPINE_AT) * L  # the root bone holds the front of the body
    bones_x = [0] + spine_bones

    def along(p):
        return blend(-p[:, 0], -stations, bones_x)

    pieces = [loft(x, width, height, looks.body, along, centre_z=0.004 * L * np.sin(np.pi * s), segments=18)]
    # fins as thin sheets in the body's mid-plane (x, z) or, for the pectorals, behind the gill
    n = 10
    r = np.linspace(0.0, 1.0, n)[:, None]
    # caudal fin: from the peduncle, forked
    sc = np.linspace(-1.0, 1.0, 13)
    reach = 0.2 * L * (0.75 + 0.35 * np.abs(sc) ** 1.5)
    base = np.stack([np.full_like(sc, snout_x - 0.80 * L), np.zeros_like(sc), 0.03 * L * sc], axis=-1)
    tip = np.stack([snout_x - 0.80 * L - reach, np.zeros_like(sc), 0.13 * L * sc], axis=-1)
    pts = base[None] + r[..., None] * (tip - base)[None]
    pieces.append(sheet(pts, np.stack(np.broadcast_arrays((sc + 1) / 2, r), axis=-1), looks.fin, along))
    # dorsal and anal fins along the back and belly
    for top, start, end, high in ((1.0, 0.30, 0.78, 0.09), (-1.0, 0.52, 0.78, 0.07)):
        sd = np.linspace(start, end, 14)
        xs = snout_x - sd * L
        zs = np.interp(sd, s, height) * top * 0.95
        h = high * L * np.sin(np.pi * (sd - start) / (end - start)) ** 0.5 * (0.6 + 0.4 * (sd - start) / (end - start))
        pts = np.stack([np.broadcast_to(xs, (n, len(sd))) - r * 0.02 * L, np.zeros((n, len(sd))),
                        zs[None, :] + top * r * h[None, :]], axis=-1)
        pieces.append(sheet(pts, np.stack(np.broadcast_arrays((sd - start) / (end - start), r), axis=-1),
                            looks.fin, along))
    # pectoral fins: sheets on their own bones, spreading back and out
    for bone, sign in zip(pectorals, (1.0, -1.0)):
        sp = np.linspace(-1.0, 1.0, 7)
        pts = np.stack([-r * 0.16 * L * (1.0 - 0.2 * np.abs(sp)), sign * r * 0.02 * L * np.ones_like(sp),
                        0.03 * L * sp * (0.4 + r)], axis=-1)
        piece = sheet(pts, np.stack(np.broadcast_arrays((sp + 1) / 2, r), axis=-1), looks.fin, rigid(1, bone))
        pieces.append(piece)
    w_eye, h_eye = float(np.interp(0.1, s, width)), float(np.interp(0.1, s, height))
    for sign in (1.0, -1.0):  # on the surface of the head, a little above its middle
        pieces.append(sphere((snout_x - 0.1 * L, sign * 0.85 * w_eye, 0.25 * h_eye), 0.022 * L, looks.eye,
                             rigid(1, 0), segments=8))
    return pieces


def fish_rig(poses, indices: list[int], length_m: float, looks: _Looks, meshes: dict) -> Rig:
    """The rig of one fish (its body the first of ``indices`` in ``poses``): module docstring."""
    t = poses.t_s
    root = body_bone(poses, indices[0], -1)
    bones: list[Bone] = [root]
    speed, accel, yaw = kinematics(t, root.position_m, root.quat_wxyz)
    weight = activity(t, accel / length_m, np.degrees(yaw), speed / length_m)
    joints, phase, f = spine_angles(t, speed, yaw, weight, length_m)
    snout_x = 0.032  # the model's snout, 0.032 m ahead of the centre of mass (fish.xml)
    z = (0.0, 0.0, 1.0)
    prev = 0
    prev_x = 0.0
    for k, frac in enumerate(SPINE_AT):
        x = snout_x - frac * length_m
        name = f"{root.name}/{'caudal' if k == len(SPINE_AT) - 1 else f'spine{k + 1}'}"
        bones.append(extra_bone(name, prev, bones, (x - prev_x, 0.0, 0.0), qaxis(z, joints[:, k])))
        prev, prev_x = len(bones) - 1, x
    spine = list(range(1, len(bones)))
    fin_hz = PECTORAL_HZ + PECTORAL_HZ_PER_BL_S * np.maximum(speed, 0.0) / length_m
    fin_phase = 2 * np.pi * np.concatenate([[0.0], np.cumsum(0.5 * (fin_hz[1:] + fin_hz[:-1]) * np.diff(t))])
    stroke = math.radians(PECTORAL_DEG) * (1.0 - weight) * np.sin(fin_phase)
    fold = math.radians(55.0) * weight  # folded against the body in a burst
    pect = []
    for side, sign in (("left", 1.0), ("right", -1.0)):
        turn = qmul(qaxis(z, sign * (math.radians(25.0) + stroke - fold)), qaxis((1.0, 0.0, 0.0), sign * stroke * 0.3))
        bones.append(extra_bone(f"{root.name}/pectoral_{side}", 0, bones,
                                (snout_x - 0.27 * length_m, sign * 0.035 * length_m, -0.01 * length_m), turn))
        pect.append(len(bones) - 1)
    if "mesh" not in meshes:
        meshes["mesh"] = assemble("damselfish", fish_mesh(length_m, looks, spine, tuple(pect), snout_x))
    return Rig(root.name, bones, meshes["mesh"], {"length_m": length_m},
               {"speed_m_s": speed, "wave": weight, "tail_beat_hz": f, "phase": phase})


def rigs(poses, length_m: float | None = None) -> list[Rig]:
    """One rig per fish of the run, all sharing one mesh and its textures."""
    from lifelike_mj.fish.scene import BODY_LENGTH_M

    L = BODY_LENGTH_M if length_m is None else float(length_m)
    looks = _Looks()
    meshes: dict = {}
    return [fish_rig(poses, idx, L, looks, meshes) for idx in creatures(poses).values()]

