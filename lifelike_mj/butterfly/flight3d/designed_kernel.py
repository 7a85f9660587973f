"""The designed controller (:mod:`~lifelike_mj.butterfly.flight3d.designed`) compiled: the same measurement, wind
observer, moment observer, guidance and gain-scheduled regulator as
:class:`~lifelike_mj.butterfly.flight3d.designed.DesignedController`, step by step, in numba, on arrays a compiled
loop can hold per flight (issue 42, point 2). The Python class is its twin and the reference:
``tests/butterfly/flight3d/test_flight3d_designed_kernel.py`` flies both and finds the same flight.

A flight's controller state is three arrays (:func:`new_state`): ``st`` (the scalars, :data:`ST_NAMES`), ``buf`` (the
last wing beat's samples, a ring of :data:`N_BUF` rows: position, velocity, rates, attitude matrix, stroke phase) and
``tmpl`` (the beat's periodic template, :data:`~lifelike_mj.butterfly.flight3d.designed.N_BINS` rows of 9 and a count).
The schedule is :func:`tables`' arrays, the same for every flight of one controller.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly.flight3d import designed as D
from lifelike_mj.butterfly.flight3d import loop as L
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d import perch_layout as PE
from lifelike_mj.butterfly.flight3d.designed import _log
from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

#: The scalars of a flight's state, in ``st``'s order.
ST_NAMES = ("k", "count", "head", "int_z", "int_v", "int_h", "v_hat_set", "v_hat_x", "v_hat_y", "v_hat_z", "w_hat_x",
            "w_hat_y", "w_hat_z", "heading_set", "heading", "airspeed_set", "airspeed", "altitude_set", "altitude",
            "orbit_waypoint", "orbit_swept", "orbit_bearing", "orbit_bearing_set", "going_out", "out_heading",
            "moment_set", "rates_before_x", "rates_before_y", "rates_before_z", "moment_x", "moment_y", "moment_z",
            "land_on", "land_bin", "land_k", "land_yaw", "land_x", "land_y", "land_z", "final_set", "final_yaw",
            "outbound")
#: Where the landing's scalars start in ``st`` (:data:`ST_NAMES`).
ST_LAND = ST_NAMES.index("land_on")
#: Rows of the sample ring: more than any wing beat holds at the coarsest time step and slowest frequency allowed.
N_BUF = 512
#: A sample's columns: position (3), velocity (3), rates (3), attitude matrix (9, row major), stroke phase (1).
N_SAMPLE = 19


def new_state() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A flight's controller state at its start: ``st``, ``buf`` and ``tmpl`` (module docstring)."""
    return np.zeros(len(ST_NAMES)), np.zeros((N_BUF, N_SAMPLE)), np.zeros((D.N_BINS, 10))


def tables(spec: dict) -> tuple[np.ndarray, ...]:
    """The schedule of a designed controller (:func:`~lifelike_mj.butterfly.flight3d.designed.design`) as arrays:
    speeds, body angles, trim velocities, gains, trim kinematics, ``A``, ``B``."""
    s = spec["schedule"]
    return (np.array([p["speed_m_s"] for p in s], float), np.array([p["body_angle_rad"] for p in s], float),
            np.array([p["v0_body_m_s"] for p in s], float), np.array([p["K"] for p in s], float),
            np.array([p["command"] for p in s], float), np.array([p["A"] for p in s], float),
            np.array([p["B"] for p in s], float))


def constants() -> np.ndarray:
    """The controller's constants in the order :func:`control` reads them (the module's values now)."""
    lo, hi = D.limits()
    return np.concatenate([[D.MAX_ALTITUDE_ERROR_M, D.MAX_HEADING_ERROR_RAD, D.MAX_SPEED_ERROR_M_S, D.MAX_RATE_RAD_S,
                            D.MAX_ATTITUDE_ERROR_RAD, D.MAX_CLIMB_M_S, D.TEMPLATE_RATE, D.TEMPLATE_MIN,
                            D.OBSERVER_HZ, D.OBSERVER_ZETA, D.APPROACH_MIN_M_S, D.APPROACH_PER_S, D.MIN_AIRSPEED_M_S,
                            D.MAX_AIRSPEED_M_S, D.MAX_SPEED_CHANGE_M_S2, D.MAX_TURN_RATE_RAD_S],
                           D.INTEGRAL_LIMITS, lo, hi, [D.MOMENT_TAU_S], D.MOMENT_WEIGHTS])


def landing_tables(landing: dict | None) -> tuple[np.ndarray, ...]:
    """A designed controller's landing (its file's ``landing``: :func:`~lifelike_mj.butterfly.flight3d.perching.
    design_landing`) as the arrays the compiled loop reads: per manoeuvre its start distance (m), length (control
    steps) and phase (rad) (``lm``), its nominal states (``ls``, :func:`~lifelike_mj.butterfly.flight3d.perching.
    state_vector`), commands (``lu``) and gains (``lk``), padded to the longest; and the landing's constants
    (``lc``). The take-off (``landing["take_off"]``, if any) is the last row, its start distance -1. Without a
    landing, zero manoeuvres."""
    lc = np.array([PE.RISE_M, PE.APPROACH_M_S, PE.START_WINDOW_M, PE.START_SIDE_M, PE.START_HEIGHT_M,
                   PE.MAX_GLIDE_S / (PE.EVERY * 1.0 / 800.0), PE.BELOW_M, *PE.CONTROL_SCALE, PE.CONTROL_LIMIT,
                   PE.FINAL_LOOKAHEAD_M, PE.FINAL_MIN_M, PE.FINAL_OUT_M, PE.TAKE_OFF_STRAIGHT_S,
                   PE.START_PHASE_GAP_RAD])
    bins = list((landing or {}).get("manoeuvres") or [])
    rising = (landing or {}).get("take_off")
    if bins and rising:
        bins.append({**rising, "start_m": -1.0, "phase_rad": 0.0})
    n = len(bins)
    t_max = max([len(b["commands"]) for b in bins] + [1])
    lm, ls = np.zeros((n, 3)), np.zeros((n, t_max + 1, PE.N_STATE + 1))
    lu, lk = np.zeros((n, t_max, N_PARAMS)), np.zeros((n, t_max, PE.N_CONTROL, PE.N_STATE))
    for i, b in enumerate(bins):
        t = len(b["commands"])
        lm[i] = (b["start_m"], t, b["phase_rad"])
        ls[i, : t + 1] = b["states"]
        lu[i, :t] = b["commands"]
        lk[i, :t] = b["gains"]
    return lm, ls, lu, lk, lc


