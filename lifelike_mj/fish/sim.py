"""Swimming fish on MuJoCo: motion units, drag, vision and wall avoidance (Satoi et al. 2015, 3.3-3.7).

Each fish is a free rigid body (``models/fish.xml``). Every control step (``control_hz``, the
paper's 60 frames per second) each fish

1. looks (3.6): five MuJoCo ray casts of length ``vision_distance_m`` from its snout into the
   fish-free vision model of the tank (``fish/scene.py``); a hit starts (or renews) wall avoidance
   for ``avoid_duration_s``, remembering the direction away from the wall (the hit normals);
2. draws its next motion unit (MU) from the Markov chain (3.3; docs/models/fish.md), with the avoidance
   weights while avoiding (3.7);
3. if the MU is *accelerate*, draws a push (3.4.1, eq. 2-9): ``r ~ U(r_min, r_max)``,
   ``theta = 90 + U(-theta_range, theta_range) + A sgn(p) / (1 + exp(-k |p|))`` with the pitch ``p``
   (3.6, balance), ``phi = 90 + U(-phi_range, phi_range)``, plus a turn of ``avoid_turn_deg`` away from
   a seen wall; in the body frame (x forward = the paper's z, y left = the paper's x, z up = the
   paper's y) the components are ``lateral = r sin(theta) cos(phi)``, ``vertical = r cos(theta)``,
   ``forward = r sin(theta) sin(phi)`` (while turning away from a wall it faces, the forward part is
   scaled by ``max(-1/2, 1 + 2 h.n)``, ``h.n`` the cosine between heading and wall normal: the fish
   turns on the spot, backing off when it faces the glass squarely, rather than pushing into it):
   a forward force, and angular accelerations
   ``vertical / (m R^2)`` nose-up and ``lateral / (m R^2)`` to the left (eq. 8-9).

MuJoCo then integrates ``substeps`` steps. The compiled passive callback (:data:`COMPILED_PASSIVE`)
adds, per fish and per step, the held push and the quadratic drag of 3.4.2-3.4.4 in the body frame,
``D = -1/2 rho C_D S v|v|`` per axis on the linear (``S_v``, ``cd``) and angular (``S_w``, ``cd_rot``) velocity, built on
:func:`lifelike_mj.physics.fluid.normal_drag_scalar`: coast and accelerate with the body's areas,
cruise without translational drag, brake with the areas enlarged by ``brake_dS_v_m2`` and
``brake_dS_w_m5``; and the righting moment of buoyancy acting ``buoyancy_offset_m`` above the centre
of mass. Water is neutral (``gravcomp``: no net sinking); the fish collide with the tank, not with
each other.

Randomness: one ``numpy.random.Generator`` per fish (seeded from ``SeedSequence(seed)``), four
uniforms per fish per control step (MU, r, theta, phi) drawn whether used or not, so that the same
seed gives the same tracks in any chunking.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numba import njit

from lifelike_mj import checks
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.fish.params import ACCELERATE, BRAKE, CRUISE, MU_NAMES, FishParams
from lifelike_mj.fish.scene import BODY_LENGTH_M, FishScene, box_areas, build_scene, check_tank, tank_size
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.fluid import normal_drag_scalar
from lifelike_mj.physics.stability import describe, likely_cause, was_reset, watching
from lifelike_mj.stepper import StepCounter

# ---- userdata layout (per model; the callback is process-global) ----------------------------------
U_MAGIC = 0  # identifies a fish model's userdata (the callback ignores other models)
U_N = 1  # number of fish
U_RHO, U_CD = 2, 3
U_SV = 4  # 3: S_v (m^2)
U_SW = 7  # 3: S_w (m^5)
U_DSV = 10  # 3: brake dS_v
U_DSW = 13  # 3: brake dS_w
U_CDROT = 16
U_RIGHT = 17  # m g h: righting moment scale (N m) of the centre of buoyancy h above the centre of mass
U_FISH = 18  # per fish: qadr, dadr, mu, F_forward (N), torque_y, torque_z (N m, body frame)
FISH_BLOCK = 6
MAGIC = 7.25e5

_O_QPOS, _O_QVEL, _O_QFRC, _O_UD = mjabi.O_QPOS, mjabi.O_QVEL, mjabi.O_QFRC, mjabi.O_UD
_mj_step = mjabi.mj_step
_mj_ray = mjabi.mj_ray
_vp = mjabi.voidptr_from_int
_addr = mjabi.int_from_voidptr


_ptr_at = mjabi.ptr_at
_f64 = mjabi.f64_at


@njit(cache=True, inline="always")
def _rotmat(q, R):
    """Rotation matrix (row-major 3x3 in ``R[9]``) of the unit quaternion ``q = (w, x, y, z)``."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R[0] = 1 - 2 * (y * y + z * z)
    R[1] = 2 * (x * y - w * z)
    R[2] = 2 * (x * z + w * y)
    R[3] = 2 * (x * y + w * z)
    R[4] = 1 - 2 * (x * x + z * z)
    R[5] = 2 * (y * z - w * x)
    R[6] = 2 * (x * z - w * y)
    R[7] = 2 * (y * z + w * x)
    R[8] = 1 - 2 * (x * x + y * y)


@njit(cache=True)
def fish_forces(ud, qpos, qvel, qfrc):
    """Add every fish's held push and drag (Satoi 2015 3.4.1-3.4.4) to ``qfrc`` (generalized forces).

    Free joint: ``qvel[d:d+3]`` is the world velocity of the body origin (= centre of mass),
    ``qvel[d+3:d+6]`` the angular velocity in the body frame; the generalized force is the world
    force and the body-frame torque. Drag per body axis: ``normal_drag_scalar`` (Oe 2010 eq. 1 form,
    ``-1/2 rho C_D S v|v|``), in N and N m."""
    n = int(ud[U_N])
    rho, cd = ud[U_RHO], ud[U_CD]
    R = np.empty(9)
    vb = np.empty(3)
    fb = np.empty(3)
    for i in range(n):
        base = U_FISH + FISH_BLOCK * i
        qa = int(ud[base])
        da = int(ud[base + 1])
        mu = int(ud[base + 2])
        _rotmat(qpos[qa + 3 : qa + 7], R)
        for a in range(3):
            vb[a] = R[a] * qvel[da] + R[3 + a] * qvel[da + 1] + R[6 + a] * qvel[da + 2]  # R^T v
        brake = 1.0 if mu == BRAKE else 0.0
        for a in range(3):
            if mu == CRUISE:
                fb[a] = 0.0
            else:
                fb[a] = normal_drag_scalar(ud[U_SV + a] + brake * ud[U_DSV + a], rho, cd, vb[a])
        fb[0] += ud[base + 3]
        for a in range(3):
            qfrc[da + a] += R[3 * a] * fb[0] + R[3 * a + 1] * fb[1] + R[3 * a + 2] * fb[2]
        for a in range(3):
            qfrc[da + 3 + a] += normal_drag_scalar(ud[U_SW + a] + brake * ud[U_DSW + a], rho, ud[U_CDROT],
                                                   qvel[da + 3 + a])
        # buoyancy W at h R e_z from the centre of mass: world torque W h (R12, -R02, 0), to the body frame
        tx, ty = ud[U_RIGHT] * R[5], -ud[U_RIGHT] * R[2]
        qfrc[da + 3] += R[0] * tx + R[3] * ty
        qfrc[da + 4] += R[1] * tx + R[4] * ty + ud[base + 4]
        qfrc[da + 5] += R[2] * tx + R[5] * ty + ud[base + 5]


