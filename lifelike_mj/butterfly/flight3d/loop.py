"""The compiled loop that flies 3D butterflies: observation, network, guidance, gusts, reward, and the one
owner of its state (:class:`Batch`).

Each step of each butterfly: the gusts advance, the reference comes from the task
(:mod:`~lifelike_mj.butterfly.flight3d.tasks`), the network (:mod:`~lifelike_mj.butterfly.flight3d.controllers`)
turns the observation into a new kinematics command every ``every`` steps, one ``mj_step`` runs the MuJoCo
model (:mod:`~lifelike_mj.butterfly.flight3d.model`), and the kinematics advance exactly in the userdata. All of
it is compiled (numba), with no Python between the steps; a batch of butterflies runs on every core.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d import tasks as _tasks
from lifelike_mj.butterfly.flight3d.controllers import ALTITUDE_CLIP_M, INPUT_SCALE, N_ACT, N_OBS
from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS, filter_at
from lifelike_mj.butterfly.flight3d.tasks import (
    R_AIM,
    R_BOOST,
    R_CLAP_UNTIL,
    R_DIVERGED,
    R_FIT,
    R_FLUTTER,
    R_GUST,
    R_LANDED_AT,
    R_NEAR_SPEED,
    R_PASSED,
    R_STEPS,
    R_STYLE,
    R_TOOK_OFF_AT,
    R_TOUCH_SPEED,
    R_TUMBLED,
    R_WP,
    STYLE_FROM_S,
    T_FLUTTER,
    T_FLUTTER_TAU,
    T_GUST,
    T_GUST_TAU,
    T_GUST_W,
    T_KIND,
    T_RADIUS,
    T_ROW0,
    T_ROWS,
    T_SEED,
    T_SPEED,
    T_WIND,
    TASK_LAND,
    TASK_PERCH,
    TASK_SCHEDULE,
    TASK_TARGET,
    TASK_WAYPOINTS,
)
from lifelike_mj.physics import mjabi

LAND_ABOVE_M, LAND_GLIDE, LAND_HOLD_M = _tasks.LAND_ABOVE_M, _tasks.LAND_GLIDE, _tasks.LAND_HOLD_M
TOUCH_MARGIN_M = _tasks.TOUCH_MARGIN_M
PERCH_FLAP_RAD, CLAP_TOP_RAD = _tasks.PERCH_FLAP_RAD, _tasks.CLAP_TOP_RAD

#: A roll or pitch beyond this (rad) is a tumble: the flight ends there (no more reward).
TUMBLE_RAD = math.radians(80.0)
_O_TIME, _O_QPOS, _O_QVEL, _O_UD, _O_CTRL = mjabi.O_TIME, mjabi.O_QPOS, mjabi.O_QVEL, mjabi.O_UD, mjabi.O_CTRL
_mj_step = mjabi.mj_step
_vp = mjabi.voidptr_from_int
_ptr_at = mjabi.ptr_at
_f64 = mjabi.f64_at


@njit(cache=True)
def wrap(a):
    """``a`` (rad) wrapped to ``(-pi, pi]``."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(cache=True)