@njit(cache=True)
def trigger(st, task, qpos, qvel, psi, lm, lc):
    """Whether a landing's manoeuvre starts now (then marked in ``st``): the one whose phase the beat's phase ``psi``
    is nearest, if it is within ``START_PHASE_GAP_RAD`` of it and the thorax's distance from the flower's axis is
    within half :data:`~lifelike_mj.butterfly.flight3d.perching.START_WINDOW_M` of its start distance, on the final
    (not flying out), flying toward the axis and passing it within ``START_SIDE_M`` and at the approach's height
    within ``START_HEIGHT_M``. The manoeuvre's frame: the flower's standing point, its ``x`` the
    bearing to the axis now."""
    b = L.T_ROW0
    sx, sy, sz = task[b], task[b + 1], task[b + 2] + task[b + 3]
    tx, ty = sx - qpos[0], sy - qpos[1]
    dist = math.sqrt(tx * tx + ty * ty)
    j, best = 0, 10.0
    for i in range(lm.shape[0]):  # the manoeuvre whose phase is nearest the beat's now (not the take-off)
        if lm[i, 0] < 0.0:
            continue
        gap = abs((psi - lm[i, 2] + math.pi) % (2.0 * math.pi) - math.pi)
        if gap < best:
            j, best = i, gap
    if abs(dist - lm[j, 0]) > 0.5 * lc[2] or best > lc[18]:
        return False
    sp = math.sqrt(qvel[0] * qvel[0] + qvel[1] * qvel[1])
    if st[ST_LAND + 9] != 0.0 or sp < 0.5 or qvel[0] * tx + qvel[1] * ty <= 0.0:  # flying out, or away
        return False
    if abs(qvel[0] * ty - qvel[1] * tx) / sp > lc[3] or abs(qpos[2] - sz - lc[0]) > lc[4]:
        return False
    s0 = ST_LAND
    st[s0], st[s0 + 1], st[s0 + 2], st[s0 + 3] = 1.0, j, 0.0, math.atan2(ty, tx)
    st[s0 + 4], st[s0 + 5], st[s0 + 6] = sx, sy, sz
    return True


@njit(cache=True)
def approach(st, task, qpos, lm, lc, wp, t, rec):
    """The landing's approach (its waypoint into ``wp``): a straight final toward the flower's axis at the approach's
    height (:data:`~lifelike_mj.butterfly.flight3d.perching.RISE_M` above the standing point), followed by aiming
    ``FINAL_LOOKAHEAD_M`` ahead of the body's foot on it. The final's line is the bearing to the axis at the landing's
    start; begun nearer than ``FINAL_MIN_M``, the butterfly first flies out along it, away from the flower, to
    ``FINAL_OUT_M``, and turns back. A final that passes every manoeuvre's start without one starting goes around:
    out beyond the flower, then back along the line the other way. For ``TAKE_OFF_STRAIGHT_S`` after a take-off (at
    ``rec[R_TOOK_OFF_AT]``; ``t`` now) it flies straight ahead first, climbing: a turn at once upsets the body."""
    b = L.T_ROW0
    sx, sy, sz = task[b], task[b + 1], task[b + 2] + task[b + 3]
    f0 = ST_LAND + 7
    if t - rec[L.R_TOOK_OFF_AT] < lc[17]:  # the take-off: straight ahead, climbing
        yaw = L.attitude(qpos[3:7])[2]
        wp[0], wp[1], wp[2] = qpos[0] + 3.0 * math.cos(yaw), qpos[1] + 3.0 * math.sin(yaw), sz + lc[0]
        return
    if st[f0] == 0.0:
        st[f0], st[f0 + 1] = 1.0, math.atan2(sy - qpos[1], sx - qpos[0])
        st[f0 + 2] = 1.0 if math.hypot(sx - qpos[0], sy - qpos[1]) < lc[15] else 0.0
    c, s = math.cos(st[f0 + 1]), math.sin(st[f0 + 1])
    along = (sx - qpos[0]) * c + (sy - qpos[1]) * s
    if st[f0 + 2] != 0.0:
        if along >= lc[16] - 0.2:
            st[f0 + 2] = 0.0
        else:
            wp[0], wp[1], wp[2] = sx - lc[16] * c, sy - lc[16] * s, sz + lc[0]
            return
    nearest = 1e9
    for i in range(lm.shape[0]):
        if lm[i, 0] >= 0.0:
            nearest = min(nearest, lm[i, 0])
    if along < nearest - 0.5 * lc[2] - 0.05:  # every start passed: around again, the other way
        st[f0 + 1] = st[f0 + 1] + math.pi
        st[f0 + 2] = 1.0
        wp[0], wp[1], wp[2] = sx + lc[16] * c, sy + lc[16] * s, sz + lc[0]
        return
    ahead = max(along - lc[14], 0.0)
    wp[0], wp[1], wp[2] = sx - ahead * c, sy - ahead * s, sz + lc[0]