@njit(cache=True)
def _passive_kernel(m, d, off):
    base = _addr(d)
    ud = _f64(_ptr_at(base + off[_O_UD]), U_FISH)
    if ud[U_MAGIC] != MAGIC:
        return
    n = int(ud[U_N])
    ud = _f64(_ptr_at(base + off[_O_UD]), U_FISH + FISH_BLOCK * n)
    last = U_FISH + FISH_BLOCK * (n - 1)
    nq = int(ud[last]) + 7
    nv = int(ud[last + 1]) + 6
    qpos = _f64(_ptr_at(base + off[_O_QPOS]), nq)
    qvel = _f64(_ptr_at(base + off[_O_QVEL]), nv)
    qfrc = _f64(_ptr_at(base + off[_O_QFRC]), nv)
    fish_forces(ud, qpos, qvel, qfrc)


#: The compiled passive callback (a ctypes function pointer MuJoCo accepts; mjabi.compiled_passive).
_PASSIVE = mjabi.compiled_passive(_passive_kernel, "fish")
COMPILED_PASSIVE = _PASSIVE.ctypes


def python_passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """The same forces through the Python bindings and ``mj_applyFT`` (the test reference)."""
    ud = d.userdata
    if ud.size <= U_FISH or ud[U_MAGIC] != MAGIC:
        return
    n = int(ud[U_N])
    rho, cd = ud[U_RHO], ud[U_CD]
    for i in range(n):
        base = U_FISH + FISH_BLOCK * i
        qa, da, mu = int(ud[base]), int(ud[base + 1]), int(ud[base + 2])
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, d.qpos[qa + 3 : qa + 7])
        R = R.reshape(3, 3)
        vb = R.T @ d.qvel[da : da + 3]
        sv = ud[U_SV : U_SV + 3] + (ud[U_DSV : U_DSV + 3] if mu == BRAKE else 0.0)
        sw = ud[U_SW : U_SW + 3] + (ud[U_DSW : U_DSW + 3] if mu == BRAKE else 0.0)
        fb = np.zeros(3) if mu == CRUISE else -0.5 * rho * cd * sv * vb * np.abs(vb)
        fb[0] += ud[base + 3]
        w = d.qvel[da + 3 : da + 6]
        tb = -0.5 * rho * ud[U_CDROT] * sw * w * np.abs(w) + np.array([0.0, ud[base + 4], ud[base + 5]])
        tb += R.T @ (ud[U_RIGHT] * np.array([R[1, 2], -R[0, 2], 0.0]))
        body = int(np.nonzero(m.jnt_qposadr == qa)[0][0])
        body = m.jnt_bodyid[body]
        mujoco.mj_applyFT(m, d, R @ fb, R @ tb, d.xipos[body], body, d.qfrc_passive)


# ---- the control step (sections 3.3-3.7), compiled ---------------------------------------------------

# per-fish state columns
S_MU, S_AVOID_T, S_AWAY = 0, 1, 2  # S_AWAY: 3 (unit vector away from the last wall seen)
S_YAW, S_PITCH = 5, 6  # turn directions chosen when an avoidance starts (+1 left / nose up, -1, or 0)
S_SPEED = 7  # running mean of the speed (time constant RUNAWAY_TAU_S, m/s)
S_KICK_T = 8  # the kick rhythm: seconds until the next kick is due (params.kick_gamma_shape > 0)
S_SOC_PHI, S_SOC_THETA = 9, 10  # the social turn of the current kick (deg added to phi and theta)
S_SINCE = 11  # seconds since the current or last kick began
S_SOC_PUSH = 12  # the social factor on the current kick's push (1: none)
N_STATE = 13
#: Time constant (s) of the running mean speed that the runaway check reads.
RUNAWAY_TAU_S = 10.0
# control constants (float array)
C_RMIN, C_RMAX, C_THR, C_PHR, C_BA, C_BK, C_R, C_VIS, C_VANG, C_AVT, C_AVF, C_TURN, C_HEAD, C_MASS = range(14)
C_IY, C_IZ, C_DT, C_VMAX = 14, 15, 16, 17
# beyond the paper (params.py): the kick rhythm, the social turns (lengths in m, angles in rad unless named)
C_KSHAPE, C_KFLOOR, C_KSCALE = 18, 19, 20
C_SATT, C_SALI, C_SDEPTH, C_SRANGE, C_SCOSBLIND, C_SD0, C_SLATT, C_SLALI, C_SNEIGH, C_SGAIN, C_BL = range(21, 32)
C_SSPEED, C_SOCIAL = 32, 33  # C_SOCIAL: 1 when any social term is on
N_CONST = 34
#: The most a social turn changes a push's angles (deg; the paper's random yaw spans +-80).
SOCIAL_MAX_DEG = 80.0
#: The most the pull to the neighbours' depth asks (rad).
SOCIAL_DEPTH_MAX = 0.5
#: The social factor on a push stays within these (params.py, ``social_speed_per_bl``).
SOCIAL_PUSH_MIN, SOCIAL_PUSH_MAX = 0.5, 1.5
#: Inside ``social_d0_bl`` a neighbour repels this many times the attraction's weight at contact (params.py).
SOCIAL_REPEL = 2.0
#: A seen surface counts when the heading points into it by more than asin(0.2) = 11.5 deg.
APPROACH_MIN = 0.2
#: During an avoidance the chosen turn side flips only when the away direction lies this far
#: (sine of the angle) on the other side.
TURN_FLIP = 0.3