def attitude(q):
    """Roll, pitch (nose up > 0), yaw of the quaternion ``q`` (w, x, y, z) (as
    :func:`~lifelike_mj.butterfly.flight3d.flight.euler_from_quat`)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    s = 2.0 * (w * y - z * x)
    s = max(-1.0, min(1.0, s))
    pitch = -math.asin(s)
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


@njit(cache=True)
def observe(qpos, qvel, heading, altitude, speed, air, obs, pitch_ref=0.0):
    """The observation (module docstring; ``obs`` holds :data:`N_OBS`, of which a network reads its first
    ``layers[0]``) of the free body whose root is at ``qpos[0:7]``, ``qvel[0:6]``, against the reference ``heading``
    (rad), ``altitude`` (m) and forward ``speed`` (m/s). The forward and
    sideways speeds are taken relative to the horizontal velocity ``air[0:2]`` (m/s): zeros for speeds over
    the ground, the wind for speeds through the air. ``pitch_ref`` (rad, a landing's flare): the pitch is seen
    relative to it, so that a network that holds its pitch flies that much more nose up."""
    roll, pitch, yaw = attitude(qpos[3:7])
    pitch -= pitch_ref
    c, s = math.cos(yaw), math.sin(yaw)
    vx, vy = qvel[0] - air[0], qvel[1] - air[1]
    obs[0] = roll
    obs[1] = pitch
    obs[2] = wrap(heading - yaw)
    obs[3] = qvel[3]
    obs[4] = -qvel[4]  # nose up positive (the body's y axis points left)
    obs[5] = qvel[5]
    obs[6] = c * vx + s * vy - speed
    obs[7] = -s * vx + c * vy
    obs[8] = qvel[2]
    obs[9] = max(-ALTITUDE_CLIP_M, min(ALTITUDE_CLIP_M, qpos[2] - altitude))
    obs[10] = speed


@njit(cache=True)
def network(layers, weights, x, out, scratch):
    """``out = tanh(last layer)`` of the network ``layers`` (hidden neurons ``tanh``) with ``weights``
    (per layer, per neuron: its input weights, then its bias) on the observation ``x`` divided by
    :data:`INPUT_SCALE`. ``scratch``: at least ``2 * max(layers)`` floats."""
    width = 0
    for k in range(len(layers)):
        width = max(width, layers[k])
    a = scratch[:width]
    b = scratch[width : 2 * width]
    for i in range(layers[0]):
        a[i] = x[i] / INPUT_SCALE[i]
    w = 0
    for k in range(1, len(layers)):
        n_in, n_out = layers[k - 1], layers[k]
        for j in range(n_out):
            s = weights[w + n_in]
            for i in range(n_in):
                s += weights[w + i] * a[i]
            b[j] = math.tanh(s)
            w += n_in + 1
        for j in range(n_out):
            a[j] = b[j]
    for j in range(layers[-1]):
        out[j] = a[j]


@njit(cache=True)
def behaviour(task, qpos, t, rec, reach):
    """Which of a controller's networks flies now (an index into
    :data:`~lifelike_mj.butterfly.flight3d.controllers.NETWORKS`): 1
    (``land``) within ``reach[0]`` (m) of a landing's flower axis, else 2 (``take_off``) within ``reach[1]`` (s) of the
    last take-off, else 0 (the flight network). A reach of 0 never picks its behaviour."""
    if int(task[T_KIND]) == TASK_LAND and to_flower(task, qpos)[2] < reach[0]:
        return 1
    if t < rec[R_TOOK_OFF_AT] + reach[1]:
        return 2
    return 0


@njit(cache=True)
def command(base, scale, u, target):
    """The kinematics parameters (``target``, :class:`KinematicsCommand`'s order) of the action ``u``
    around ``base`` (module docstring)."""
    for i in range(N_PARAMS):
        target[i] = base[i]
    d_off, a_off = scale[0] * u[0], scale[1] * u[1]
    d_amp, a_amp = scale[2] * u[2], scale[3] * u[3]
    d_fm, a_fm = scale[4] * u[4], scale[5] * u[5]
    target[1] += d_off + a_off
    target[2] += d_off - a_off
    target[3] += d_amp + a_amp
    target[4] += d_amp - a_amp
    target[5] += d_fm + a_fm
    target[6] += d_fm - a_fm
    target[7] += scale[6] * u[6]
    target[8] += scale[6] * u[6]
    target[10] += scale[7] * u[7]
    target[0] += scale[8] * u[8]


@njit(cache=True)
def reference(task, t, pos, rec):
    """The reference (heading rad, altitude m, speed m/s) of ``task`` at time ``t`` and position ``pos``;
    advances the waypoint counter ``rec[R_PASSED]`` when the current waypoint is within the pass radius,
    keeping the closest approach to each waypoint (while it is the one aimed at) in ``rec[R_WP + i]``. A moving
    target is aimed at where it is now, at the cruise speed or, when close, the target's speed plus the
    distance per second (at least 1 m/s); ``rec[R_PASSED]`` then counts the steps spent within the radius and
    ``rec[R_WP]``, ``rec[R_WP + 1]`` hold the closest and the current distance."""
    rows = int(task[T_ROWS])
    kind = int(task[T_KIND])
    if kind == TASK_LAND or kind == TASK_PERCH:
        # a landing (tasks.land): aim at the flower, lower and slower the closer; a perch holds where it is
        b = T_ROW0
        dx, dy, dh = to_flower(task, pos)
        aim_z = task[b + 2] + task[b + 3]
        dz = aim_z - pos[2]
        rec[R_WP] = min(rec[R_WP], math.sqrt(dh * dh + dz * dz))
        if kind == TASK_PERCH:
            return rec[R_AIM], pos[2], 0.0
        if dh > LAND_HOLD_M:
            rec[R_AIM] = math.atan2(dy, dx)
        return (rec[R_AIM], aim_z + min(LAND_ABOVE_M, LAND_GLIDE * dh) - task[b + 6],
                min(task[T_SPEED], task[b + 7] * dh))
    if kind == TASK_TARGET:
        # a moving target: on a circle (centre, radius; rate, phase) bobbing by the vertical amplitude
        b = T_ROW0
        w, ph, amp = task[b + 4], task[b + 5], task[b + 6]
        tx = task[b] + task[b + 3] * math.cos(w * t + ph)
        ty = task[b + 1] + task[b + 3] * math.sin(w * t + ph)
        tz = task[b + 2] + amp * math.sin(2.0 * w * t)
        dx, dy, dz = tx - pos[0], ty - pos[1], tz - pos[2]
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        rec[R_WP] = min(rec[R_WP], dist)
        rec[R_WP + 1] = dist  # the distance now
        if dist < task[T_RADIUS]:
            rec[R_PASSED] += 1.0  # steps spent within the radius
        v_target = abs(w) * task[b + 3]
        return math.atan2(dy, dx), tz, min(task[T_SPEED], max(1.0, v_target + dist))
    if kind == TASK_SCHEDULE:
        r = 0
        while r + 1 < rows and task[T_ROW0 + 4 * (r + 1)] <= t:
            r += 1
        b = T_ROW0 + 4 * r
        return task[b + 1], task[b + 2], task[b + 3]
    i = int(rec[R_PASSED])
    if i >= rows:
        i = rows - 1
    b = T_ROW0 + 4 * i
    dx, dy, dz = task[b] - pos[0], task[b + 1] - pos[1], task[b + 2] - pos[2]
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    if dist < rec[R_WP + i]:
        rec[R_WP + i] = dist
    if dist < task[T_RADIUS] and rec[R_PASSED] < rows:
        rec[R_PASSED] += 1.0
    return math.atan2(dy, dx), task[b + 2], task[T_SPEED]


@njit(cache=True)
def _mix(z):
    # splitmix64's finaliser: a 64-bit hash with full avalanche
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@njit(cache=True)
def uniform(seed, step, channel):
    """A number in ``(0, 1)`` that depends only on ``(seed, step, channel)`` (a counter-based generator: the
    same flight draws the same numbers in any thread, batch or order)."""
    z = _mix(np.uint64(seed) * np.uint64(0x9E3779B97F4A7C15) + np.uint64(step) * np.uint64(64) + np.uint64(channel))
    return (float(z >> np.uint64(11)) + 0.5) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def normal(seed, step, channel):
    """A standard normal number of ``(seed, step, channel)`` (Box-Muller on two :func:`uniform` numbers)."""
    u1 = uniform(seed, step, 2 * channel)
    u2 = uniform(seed, step, 2 * channel + 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)


@njit(cache=True)
def ou_step(x, sigma, tau, dt, n):
    """One step of an Ornstein-Uhlenbeck process (a first-order Gauss-Markov process, the Dryden gust
    model's simplest form): stationary standard deviation ``sigma``, correlation time ``tau`` (s), driven by
    the standard normal ``n``."""
    a = math.exp(-dt / tau)
    return a * x + sigma * math.sqrt(1.0 - a * a) * n


@njit(cache=True)
def reward(obs):
    """One step's reward in ``[0, 1]``: 0.1 for flying upright, and 0.3 more for each of the speed (within
    about 0.3 m/s), the altitude (0.2 m) and the heading (0.3 rad) held."""
    e_v, e_z, e_h = obs[6] / 0.3, obs[9] / 0.2, obs[2] / 0.3
    return 0.1 + 0.3 * (1.0 / (1.0 + e_v * e_v) + 1.0 / (1.0 + e_z * e_z) + 1.0 / (1.0 + e_h * e_h))


@njit(cache=True)
def to_flower(task, pos):
    """``(dx, dy, dh)``: from ``pos`` (m) to a landing task's flower axis, horizontally (m), and that distance."""
    dx, dy = task[T_ROW0] - pos[0], task[T_ROW0 + 1] - pos[1]
    return dx, dy, math.sqrt(dx * dx + dy * dy)


@njit(cache=True)
def lowest_foot(qpos, feet):
    """The height (m) of the lowest of the feet ``feet`` (``(4, 3)``, m, in the thorax's frame: the userdata's
    ``U_FEET``) of the body at ``qpos[0:7]``."""
    w, x, y, z = qpos[3], qpos[4], qpos[5], qpos[6]
    r0, r1, r2 = 2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)  # the frame's z row
    low = math.inf
    for k in range(4):
        low = min(low, r0 * feet[3 * k] + r1 * feet[3 * k + 1] + r2 * feet[3 * k + 2])
    return qpos[2] + low


