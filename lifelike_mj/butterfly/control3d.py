"""Steering the 3D butterfly by its kinematics: observations, networks, guidance and the compiled loop.

A 3D controller sees the body's attitude and motion relative to a **reference** (a heading, an altitude
and a forward speed) and answers with changes of the kinematics around a **base command**
(:class:`~lifelike_mj.butterfly.kinematics3d.KinematicsCommand`). The reference comes from a **task**:
a schedule of references over time (level flight, turns) or a course of waypoints (the reference then
points at the next waypoint). The network never sees where it is, only how far it is off.

Observation (:data:`OBS_NAMES`; SI units, in the heading frame: forward, left, up):
roll, pitch, heading error (reference less yaw, wrapped to ``(-pi, pi]``), the thorax's angular
velocity (roll, pitch, yaw rates in its own axes), forward-speed error, sideways speed, climb rate and
altitude error (clipped to +-1 m). A controller's ``inputs`` say what the forward and sideways speeds are
measured against: ``"ground"`` (the shipped ``steer`` and ``cruise``) or ``"air"`` (the air around the
butterfly, wind and gusts included, as a butterfly's antennae sense it; the speed reference is then an air
speed). The climb rate and the altitude are always the ground's.

Action (:data:`ACTION_NAMES`): nine numbers ``u`` in ``(-1, 1)`` (the network's last layer through
``tanh``), each scaled by its entry of ``scale`` (rad; Hz for the frequency) and added to the base
command: the wings' stroke offset and amplitude, both wings alike (``sym``) and left against right
(``asym``), the feathering mean (``sym``, ``asym``), the feathering amplitude, the abdomen's mean angle
and the flap frequency. The kinematics follow each
new command smoothly (the filter of :mod:`~lifelike_mj.butterfly.kinematics3d`).

Networks: ``layers = [10, ..., 9]``, hidden neurons ``tanh``; ``[10, 9]`` is a linear policy.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly.backends import mj3d
from lifelike_mj.butterfly.kinematics3d import N_PARAMS, filter_at
from lifelike_mj.physics import mjabi

OBS_NAMES = ("roll_rad", "pitch_rad", "heading_error_rad", "roll_rate_rad_s", "pitch_rate_rad_s",
             "yaw_rate_rad_s", "speed_error_m_s", "sideways_m_s", "climb_m_s", "altitude_error_m")
ACTION_NAMES = ("offset_sym", "offset_asym", "amplitude_sym", "amplitude_asym", "feather_sym", "feather_asym",
                "feather_amplitude", "abdomen_mean", "frequency")
N_OBS, N_ACT = len(OBS_NAMES), len(ACTION_NAMES)
#: Altitude errors beyond this (m) are seen as this.
ALTITUDE_CLIP_M = 1.0
#: What the network's inputs are divided by (the observation's units): angles by 1 rad, rates by 10 rad/s,
#: speeds by 1 m/s, the altitude error by 0.5 m, so that every input is of order one in flight.
INPUT_SCALE = np.array([1.0, 1.0, 1.0, 10.0, 10.0, 10.0, 1.0, 1.0, 1.0, 0.5])

# task array: kind, then either a schedule (rows of t_start, heading, altitude, speed) or waypoints
TASK_SCHEDULE, TASK_WAYPOINTS, TASK_TARGET = 0, 1, 2
#: Task header: kind, rows, pass radius (m), cruise speed (m/s), mean wind (3, m/s), gusts' standard deviation
#: (m/s, horizontal) and correlation time (s), flutter's standard deviation (action units) and correlation time
#: (s), the seed of both, the vertical gusts' standard deviation (m/s); then 4 numbers per row.
T_KIND, T_ROWS, T_RADIUS, T_SPEED, T_WIND = 0, 1, 2, 3, 4
T_GUST, T_GUST_TAU, T_FLUTTER, T_FLUTTER_TAU, T_SEED, T_GUST_W, T_ROW0 = 7, 8, 9, 10, 11, 12, 13

# per-copy run record (float64): fitness, steps flown, diverged step, waypoints passed, tumble step, the gust
# (3, m/s) and the flutter (one per action) now, then the closest approach to each waypoint
R_FIT, R_STEPS, R_DIVERGED, R_PASSED, R_TUMBLED, R_GUST, R_FLUTTER = 0, 1, 2, 3, 4, 5, 8
R_WP = R_FLUTTER + 9
#: A roll or pitch beyond this (rad) is a tumble: the flight ends there (no more reward).
TUMBLE_RAD = math.radians(80.0)

_O_TIME, _O_QPOS, _O_QVEL, _O_UD = mjabi.O_TIME, mjabi.O_QPOS, mjabi.O_QVEL, mjabi.O_UD
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
    """Roll, pitch (nose up > 0), yaw of the quaternion ``q`` (w, x, y, z) (as :func:`sim3d.euler_from_quat`)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    s = 2.0 * (w * y - z * x)
    s = max(-1.0, min(1.0, s))
    pitch = -math.asin(s)
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