@njit(cache=True)
def tracking_error(st, ud, qpos, qvel, nom, lc):
    """The state's error from the nominal's state ``nom`` (:func:`~lifelike_mj.butterfly.flight3d.perching.
    state_error`'s order), the state taken in the manoeuvre's frame (``st``'s landing scalars: the standing point and
    the final's bearing) as the nominal was shot: the standing point ``RISE_M`` below the start, the approach along
    ``x``."""
    s0 = ST_LAND
    cy, sy = math.cos(st[s0 + 3]), math.sin(st[s0 + 3])
    rx, ry, rz = qpos[0] - st[s0 + 4], qpos[1] - st[s0 + 5], qpos[2] - st[s0 + 6]
    e = np.empty(PE.N_STATE)
    e[0] = cy * rx + sy * ry - nom[0]
    e[1] = -sy * rx + cy * ry - nom[1]
    e[2] = rz - lc[0] - nom[2]
    e[3] = cy * qvel[0] + sy * qvel[1] - nom[3]
    e[4] = -sy * qvel[0] + cy * qvel[1] - nom[4]
    e[5] = qvel[2] - nom[5]
    # the attitude in the manoeuvre's frame: the yaw taken off, then the rotation from the nominal's
    h = -0.5 * st[s0 + 3]
    qz = np.array([math.cos(h), 0.0, 0.0, math.sin(h)])
    q = qpos[3:7]
    ql = np.array([qz[0] * q[0] - qz[3] * q[3], qz[0] * q[1] - qz[3] * q[2], qz[0] * q[2] + qz[3] * q[1],
                   qz[0] * q[3] + qz[3] * q[0]])
    e[6:9] = _log(D.quat2mat(nom[6:10]).T @ D.quat2mat(ql))
    for i in range(3):
        e[9 + i] = qvel[3 + i] - nom[10 + i]
    for i in range(5):
        e[12 + i] = qpos[int(ud[mj3d.U_DRIVEN_Q + i])] - nom[13 + i]
        e[17 + i] = qvel[int(ud[mj3d.U_DRIVEN_D + i])] - nom[18 + i]
    e[22] = (ud[mj3d.U_PSI0] - nom[23] + math.pi) % (2.0 * math.pi) - math.pi
    for i in range(N_PARAMS):
        e[23 + i] = ud[mj3d.U_P0 + i] - nom[24 + i]
        e[23 + N_PARAMS + i] = ud[mj3d.U_DP0 + i] - nom[24 + N_PARAMS + i]
    return e


@njit(cache=True)
def rise(st, qpos, ls, j):
    """Start the take-off's manoeuvre (row ``j`` of the landing's tables, :func:`landing_tables`): its frame (``st``'s
    landing scalars, as :func:`tracking_error` reads them) placed so that the nominal's first state lies where the
    body is, turned to its heading: the error starts with the attitude's and the joints' alone."""
    s0 = ST_LAND
    yaw = L.attitude(qpos[3:7])[2] - L.attitude(ls[j, 0, 6:10])[2]
    c, s = math.cos(yaw), math.sin(yaw)
    n0 = ls[j, 0]
    st[s0], st[s0 + 1], st[s0 + 2], st[s0 + 3] = 1.0, j, 0.0, yaw
    st[s0 + 4] = qpos[0] - (c * n0[0] - s * n0[1])
    st[s0 + 5] = qpos[1] - (s * n0[0] + c * n0[1])
    st[s0 + 6] = qpos[2] - PE.RISE_M - n0[2]


@njit(cache=True)
def tracked(st, ud, qpos, qvel, lm, ls, lu, lk, lc, out):
    """The command (into ``out``) of a landing's manoeuvre under way (``st``'s landing scalars): its nominal's
    command at this control step less its gain times the state's error from the nominal
    (:func:`~lifelike_mj.butterfly.flight3d.perching.state_error`, the state taken in the manoeuvre's frame), each
    control within :data:`~lifelike_mj.butterfly.flight3d.perching.CONTROL_LIMIT` of its scales; after the nominal's
    end, its last command. A manoeuvre that has glided on ``MAX_GLIDE_S`` or sunk ``BELOW_M`` under the standing point
    without touching down is given up (the approach flies again)."""
    s0 = ST_LAND
    j, k = int(st[s0 + 1]), int(st[s0 + 2])
    t = int(lm[j, 1])
    if k >= t + lc[5] or qpos[2] < st[s0 + 6] - lc[6] or (lm[j, 0] < 0.0 and k >= t):  # a take-off: no glide
        st[s0] = 0.0
        return
    st[s0 + 2] = k + 1
    if k >= t:
        for i in range(N_PARAMS):
            out[i] = lu[j, t - 1, i]
        return
    e = tracking_error(st, ud, qpos, qvel, ls[j, k], lc)
    u = -(np.ascontiguousarray(lk[j, k]) @ e)
    full = np.zeros(9)
    for i in range(PE.N_CONTROL):
        lim = lc[13] * lc[7 + i]
        full[PE.TRACKED_CONTROLS[i]] = min(max(u[i], -lim), lim)
    p = _command_from_controls(np.ascontiguousarray(lu[j, k]), full)
    for i in range(N_PARAMS):
        out[i] = p[i]


@njit(cache=True)
def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@njit(cache=True)
def _exp(a):
    t = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    if t < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + math.sin(t) / t * k + (1.0 - math.cos(t)) / t ** 2 * (k @ k)