@njit(cache=True)
def _look(vm, vd, pos, R, head, dist_m, ang, away, scratch, gid):
    """Five rays (ahead, left, right, up, down at ``ang`` rad) from the snout; returns True when
    one hits, within ``dist_m``, a surface that the fish is heading into (at more than
    ``asin(APPROACH_MIN)`` to it: a wall the fish swims along is no threat), and writes the
    weighted sum of those hit normals to ``away``. ``scratch`` (9,) and ``gid`` (1,) int32 are
    work arrays of the caller (the ray's point, direction and hit normal, and the hit geom)."""
    pnt = scratch[0:3]
    vec = scratch[3:6]
    nrm = scratch[6:9]
    for a in range(3):
        pnt[a] = pos[a] + R[3 * a] * head
        away[a] = 0.0
    c, s = math.cos(ang), math.sin(ang)
    seen = False
    for r in range(5):
        bx, by, bz = 1.0, 0.0, 0.0
        if r == 1:
            bx, by = c, s
        elif r == 2:
            bx, by = c, -s
        elif r == 3:
            bx, bz = c, s
        elif r == 4:
            bx, bz = c, -s
        for a in range(3):
            vec[a] = R[3 * a] * bx + R[3 * a + 1] * by + R[3 * a + 2] * bz
        dist = _mj_ray(_vp(vm), _vp(vd), _vp(pnt.ctypes.data), _vp(vec.ctypes.data), _vp(0), np.uint8(1), np.int32(-1),
                       _vp(gid.ctypes.data), _vp(nrm.ctypes.data))
        approach = -(R[0] * nrm[0] + R[3] * nrm[1] + R[6] * nrm[2])  # heading . (-normal)
        if dist >= 0.0 and dist <= dist_m and approach > APPROACH_MIN:
            seen = True
            w = 1.0 - dist / dist_m + 1e-3
            for a in range(3):
                away[a] += w * nrm[a]
    return seen


@njit(cache=True)
def _social_turn(i, qpos, ud, c, n, out):
    """The turn (rad; ``out[0]`` yaw, left positive; ``out[1]`` pitch, nose up positive) that fish ``i`` asks of
    its next kick from the neighbours it sees (params.py, "Social turns"): each neighbour within range and outside
    the rear blind sector adds attraction and alignment in Calovi et al.'s forms; the ``C_SNEIGH`` of largest
    effect are summed, and the pull to their mean depth added. ``out[2]``: how far ahead of the fish those
    neighbours are on average (m, along its heading; 0 for none)."""
    qa = int(ud[U_FISH + FISH_BLOCK * i])
    xi, yi, zi = qpos[qa], qpos[qa + 1], qpos[qa + 2]
    w, x, y, z = qpos[qa + 3], qpos[qa + 4], qpos[qa + 5], qpos[qa + 6]
    hx, hy = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z)  # the body's x axis, horizontal part
    hn = math.sqrt(hx * hx + hy * hy)
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0
    if hn < 1e-9:
        return
    hx, hy = hx / hn, hy / hn
    k = int(c[C_SNEIGH])
    best = np.zeros(k)  # |effect| of the k kept so far
    eff = np.zeros(k)
    dz = np.zeros(k)
    ahead = np.zeros(k)
    for j in range(n):
        if j == i:
            continue
        qb = int(ud[U_FISH + FISH_BLOCK * j])
        rx, ry, rz = qpos[qb] - xi, qpos[qb + 1] - yi, qpos[qb + 2] - zi
        d = math.sqrt(rx * rx + ry * ry + rz * rz)
        dh = math.sqrt(rx * rx + ry * ry)
        if d > c[C_SRANGE] or dh < 1e-9:
            continue
        cpsi = (hx * rx + hy * ry) / dh
        if cpsi < c[C_SCOSBLIND]:
            continue  # behind, in the blind sector
        spsi = (hx * ry - hy * rx) / dh
        w2, x2, y2, z2 = qpos[qb + 3], qpos[qb + 4], qpos[qb + 5], qpos[qb + 6]
        gx, gy = 1 - 2 * (y2 * y2 + z2 * z2), 2 * (x2 * y2 + w2 * z2)
        gn = math.sqrt(gx * gx + gy * gy)
        if gn < 1e-9:
            continue
        gx, gy = gx / gn, gy / gn
        sdphi = hx * gy - hy * gx
        cdphi = hx * gx + hy * gy
        latt, lali = c[C_SLATT], c[C_SLALI]
        if d >= c[C_SD0]:
            att = c[C_SATT] * ((d - c[C_SD0]) / latt) / (1.0 + (d / latt) ** 2) * spsi * (1.0 + cpsi)
        else:  # too close: turn away, the harder the closer (whatever the bearing: a fish ahead is avoided too)
            att = -c[C_SATT] * SOCIAL_REPEL * (1.0 - d / c[C_SD0]) * (1.0 if spsi >= 0.0 else -1.0)
        c2psi = 2 * cpsi * cpsi - 1
        c2dphi = 2 * cdphi * cdphi - 1
        ali = (c[C_SALI] * math.exp(-((d / lali) ** 2)) * sdphi * (1.0 + 0.3 * c2dphi)
               * (1.0 + 0.6 * cpsi - 0.32 * c2psi))
        e = att + ali
        m = 0
        for q in range(1, k):
            if best[q] < best[m]:
                m = q
        if abs(e) > best[m] or best[m] == 0.0:
            best[m] = abs(e) if e != 0.0 else 1e-300
            eff[m] = e
            dz[m] = rz
            ahead[m] = dh * cpsi
    kept = 0
    mz = 0.0
    for q in range(k):
        if best[q] > 0.0:
            out[0] += eff[q]
            mz += dz[q]
            out[2] += ahead[q]
            kept += 1
    if kept > 0:
        out[2] /= kept
    if kept > 0 and c[C_SDEPTH] > 0.0:
        pull = c[C_SDEPTH] * (mz / kept) / c[C_BL]
        out[1] = max(-SOCIAL_DEPTH_MAX, min(SOCIAL_DEPTH_MAX, pull))


@njit(cache=True)
def _gamma_wait(shape, scale, u2):
    """A gamma-distributed wait (s) of whole ``shape`` (an Erlang wait) and ``scale``: the sum of ``shape``
    exponential waits of mean ``scale``, from the uniforms ``u2`` (at least ``shape`` of them)."""
    m = int(shape)
    t = 0.0
    for q in range(m):
        t -= math.log(u2[q])
    return scale * t