@njit(cache=True)
def observe(qpos, qvel, heading, altitude, speed, air, obs):
    """The observation (module docstring) of the free body whose root is at ``qpos[0:7]``, ``qvel[0:6]``,
    against the reference ``heading`` (rad), ``altitude`` (m) and forward ``speed`` (m/s). The forward and
    sideways speeds are taken relative to the horizontal velocity ``air[0:2]`` (m/s): zeros for speeds over
    the ground, the wind for speeds through the air."""
    roll, pitch, yaw = attitude(qpos[3:7])
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


def n_weights(layers) -> int:
    """How many weights a network of ``layers`` has (biases included)."""
    return int(sum((layers[k - 1] + 1) * layers[k] for k in range(1, len(layers))))


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
    if int(task[T_KIND]) == TASK_TARGET:
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
    if int(task[T_KIND]) == TASK_SCHEDULE:
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
def fly_steps(mptr, dptr, off, nq, nv, n_steps, dt, every, layers, weights, base, scale, task, rec, path, path_every,
              tumble_rad, air_inputs):
    """Fly one butterfly ``n_steps`` steps from its current state: every ``every`` steps the network turns
    the observation into a new command; after each ``mj_step`` the kinematics advance exactly in the
    userdata. ``rec``: the run record (``R_*``); ``path``: rows of (t, x, y, z, roll, pitch, yaw) every
    ``path_every`` steps (none when 0). A roll or pitch beyond ``tumble_rad`` (a tumble) or a runaway
    ends the flight (recorded in ``rec``). Without weights the command in the userdata stays. ``air_inputs``:
    the network's speeds are through the air (the controller's ``inputs == "air"``), else over the ground."""
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
    p = np.empty(N_PARAMS)
    dp = np.empty(N_PARAMS)
    ddp = np.empty(N_PARAMS)
    w_c = ud[mj3d.U_OMEGA_C]
    ground = np.zeros(3)
    n_path = 0
    for _ in range(n_steps):
        if rec[R_DIVERGED] >= 0 or rec[R_TUMBLED] >= 0:
            return
        step = int(rec[R_STEPS])
        seed = int(task[T_SEED])
        if task[T_GUST] > 0.0 or task[T_GUST_W] > 0.0:
            for i in range(3):
                sigma = task[T_GUST] if i < 2 else task[T_GUST_W]
                rec[R_GUST + i] = ou_step(rec[R_GUST + i], sigma, task[T_GUST_TAU], dt, normal(seed, step, i))
        for i in range(3):
            ud[mj3d.U_AIR + i] = task[T_WIND + i] + rec[R_GUST + i]
        heading, altitude, speed = reference(task, time[0], qpos[0:3], rec)
        observe(qpos, qvel, heading, altitude, speed, ud[mj3d.U_AIR : mj3d.U_AIR + 3] if air_inputs else ground, obs)
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
            return
        if step % every == 0 and len(weights) > 0:
            network(layers, weights, obs, u, scratch)
            if task[T_FLUTTER] > 0.0:
                for i in range(N_ACT):
                    rec[R_FLUTTER + i] = ou_step(rec[R_FLUTTER + i], task[T_FLUTTER], task[T_FLUTTER_TAU], dt * every,
                                                 normal(seed, step, 3 + i))
                    u[i] = max(-1.0, min(1.0, u[i] + rec[R_FLUTTER + i]))
            command(base, scale, u, ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS])
        ud[mj3d.U_T0] = time[0]
        t0 = time[0]
        _mj_step(_vp(mptr), _vp(dptr))
        ud[mj3d.U_PSI0] = filter_at(ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS], ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS],
                                    ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS], ud[mj3d.U_PSI0], w_c, dt, p, dp, ddp)
        for i in range(N_PARAMS):
            ud[mj3d.U_P0 + i] = p[i]
            ud[mj3d.U_DP0 + i] = dp[i]
        rec[R_STEPS] = step + 1
        if abs(time[0] - (t0 + dt)) > 0.5 * dt or not (abs(qvel[0]) + abs(qvel[1]) + abs(qvel[2]) < 1e3):
            rec[R_DIVERGED] = step + 1
            return
        rec[R_FIT] += reward(obs) * dt