@njit(cache=True)
def _rotation(roll, pitch, yaw):
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), math.sin(yaw)
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, -sp], [0.0, 1.0, 0.0], [sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    return rz @ ry @ rx


@njit(cache=True)
def _at(speeds, speed):
    """The row below ``speed`` and the weight of the row above (``designed._lerp``)."""
    x = min(max(speed, speeds[0]), speeds[-1])
    i = np.searchsorted(speeds, x) - 1
    i = min(max(i, 0), len(speeds) - 2)
    return i, (x - speeds[i]) / (speeds[i + 1] - speeds[i])


@njit(cache=True)
def _controls_of(p):
    return np.array([p[0], 0.5 * (p[1] + p[2]), 0.5 * (p[3] + p[4]), p[1] - p[2], p[3] - p[4], 0.5 * (p[5] + p[6]),
                     p[5] - p[6], 0.5 * (p[7] + p[8]), p[10]])


@njit(cache=True)
def _command_from_controls(base, u):
    p = base.copy()
    p[0] += u[0]
    p[1] += u[1] + 0.5 * u[3]
    p[2] += u[1] - 0.5 * u[3]
    p[3] += u[2] + 0.5 * u[4]
    p[4] += u[2] - 0.5 * u[4]
    p[5] += u[5] + 0.5 * u[6]
    p[6] += u[5] - 0.5 * u[6]
    p[7] += u[7]
    p[8] += u[7]
    p[10] += u[8]
    return p


@njit(cache=True)
def _wind_triangle(d, ground_speed, wind_xy, vmin, vmax):
    air = ground_speed * d - wind_xy
    if math.sqrt(air[0] ** 2 + air[1] ** 2) > vmax:
        along = d[0] * wind_xy[0] + d[1] * wind_xy[1]
        disc = along * along - (wind_xy[0] ** 2 + wind_xy[1] ** 2) + vmax ** 2
        g = along + math.sqrt(disc) if disc >= 0.0 else 0.0
        air = max(g, 0.0) * d - wind_xy
        n = math.sqrt(air[0] ** 2 + air[1] ** 2)
        if n > vmax:
            air = air * (vmax / n)
    speed = math.sqrt(air[0] ** 2 + air[1] ** 2)
    if speed < 1e-9:
        return math.atan2(d[1], d[0]), vmin
    return math.atan2(air[1], air[0]), min(max(speed, vmin), vmax)


@njit(cache=True)
def sample(st, buf, qpos, qvel, R, psi, n_beat):
    """One physics step's sample into the ring (``DesignedController.__call__``'s first lines): the thorax's position
    and velocity, its rates, attitude matrix ``R`` and the stroke phase ``psi``; the ring keeps the last ``n_beat``,
    and ``st[0]`` counts the samples (the caller sets a new command at every ``every``-th)."""
    h = int(st[2])
    buf[h, 0:3] = qpos[0:3]
    buf[h, 3:6] = qvel[0:3]
    buf[h, 6:9] = qvel[3:6]
    buf[h, 9:18] = R.ravel()
    buf[h, 18] = psi
    st[2] = (h + 1) % N_BUF
    st[1] = min(st[1] + 1.0, float(n_beat))
    st[0] += 1.0


@njit(cache=True)
def _row(buf, st, j):
    """The ring's ``j``-th sample from the oldest kept."""
    n = int(st[1])
    return buf[(int(st[2]) - n + j) % N_BUF]


@njit(cache=True)
def control(st, buf, tmpl, speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins, ud_p, ud_dp, dt, every, kind,
            waypoint, task_speed, reference, n_beat):
    """The command (kinematics parameters) of one control step (``DesignedController.__call__`` after the sample):
    ``c`` the :func:`constants`, ``ud_p`` and ``ud_dp`` the kinematics' parameters and rates as flown, ``kind`` 0 for
    a waypoint (``waypoint``, at ``task_speed``), 1 for a reference (heading, altitude, airspeed)."""
    (max_alt, max_head, max_speed, max_rate, max_att, max_climb, t_rate, t_min, obs_hz, obs_zeta, app_min, app_per,
     vmin, vmax, max_dv, max_turn) = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9], c[10], c[11], c[12], \
        c[13], c[14], c[15]
    int_lim = c[16:19]
    lo, hi = c[19:28], c[28:37]
    n = int(st[1])
    pos = np.zeros(3)
    vel = np.zeros(3)
    rates = np.zeros(3)
    for j in range(n):
        r = _row(buf, st, j)
        pos += r[0:3]
        vel += r[3:6]
        rates += r[6:9]
    pos /= n
    vel /= n
    rates /= n
    last = _row(buf, st, n - 1)
    R_last = last[9:18].copy().reshape(3, 3)
    Rm = R_last
    a_mean = np.zeros(3)
    for j in range(n):
        a_mean += _log(Rm.T @ _row(buf, st, j)[9:18].copy().reshape(3, 3))
    a_mean /= n
    Rm = Rm @ _exp(a_mean)
    if n == n_beat:  # the slow motion without the mean's half-beat lag (DesignedController._unlagged)
        mid = _row(buf, st, n // 2)
        Rmid = mid[9:18].copy().reshape(3, 3)
        k = int(mid[18] % (2.0 * math.pi) / (2.0 * math.pi) * n_bins) % n_bins
        dev = np.empty(9)
        dev[0:3] = Rmid.T @ (mid[3:6] - vel)
        dev[3:6] = mid[6:9] - rates
        dev[6:9] = _log(Rm.T @ Rmid)
        tmpl[k, 0:9] += t_rate * (dev - tmpl[k, 0:9])
        tmpl[k, 9] += 1.0
        j = int(last[18] % (2.0 * math.pi) / (2.0 * math.pi) * n_bins) % n_bins
        if tmpl[j, 9] >= t_min:
            vel = last[3:6] - R_last @ tmpl[j, 0:3]
            rates = last[6:9] - tmpl[j, 3:6]
            Rm = R_last @ _exp(-tmpl[j, 6:9])
    t_ctrl = every * dt
    # the wind observer (DesignedController.wind)
    wind = st[10:13].copy()
    if st[6] == 0.0:
        st[6] = 1.0
        st[7:10] = vel
    else:
        air = st[7:9] - st[10:12]
        spd = math.sqrt(air[0] ** 2 + air[1] ** 2)
        i, t = _at(speeds, spd)
        A = (1.0 - t) * As[i] + t * As[i + 1]
        B = (1.0 - t) * Bs[i] + t * Bs[i + 1]
        v0 = (1.0 - t) * v0s[i] + t * v0s[i + 1]
        pitch0 = (1.0 - t) * pitches[i] + t * pitches[i + 1]
        trim_cmd = (1.0 - t) * commands[i] + t * commands[i + 1]
        yaw = math.atan2(Rm[1, 0], Rm[0, 0])
        a = _log(_rotation(0.0, pitch0, yaw).T @ Rm)
        u = _controls_of(ud_p) - _controls_of(trim_cmd)
        v_b = Rm.T @ (st[7:10] - st[10:13])
        Avv_b = np.ascontiguousarray(A[0:3, 0:3])
        acc = Rm @ (Avv_b @ (v_b - v0) + np.ascontiguousarray(A[0:3, 3:6]) @ rates
                    + np.ascontiguousarray(A[0:3, 6:9]) @ a + np.ascontiguousarray(B[0:3]) @ u)
        Avv = Rm @ Avv_b @ np.ascontiguousarray(Rm.T)
        e = vel - st[7:10]
        wn = 2.0 * math.pi * obs_hz
        st[7:10] = st[7:10] + t_ctrl * (acc + 2.0 * obs_zeta * wn * e)
        dw = -wn * wn * np.linalg.solve(Avv, e)
        dw[2] = 0.0
        st[10:13] = st[10:13] + t_ctrl * dw
        wind = st[10:13].copy()
    # guidance (DesignedController.references)
    if kind == 0 or kind == 2:  # a waypoint (2: at the task's speed to the end, a landing's approach)
        to = waypoint[0:2] - pos[0:2]
        dist = math.sqrt(to[0] ** 2 + to[1] ** 2)
        d = to / dist if dist > 1e-9 else np.array([1.0, 0.0])
        if kind == 0:
            d = D.orbit_direction(st[19:25], reference[0], to, dist, d, st[14], st[13] != 0.0)  # circling
        gs = task_speed if kind == 2 else min(task_speed, app_min + app_per * dist)
        target, asked = _wind_triangle(d, gs, wind[0:2], vmin, vmax)
        altitude_asked = waypoint[2]
    else:
        target, altitude_asked, asked = reference[0], reference[1], min(max(reference[2], vmin), vmax)
    if st[17] == 0.0:
        st[17] = 1.0
        st[18] = pos[2]
    dz_max = max_climb * t_ctrl
    climb = min(max(altitude_asked - st[18], -dz_max), dz_max)
    st[18] = st[18] + climb
    altitude = st[18]
    climb_rate = climb / t_ctrl
    if st[15] == 0.0:
        st[15] = 1.0
        st[16] = asked
        if kind == 2:  # a landing's approach, from a perch: the speed asked starts from the speed flown
            st[16] = min(max(math.sqrt(vel[0] ** 2 + vel[1] ** 2), vmin), asked)
    dv = max_dv * every * dt
    st[16] = st[16] + min(max(asked - st[16], -dv), dv)
    airspeed = st[16]
    if st[13] == 0.0:
        st[13] = 1.0
        st[14] = math.atan2(Rm[1, 0], Rm[0, 0])
    step = max_turn * t_ctrl
    turn = min(max(_wrap(target - st[14]), -step), step)
    st[14] = _wrap(st[14] + turn)
    heading = st[14]
    turn_rate = turn / t_ctrl
    # the regulator
    i, t = _at(speeds, airspeed)
    pitch0 = (1.0 - t) * pitches[i] + t * pitches[i + 1]
    v0 = (1.0 - t) * v0s[i] + t * v0s[i + 1]
    K = (1.0 - t) * Ks[i] + t * Ks[i + 1]
    trim_cmd = (1.0 - t) * commands[i] + t * commands[i + 1]
    trim_u = _controls_of(trim_cmd)
    yaw = math.atan2(Rm[1, 0], Rm[0, 0])
    herr = min(max(_wrap(yaw - heading), -max_head), max_head)
    bank = -math.atan(airspeed * turn_rate / 9.81)
    R0 = _rotation(bank, pitch0, yaw - herr)
    a = _log(R0.T @ Rm)
    v_air = Rm.T @ (vel - wind - np.array([0.0, 0.0, climb_rate]))
    x = np.zeros(K.shape[1])
    ez = R0.T @ np.array([0.0, 0.0, turn_rate])
    for q in range(3):
        x[q] = min(max(v_air[q] - v0[q], -max_speed), max_speed)
        x[3 + q] = min(max(rates[q] - ez[q], -max_rate), max_rate)
        x[6 + q] = min(max(a[q], -max_att), max_att)
    nu = 9
    x[13 : 13 + nu] = _controls_of(ud_p) - trim_u
    x[13 + nu :] = _controls_of(ud_dp)
    zerr = min(max(pos[2] - altitude, -max_alt), max_alt)
    x[9] = zerr
    x[10:13] = st[3:6]
    u = -(K @ x)
    # the moment observer (DesignedController.moment)
    A = (1.0 - t) * As[i] + t * As[i + 1]
    B = (1.0 - t) * Bs[i] + t * Bs[i + 1]
    Aw = np.ascontiguousarray(A[3:6, 0:9])
    Bw = np.ascontiguousarray(B[3:6])
    if st[25] == 0.0:
        st[25] = 1.0
        st[26:29] = rates
    else:
        measured = (rates - st[26:29]) / t_ctrl
        st[26:29] = rates
        predicted = Aw @ np.ascontiguousarray(x[0:9]) + Bw @ np.ascontiguousarray(x[13 : 13 + nu])
        st[29:32] = st[29:32] + min(1.0, t_ctrl / c[37]) * (measured - predicted - st[29:32])
    W = np.diag(c[38:47] ** 2)
    BwT = np.ascontiguousarray(Bw.T)
    lateral = st[29:32].copy()
    lateral[1] = 0.0  # the roll and yaw only
    u = u - W @ BwT @ np.linalg.solve(Bw @ W @ BwT, lateral)
    change = np.empty(nu)
    for q in range(nu):
        change[q] = min(max(trim_u[q] + u[q], lo[q]), hi[q]) - trim_u[q]
    fwd = math.cos(heading) * (vel[0] - wind[0]) + math.sin(heading) * (vel[1] - wind[1])
    inc = np.array([zerr, fwd - airspeed, herr])
    for q in range(3):
        st[3 + q] = min(max(st[3 + q] + t_ctrl * inc[q], -int_lim[q]), int_lim[q])
    return _command_from_controls(trim_cmd, change)


def load_compiled(name_or_path):
    """Any 3D controller by name (``"designed"``, ``"monarch"``: the shipped files) or path, ready to fly in the
    compiled loop: a network (:class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D`) as it is read, a
    designed controller as a :class:`CompiledDesigned` (the same flight as its Python twin). For
    ``Flight3D(controller=load_compiled(name))`` and the commands' ``--controller``."""
    ctrl = D.load_any(name_or_path)
    return CompiledDesigned.of(ctrl) if isinstance(ctrl, D.DesignedController) else ctrl


class CompiledDesigned:
    """A designed controller (:func:`~lifelike_mj.butterfly.flight3d.designed.design`'s answer or a controller file's
    content) for the compiled loop: ``Flight3D(controller=CompiledDesigned(spec))`` flies it inside
    :class:`~lifelike_mj.butterfly.flight3d.loop.Batch` (:func:`fly_designed`), as a network is flown, bit for bit as
    :class:`~lifelike_mj.butterfly.flight3d.designed.DesignedController` flies from Python."""

    #: what ``Flight3D`` looks for to fly it in the compiled loop
    compiled = True

    def __init__(self, spec: dict, every: int = 8, name: str = "", provenance: dict | None = None) -> None:
        self.every, self.name = int(every), name
        self.provenance = dict(provenance or spec.get("provenance") or {})
        self.animal = spec.get("animal", "monarch")
        self.force_law = spec.get("force_law", "calibrated")
        self.tables, self.constants = tables(spec), constants()
        #: The landing's manoeuvres as arrays (:func:`landing_tables`; none: zero of them, no landing).
        self.landing = landing_tables(spec.get("landing"))
        self.spec_landing = spec.get("landing")

    def start_command(self, speed_m_s: float = 1.5):
        """The trim's kinematics at ``speed_m_s`` (``DesignedController.start_command``)."""
        from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

        return KinematicsCommand(*D._lerp(self.tables[0], self.tables[4], speed_m_s))

    @classmethod
    def of(cls, controller: D.DesignedController) -> CompiledDesigned:
        """The same controller as ``controller`` (its schedule, rate, name and provenance), for the compiled loop."""
        spec = {"animal": controller.animal, "force_law": controller.force_law, "schedule": controller.schedule,
                "landing": getattr(controller, "landing", None)}
        return cls(spec, controller.every, controller.name, controller.provenance)

    def advance(self, batch, n_steps: int, path: np.ndarray, path_every: int) -> None:
        """Fly ``batch`` (:class:`~lifelike_mj.butterfly.flight3d.loop.Batch`, made with ``designed=self``, its
        per-flight states in ``batch.designed_states``) ``n_steps`` steps (:func:`fly_designed`, threads over the
        flights of a batch of more than one); ``path`` as ``Batch.advance`` takes it (a batch of one only)."""
        from lifelike_mj.physics import mjabi

        m = batch.model
        sts, bufs, tmpls = batch.designed_states
        args = (*self.tables, self.constants, D.N_BINS, *self.landing)
        if batch.n == 1:
            fly_designed(m._address, int(batch.ptrs[0]), mjabi.offsets_tuple(), m.nq, m.nv, n_steps, batch.dt,
                         self.every, batch.tasks[0], batch.records[0], path, path_every, batch.tumble_rad, batch.base,
                         sts[0], bufs[0], tmpls[0], *args)
        else:
            fly_designed_batch(m._address, batch.ptrs, mjabi.offsets_tuple(), m.nq, m.nv, n_steps, batch.dt,
                               self.every, batch.tasks, batch.records, batch.tumble_rad, batch.base, sts, bufs, tmpls,
                               *args)

    def decide(self, batch, actions: np.ndarray, n_max: int, act: np.ndarray) -> np.ndarray:
        """Fly every flight of ``batch`` to the controller's next command with a residual policy's ``actions`` (one
        row of nine per flight, in ``[-1, 1]``, times :data:`~lifelike_mj.butterfly.flight3d.designed.RESIDUAL_SCALE`, or
        the batch's ``residual_scale`` when set)
        added to this command (:func:`decide_designed`); ``act``: which flights act (the others fly on to their next
        command). The designed commands reached are then in ``batch.baselines``, the observations in
        ``batch.observations``. Returns whether each flight goes on."""
        from lifelike_mj.physics import mjabi

        m = batch.model
        sts, bufs, tmpls = batch.designed_states
        args = (*self.tables, self.constants, D.N_BINS, *self.landing)
        scale = D.RESIDUAL_SCALE if batch.residual_scale is None else batch.residual_scale
        going = np.zeros(batch.n, dtype=np.bool_)
        if batch.n == 1:
            going[0] = decide_designed(m._address, int(batch.ptrs[0]), mjabi.offsets_tuple(), m.nq, m.nv, int(n_max),
                                       batch.dt, self.every, actions[0], bool(act[0]), scale, batch.tasks[0],
                                       batch.records[0], batch.observations[0], batch.tumble_rad, batch.base, sts[0],
                                       bufs[0], tmpls[0], batch.baselines[0], *args)
        else:
            decide_designed_batch(m._address, batch.ptrs, mjabi.offsets_tuple(), m.nq, m.nv, int(n_max), batch.dt,
                                  self.every, actions, act, scale, batch.tasks, batch.records, batch.observations,
                                  batch.tumble_rad, batch.base, sts, bufs, tmpls, batch.baselines, *args, going)
        return going

    def states(self, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Fresh controller states for ``n`` flights (:func:`new_state`, stacked)."""
        st, buf, tmpl = new_state()
        return (np.zeros((n, *st.shape)), np.zeros((n, *buf.shape)), np.zeros((n, *tmpl.shape)))


@njit(cache=True)
def _views(dptr, off, nq, nv):
    """The ``mjData`` at ``dptr``'s userdata, ``qpos``, ``qvel`` and clock, as arrays the loop writes through."""
    return (L._f64(L._ptr_at(dptr + off[L._O_UD]), mj3d.N_USERDATA), L._f64(L._ptr_at(dptr + off[L._O_QPOS]), nq),
            L._f64(L._ptr_at(dptr + off[L._O_QVEL]), nv), L._f64(dptr + off[L._O_TIME], 1))


@njit(cache=True)
def _scratch():
    """A flight loop's working arrays: the kinematics' parameters, rates and accelerations, the calm air of speeds
    over the ground, the loop's options (none), a waypoint and a reference."""
    return (np.empty(N_PARAMS), np.empty(N_PARAMS), np.empty(N_PARAMS), np.zeros(3), np.zeros(3), np.zeros(3),
            np.zeros(3))


@njit(cache=True)
def _head(ud, qpos, qvel, time, dt, every, task, rec, st, buf, tmpl, wp, ref, baseline, speeds, pitches, v0s, Ks,
          commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc):
    """A step's first part for the designed controller: its sample (:func:`sample`) and, every ``every`` samples, its
    command (:func:`control`, the waypoint or the schedule's references the task gives) into ``baseline`` and the
    kinematics' target. Returns whether a new command was set (a control step: a residual policy's decision)."""
    if int(task[L.T_KIND]) == L.TASK_PERCH:  # perched: the perch's kinematics stay (loop.perch_command), and the
        st[:] = 0.0  # controller starts afresh at the take-off, as a new flight's does
        tmpl[:] = 0.0
        return False
    freq = ud[mj3d.U_P0]
    n_beat = max(1, int(round(1.0 / (freq * dt))))
    sample(st, buf, qpos, qvel, D.quat2mat(qpos[3:7]), ud[mj3d.U_PSI0], n_beat)
    if (int(st[0]) - 1) % every != 0:
        return False
    kind = int(task[L.T_KIND])
    j = lm.shape[0] - 1
    if j >= 0 and lm[j, 0] < 0.0:  # a take-off's manoeuvre: started at the take-off's first step, whatever the task
        # (its time as the caller's clock gives it: a sum of steps, which the data's may differ from by a rounding)
        if st[ST_LAND] == 0.0 and abs(time[0] - rec[L.R_TOOK_OFF_AT]) < 0.5 * every * dt:
            rise(st, qpos, ls, j)
        if st[ST_LAND] != 0.0 and int(st[ST_LAND + 1]) == j and _manoeuvre(st, ud, qpos, qvel, lm, ls, lu, lk, lc,
                                                                             baseline):
            return True
    if kind == L.TASK_LAND and lm.shape[0] > 0:
        if st[ST_LAND] == 0.0:
            trigger(st, task, qpos, qvel, ud[mj3d.U_PSI0], lm, lc)
        if st[ST_LAND] != 0.0 and _manoeuvre(st, ud, qpos, qvel, lm, ls, lu, lk, lc, baseline):
            return True
        approach(st, task, qpos, lm, lc, wp, time[0], rec)
        cmd = control(st, buf, tmpl, speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins,
                      ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS].copy(), ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS].copy(), dt,
                      every, 2, wp, lc[1], ref, n_beat)
        for j in range(N_PARAMS):
            baseline[j] = cmd[j]
            ud[mj3d.U_TARGET + j] = cmd[j]
        clap(ud, time[0], rec)
        return True
    if kind == L.TASK_WAYPOINTS:
        i = min(int(rec[L.R_PASSED]), int(task[L.T_ROWS]) - 1)
        b = L.T_ROW0 + 4 * i
        wp[0], wp[1], wp[2] = task[b], task[b + 1], task[b + 2]
        ref[0] = i
        k = 0
    elif kind == L.TASK_SCHEDULE:
        # the schedule's row at steps x dt, the time Flight3D.reference reads (the data's clock, a sum of steps, can
        # fall a rounding short of a row's start)
        ref[0], ref[1], ref[2] = L.reference(task, rec[L.R_STEPS] * dt, qpos[0:3], rec)
        k = 1
    else:
        ref[0], ref[1], ref[2] = L.attitude(qpos[3:7])[2], qpos[2], task[L.T_SPEED]
        k = 1
    cmd = control(st, buf, tmpl, speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins,
                  ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS].copy(), ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS].copy(), dt, every,
                  k, wp, task[L.T_SPEED], ref, n_beat)
    for j in range(N_PARAMS):
        baseline[j] = cmd[j]
        ud[mj3d.U_TARGET + j] = cmd[j]
    clap(ud, time[0], rec)
    return True