@njit(cache=True)
def _control(vm, vd, qpos, qvel, ud, state, cum, cum_avoid, u, c, n, forced_mu, forced_push, u2):
    """One control step for all fish: look, choose the MU, set the push (module docstring). A fish
    whose ``forced_mu`` is >= 0 takes that MU instead of the chain's draw; an accelerating fish whose
    ``forced_push`` row is finite pushes with that ``(r (N), theta (deg), phi (deg))`` instead of the
    drawn one (the avoidance scaling and turn still apply). The random numbers are used the same way
    either way, so forcing one fish does not change the draws of the others."""
    R = np.empty(9)
    away = np.empty(3)
    scratch = np.empty(9)
    gid = np.empty(1, dtype=np.int32)
    for i in range(n):
        base = U_FISH + FISH_BLOCK * i
        qa = int(ud[base])
        _rotmat(qpos[qa + 3 : qa + 7], R)
        if _look(vm, vd, qpos[qa : qa + 3], R, c[C_HEAD], c[C_VIS], c[C_VANG], away, scratch, gid):
            nn = math.sqrt(away[0] ** 2 + away[1] ** 2 + away[2] ** 2)
            if nn > 0:
                fresh = state[i, S_AVOID_T] <= 0.0
                # the away direction: this look's, or during an avoidance the running mean of the
                # looks (two walls of a corner, seen in turn, add up to the way out of the corner)
                for a in range(3):
                    away[a] = away[a] / nn + (0.0 if fresh else state[i, S_AWAY + a])
                nn = math.sqrt(away[0] ** 2 + away[1] ** 2 + away[2] ** 2)
                if nn < 1e-9:
                    nn = 1.0
                for a in range(3):
                    state[i, S_AWAY + a] = away[a] / nn
                # turn towards it (body frame); the side is chosen when an avoidance starts and
                # changed only when clearly wrong, so that the fish does not dither
                ay = R[1] * state[i, 2] + R[4] * state[i, 3] + R[7] * state[i, 4]
                az = R[2] * state[i, 2] + R[5] * state[i, 3] + R[8] * state[i, 4]
                if fresh or ay * state[i, S_YAW] < -TURN_FLIP:
                    state[i, S_YAW] = 1.0 if ay >= 0.0 else -1.0
                if fresh or az * state[i, S_PITCH] < -TURN_FLIP:
                    state[i, S_PITCH] = (1.0 if az >= 0.0 else -1.0) if abs(state[i, 4]) > 0.5 else 0.0
                state[i, S_AVOID_T] = c[C_AVT]
        avoiding = state[i, S_AVOID_T] > 0.0
        if avoiding:
            state[i, S_AVOID_T] -= c[C_DT]
        mu = int(state[i, S_MU])
        tab = cum_avoid if avoiding else cum
        nxt = 3
        if c[C_KSHAPE] > 0.0 and mu != ACCELERATE and not (avoiding and state[i, S_SINCE] >= c[C_KFLOOR]):
            # the kick rhythm: no kick before it is due, one as soon as it is; between kicks the chain runs
            # among coast, cruise and brake (the same uniform, over their share of the row)
            state[i, S_KICK_T] -= c[C_DT]
            if state[i, S_KICK_T] <= 0.0:
                nxt = ACCELERATE
            else:
                lo = tab[mu, 0]
                x = lo + u[i, 0] * (1.0 - lo)
                for j in range(1, 4):
                    if x < tab[mu, j]:
                        nxt = j
                        break
        else:
            if c[C_KSHAPE] > 0.0:
                state[i, S_KICK_T] -= c[C_DT]
            for j in range(4):
                if u[i, 0] < tab[mu, j]:
                    nxt = j
                    break
        if forced_mu[i] >= 0:
            nxt = forced_mu[i]
        onset = nxt == ACCELERATE and mu != ACCELERATE
        state[i, S_SINCE] = 0.0 if onset else state[i, S_SINCE] + c[C_DT]
        if onset and c[C_KSHAPE] > 0.0:
            state[i, S_KICK_T] = c[C_KFLOOR] + _gamma_wait(c[C_KSHAPE], c[C_KSCALE], u2[i])
        if onset and c[C_SOCIAL] > 0.0:
            _social_turn(i, qpos, ud, c, n, away)
            state[i, S_SOC_PHI] = max(-SOCIAL_MAX_DEG, min(SOCIAL_MAX_DEG, c[C_SGAIN] * math.degrees(away[0])))
            state[i, S_SOC_THETA] = max(-SOCIAL_MAX_DEG, min(SOCIAL_MAX_DEG, c[C_SGAIN] * math.degrees(away[1])))
            state[i, S_SOC_PUSH] = max(SOCIAL_PUSH_MIN, min(SOCIAL_PUSH_MAX, 1.0 + c[C_SSPEED] * away[2] / c[C_BL]))
        state[i, S_MU] = nxt
        ud[base + 2] = nxt
        ud[base + 3] = 0.0
        ud[base + 4] = 0.0
        ud[base + 5] = 0.0
        if nxt != ACCELERATE:
            continue
        scale = c[C_AVF] if avoiding else 1.0
        fwd_scale = 1.0
        r = scale * (c[C_RMIN] + (c[C_RMAX] - c[C_RMIN]) * u[i, 1])
        if c[C_SSPEED] > 0.0:
            r *= state[i, S_SOC_PUSH]
        pitch = math.degrees(math.asin(min(1.0, max(-1.0, R[6]))))  # nose up > 0
        sg = 1.0 if pitch > 0 else (-1.0 if pitch < 0 else 0.0)
        theta = 90.0 + c[C_THR] * (2.0 * u[i, 2] - 1.0) + c[C_BA] * sg / (1.0 + math.exp(-c[C_BK] * abs(pitch)))
        phi = 90.0 + c[C_PHR] * (2.0 * u[i, 3] - 1.0)
        if math.isfinite(forced_push[i, 0]):
            r = scale * forced_push[i, 0]
            theta = forced_push[i, 1]
            phi = forced_push[i, 2]
        if avoiding:
            # turn until the heading no longer points into the wall (parallel to it is enough:
            # facing straight away from one wall of a long tank means facing the opposite one)
            ax = R[0] * state[i, 2] + R[3] * state[i, 3] + R[6] * state[i, 4]
            if ax < 0.0:
                phi -= c[C_TURN] * state[i, S_YAW]
                theta -= c[C_TURN] * state[i, S_PITCH]
                # facing the wall: turn on the spot, and back off when facing it squarely (a fish
                # wedged nose-first in a corner cannot turn without backing off)
                fwd_scale = max(-0.5, 1.0 + 2.0 * ax)
        th = math.radians(theta)
        ph = math.radians(phi)
        lateral = r * math.sin(th) * math.cos(ph)
        vertical = r * math.cos(th)
        forward = fwd_scale * r * math.sin(th) * math.sin(ph)
        if c[C_SOCIAL] > 0.0:
            # the social turn steers the kick as a push of that angle would turn it (eq. 8-9: left and nose up
            # positive), its forward share left as drawn
            lateral += r * math.sin(math.radians(state[i, S_SOC_PHI]))
            vertical += r * math.sin(math.radians(state[i, S_SOC_THETA]))
        mr2 = c[C_MASS] * c[C_R] * c[C_R]
        ud[base + 3] = forward
        ud[base + 4] = -c[C_IY] * vertical / mr2  # about the body's left axis: negative = nose up
        ud[base + 5] = c[C_IZ] * lateral / mr2  # about the up axis: positive = turn left