@njit(cache=True)
def touched_down(task, qpos, feet):
    """Whether the butterfly landing on ``task`` (``TASK_LAND``) touches down now (:func:`~lifelike_mj.butterfly.
    flight3d.tasks.land`): its thorax within the task's radius of the flower's axis and its lowest foot
    (:func:`lowest_foot`) within ``TOUCH_MARGIN_M`` of the landing surface (above it, or through it by as much)."""
    surface = task[T_ROW0 + 2]
    foot = lowest_foot(qpos, feet)
    return to_flower(task, qpos)[2] < task[T_RADIUS] and surface - TOUCH_MARGIN_M < foot < surface + TOUCH_MARGIN_M


@njit(cache=True)
def flare(task, qpos):
    """A landing's flare (rad, nose up): from the task's flare distance out to the flower's axis the pitch the network
    is shown is lowered by up to the task's flare pitch (:func:`~lifelike_mj.butterfly.flight3d.tasks.land`), so that
    it holds its body that much more nose up and slows down, as a butterfly does before it lands."""
    return task[T_ROW0 + 4] * max(0.0, 1.0 - to_flower(task, qpos)[2] / task[T_ROW0 + 5])


@njit(cache=True)
def perch_command(base, target):
    """The kinematics of a perched butterfly (``target``, :class:`KinematicsCommand`'s order): the wings closed over
    the back (:data:`~lifelike_mj.butterfly.flight3d.tasks.PERCH_FLAP_RAD`), no stroke, no feathering, the abdomen
    held at ``base``'s mean; the flap frequency stays ``base``'s (the phase runs on, nothing moves with it)."""
    for i in range(N_PARAMS):
        target[i] = base[i]
    target[1] = PERCH_FLAP_RAD
    target[2] = PERCH_FLAP_RAD
    target[3] = 0.0
    target[4] = 0.0
    target[5] = 0.0
    target[6] = 0.0
    target[7] = 0.0
    target[8] = 0.0
    target[11] = 0.0