@njit(cache=True)
def _manoeuvre(st, ud, qpos, qvel, lm, ls, lu, lk, lc, baseline):
    """The manoeuvre under way (:func:`tracked`) sets the kinematics' target (and ``baseline``); ``False`` when it has
    just ended or been given up (the regulator flies this step)."""
    tracked(st, ud, qpos, qvel, lm, ls, lu, lk, lc, baseline)
    if st[ST_LAND] == 0.0:
        return False
    for i in range(N_PARAMS):
        ud[mj3d.U_TARGET + i] = baseline[i]
    return True


@njit(cache=True)
def clap(ud, t, rec):
    """A take-off's first :data:`~lifelike_mj.butterfly.flight3d.tasks.CLAP_S` (until ``rec[R_CLAP_UNTIL]``): each
    wing's amplitude puts the top of its stroke at ``CLAP_TOP_RAD`` about the offset asked, so that the wings clap with
    a larger stroke and the body climbs from its first downstroke (Sunada et al. 1993), as a network's take-off does
    (``loop._act``)."""
    if t < rec[L.R_CLAP_UNTIL]:
        ud[mj3d.U_TARGET + 3] = L.CLAP_TOP_RAD - ud[mj3d.U_TARGET + 1]
        ud[mj3d.U_TARGET + 4] = L.CLAP_TOP_RAD - ud[mj3d.U_TARGET + 2]