@njit(cache=True)
def _run_chunk(mptr, dptr, vm, vd, qpos, qvel, ud, state, cum, cum_avoid, U, c, n, substeps, out_pos, out_quat,
               out_mu, record, err, forced_mu, forced_push, U2):
    """Control steps ``U.shape[0]`` (each: :func:`_control`, then ``substeps`` ``mj_step``), recording
    positions, orientations and MUs after each when ``record``. On a runaway (the running mean speed
    above ``C_VMAX``) or NaN writes ``err = (kind, step, fish, speed)`` (kind 1 runaway, 2 not
    finite) and returns."""
    for k in range(U.shape[0]):
        _control(vm, vd, qpos, qvel, ud, state, cum, cum_avoid, U[k], c, n, forced_mu, forced_push, U2[k])
        for _ in range(substeps):
            _mj_step(_vp(mptr), _vp(dptr))
        for i in range(n):
            qa = int(ud[U_FISH + FISH_BLOCK * i])
            da = int(ud[U_FISH + FISH_BLOCK * i + 1])
            sp = math.sqrt(qvel[da] ** 2 + qvel[da + 1] ** 2 + qvel[da + 2] ** 2)
            ok = True
            for a in range(7):
                if not math.isfinite(qpos[qa + a]):
                    ok = False
            if not ok or not math.isfinite(sp):
                err[0], err[1], err[2], err[3] = 2.0, k, i, sp
                return
            state[i, S_SPEED] += (sp - state[i, S_SPEED]) * c[C_DT] / RUNAWAY_TAU_S
            if state[i, S_SPEED] > c[C_VMAX]:
                err[0], err[1], err[2], err[3] = 1.0, k, i, state[i, S_SPEED]
                return
            if record:
                for a in range(3):
                    out_pos[k, i, a] = qpos[qa + a]
                for a in range(4):
                    out_quat[k, i, a] = qpos[qa + 3 + a]
                out_mu[k, i] = int(state[i, S_MU]) + (4 if state[i, S_AVOID_T] > 0.0 else 0)


# ---- Python driver ----------------------------------------------------------------------------------


@dataclass
class SwimResult:
    """Tracks of a swim: ``times_s`` (T,), ``positions`` (T, F, 3) m, ``quats`` (T, F, 4), ``mu``
    (T, F) MU codes (0 accelerate, 1 coast, 2 cruise, 3 brake), sampled every control step;
    row 0 is the initial state."""

    params: FishParams
    seed: int
    tank_m: tuple[float, float, float]
    times_s: np.ndarray
    positions: np.ndarray
    quats: np.ndarray
    mu: np.ndarray
    wall_time_s: float = 0.0
    extra: dict = field(default_factory=dict)

    @property
    def n_fish(self) -> int:
        return self.positions.shape[1]

    def outside_tank(self, tol_m: float = 0.0) -> np.ndarray:
        """Per fish: True if its centre of mass was ever outside the water volume (+ ``tol_m``)."""
        L, D, H = self.tank_m
        p = self.positions
        out = (np.abs(p[..., 0]) > L / 2 + tol_m) | (np.abs(p[..., 1]) > D / 2 + tol_m)
        out |= (p[..., 2] < -tol_m) | (p[..., 2] > H + tol_m)
        return out.any(axis=0)


#: Names of :meth:`Tank.state` and their units.
STATE_UNITS = {
    "position_m": "m: each fish's centre of mass (x along the tank, y across, z up from the floor)",
    "quat": "unit quaternion (w, x, y, z) of each fish's body frame (x forward, y left, z up)",
    "velocity_m_s": "m/s: each fish's velocity (world frame)",
    "mu": "motion unit of each fish: 0 accelerate, 1 coast, 2 cruise, 3 brake (MU_NAMES)",
    "avoiding": "whether each fish is avoiding a wall it saw",
}