@njit(cache=True, parallel=True)
def fly_batch(mptr, dptrs, off, nq, nv, n_steps, dt, every, layers, weights, base, scale, tasks, recs, tumble_rad,
              air_inputs):
    """:func:`fly_steps` for many butterflies at once (one ``mjData`` each, ``weights[i]`` and
    ``tasks[i]`` per copy), threads over the copies; no paths are recorded."""
    none = np.empty((0, 7))
    for i in prange(len(dptrs)):
        fly_steps(mptr, dptrs[i], off, nq, nv, n_steps, dt, every, layers, weights[i], base, scale, tasks[i], recs[i],
                  none, 0, tumble_rad, air_inputs)


# ---- controller files ------------------------------------------------------------------------

FORMAT = "lifelike-mj/butterfly3d-controller"
#: Bounds of a 3D controller (files and Python alike; every one of these numbers reaches the compiled loop):
#: at most this many layers (inputs and outputs included), neurons per hidden layer, size of a weight, steps
#: between two runs of the network, and rate at which the kinematics follow a command (rad/s).
MAX_LAYERS, MAX_WIDTH, MAX_WEIGHT, MAX_EVERY, MAX_OMEGA_C = 6, 256, 1.0e6, 12_000, 1.0e4
#: What a controller's forward and sideways speeds are measured against (module docstring).
INPUTS = ("ground", "air")
#: Default ``scale`` of the actions (rad; Hz for the frequency).
DEFAULT_SCALE = {"offset_sym": 0.3, "offset_asym": 0.3, "amplitude_sym": 0.3, "amplitude_asym": 0.3, "feather_sym": 0.5,
                 "feather_asym": 0.3, "feather_amplitude": 0.3, "abdomen_mean": 0.8, "frequency": 3.0}


def default_base():
    """The base command of the shipped 3D controllers: the paper's 10 Hz flap over [-60, 75] deg (Oe 2010
    section 6), feathered by 0.3 rad a quarter beat ahead (leading edge down on the downstroke)."""
    from lifelike_mj.butterfly.kinematics3d import KinematicsCommand

    return KinematicsCommand(feather_amplitude_left=0.3, feather_amplitude_right=0.3, feather_phase=-math.pi / 2)


class Controller3D:
    """A 3D controller: a network from the observation to the action (module docstring), the base command
    and the actions' scales, how often it runs (``every`` steps), how fast the kinematics follow
    (``omega_c_rad_s``) and what its speeds are measured against (``inputs``: ``"ground"`` or ``"air"``), with
    its provenance. Plain data: :meth:`to_dict` / :func:`controller_from_dict`."""

    def __init__(self, layers, weights, base=None, scale: dict | None = None, every: int = 1,
                 omega_c_rad_s: float = 2.0 * math.pi * 10.0, provenance: dict | None = None, name: str = "",
                 inputs: str = "ground") -> None:
        from lifelike_mj import checks
        from lifelike_mj.butterfly.kinematics3d import KinematicsCommand
        from lifelike_mj.errors import UserError

        self.name = name
        where = f"3D controller {name}" if name else "3D controller"
        try:
            given = list(layers)
        except TypeError:
            given = None
        ok = (given is not None and 2 <= len(given) <= MAX_LAYERS and all(checks.is_whole(v) for v in given)
              and given[0] == N_OBS and given[-1] == N_ACT and all(1 <= v <= MAX_WIDTH for v in given))
        if not ok:
            raise UserError(f"{where}: layers must be whole numbers running from {N_OBS} inputs to {N_ACT} outputs, "
                            f"at most {MAX_LAYERS} layers of at most {MAX_WIDTH} neurons, got {layers!r}.")
        layers = [int(v) for v in given]
        self.layers = np.array(layers, dtype=np.int64)
        try:
            self.weights = np.ascontiguousarray(weights, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError):
            raise UserError(f"{where}: the weights must be numbers, got {weights!r}.") from None
        if len(self.weights) != n_weights(layers) or not np.all(np.abs(self.weights) <= MAX_WEIGHT):
            raise UserError(f"{where}: layers {layers} need {n_weights(layers)} finite weights, each within "
                            f"+-{MAX_WEIGHT:g}, got {len(self.weights)}"
                            + ("" if len(self.weights) != n_weights(layers) else " with one beyond") + ".")
        self.base = base if base is not None else default_base()
        if not isinstance(self.base, KinematicsCommand):
            raise UserError(f"{where}: the base is a KinematicsCommand, got {self.base!r}.")
        if scale is not None and not isinstance(scale, dict):
            raise UserError(f"{where}: scale is a mapping of action names to numbers, got {scale!r}.")
        scale = dict(DEFAULT_SCALE, **(scale or {}))
        unknown = set(scale) - set(ACTION_NAMES)
        if unknown:
            from lifelike_mj.errors import unknown_name

            raise unknown_name(f"{where}: unknown action", sorted(unknown, key=str)[0], ACTION_NAMES, "in scale")
        self.scale = np.array([checks.number(f"scale of {a}", scale[a], 0.0, math.pi) for a in ACTION_NAMES])
        self.every = checks.whole("every", every, 1, MAX_EVERY)
        self.omega_c_rad_s = checks.number("omega_c_rad_s", omega_c_rad_s, 0.0, MAX_OMEGA_C, lo_open=True, unit="rad/s")
        if inputs not in INPUTS:
            raise UserError(f"{where}: inputs are {' or '.join(repr(v) for v in INPUTS)}, got {inputs!r}.")
        self.inputs = inputs
        self.provenance = dict(provenance or {})

    def to_dict(self) -> dict:
        from dataclasses import asdict

        return {"format": FORMAT, "version": 1, "layers": [int(v) for v in self.layers],
                "weights": [float(v) for v in self.weights], "base": asdict(self.base),
                "scale": dict(zip(ACTION_NAMES, (float(v) for v in self.scale))), "every": self.every,
                "omega_c_rad_s": self.omega_c_rad_s, "inputs": self.inputs, "provenance": self.provenance}

    @property
    def air_inputs(self) -> bool:
        """Whether the network's speeds are through the air (the compiled loop's flag)."""
        return self.inputs == "air"

    def with_weights(self, weights, inputs: str | None = None) -> Controller3D:
        """The same controller with other weights (and, given ``inputs``, other inputs)."""
        return Controller3D(self.layers, weights, self.base, dict(zip(ACTION_NAMES, self.scale)), self.every,
                            self.omega_c_rad_s, self.provenance, self.name, inputs or self.inputs)