@njit(cache=True)
def fly_designed(mptr, dptr, off, nq, nv, n_steps, dt, every, task, rec, path, path_every, tumble_rad, base, st, buf,
                 tmpl, speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc):
    """:func:`~lifelike_mj.butterfly.flight3d.loop.fly_steps` with the designed controller in place of the network:
    each step :func:`_head` (the sample, and every ``every`` steps a new command), then the loop's step as for every
    controller (gusts, air, references, one ``mj_step``, the kinematics advanced)."""
    ud, qpos, qvel, time = _views(dptr, off, nq, nv)
    obs = np.empty(L.N_OBS)
    p, dp, ddp, ground, opts, wp, ref = _scratch()
    baseline = np.empty(N_PARAMS)
    n_path = 0
    for _ in range(n_steps):
        if rec[L.R_DIVERGED] >= 0 or rec[L.R_TUMBLED] >= 0:
            return
        _head(ud, qpos, qvel, time, dt, every, task, rec, st, buf, tmpl, wp, ref, baseline, speeds, pitches, v0s, Ks,
              commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc)
        tumbled, n_path = L._before(ud, qpos, qvel, time, dt, task, rec, obs, opts, ground, path, path_every,
                                    n_path, tumble_rad, base)
        if tumbled:
            return
        if not L._after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return