class Tank(StepCounter):
    """A tank of fish (Satoi 2015), in the stepper shape every creature shares (:mod:`lifelike_mj.stepper`).

    ``params``: a preset (:class:`~lifelike_mj.fish.params.FishParams`; default ``B-D``); ``n_fish``
    fish (1 to :data:`~lifelike_mj.fish.params.MAX_FISH`) in a tank of ``size`` (L, D, H) m (default the filmed
    5 x 0.5 x 1 m; each side 2.5 body lengths to 100 m, as ``--tank`` takes), or in a ``scene`` built already
    (:func:`~lifelike_mj.fish.scene.build_scene`; then no ``size``); ``seed`` (0 to 2^32 - 1) fixes the
    start and every random draw. Each argument is checked before anything is built: a wrong one is a
    :class:`~lifelike_mj.errors.UserError` naming it. One step is one control step (``params.control_hz``, 60 per second:
    look, choose the motion unit, push), then ``params.substeps`` MuJoCo steps. One tank per thread
    (it owns its ``MjData``).

    Behaviours of your own, called once per control step with the tank (read ``tank.state()``,
    ``tank.time``):

    * ``mu_policy(tank)``: ``n_fish`` motion units (0 accelerate, 1 coast, 2 cruise, 3 brake), or -1
      for a fish left to the Markov chain (Satoi 2015 section 3.3);
    * ``push_policy(tank)``: an ``(n_fish, 3)`` array of pushes ``(r (N), theta (deg), phi (deg))``
      (eq. 2-9's magnitude and angles) for the fish that accelerate this step, NaN rows for the drawn
      push.

    Each draws the same random numbers as without it, so the other fish swim as they would have.
    With a policy the control steps run one by one from Python (tens of microseconds each).
    """

    @checks.known_keywords
    def __init__(self, params: FishParams | None = None, n_fish: int = 10, seed: int = 0, size=None,
                 scene: FishScene | None = None, mu_policy=None, push_policy=None):
        from lifelike_mj.fish.params import MAX_FISH, load_preset

        # every argument checked before the scene is built (seconds for thousands of fish), each in one sentence
        if params is not None and not isinstance(params, FishParams):
            raise UserError(f"params must be a fish preset (a FishParams, as fish.load_preset('B-D') gives) or None "
                            f"for B-D, got {_kind(params)}.")
        if not checks.is_whole(n_fish) or not 1 <= n_fish <= MAX_FISH:
            raise UserError(f"the number of fish must be a whole number from 1 to {MAX_FISH:,} (n_fish), got "
                            f"{_kind(n_fish)}.")
        seed = _check_seed(seed)
        if scene is not None and not isinstance(scene, FishScene):
            raise UserError(f"scene must be a FishScene (fish.scene.build_scene) or None, got {_kind(scene)}.")
        if scene is not None and size is not None:
            raise UserError("give the tank either as scene or as size, not both.")
        if scene is None:
            size = check_tank(size if size is not None else tank_size(), "size")
        for name, fn in (("mu_policy", mu_policy), ("push_policy", push_policy)):
            if fn is not None and not callable(fn):
                raise UserError(f"{name} must be a function of the tank, got {_kind(fn)}.")
        self.params = params if params is not None else load_preset("B-D")
        self._seed = seed
        self.scene = scene if scene is not None else build_scene(n_fish, size, nuserdata=U_FISH + FISH_BLOCK * n_fish)
        self.scene.model.opt.timestep = self.params.timestep_s
        if self.scene.model.nuserdata < U_FISH + FISH_BLOCK * self.scene.n:
            raise RuntimeError("internal: the scene was compiled without room for the fish userdata")
        if self.params.fish_contacts:
            # the fish's collision capsules (contype 1) collide with each other too (params.py, "Fish that touch")
            m = self.scene.model
            caps = np.flatnonzero((m.geom_contype == 1) & np.isin(m.geom_bodyid, self.scene.body))
            m.geom_conaffinity[caps] = 1
            m.body_conaffinity[self.scene.body] |= 1  # the broad phase filters bodies by these (the OR of their geoms')
        self.vision_data = mujoco.MjData(self.scene.vision_model)
        mujoco.mj_kinematics(self.scene.vision_model, self.vision_data)
        self.mu_policy, self.push_policy = mu_policy, push_policy
        self.reset()

    @property
    def seed(self) -> int:
        return self._seed

    @property
    def dt(self) -> float:
        """Seconds per step (one control step)."""
        return self.params.control_dt_s

    @property
    def model(self) -> mujoco.MjModel:
        return self.scene.model

    @property
    def n_fish(self) -> int:
        return self.scene.n

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: fish placed at random (from the seed) at rest, every fish coasting.
        ``seed``: a new seed, or ``None`` for the tank's own."""
        if seed is not None:
            self._seed = _check_seed(seed)
        params, sc = self.params, self.scene
        m = sc.model
        n = sc.n
        self.data = mujoco.MjData(m)
        mjabi.verify_offsets(self.data)
        ud = self.data.userdata
        sv, sw = box_areas(sc.mass_kg, sc.inertia)
        ud[U_MAGIC] = MAGIC
        ud[U_N] = n
        ud[U_RHO] = params.water_density_kg_m3
        ud[U_CD] = params.cd
        ud[U_CDROT] = params.cd_rot
        ud[U_RIGHT] = sc.mass_kg * float(np.linalg.norm(m.opt.gravity)) * params.buoyancy_offset_m
        ud[U_SV : U_SV + 3] = sv
        ud[U_SW : U_SW + 3] = sw
        ud[U_DSV : U_DSV + 3] = params.brake_dS_v_m2
        ud[U_DSW : U_DSW + 3] = params.brake_dS_w_m5
        for i in range(n):
            b = U_FISH + FISH_BLOCK * i
            ud[b] = sc.qadr[i]
            ud[b + 1] = sc.dadr[i]
            ud[b + 2] = 1  # coast
        ss = np.random.SeedSequence(self._seed)
        children = ss.spawn(n + 1)
        self.rngs = [np.random.Generator(np.random.PCG64(ch)) for ch in children[1:]]
        self._place(np.random.Generator(np.random.PCG64(children[0])))
        self.state_array = np.zeros((n, N_STATE))
        self.state_array[:, S_MU] = 1
        self.cum = np.cumsum(params.transition_matrix(False), axis=1)
        self.cum_avoid = np.cumsum(params.transition_matrix(True), axis=1)
        self.cum[:, -1] = self.cum_avoid[:, -1] = 1.0
        c = np.zeros(N_CONST)
        c[C_RMIN], c[C_RMAX] = params.r_min_N, params.r_max_N
        c[C_THR], c[C_PHR] = params.theta_range_deg, params.phi_range_deg
        c[C_BA], c[C_BK] = params.balance_A_deg, params.balance_k_per_deg
        c[C_R] = params.inertia_radius_m
        c[C_VIS], c[C_VANG] = params.vision_distance_m, math.radians(params.vision_angle_deg)
        c[C_AVT], c[C_AVF], c[C_TURN] = params.avoid_duration_s, params.avoid_force_scale, params.avoid_turn_deg
        c[C_HEAD], c[C_MASS] = sc.head_m, sc.mass_kg
        c[C_IY], c[C_IZ] = sc.inertia[1], sc.inertia[2]
        c[C_DT] = params.control_dt_s
        c[C_VMAX] = params.runaway_speed_bl_s * BODY_LENGTH_M
        c[C_KSHAPE], c[C_KFLOOR] = params.kick_gamma_shape, params.kick_floor_s
        if params.kick_gamma_shape > 0:
            c[C_KSCALE] = (params.kick_mean_s - params.kick_floor_s) / params.kick_gamma_shape
        c[C_SATT], c[C_SALI] = params.social_attraction_rad, params.social_alignment_rad
        c[C_SDEPTH] = params.social_depth_rad_per_bl
        c[C_SRANGE] = params.social_range_bl * BODY_LENGTH_M
        c[C_SCOSBLIND] = -math.cos(math.radians(params.social_blind_deg) / 2.0)
        c[C_SD0], c[C_SLATT], c[C_SLALI] = (params.social_d0_bl * BODY_LENGTH_M, params.social_l_att_bl * BODY_LENGTH_M,
                                            params.social_l_ali_bl * BODY_LENGTH_M)
        c[C_SNEIGH], c[C_SGAIN], c[C_BL] = params.social_neighbours, params.social_turn_gain, BODY_LENGTH_M
        c[C_SSPEED] = params.social_speed_per_bl
        c[C_SOCIAL] = float(params.social)
        self.state_array[:, S_SOC_PUSH] = 1.0
        self.c = c
        #: A second random stream per fish, for what the paper's chain does not draw (the kick rhythm's waits), so
        #: that the paper's own draws stay as they were; drawn only when the rhythm is on.
        self.rngs2 = [np.random.Generator(np.random.PCG64(ch)) for ch in ss.spawn(n)]
        if params.kick_gamma_shape > 0:  # the first kick is due at a random phase of the mean interval
            self.state_array[:, S_KICK_T] = [g.random() * params.kick_mean_s for g in self.rngs2]
        self._k = 0
        mujoco.mj_forward(m, self.data)

    def _place(self, rng: np.random.Generator) -> None:
        """Random positions in the water (a body length from every wall), random heading, level."""
        L, D, H = self.scene.size
        mgn = BODY_LENGTH_M
        d = self.data
        for i in range(self.scene.n):
            qa = self.scene.qadr[i]
            d.qpos[qa : qa + 3] = [rng.uniform(-L / 2 + mgn, L / 2 - mgn), rng.uniform(-D / 2 + mgn, D / 2 - mgn),
                                   rng.uniform(mgn, H - mgn)]
            yaw = rng.uniform(-math.pi, math.pi)
            d.qpos[qa + 3 : qa + 7] = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        d.qvel[:] = 0.0

    def _randoms(self, k: int) -> np.ndarray:
        U = np.empty((k, self.scene.n, 4))
        for i, g in enumerate(self.rngs):
            U[:, i, :] = g.random((k, 4))
        return U

    #: Uniforms per fish and control step of the second stream (the kick rhythm's gamma wait: its shape, at most).
    N_U2 = 8

    def _randoms2(self, k: int) -> np.ndarray:
        """The second stream's uniforms for ``k`` control steps (zeros, none drawn, while the rhythm is off)."""
        if self.params.kick_gamma_shape <= 0:
            return np.zeros((k, self.scene.n, 1))
        U = np.empty((k, self.scene.n, self.N_U2))
        for i, g in enumerate(self.rngs2):
            U[:, i, :] = 1.0 - g.random((k, self.N_U2))  # in (0, 1]: their logarithms are finite
        return U

    def step(self, n: int = 1) -> None:
        """Advance ``n`` control steps; a runaway speed raises :class:`~lifelike_mj.errors.Diverged`."""
        self.run(checks.whole("the number of steps", n, 0), record=False)

    def run(self, n_control_steps: int, record: bool = True):
        """Advance ``n_control_steps`` control steps. Returns ``(pos, quat, mu)`` for them (empty
        arrays when not recording). Raises :class:`~lifelike_mj.errors.Diverged` on a runaway speed."""
        k = int(n_control_steps)
        if self.mu_policy is None and self.push_policy is None:
            n = self.scene.n
            return self._run(k, record, np.full(n, -1, dtype=np.int64), np.full((n, 3), np.nan))
        parts = [self._run(1, record, *self._forced()) for _ in range(k)]
        return tuple(np.concatenate([p[j] for p in parts]) for j in range(3))

    def _forced(self) -> tuple[np.ndarray, np.ndarray]:
        """The policies' choices for the next control step, checked."""
        n = self.scene.n
        mu = np.full(n, -1, dtype=np.int64)
        push = np.full((n, 3), np.nan)
        if self.mu_policy is not None:
            got = np.asarray(self.mu_policy(self), dtype=float).reshape(-1)
            if got.shape != (n,) or not np.all(np.isin(got, (-1, 0, 1, 2, 3))):
                raise UserError(f"mu_policy must return {n} motion units, each 0, 1, 2, 3 or -1 (the chain's choice).")
            mu = got.astype(np.int64)
        if self.push_policy is not None:
            got = np.asarray(self.push_policy(self), dtype=float)
            if got.shape != (n, 3) or np.any(np.isinf(got)) or np.any(got[:, 0] < 0):
                raise UserError(f"push_policy must return an ({n}, 3) array of (r >= 0 N, theta deg, phi deg), "
                                "NaN rows for the drawn push.")
            push = got
        return mu, push

    def _run(self, k: int, record: bool, forced_mu: np.ndarray, forced_push: np.ndarray):
        sc = self.scene
        n = sc.n
        U = self._randoms(k)
        shape = (k if record else 0, n)
        pos = np.zeros((*shape, 3))
        quat = np.zeros((*shape, 4))
        mu = np.zeros(shape, dtype=np.int8)
        err = np.zeros(4)
        t0 = float(self.data.time)
        with passive_callback(COMPILED_PASSIVE), watching():
            _run_chunk(sc.model._address, self.data._address, sc.vision_model._address, self.vision_data._address,
                       self.data.qpos, self.data.qvel, self.data.userdata, self.state_array, self.cum, self.cum_avoid,
                       U, self.c, n, int(self.params.substeps), pos, quat, mu, record, err, forced_mu, forced_push,
                       self._randoms2(k))
            done = (int(err[1]) + 1 if err[0] != 0 else k) * int(self.params.substeps)
            if was_reset(self.data, t0, done, float(self.scene.model.opt.timestep)):
                raise Diverged(describe(self.data, "the tank") + " " + self._unstable_cause(), self._k + k)
        if err[0] != 0:
            t = (self._k + err[1] + 1) * self.params.control_dt_s
            self._k += int(err[1]) + 1
            raise Diverged(self._runaway_message(int(err[0]), int(err[2]), err[3], t), self._k)
        self._k += k
        return pos, quat, mu

    def record(self, n_steps: int | None = None, *, duration_s: float | None = None, chunk_steps: int = 60,
               progress: bool = False) -> SwimResult:
        """Swim on ``n_steps`` control steps (or ``duration_s`` s) and return the tracks at every control
        step, the current state first (:class:`SwimResult`). ``progress``: a tqdm bar."""
        import time

        if (n_steps is None) == (duration_s is None):
            raise UserError("give either n_steps or duration_s.")
        chunk_steps = checks.whole("chunk_steps", chunk_steps, 1)
        progress = checks.flag("progress", progress)
        total = (checks.whole("the number of steps", n_steps, 1) if n_steps is not None
                 else checks.steps_of(checks.positive("duration", duration_s, "s"), self.params.control_dt_s))
        check_swim_work(self.params, self.n_fish, total)
        t0 = time.perf_counter()
        k0 = self._k
        p0, q0 = self.snapshot()
        m0 = (self.state_array[:, S_MU] + 4 * (self.state_array[:, S_AVOID_T] > 0.0)).astype(np.int8)
        P, Q, M = [p0[None]], [q0[None]], [m0[None]]
        bar = None
        if progress:
            from lifelike_mj.progress import bar as progress_bar

            bar = progress_bar(total, "swim", unit="step")
        try:
            done = 0
            while done < total:
                k = min(chunk_steps, total - done)
                p, q, m = self.run(k)
                P.append(p)
                Q.append(q)
                M.append(m)
                done += k
                if bar is not None:
                    bar.update(k)
        finally:
            if bar is not None:
                bar.close()
        times = (k0 + np.arange(total + 1)) * self.params.control_dt_s
        return SwimResult(self.params, self.seed, self.scene.size, times, np.concatenate(P), np.concatenate(Q),
                          np.concatenate(M), time.perf_counter() - t0)

    def state(self) -> dict[str, np.ndarray]:
        """The current state as named arrays (:data:`STATE_UNITS`)."""
        pos, quat = self.snapshot()
        vel = np.array([self.data.qvel[a : a + 3] for a in self.scene.dadr])
        return {"position_m": pos, "quat": quat, "velocity_m_s": vel,
                "mu": self.state_array[:, S_MU].astype(np.int64), "avoiding": self.state_array[:, S_AVOID_T] > 0.0}

    def sync(self) -> None:
        """Bring the drawing quantities (body poses, cameras, lights) up to the current state; ``mj_step``
        leaves them at the start of its last step. They are derived quantities that the next step
        recomputes, so this does not change the swim."""
        mujoco.mj_kinematics(self.scene.model, self.data)
        mujoco.mj_comPos(self.scene.model, self.data)
        mujoco.mj_camlight(self.scene.model, self.data)

    def _unstable_cause(self) -> str:
        """The likely cause of a MuJoCo instability: the parameters raised most above the default preset."""
        raised = likely_cause(self.params, FishParams())
        dt_ms = 1000 * self.params.timestep_s
        if raised:
            return (f"the likely cause is the parameters furthest from the calibrated default: {raised}; bring them "
                    f"back, or take smaller time steps (substeps; now {dt_ms:.3g} ms).")
        return f"take smaller time steps (raise substeps; now {dt_ms:.3g} ms)."

    def _runaway_message(self, kind: int, fish: int, speed: float, t: float) -> str:
        p = self.params
        T = p.transition_matrix(False)
        name, val, prob = ("P_a", p.P_a, T[0, 0]) if T[0, 0] >= T[1, 0] else ("P_b", p.P_b, T[1, 0])
        if p.transition is not None:
            return (f"the speed ran away: fish {fish} at t = {t:.2f} s; the preset's transition weights to "
                    f"accelerate are too high (from accelerate: {T[0, 0]:.2f}, from coast: {T[1, 0]:.2f} per step).")
        what = "became NaN" if kind == 2 else (f"kept up {speed:.2f} m/s ({speed / BODY_LENGTH_M:.1f} body lengths/s over "
                                                f"{RUNAWAY_TAU_S:g} s, above runaway_speed_bl_s = {p.runaway_speed_bl_s:g})")
        top = likely_cause(p, FishParams(), top=1)
        if top and not top.startswith(("P_a ", "P_b ")):
            return (f"the speed ran away: fish {fish} {what} at t = {t:.2f} s; the likely cause is the parameters "
                    f"furthest from the calibrated default: {likely_cause(p, FishParams())}: bring them back.")
        return (f"the speed ran away: fish {fish} {what} at t = {t:.2f} s; {name} = {val:g} is too high "
                f"(the chance to accelerate again is {prob:.2f} per step): lower {name}.")

    def snapshot(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions (m) and orientations (quaternions) of every fish now."""
        sc = self.scene
        pos = np.array([self.data.qpos[a : a + 3] for a in sc.qadr])
        quat = np.array([self.data.qpos[a + 3 : a + 7] for a in sc.qadr])
        return pos, quat


def _check_seed(seed) -> int:
    """A seed as the command line takes it (``--seed``): a whole number from 0 to 2^32 - 1."""
    return checks.whole("seed", seed, 0, 2**32 - 1)


def _kind(v: object) -> str:
    """``v`` for an error sentence: its repr when short, else its type ("a FishParams")."""
    text = repr(v)
    return text if len(text) <= 60 else f"a {type(v).__name__}"


def check_swim_work(params: FishParams, n_fish: int, steps: int, recorded: bool = True) -> None:
    """Before ``steps`` control steps of ``n_fish`` fish: refused in one sentence when their MuJoCo steps would pass
    :data:`~lifelike_mj.checks.MAX_BODY_STEPS` or, ``recorded``, the tracks' rows (one per fish and step)
    :data:`~lifelike_mj.checks.MAX_RECORD_ROWS`."""
    what = f"{n_fish:,} fish for {steps:,} control steps"
    checks.work(what, float(steps) * n_fish * params.substeps, checks.MAX_BODY_STEPS, "fish-steps (substeps included)",
                "fewer fish or a shorter swim")
    if recorded:
        checks.work(f"recording {what}", float(steps) * n_fish, checks.MAX_RECORD_ROWS, "track rows",
                    "fewer fish or a shorter swim")


def swim(params: FishParams, n_fish: int = 10, duration_s: float = 30.0, seed: int = 0, size=None,
         progress: bool = False, chunk_s: float = 1.0) -> SwimResult:
    """Simulate ``n_fish`` fish for ``duration_s`` seconds; the tracks at every control step
    (:meth:`Tank.record` of a new :class:`Tank`)."""
    checks.positive("duration", duration_s, "s")
    checks.positive("chunk_s", chunk_s, "s")
    tank = Tank(params, n_fish, seed, size)
    return tank.record(duration_s=duration_s, chunk_steps=max(1, int(round(chunk_s * tank.params.control_hz))),
                       progress=progress)


__all__ = ["MU_NAMES", "STATE_UNITS", "SwimResult", "Tank", "swim", "COMPILED_PASSIVE", "python_passive", "fish_forces"]