def take_off_kinematics(ud: np.ndarray, base: np.ndarray) -> None:
    """A perched butterfly's kinematics at take-off (its ``userdata`` ``ud``): the wings open to ``base``'s top of
    the stroke, from where the first downstroke starts (the parameters at ``base``, still; the flap phase at the next
    whole beat): the state every flight of an evolution starts from."""
    n = N_PARAMS
    ud[mj3d.U_P0 : mj3d.U_P0 + n] = base
    ud[mj3d.U_DP0 : mj3d.U_DP0 + n] = 0.0
    ud[mj3d.U_TARGET : mj3d.U_TARGET + n] = base
    ud[mj3d.U_PSI0] = 2.0 * math.pi * math.ceil(ud[mj3d.U_PSI0] / (2.0 * math.pi))


@njit(cache=True)
def _before(ud, qpos, qvel, time, dt, task, rec, obs, opts, ground, path, path_every, n_path, tumble_rad, base):
    """The first half of a step: the gusts advance, the air is set, the reference is taken and the observation made
    (into ``obs``), the path sampled. Returns ``(tumbled, n_path)``: a roll or pitch beyond ``tumble_rad`` ends the
    flight here (recorded in ``rec``). A landing keeps its speed at its closest approach (``R_NEAR_SPEED``); one that
    touches down now becomes a perch (recorded in ``rec``: the time and the speed), its kinematics
    :func:`perch_command` of ``base``."""
    step = int(rec[R_STEPS])
    seed = int(task[T_SEED])
    if task[T_GUST] > 0.0 or task[T_GUST_W] > 0.0:
        for i in range(3):
            sigma = task[T_GUST] if i < 2 else task[T_GUST_W]
            rec[R_GUST + i] = ou_step(rec[R_GUST + i], sigma, task[T_GUST_TAU], dt, normal(seed, step, i))
    for i in range(3):
        ud[mj3d.U_AIR + i] = task[T_WIND + i] + rec[R_GUST + i]
    closest = rec[R_WP]
    heading, altitude, speed = reference(task, time[0], qpos[0:3], rec)
    if int(task[T_KIND]) == TASK_LAND and rec[R_WP] < closest:
        rec[R_NEAR_SPEED] = math.sqrt(qvel[0] * qvel[0] + qvel[1] * qvel[1] + qvel[2] * qvel[2])
    if int(task[T_KIND]) == TASK_LAND and touched_down(task, qpos, ud[mj3d.U_FEET : mj3d.U_FEET + 12]):
        task[T_KIND] = TASK_PERCH
        rec[R_LANDED_AT] = time[0]
        rec[R_TOUCH_SPEED] = math.sqrt(qvel[0] * qvel[0] + qvel[1] * qvel[1] + qvel[2] * qvel[2])
        perch_command(base, ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS])
    pitch_ref = 0.0
    if int(task[T_KIND]) == TASK_LAND:
        pitch_ref = flare(task, qpos)
    kind = int(task[T_KIND])
    if opts[1] > 0.0 and (kind == TASK_SCHEDULE or kind == TASK_WAYPOINTS):
        along = math.cos(heading) * qvel[0] + math.sin(heading) * qvel[1]
        rec[R_BOOST] = max(0.0, min(opts[2], rec[R_BOOST] + opts[1] * (speed - along) * dt))
    observe(qpos, qvel, heading, altitude, speed, ud[mj3d.U_AIR : mj3d.U_AIR + 3] if opts[0] != 0.0 else ground, obs,
            pitch_ref)
    obs[10] += rec[R_BOOST]
    if path_every > 0 and step % path_every == 0 and n_path < path.shape[0]:
        path[n_path, 0] = time[0]
        for i in range(3):
            path[n_path, 1 + i] = qpos[i]
        r_, p_, y_ = attitude(qpos[3:7])
        path[n_path, 4] = r_
        path[n_path, 5] = p_
        path[n_path, 6] = y_
        n_path += 1
    if abs(obs[0]) > tumble_rad or abs(obs[1]) > tumble_rad:
        rec[R_TUMBLED] = step
        return True, n_path
    return False, n_path