@njit(cache=True)
def residual_command(baseline, action, scale, lo, hi, target):
    """The kinematics' target (``target``) of the designed controller's command ``baseline`` with a residual policy's
    ``action`` (nine numbers in ``[-1, 1]``, one per control of
    :data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS`) times ``scale`` added to its controls, each control
    kept within the controller's limits ``lo``, ``hi`` (the natural envelope); a zero action leaves the command
    exactly as it is."""
    cb = _controls_of(baseline)
    change = np.zeros(len(cb))
    for q in range(len(cb)):
        if action[q] != 0.0:
            change[q] = min(max(cb[q] + action[q] * scale[q], lo[q]), hi[q]) - cb[q]
    p = _command_from_controls(baseline, change)
    for j in range(N_PARAMS):
        target[j] = p[j]


@njit(cache=True)
def decide_designed(mptr, dptr, off, nq, nv, n_max, dt, every, action, act, scale, task, rec, obs, tumble_rad, base,
                    st, buf, tmpl, baseline, speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc):
    """:func:`~lifelike_mj.butterfly.flight3d.loop.to_decision` for the designed controller with a residual policy on
    top: with ``act``, the designed command of this decision (``baseline``) plus the residual ``action``
    (:func:`residual_command`, ``scale`` per control) becomes the kinematics' target; then the steps go on, as
    :func:`fly_designed` flies them, to the controller's next command (whose observation is then in ``obs``, its
    command in ``baseline``), the flight's end or ``n_max`` steps. Without ``act``: on to the first command (at the
    start). With a zero action every step is :func:`fly_designed`'s, bit for bit. Returns whether the flight goes
    on."""
    ud, qpos, qvel, time = _views(dptr, off, nq, nv)
    p, dp, ddp, ground, opts, wp, ref = _scratch()
    none = np.empty((0, 7))
    if rec[L.R_DIVERGED] >= 0 or rec[L.R_TUMBLED] >= 0:
        return False
    if act:
        residual_command(baseline, action, scale, c[19:28], c[28:37], ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS])
        if not L._after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return False
    while True:
        decision = _head(ud, qpos, qvel, time, dt, every, task, rec, st, buf, tmpl, wp, ref, baseline, speeds,
                         pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc)
        tumbled, _ = L._before(ud, qpos, qvel, time, dt, task, rec, obs, opts, ground, none, 0, 0, tumble_rad, base)
        if tumbled:
            return False
        if decision or int(rec[L.R_STEPS]) >= n_max:
            return True
        if not L._after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return False