def json_schema() -> dict:
    """The JSON Schema of a 3D controller file (``docs/schemas/butterfly3d-controller.schema.json``): what
    :func:`controller_from_dict` enforces before building the controller."""
    from lifelike_mj.butterfly.kinematics3d import KinematicsCommand
    from lifelike_mj.schema import document_schema, number

    max_weights = n_weights([N_OBS, *[MAX_WIDTH] * (MAX_LAYERS - 2), N_ACT])
    props = {
        "layers": {"type": "array", "minItems": 2, "maxItems": MAX_LAYERS,
                   "items": {"type": "integer", "minimum": 1, "maximum": MAX_WIDTH},
                   "description": f"neurons per layer, from the {N_OBS} observations to the {N_ACT} actions"},
        "weights": {"type": "array", "maxItems": max_weights, "items": number("", -MAX_WEIGHT, MAX_WEIGHT),
                    "description": "per layer, per neuron: its input weights, then its bias"},
        "base": KinematicsCommand.json_schema(),
        "scale": {"type": "object", "additionalProperties": False, "description": "each action's full scale (rad; Hz "
                  "for the frequency); missing ones take the defaults",
                  "properties": {a: number("rad (Hz for frequency)", 0.0, math.pi) for a in ACTION_NAMES}},
        "every": {"type": "integer", "minimum": 1, "maximum": MAX_EVERY, "description": "time steps between two runs "
                  "of the network"},
        "omega_c_rad_s": number("rad/s: how fast the kinematics follow a command", maximum=MAX_OMEGA_C,
                                exclusive_minimum=0.0),
        "inputs": {"enum": list(INPUTS), "description": "the network's speeds over the ground or through the air"},
        "provenance": {"type": "object"},
    }
    return document_schema(FORMAT, "lifelike-mj 3D butterfly controller", props, ["layers", "weights"],
                           "A network from the 3D butterfly's attitude and motion to changes of its wing and abdomen "
                           "kinematics, with the base command and the actions' scales.")


def controller_from_dict(data: object, name: str = "") -> Controller3D:
    """A :class:`Controller3D` from plain data (a parsed controller file); one sentence for anything wrong
    (checked against :func:`json_schema` before any value is used)."""
    from lifelike_mj.butterfly.kinematics3d import KinematicsCommand
    from lifelike_mj.schema import check_header, validate

    where = f"3D controller {name}" if name else "3D controller"
    d = check_header(data, FORMAT, f"file {name}" if name else "the data", kind="3D controller file")
    validate(d, json_schema(), where)
    base = d.get("base")
    if base is not None:
        base = KinematicsCommand(**{k: float(v) for k, v in base.items()})
    return Controller3D(d["layers"], d["weights"], base, d.get("scale"), d.get("every", 1),
                        d.get("omega_c_rad_s", 2.0 * math.pi * 10.0), d.get("provenance"), name, d.get("inputs", "ground"))


def load_controller(name_or_path) -> Controller3D:
    """A shipped 3D controller by name (``controllers/butterfly3d/``) or any 3D controller file by path."""
    from lifelike_mj.paths import load_named_json

    data, path = load_named_json("butterfly3d", name_or_path, "3D controller")
    return controller_from_dict(data, path.stem)