@njit(cache=True)
def _act(u, dt, every, base, scale, task, rec, ud, t):
    """The action ``u`` (changed in place by the flutter, if the task has any) becomes the kinematics' new target; until
    ``rec[R_CLAP_UNTIL]`` (a take-off, at time ``t`` now) each wing's amplitude puts the top of its stroke at
    ``CLAP_TOP_RAD``, about the offset asked: the wings clap, with a larger stroke."""
    step = int(rec[R_STEPS])
    if task[T_FLUTTER] > 0.0:
        seed = int(task[T_SEED])
        for i in range(N_ACT):
            rec[R_FLUTTER + i] = ou_step(rec[R_FLUTTER + i], task[T_FLUTTER], task[T_FLUTTER_TAU], dt * every,
                                         normal(seed, step, 3 + i))
            u[i] = max(-1.0, min(1.0, u[i] + rec[R_FLUTTER + i]))
    command(base, scale, u, ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS])
    if t < rec[R_CLAP_UNTIL]:
        ud[mj3d.U_TARGET + 3] = CLAP_TOP_RAD - ud[mj3d.U_TARGET + 1]
        ud[mj3d.U_TARGET + 4] = CLAP_TOP_RAD - ud[mj3d.U_TARGET + 2]


@njit(cache=True)
def grip(dptr, off, ud, task):
    """The legs hold on while the butterfly is perched, and let go when it takes off: the grip actuator of
    :func:`~lifelike_mj.butterfly.flight3d.model.add_legs` (its index + 1 in ``ud[U_GRIP]``, 0 without one) gets
    control 1 on a perch (``TASK_PERCH``), else 0."""
    a = int(ud[mj3d.U_GRIP]) - 1
    if a >= 0:
        ctrl = _f64(_ptr_at(dptr + off[_O_CTRL]), a + 1)
        ctrl[a] = 1.0 if int(task[T_KIND]) == TASK_PERCH else 0.0


@njit(cache=True)
def _after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
    """The second half of a step: the legs' grip set (:func:`grip`), one ``mj_step``, the kinematics advanced
    exactly, the reward of the observation ``obs`` added (none while perched). Returns ``False`` if the flight
    diverged (recorded in ``rec``)."""
    step = int(rec[R_STEPS])
    grip(dptr, off, ud, task)
    ud[mj3d.U_T0] = time[0]
    t0 = time[0]
    _mj_step(_vp(mptr), _vp(dptr))
    ud[mj3d.U_PSI0] = filter_at(ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS], ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS],
                                ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS], ud[mj3d.U_PSI0], ud[mj3d.U_OMEGA_C], dt,
                                p, dp, ddp)
    for i in range(N_PARAMS):
        ud[mj3d.U_P0 + i] = p[i]
        ud[mj3d.U_DP0 + i] = dp[i]
    rec[R_STEPS] = step + 1
    if abs(time[0] - (t0 + dt)) > 0.5 * dt or not (abs(qvel[0]) + abs(qvel[1]) + abs(qvel[2]) < 1e3):
        rec[R_DIVERGED] = step + 1
        return False
    if int(task[T_KIND]) == TASK_PERCH:
        return True
    rec[R_FIT] += reward(obs) * dt
    if t0 >= STYLE_FROM_S:
        style(ud, qpos, qvel, obs, p, dt, rec)
    return True


@njit(cache=True)
def style(ud, qpos, qvel, obs, p, dt, rec):
    """Add this step's share of the style integrals (:data:`~lifelike_mj.butterfly.flight3d.tasks.STYLE_NAMES`) to
    the record (after the flight's first :data:`~lifelike_mj.butterfly.flight3d.tasks.STYLE_FROM_S`): they do not
    enter the reward, only the naturalness an evolution may ask for."""
    rec[R_STYLE] += obs[0] * dt
    rec[R_STYLE + 1] += obs[1] * dt
    rec[R_STYLE + 2] += abs(p[3] - p[4]) * dt
    rec[R_STYLE + 3] += abs(p[1] - p[2]) * dt
    # the top of the stroke as flown: the higher wing's largest flap angle in each beat, added up beat by beat
    flap = max(qpos[int(ud[mj3d.U_DRIVEN_Q])], qpos[int(ud[mj3d.U_DRIVEN_Q + 1])])
    beat = math.floor(ud[mj3d.U_PSI0] / (2.0 * math.pi))
    if rec[R_STYLE + 9] == 0.0:  # the first step counted: this beat is under way
        rec[R_STYLE + 10] = beat
        rec[R_STYLE + 8] = flap
    elif beat != rec[R_STYLE + 10]:
        rec[R_STYLE + 4] += rec[R_STYLE + 8]
        rec[R_STYLE + 11] += 1.0
        rec[R_STYLE + 10] = beat
        rec[R_STYLE + 8] = flap
    else:
        rec[R_STYLE + 8] = max(rec[R_STYLE + 8], flap)
    rec[R_STYLE + 9] = 1.0
    work = 0.0
    for j in range(5):
        pw = ud[mj3d.U_OUT + mj3d.O_DRIVE + j] * qvel[int(ud[mj3d.U_DRIVEN_D + j])]
        if pw > 0.0:
            work += pw
    rec[R_STYLE + 5] += work * dt
    rec[R_STYLE + 6] += (p[3] + p[4]) * p[0] * dt
    rec[R_STYLE + 7] += dt