@njit(cache=True, parallel=True)
def decide_designed_batch(mptr, dptrs, off, nq, nv, n_max, dt, every, actions, act, scale, tasks, recs, obs,
                          tumble_rad, base, sts, bufs, tmpls, baselines, speeds, pitches, v0s, Ks, commands, As, Bs, c,
                          n_bins, lm, ls, lu, lk, lc, going):
    """:func:`decide_designed` for many butterflies at once (threads over the copies), each with its own state and
    action row; copies with ``act[i]`` false only fly on to their next command."""
    for i in prange(len(dptrs)):
        going[i] = decide_designed(mptr, dptrs[i], off, nq, nv, n_max, dt, every, actions[i], act[i], scale, tasks[i],
                                   recs[i], obs[i], tumble_rad, base, sts[i], bufs[i], tmpls[i], baselines[i], speeds,
                                   pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc)


@njit(cache=True, parallel=True)
def fly_designed_batch(mptr, dptrs, off, nq, nv, n_steps, dt, every, tasks, recs, tumble_rad, base, sts, bufs, tmpls,
                       speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc):
    """:func:`fly_designed` for many butterflies at once (threads over the copies), each with its own state."""
    none = np.empty((0, 7))
    for i in prange(len(dptrs)):
        fly_designed(mptr, dptrs[i], off, nq, nv, n_steps, dt, every, tasks[i], recs[i], none, 0, tumble_rad, base,
                     sts[i], bufs[i], tmpls[i], speeds, pitches, v0s, Ks, commands, As, Bs, c, n_bins, lm, ls, lu, lk, lc)