@njit(cache=True)
def fly_steps(mptr, dptr, off, nq, nv, n_steps, dt, every, layers, weights, reach, base, scale, task, rec, path,
              path_every, tumble_rad, opts):
    """Fly one butterfly ``n_steps`` steps from its current state: every ``every`` steps the network turns
    the observation into a new command; after each ``mj_step`` the kinematics advance exactly in the
    userdata. ``rec``: the run record (``R_*``); ``path``: rows of (t, x, y, z, roll, pitch, yaw) every
    ``path_every`` steps (none when 0). A roll or pitch beyond ``tumble_rad`` (a tumble) or a runaway
    ends the flight (recorded in ``rec``). ``weights``: the flight network's, then the behaviours' (the controller's
    ``all_weights``), each network picked by :func:`behaviour` with ``reach``. Without weights the command in the
    userdata stays. ``opts`` (the controller's :meth:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D.
    loop_options`): whether the network's speeds are through the air (``inputs == "air"``; else over the ground),
    and the gain (1/s) and bound (m/s) of the speed boost (the run record's ``R_BOOST``: the speed asked that an
    eleven-input network sees rises while the ground speed toward the heading asked falls short, as a butterfly flies
    faster through the air in a head wind)."""
    ud = _f64(_ptr_at(dptr + off[_O_UD]), mj3d.N_USERDATA)
    qpos = _f64(_ptr_at(dptr + off[_O_QPOS]), nq)
    qvel = _f64(_ptr_at(dptr + off[_O_QVEL]), nv)
    time = _f64(dptr + off[_O_TIME], 1)
    obs = np.empty(N_OBS)
    u = np.zeros(N_ACT)
    width = 0
    for k in range(len(layers)):
        width = max(width, layers[k])
    scratch = np.empty(2 * width)
    n_w = 0
    for k in range(1, len(layers)):
        n_w += (layers[k - 1] + 1) * layers[k]
    p = np.empty(N_PARAMS)
    dp = np.empty(N_PARAMS)
    ddp = np.empty(N_PARAMS)
    ground = np.zeros(3)
    n_path = 0
    for _ in range(n_steps):
        if rec[R_DIVERGED] >= 0 or rec[R_TUMBLED] >= 0:
            return
        tumbled, n_path = _before(ud, qpos, qvel, time, dt, task, rec, obs, opts, ground, path, path_every,
                                  n_path, tumble_rad, base)
        if tumbled:
            return
        if int(rec[R_STEPS]) % every == 0 and len(weights) > 0 and int(task[T_KIND]) != TASK_PERCH:
            k = behaviour(task, qpos, time[0], rec, reach)
            network(layers, weights[k * n_w : (k + 1) * n_w], obs, u, scratch)
            _act(u, dt, every, base, scale, task, rec, ud, time[0])
        if not _after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return


@njit(cache=True)
def to_decision(mptr, dptr, off, nq, nv, n_max, dt, every, action, act, base, scale, task, rec, obs, tumble_rad,
                opts):
    """Fly one butterfly to its next decision with an action from outside (a policy, not the network): with
    ``act``, the action ``action`` (``(N_ACT,)``, in ``[-1, 1]``, the flutter added as for a network's) is taken at
    the current step, whose observation is ``obs``; then the steps go on, as :func:`fly_steps` flies them, until the
    next step at which the network would run (``every``), the flight ends (a tumble, a runaway) or ``n_max`` steps
    have been flown. ``obs`` then holds that step's observation. Without ``act``: the current step's observation
    only (at the start). Returns whether the flight goes on."""
    ud = _f64(_ptr_at(dptr + off[_O_UD]), mj3d.N_USERDATA)
    qpos = _f64(_ptr_at(dptr + off[_O_QPOS]), nq)
    qvel = _f64(_ptr_at(dptr + off[_O_QVEL]), nv)
    time = _f64(dptr + off[_O_TIME], 1)
    p = np.empty(N_PARAMS)
    dp = np.empty(N_PARAMS)
    ddp = np.empty(N_PARAMS)
    ground = np.zeros(3)
    none = np.empty((0, 7))
    if rec[R_DIVERGED] >= 0 or rec[R_TUMBLED] >= 0:
        return False
    if act:
        if int(task[T_KIND]) != TASK_PERCH:
            u = action.copy()
            _act(u, dt, every, base, scale, task, rec, ud, time[0])
        if not _after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return False
    while True:
        tumbled, _ = _before(ud, qpos, qvel, time, dt, task, rec, obs, opts, ground, none, 0, 0, tumble_rad,
                             base)
        if tumbled:
            return False
        step = int(rec[R_STEPS])
        if step >= n_max or step % every == 0:
            return True
        if not _after(mptr, dptr, off, ud, qpos, qvel, time, dt, rec, obs, p, dp, ddp, task):
            return False


@njit(cache=True, parallel=True)
def to_decisions(mptr, dptrs, off, nq, nv, n_max, dt, every, actions, act, base, scale, tasks, recs, obs, tumble_rad,
                 opts, going):
    """:func:`to_decision` for many butterflies at once, one action row each (threads over the copies); copies with
    ``act[i]`` false only observe. ``going[i]``: whether copy ``i`` goes on."""
    for i in prange(len(dptrs)):
        going[i] = to_decision(mptr, dptrs[i], off, nq, nv, n_max, dt, every, actions[i], act[i], base, scale,
                               tasks[i], recs[i], obs[i], tumble_rad, opts)


@njit(cache=True, parallel=True)
def fly_batch(mptr, dptrs, off, nq, nv, n_steps, dt, every, layers, weights, reach, base, scale, tasks, recs, tumble_rad,
              opts):
    """:func:`fly_steps` for many butterflies at once (one ``mjData`` each, ``weights[i]`` and
    ``tasks[i]`` per copy), threads over the copies; no paths are recorded."""
    none = np.empty((0, 7))
    for i in prange(len(dptrs)):
        fly_steps(mptr, dptrs[i], off, nq, nv, n_steps, dt, every, layers, weights[i], reach, base, scale, tasks[i],
                  recs[i], none, 0, tumble_rad, opts)




#: About how long the first run's compilation of the 3D flight's kernels takes (s): the air's callback and one
#: flight loop, 15-20 s measured on 2 busy cores with an empty cache (the callback 7 s, the loop 8 s, more under
#: load); said once, when the cache does not hold them yet (:func:`~lifelike_mj._numba_cache.compile_notice`).
COMPILE_S = 20.0

class Batch:
    """The one owner of the compiled loop's state: one MuJoCo model and, per butterfly, its ``mjData``, its task
    array and run record (:mod:`~lifelike_mj.butterfly.flight3d.tasks`), and its network weights; the network's
    shape, base command and scales are shared. A flight is a batch of one, a garden a batch of ``n``, an
    evolution's generation a batch of candidates x tasks. :meth:`advance` flies them all in one native call.

    ``controller``: a :class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D`, or ``None`` for flights
    that keep the command in their userdata (then ``base`` is that command's array); ``weights``: one row per
    butterfly, laid out as the controller's ``all_weights`` (default: the controller's own, for each);
    ``tumble_rad``: a roll or pitch beyond which a flight ends (``inf``: never)."""

    def __init__(self, model, datas, tasks: np.ndarray, controller=None, *, weights=None, dt_s: float,
                 records: np.ndarray, tumble_rad: float = math.inf, base: np.ndarray | None = None,
                 designed=None) -> None:
        self.model, self.datas = model, list(datas)
        self.n = len(self.datas)
        self.tasks = np.ascontiguousarray(tasks, dtype=np.float64).reshape(self.n, -1)
        self.records = records
        self.dt, self.tumble_rad = float(dt_s), float(tumble_rad)
        self.ptrs = np.array([d._address for d in self.datas], dtype=np.int64)
        #: Each butterfly's observation at its last decision (:meth:`decide`; ``OBS_NAMES``, SI units).
        self.observations = np.zeros((self.n, N_OBS))
        if controller is None:
            self.layers, self.scale, self.every, self.opts = np.zeros(1, dtype=np.int64), np.zeros(N_ACT), 1, np.zeros(3)
            self.weights, self.reach = np.zeros((self.n, 0)), np.zeros(2)
            self.base = np.asarray(base, dtype=np.float64)
        else:
            self.layers, self.scale = controller.layers, controller.scale
            self.every, self.opts = controller.every, controller.loop_options()
            self.base = controller.base.as_array() if base is None else np.asarray(base, dtype=np.float64)
            own = controller.all_weights()
            w = own if weights is None else weights
            self.weights = np.ascontiguousarray(np.broadcast_to(w, (self.n, len(own))), dtype=np.float64)
            self.reach = controller.mode_reach()
        #: A designed controller flown in the loop (``designed_kernel.CompiledDesigned``), with each flight's state.
        self.designed = designed
        #: A residual policy's reach per control on the designed controller (:meth:`decide`; ``None``: the module's
        #: :data:`~lifelike_mj.butterfly.flight3d.designed.RESIDUAL_SCALE`).
        self.residual_scale: np.ndarray | None = None
        if designed is not None:
            self.every = designed.every
            self.designed_states = designed.states(self.n)
            #: Each flight's designed command at its last decision (:meth:`decide`; kinematics parameters).
            self.baselines = np.zeros((self.n, N_PARAMS))

    def advance(self, n_steps: int, path: np.ndarray | None = None, path_every: int = 0) -> None:
        """Fly every butterfly ``n_steps`` steps (threads over the butterflies), with the model's compiled air
        forces installed. ``path`` (a batch of one only): rows of (t, x, y, z, roll, pitch, yaw) every
        ``path_every`` steps. A flight that has ended (diverged, tumbled) stays where it ended."""
        from lifelike_mj._numba_cache import compile_notice
        from lifelike_mj.physics.callbacks import passive_callback
        from lifelike_mj.physics.stability import watching

        m = self.model
        group = "flight3d-steps" if self.n == 1 else "flight3d-batch"
        if self.designed is not None:
            group = "flight3d-designed" if self.n == 1 else "flight3d-designed-batch"
        with compile_notice(group, "the 3D flight", COMPILE_S), passive_callback(mj3d.COMPILED_PASSIVE), watching():
            if self.designed is not None:  # its own loop (designed_kernel.fly_designed), given this batch's state
                self.designed.advance(self, n_steps, _NO_PATH if path is None else path, path_every)
            elif self.n == 1:
                fly_steps(m._address, int(self.ptrs[0]), mjabi.offsets_tuple(), m.nq, m.nv, n_steps, self.dt,
                          self.every, self.layers, self.weights[0], self.reach, self.base, self.scale, self.tasks[0],
                          self.records[0], _NO_PATH if path is None else path, path_every, self.tumble_rad,
                          self.opts)
            else:
                fly_batch(m._address, self.ptrs, mjabi.offsets_tuple(), m.nq, m.nv, n_steps, self.dt, self.every,
                          self.layers, self.weights, self.reach, self.base, self.scale, self.tasks, self.records,
                          self.tumble_rad, self.opts)

    def decide(self, actions: np.ndarray | None, n_max: int, act: np.ndarray | None = None) -> np.ndarray:
        """Fly every butterfly to its next decision (:func:`to_decision`) with ``actions`` (one row of ``N_ACT``
        numbers in ``[-1, 1]`` per butterfly, from outside, taken now) or, with ``None``, only observe the current
        step; ``act`` (a mask): which butterflies act (the others only observe). The observations are then in
        :attr:`observations`; returns whether each flight goes on. With a designed controller the actions are a
        residual policy's, added to its command at each of its control steps
        (:meth:`~lifelike_mj.butterfly.flight3d.designed_kernel.CompiledDesigned.decide`; the commands in
        :attr:`baselines`)."""
        from lifelike_mj.physics.callbacks import passive_callback
        from lifelike_mj.physics.stability import watching

        m = self.model
        act = np.full(self.n, actions is not None) if act is None else np.asarray(act, dtype=np.bool_) & (
            actions is not None)
        a = np.zeros((self.n, N_ACT)) if actions is None else np.ascontiguousarray(actions, dtype=np.float64)
        if self.designed is not None:  # a residual policy on the designed controller (designed_kernel.decide_designed)
            from lifelike_mj._numba_cache import compile_notice

            group = "flight3d-designed-decide" if self.n == 1 else "flight3d-designed-decisions"
            with compile_notice(group, "the 3D flight", COMPILE_S), passive_callback(mj3d.COMPILED_PASSIVE), \
                    watching():
                return self.designed.decide(self, a, n_max, act)
        going = np.zeros(self.n, dtype=np.bool_)
        from lifelike_mj._numba_cache import compile_notice

        group = "flight3d-decide" if self.n == 1 else "flight3d-decisions"
        with compile_notice(group, "the 3D flight", COMPILE_S), passive_callback(mj3d.COMPILED_PASSIVE), watching():
            if self.n == 1:
                going[0] = to_decision(m._address, int(self.ptrs[0]), mjabi.offsets_tuple(), m.nq, m.nv, int(n_max),
                                       self.dt, self.every, a[0], bool(act[0]), self.base, self.scale, self.tasks[0],
                                       self.records[0], self.observations[0], self.tumble_rad, self.opts)
            else:
                to_decisions(m._address, self.ptrs, mjabi.offsets_tuple(), m.nq, m.nv, int(n_max), self.dt, self.every,
                             a, act, self.base, self.scale, self.tasks, self.records, self.observations,
                             self.tumble_rad, self.opts, going)
        return going

    def diverged(self) -> np.ndarray:
        """Indices of the butterflies whose flight diverged."""
        return np.nonzero(self.records[:, R_DIVERGED] >= 0)[0]


_NO_PATH = np.empty((0, 7))
