"""A flight controller designed from the averaged model (issue 42, point 2): gain-scheduled LQR with integral action,
a wind estimate from the body's own motion, and guidance that crabs and speeds up into the wind.

**What it sees.** Its own motion only: the thorax's position and velocity over the ground, its attitude and its
rates of turn (what an insect has from its eyes, halteres or antennae' mechanosensors, and gravity). Never the wind.
The beat shakes and rocks the body periodically. A moving mean one beat long removes that, but it lags half a beat,
which leaves the loop no margin on the slow trims (:func:`lagged_poles`). So the velocity, rates and attitude are
the latest sample less the beat's periodic part at its phase, a template learnt in flight from the samples half a
beat back against the mean centred on them (:meth:`DesignedController._unlagged`); the position stays the moving
mean. Insects correct upsets with about one beat of latency (Ristroph et al. 2010; Beatus et al. 2015).

**The plant.** At each forward speed of the envelope the trim and the linear model of
:mod:`~lifelike_mj.butterfly.flight3d.averaged` (``A``, ``B``: 9 states, 9 controls), augmented with the altitude
error and three integrals: of the altitude error, of the airspeed error and of the heading error. The heading and
altitude errors and the airspeed error are outputs of the state (their rows are the world's vertical, forward and yaw
components of the body's motion and rotation at the trim attitude).

**The gains** (:func:`design`): at each speed the infinite-horizon LQR gain of the augmented model
(``scipy.linalg.solve_continuous_are``) for the weights :data:`Q_SCALES` and :data:`R_SCALES` (Bryson's rule: each
state or control divided by the size it may reach). In flight the gains and the trim are interpolated linearly in the
airspeed asked.

**The wind** (:meth:`DesignedController.wind`): an observer on the velocity over the ground. The linear model about the
trim at the estimated airspeed predicts the beat-averaged acceleration from the estimated air velocity, the rates,
the attitude and the controls as flown; the wind estimate moves until the prediction matches the measured velocity.

**Guidance.** On a course the butterfly is asked to make good a ground velocity along the line to the next waypoint
at the task's speed. The air velocity that does so is that ground velocity less the estimated wind: its direction is
the heading asked (it crabs into a cross wind), its size the airspeed asked, clipped to the envelope; when a head wind
asks for more than the envelope's top speed, the ground speed asked is lowered so that the track is still held, as
butterflies that make ground upwind do by flying faster than the wind (Srygley et al. 1996). The altitude asked is the
waypoint's, reached by a climb or descent at :data:`MAX_CLIMB_M_S` at most (the velocity asked includes it), and the
heading asked turns at :data:`MAX_TURN_RATE_RAD_S` at most; errors beyond :data:`MAX_ALTITUDE_ERROR_M` and
:data:`MAX_HEADING_ERROR_RAD` are clipped, so that a far target asks a steady climb or turn, not a saturated one. A
waypoint circled without being passed (:data:`ORBIT_TURNS_RAD` of bearing swept near it: the slowest turn is wider than
a course's radius) is left straight ahead and met again from further out (:func:`orbit_direction`).

**Moments the model does not predict** (:meth:`DesignedController.moment`). The averaged model's lateral divergence
is slower than the simulator's, its lateral controls weaker, and a gust's moment is not in it at all. So the
controller measures them: the angular acceleration (the rates' change over a control step) less what the model
predicts from the state and the controls as flown, low-passed over :data:`MOMENT_TAU_S`, is an angular acceleration
the body gets from elsewhere, and the controls are changed by the least change (weighed by :data:`MOMENT_WEIGHTS`)
that the model says cancels its roll and yaw and leaves the pitch alone. (The pitch is left to the regulator: in level
flight the model's pitch prediction is off by a steady 50 rad/s^2 or so, which the altitude and airspeed integrals
already take up; cancelled as well, it slowed the recovery from a 30 deg nose-down upset from 2.4 beats to 11.) This
is the disturbance estimation and cancellation with which Chirarattananon et al. (2017) halved a flapping robot's
position error in wind, here on the rotation: a disturbance observer on the model's angular acceleration, akin to the
incremental dynamic inversion of Smeur, de Croon and Chu (2016), which measures the acceleration too but leans on the
controls' effect alone.

**Saturation.** Every control is clipped to the natural envelope (:data:`~lifelike_mj.butterfly.flight3d.controls.ENVELOPE`
for the symmetric ones, :data:`DIFFERENCE_LIMITS` for left against right); the integrals are bounded
(:data:`INTEGRAL_LIMITS`), so they do not wind up.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np
from numba import njit

from lifelike_mj.butterfly.flight3d import controls as ct
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

#: Bryson's scales of the augmented state: 9 model states (m/s, rad/s, rad), then the altitude error (m), its integral
#: (m s), the airspeed error's integral (m) and the heading error's integral (rad s).
Q_SCALES = np.array([0.9, 0.9, 0.9, 3.0, 3.0, 3.0, 0.45, 0.45, 0.3, 0.15, 0.15, 0.45, 0.3])
#: Bryson's scales of the controls (Hz, rad), :data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS` order. The
#: left-right differences are kept small (0.06 rad). Seen through the moving mean alone (half a beat late), the lateral
#: loop needed 0.03: at 0.1 rad for the feathering difference it fell into a 2 Hz roll-and-yaw cycle of +-60 deg with
#: that control slamming between its limits (seeds 100-119: 2 of 20 calm courses tumbled; at 0.2 rad, 14 of 20).
#: Without that lag (:meth:`DesignedController._unlagged`) it carries 0.06, and the rates' weights three times more.
R_SCALES = np.array([0.5, 0.06, 0.06, 0.06, 0.06, 0.1, 0.06, 0.1, 0.15])
#: A residual policy's reach (:mod:`~lifelike_mj.envs.butterfly3d`: the designed controller as a baseline, a policy's
#: nine actions in [-1, 1] times these added to its controls, in :data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS`
#: order; Hz, rad): the controls' Bryson scales, the change the design itself counts as large.
RESIDUAL_SCALE = R_SCALES.copy()
#: Limits of the antisymmetric controls (rad): offset, amplitude and feathering differences left less right.
DIFFERENCE_LIMITS = {"offset_difference": math.radians(15.0), "amplitude_difference": math.radians(15.0),
                     "feather_mean_difference": math.radians(20.0)}
#: Errors fed to the regulator are clipped to these (m, rad).
MAX_ALTITUDE_ERROR_M, MAX_HEADING_ERROR_RAD = 0.25, math.radians(30.0)
#: The velocity, rate and attitude errors fed to the regulator are clipped to these (m/s, rad/s, rad): far from its
#: trim the linear model no longer holds, and a clipped error asks the largest correction it still describes.
MAX_SPEED_ERROR_M_S, MAX_RATE_RAD_S, MAX_ATTITUDE_ERROR_RAD = 0.4, 4.0, math.radians(30.0)
#: The integrals of the altitude, airspeed and heading errors are kept within these (m s, m, rad s): a clipped
#: control cannot wind them up further than what their own gains turn into a full correction.
INTEGRAL_LIMITS = np.array([0.3, 0.6, 0.3])
#: The most the altitude asked moves toward a waypoint's (m/s): a new waypoint's altitude is a climb at this rate,
#: flown as such (the climb rate is part of the velocity asked), not a step that the regulator meets by pitching up.
MAX_CLIMB_M_S = 0.3
#: The beat's periodic motion, learnt per phase (:meth:`DesignedController._unlagged`): bins per beat, the share of
#: each new sample in its bin's mean, and how many samples a bin needs before it is used.
N_BINS, TEMPLATE_RATE, TEMPLATE_MIN = 40, 0.5, 3
#: The lag the controller sees the body's motion with (s): one control step of 10 ms (its sample held until the next).
CONTROL_LAG_S = 0.01
#: Poles of the wind observer's error (1/s, per axis): its natural frequency and damping ratio.
OBSERVER_HZ, OBSERVER_ZETA = 0.5, 1.0
#: The moment observer (:meth:`DesignedController.moment`): the time constant (s) of the low-pass through which the
#: measured angular acceleration less the model's prediction becomes the estimated disturbance, and the weights (the
#: controls' sizes, Hz and rad, :data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS` order) by which its
#: cancellation is shared among the controls (the least-squares change of the controls, each divided by its weight,
#: that gives the opposite angular acceleration through the model's ``B``). Chosen on the tuning courses 100-119 among
#: 0.05, 0.15 and 0.3 s: at 0.05 s Dryden's gusts completed 5 of 8, at 0.3 s 20 of 20; checked again with the 2.25 m/s
#: top speed in gusts on every axis (seeds 100-139): 0.15, 0.3 and 0.6 s completed 23, 25 and 16 of 40.
MOMENT_TAU_S = 0.3
MOMENT_WEIGHTS = R_SCALES.copy()
#: Near a waypoint the ground speed asked is at most ``APPROACH_MIN_M_S + APPROACH_PER_S * distance`` (m/s, 1/s).
APPROACH_MIN_M_S, APPROACH_PER_S = 1.0, 1.0
#: Airspeed limits of guidance (m/s). Below 1 m/s: seen through the beat's moving mean, the slow trims' lateral
#: divergence was too fast for the loop (:func:`lagged_poles`: unstable at 0.5 and 0.75 m/s; flown, a 20 deg roll upset
#: at 0.75 m/s left a roll cycle of +-36 deg); seen without that lag the loop holds them, but those trims are the model's
#: least accurate (they speed up by 0.3 m/s in free flight) and a floor of 0.8 m/s completed fewer courses (19 of 20
#: calm, seeds 100-119). The top is 2.25 m/s, the maximum-range speed measured for *Heliconius sara* (Srygley et al.
#: 2023), where the level trim beats at 10.7 Hz: in a 1 m/s wind with gusts of 0.5 m/s on every axis (tuning seeds
#: 100-139) a top of 1.75, 2, 2.25 and 2.5 m/s completed 1 of 16 (seeds 100-115), 19, 25 and 19 of 40 courses; faster
#: than 2.25 the trims beat at the frequency's top and cannot climb.
MIN_AIRSPEED_M_S, MAX_AIRSPEED_M_S = 1.0, 2.25
#: The most the airspeed asked changes (m/s^2): a wind triangle that flips as a waypoint passes does not jerk the
#: speed loop.
MAX_SPEED_CHANGE_M_S2 = 1.0
#: The regulator's state: the 9 model states, the altitude error and three integrals, then the 9 controls as flown and
#: their 9 rates (the kinematics follow a command through a critically damped filter of one wing beat: the
#: controller knows its own motor state, as an animal's efference copy does).
N_PLANT, N_AUG = 13, 31
#: The most the heading asked turns (rad/s) toward where guidance points: a turn is a steady bank, not a step.
MAX_TURN_RATE_RAD_S = 2.0
#: Circling a waypoint: ``ORBIT_TURNS_RAD`` of bearing swept within ``ORBIT_M`` of it (m) without passing it (a turn at
#: the slowest airspeed and fastest turn rate has a radius of 0.5 m, wider than a course's 0.3 m), the butterfly flies
#: straight out until ``ORBIT_OUT_M`` away (m), then homes on it again. Measured before: calm course 105 circled its
#: second waypoint for 58 s; then completed in 18.4 s. A single turn swept was too eager in gusts (one of the ten
#: held-out courses at Dryden's ratio lost); one and a half changed none of them. ``ORBIT_M`` is about the diameter of
#: the widest turns (2 m at 2 m/s and 2 rad/s, 2.25 m at the top speed): at 1 m, a waypoint 0.7 m to the side of the
#: track at 1.5 m/s was circled at 0.8-1.1 m for a minute, each pass beyond 1 m starting the count again.
ORBIT_M, ORBIT_OUT_M, ORBIT_TURNS_RAD = 2.0, 2.5, 3.0 * math.pi


def _outputs(trim_pitch: float, v0_body: np.ndarray) -> np.ndarray:
    """Rows of the world's vertical speed, forward speed and heading (yaw) as linear functions of the 9 model states at
    a trim of body angle ``trim_pitch`` moving at ``v0_body`` (body axes): the world velocity is ``R0 (dv + a x v0)``,
    the heading the world vertical component of ``R0 a``."""
    R0 = ct.rotation(0.0, trim_pitch, 0.0)
    C = np.zeros((3, 9))
    cross = np.array([[0.0, v0_body[2], -v0_body[1]], [-v0_body[2], 0.0, v0_body[0]], [v0_body[1], -v0_body[0], 0.0]])
    # a x v0 = -v0 x a = cross @ a
    world_v = np.hstack([R0, np.zeros((3, 3)), R0 @ cross])
    C[0] = world_v[2]
    C[1] = world_v[0]
    C[2, 6:9] = R0[2]
    return C


def augment(A: np.ndarray, B: np.ndarray, trim_pitch: float, v0_body: np.ndarray,
            omega_c: float) -> tuple[np.ndarray, np.ndarray]:
    """The augmented model (module docstring): states 9 + altitude error, its integral, the airspeed error's
    integral, the heading error's integral, then the controls as flown and their rates, which follow the command
    ``u`` through the kinematics' critically damped filter of natural frequency ``omega_c`` (rad/s)."""
    C = _outputs(trim_pitch, v0_body)
    nu = B.shape[1]
    Aa = np.zeros((N_AUG, N_AUG))
    Aa[:9, :9] = A
    Aa[:9, N_PLANT : N_PLANT + nu] = B  # the body feels the controls as flown
    Aa[9, :9] = C[0]  # altitude error rate = vertical speed
    Aa[10, 9] = 1.0
    Aa[11, :9] = C[1]
    Aa[12, :9] = C[2]
    Aa[N_PLANT : N_PLANT + nu, N_PLANT + nu :] = np.eye(nu)
    Aa[N_PLANT + nu :, N_PLANT : N_PLANT + nu] = -omega_c ** 2 * np.eye(nu)
    Aa[N_PLANT + nu :, N_PLANT + nu :] = -2.0 * omega_c * np.eye(nu)
    Ba = np.zeros((N_AUG, nu))
    Ba[N_PLANT + nu :] = omega_c ** 2 * np.eye(nu)
    return Aa, Ba


def lqr(A: np.ndarray, B: np.ndarray, q_scales=Q_SCALES, r_scales=R_SCALES) -> np.ndarray:
    """The infinite-horizon LQR gain ``K`` (``u = -K x``) for Bryson's weights: ``q_scales`` of the first states, the
    controls as flown weighed as the commands (``r_scales``) and their rates not at all."""
    from scipy.linalg import solve_continuous_are

    q = np.full(A.shape[0], np.inf)
    q[: len(q_scales)] = q_scales
    q[N_PLANT : N_PLANT + len(r_scales)] = r_scales
    Q = np.diag(1.0 / q ** 2)
    R = np.diag(1.0 / np.asarray(r_scales) ** 2)
    P = solve_continuous_are(A, B, Q, R)
    return np.linalg.solve(R, B.T @ P)


def design(model: dict, q_scales=Q_SCALES, r_scales=R_SCALES) -> dict:
    """The designed controller's schedule from an averaged model (:func:`~lifelike_mj.butterfly.flight3d.averaged.build`
    output; its level trims): per speed the trim (body angle, kinematics, body velocity), the model rows the wind
    observer needs, the gain, and the closed loop's slowest pole (1/s)."""
    rows = sorted((p for p in model["points"] if p["climb_m_s"] == 0.0), key=lambda p: p["speed_m_s"])
    out = []
    for p in rows:
        A, B = np.array(p["A"]), np.array(p["B"])
        pitch = math.radians(p["body_angle_deg"])
        v0 = ct.rotation(0.0, pitch, 0.0).T @ np.array([p["speed_m_s"], 0.0, 0.0])
        omega_c = 2.0 * math.pi * p["command"]["frequency_hz"]  # the kinematics follow a command in one beat
        Aa, Ba = augment(A, B, pitch, v0, omega_c)
        K = lqr(Aa, Ba, q_scales, r_scales)
        poles = np.linalg.eigvals(Aa - Ba @ K)
        out.append({"speed_m_s": p["speed_m_s"], "body_angle_rad": pitch, "command": list(p["command"].values()),
                    "v0_body_m_s": v0.tolist(), "A": A.tolist(), "B": B.tolist(), "K": K.tolist(),
                    "slowest_pole_per_s": float(-poles.real.max())})
    return {"kind": "designed", "animal": model.get("animal", "monarch"), "force_law": model.get("force_law", "calibrated"),
            "schedule": out, "q_scales": list(map(float, q_scales)), "r_scales": list(map(float, r_scales))}


def _pade2(tau: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """A state-space form ``(A, B, C, D)`` of the second-order Pade approximation of a delay of ``tau`` (s),
    ``(1 - s tau/2 + (s tau)^2/12) / (1 + s tau/2 + (s tau)^2/12)``."""
    a2, a1 = tau * tau / 12.0, tau / 2.0
    return (np.array([[0.0, 1.0], [-1.0 / a2, -a1 / a2]]), np.array([0.0, 1.0]), np.array([0.0, -2.0 * a1 / a2]), 1.0)


def lagged_poles(model: dict, spec: dict, lag_s: float | None = None, extra_s: float = 0.0) -> list[dict]:
    """The closed loop's poles at each level trim of ``spec`` (:func:`design` of ``model``) when the controller sees
    the body's motion late: by ``lag_s`` (s), or with ``None`` by half a beat (``0.5 / f``), as a moving mean of one
    wing beat sees it; plus ``extra_s`` (a total of 0: the loop as designed). The lag is a second-order Pade form on
    the 9 model states and the altitude error; the controls as flown are the controller's own and seen at once. Per
    speed: the fastest growth or slowest decay (``growth_per_s``, 1/s: positive is unstable) and the least damped
    oscillation (``damping``, its ``frequency_hz``). The design itself assumes no lag: this is how much of its margin a
    lag takes."""
    points = {p["speed_m_s"]: p for p in model["points"] if p["climb_m_s"] == 0.0}
    out = []
    for s in spec["schedule"]:
        p = points[s["speed_m_s"]]
        f = p["command"]["frequency_hz"]
        Aa, Ba = augment(np.array(p["A"]), np.array(p["B"]), s["body_angle_rad"], np.array(s["v0_body_m_s"]),
                         2.0 * math.pi * f)
        K = np.array(s["K"])
        tau = (0.5 / f if lag_s is None else lag_s) + extra_s
        # the 9 model states and the altitude error, seen late (none with no lag: the design's own loop)
        n, lagged = Aa.shape[0], (range(N_PLANT - 3) if tau > 0.0 else range(0))
        if tau > 0.0:
            Ap, Bp, Cp, Dp = _pade2(tau)
        M = np.zeros((n + 2 * len(lagged), n + 2 * len(lagged)))
        M[:n, :n] = Aa
        Kfb = np.zeros((K.shape[0], M.shape[0]))  # u = -Kfb [x, z]: the lagged states through their filters
        Kfb[:, :n] = K
        for j, i in enumerate(lagged):
            z = slice(n + 2 * j, n + 2 * j + 2)
            M[z, z], M[z, i] = Ap, Bp
            Kfb[:, i] = K[:, i] * Dp
            Kfb[:, z] += np.outer(K[:, i], Cp)
        M[:n] -= Ba @ Kfb
        ev = np.linalg.eigvals(M)
        osc = ev[np.abs(ev.imag) > 1.0]
        zeta = -osc.real / np.abs(osc)
        k = int(np.argmin(zeta))
        out.append({"speed_m_s": s["speed_m_s"], "growth_per_s": float(ev.real.max()), "damping": float(zeta[k]),
                    "frequency_hz": float(abs(osc[k].imag) / (2.0 * math.pi))})
    return out


def _lerp(speeds: np.ndarray, values: np.ndarray, speed: float) -> np.ndarray:
    """``values`` (one row per speed of ``speeds``, ascending) interpolated linearly at ``speed``, held at the ends."""
    x = float(np.clip(speed, speeds[0], speeds[-1]))
    i = int(np.clip(np.searchsorted(speeds, x) - 1, 0, len(speeds) - 2))
    t = (x - speeds[i]) / (speeds[i + 1] - speeds[i])
    return (1.0 - t) * values[i] + t * values[i + 1]


def _interp(schedule: list[dict], speed: float, key: str) -> np.ndarray:
    """The schedule's ``key`` (:func:`design`) interpolated at the airspeed ``speed`` (m/s)."""
    return _lerp(np.array([s["speed_m_s"] for s in schedule]), np.array([s[key] for s in schedule], float), speed)


@njit(cache=True)
def _log(R: np.ndarray) -> np.ndarray:
    """The rotation vector (rad) of the rotation matrix ``R`` (compiled once for both forms of the controller)."""
    c = max(-1.0, min(1.0, 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)))
    t = math.acos(c)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if t < 1e-9:
        return 0.5 * w
    return t / (2.0 * math.sin(t)) * w


@njit(cache=True)
def quat2mat(q):
    """The rotation matrix of the unit quaternion ``q`` (w, x, y, z): MuJoCo's ``mju_quat2Mat`` formula, compiled once
    for both forms of the controller, so that the Python twin and the compiled loop read the same attitude to the
    last bit (MuJoCo's own build may fuse a multiply into an add, and its matrices differ by a rounding)."""
    R = np.empty((3, 3))
    if q[0] == 1.0 and q[1] == 0.0 and q[2] == 0.0 and q[3] == 0.0:
        return np.eye(3)
    q00, q01, q02, q03 = q[0] * q[0], q[0] * q[1], q[0] * q[2], q[0] * q[3]
    q11, q12, q13 = q[1] * q[1], q[1] * q[2], q[1] * q[3]
    q22, q23, q33 = q[2] * q[2], q[2] * q[3], q[3] * q[3]
    R[0, 0] = q00 + q11 - q22 - q33
    R[1, 1] = q00 - q11 + q22 - q33
    R[2, 2] = q00 - q11 - q22 + q33
    R[0, 1] = 2.0 * (q12 - q03)
    R[0, 2] = 2.0 * (q13 + q02)
    R[1, 0] = 2.0 * (q12 + q03)
    R[1, 2] = 2.0 * (q23 - q01)
    R[2, 0] = 2.0 * (q13 - q02)
    R[2, 1] = 2.0 * (q23 + q01)
    return R


@njit(cache=True)
def orbit_direction(o, waypoint, to, dist, d, heading, has_heading):
    """The direction to fly (unit vector) when homing on waypoint number ``waypoint`` along ``d`` (``to`` it, ``dist`` m
    away), compiled once for both forms of the controller: having swept :data:`ORBIT_TURNS_RAD` of bearing within
    :data:`ORBIT_M` of it without passing (circling, as a turn too wide for its radius does), it flies straight out on
    the heading asked (``heading``, if ``has_heading``, else the bearing) until :data:`ORBIT_OUT_M` away, then homes
    again, now from straight ahead. ``o`` (6, changed in place): the waypoint, the bearing swept, the last bearing and
    whether set, whether going out and its heading."""
    if o[0] != waypoint:
        o[0], o[1], o[3], o[4] = waypoint, 0.0, 0.0, 0.0
    if o[4] != 0.0:
        if dist > ORBIT_OUT_M:
            o[1], o[3], o[4] = 0.0, 0.0, 0.0
        else:
            d = np.array([math.cos(o[5]), math.sin(o[5])])
    if o[4] == 0.0:
        if dist < ORBIT_M:
            b = math.atan2(to[1], to[0])
            if o[3] != 0.0:
                o[1] = o[1] + abs((b - o[2] + math.pi) % (2.0 * math.pi) - math.pi)
            o[2], o[3] = b, 1.0
            if o[1] > ORBIT_TURNS_RAD:
                o[4] = 1.0
                o[5] = heading if has_heading else b
                d = np.array([math.cos(o[5]), math.sin(o[5])])
        else:
            o[1], o[3] = 0.0, 0.0
    return d


def _wrap(a: float) -> float:
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def limits() -> tuple[np.ndarray, np.ndarray]:
    """The lowest and highest value of each control (:data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS`) as
    an absolute value: the symmetric ones' natural envelope, the differences' :data:`DIFFERENCE_LIMITS`."""
    lo, hi = np.empty(len(ct.CONTROLS)), np.empty(len(ct.CONTROLS))
    for i, name in enumerate(ct.CONTROLS):
        if name in DIFFERENCE_LIMITS:
            lo[i], hi[i] = -DIFFERENCE_LIMITS[name], DIFFERENCE_LIMITS[name]
        elif name == "offset":
            lo[i], hi[i] = ct.TOP_RANGE[0] - ct.ENVELOPE["amplitude"][1], ct.TOP_RANGE[1] - ct.ENVELOPE["amplitude"][0]
        else:
            lo[i], hi[i] = ct.ENVELOPE[name]
    return lo, hi


class DesignedController:
    """The designed controller (module docstring) as a Python callable for :class:`Flight3D`
    (``controller=DesignedController(design(model))``, ``control_every=1``): it measures at every step and sets a new
    command every ``every`` steps. ``spec``: :func:`design`'s answer or a designed controller file's content
    (:func:`controller_from_dict` checks a file first); ``name`` and ``provenance`` as a file gives them. Its
    ``animal`` and ``force_law`` are those of the model it was designed on (a flight takes them unless told
    otherwise), :meth:`start_command` the trim to start from."""

    def __init__(self, spec: dict, every: int = 8, name: str = "", provenance: dict | None = None) -> None:
        self.name = name
        self.provenance = dict(provenance or spec.get("provenance") or {})
        self.animal = spec.get("animal", "monarch")
        self.force_law = spec.get("force_law", "calibrated")
        self.q_scales, self.r_scales = spec.get("q_scales"), spec.get("r_scales")
        self.schedule = spec["schedule"]
        #: The landing's manoeuvres (:mod:`~lifelike_mj.butterfly.flight3d.perching`), flown by the compiled loop only;
        #: ``None`` without.
        self.landing = spec.get("landing")
        # the schedule as arrays, made once: what each control step interpolates
        self._speeds = np.array([s["speed_m_s"] for s in self.schedule])
        self._table = {k: np.array([s[k] for s in self.schedule], float)
                       for k in ("body_angle_rad", "v0_body_m_s", "K", "command", "A", "B")}
        self.every = every
        self.lo, self.hi = limits()
        self.reset()

    def reset(self) -> None:
        self.buffer: deque = deque()
        self.integral = np.zeros(3)
        self.v_hat = None
        self.w_hat = np.zeros(3)
        self.k = 0
        self.heading = None
        #: circling a waypoint (:func:`orbit_direction`)
        self.orbit = np.array([-1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        self.airspeed = None
        self.altitude = None
        self.template = np.zeros((N_BINS, 9))
        self.learnt = np.zeros(N_BINS, dtype=int)
        #: the rates at the last control step (rad/s) and the estimated angular acceleration from moments the model
        #: does not predict (rad/s^2, body axes)
        self.rates_before = None
        self.moment_hat = np.zeros(3)
        #: what the last control step saw and did: time, wind estimate, references, state and controls
        self.last: dict | None = None

    def _unlagged(self, vel: np.ndarray, rates: np.ndarray, Rm: np.ndarray):
        """The slow motion now, without the moving mean's half-beat lag: the latest sample less the beat's periodic
        part at its phase, a template learnt from the samples half a beat back against the beat's mean, which is
        centred on them (per phase bin, body axes)."""
        def phase_bin(sample) -> int:
            return int(sample[4] % (2.0 * math.pi) / (2.0 * math.pi) * N_BINS) % N_BINS

        mid = self.buffer[len(self.buffer) // 2]
        k = phase_bin(mid)
        dev = np.concatenate([mid[3].T @ (mid[1] - vel), mid[2] - rates, _log(Rm.T @ mid[3])])
        self.template[k] += TEMPLATE_RATE * (dev - self.template[k])
        self.learnt[k] += 1
        now = self.buffer[-1]
        j = phase_bin(now)
        if self.learnt[j] < TEMPLATE_MIN:
            return vel, rates, Rm
        t = self.template[j]
        return now[1] - now[3] @ t[0:3], now[2] - t[3:6], now[3] @ ct.exp_rotation(-t[6:9])

    def start_command(self, speed_m_s: float = 1.5):
        """The trim's kinematics at the airspeed ``speed_m_s`` (m/s, held within the schedule's speeds): where a
        flight with this controller starts."""
        from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

        return KinematicsCommand(*self._at(speed_m_s, "command"))

    def to_dict(self) -> dict:
        """The controller file's content (:data:`~lifelike_mj.butterfly.flight3d.controllers.FORMAT`, ``kind``
        ``"designed"``): what :func:`controller_from_dict` reads back."""
        from lifelike_mj.butterfly.flight3d.controllers import FORMAT

        out = {"format": FORMAT, "version": 1, "kind": "designed", "animal": self.animal, "force_law": self.force_law,
               "schedule": self.schedule}
        if self.q_scales is not None:
            out["q_scales"], out["r_scales"] = list(self.q_scales), list(self.r_scales)
        if self.landing is not None:
            out["landing"] = self.landing
        if self.name:
            out["name"] = self.name
        out["provenance"] = self.provenance
        return out

    def _at(self, speed: float, key: str) -> np.ndarray:
        return _lerp(self._speeds, self._table[key], speed)

    # ---- guidance -----------------------------------------------------------------------------------------------

    def references(self, flight, pos: np.ndarray, wind: np.ndarray) -> tuple[float, float, float]:
        """Heading (rad), altitude (m) and airspeed (m/s) asked now (module docstring)."""
        from lifelike_mj.butterfly.flight3d.tasks import R_PASSED

        task = flight.task
        if task.kind == "waypoints":
            i = min(int(flight._rec[R_PASSED]), len(task.rows) - 1)
            wp = np.array(task.rows[i][:3])
            to = wp[:2] - pos[:2]
            dist = float(np.linalg.norm(to))
            d = to / dist if dist > 1e-9 else np.array([1.0, 0.0])
            d = orbit_direction(self.orbit, float(i), to, dist, d, self.heading or 0.0, self.heading is not None)
            # slower as it closes, so that its turns are tighter than the waypoint's radius
            speed = min(task.speed_m_s, APPROACH_MIN_M_S + APPROACH_PER_S * dist)
            heading, airspeed = self.wind_triangle(d, speed, wind[:2])
            return heading, float(wp[2]), airspeed
        heading, altitude, speed = flight.reference  # a schedule asks for a heading and an airspeed
        return float(heading), float(altitude), float(np.clip(speed, MIN_AIRSPEED_M_S, MAX_AIRSPEED_M_S))

    @staticmethod
    def wind_triangle(d: np.ndarray, ground_speed: float, wind_xy: np.ndarray) -> tuple[float, float]:
        """The heading (rad) and airspeed (m/s) that make good ``ground_speed`` along the unit vector ``d`` in the wind
        ``wind_xy`` (m/s), the ground speed lowered where the airspeed would pass :data:`MAX_AIRSPEED_M_S`."""
        air = ground_speed * d - wind_xy
        if np.linalg.norm(air) > MAX_AIRSPEED_M_S:
            along = float(d @ wind_xy)
            disc = along * along - float(wind_xy @ wind_xy) + MAX_AIRSPEED_M_S ** 2
            g = along + math.sqrt(disc) if disc >= 0.0 else 0.0
            air = max(g, 0.0) * d - wind_xy
            n = float(np.linalg.norm(air))
            if n > MAX_AIRSPEED_M_S:
                air *= MAX_AIRSPEED_M_S / n
        speed = float(np.linalg.norm(air))
        if speed < 1e-9:
            return float(math.atan2(d[1], d[0])), MIN_AIRSPEED_M_S
        return float(math.atan2(air[1], air[0])), float(np.clip(speed, MIN_AIRSPEED_M_S, MAX_AIRSPEED_M_S))

    # ---- the loop -------------------------------------------------------------------------------------------------

    def __call__(self, flight):
        from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

        d = flight.data
        dt = flight.dt
        quat = d.qpos[3:7]
        R = quat2mat(np.ascontiguousarray(quat))
        freq = float(d.userdata[mj3d.U_P0])  # the flap frequency flown
        n_beat = max(1, int(round(1.0 / (freq * dt))))
        self.buffer.append((d.qpos[0:3].copy(), d.qvel[0:3].copy(), d.qvel[3:6].copy(), R.copy(),
                            float(d.userdata[mj3d.U_PSI0])))
        while len(self.buffer) > n_beat:
            self.buffer.popleft()
        self.k += 1
        if (self.k - 1) % self.every:
            return None
        pos = np.mean([b[0] for b in self.buffer], axis=0)
        vel = np.mean([b[1] for b in self.buffer], axis=0)
        rates = np.mean([b[2] for b in self.buffer], axis=0)
        Rm = self.buffer[-1][3]
        # a mean attitude: the beat's rotations averaged about the latest (small swings)
        a_mean = np.mean([_log(Rm.T @ b[3]) for b in self.buffer], axis=0)
        Rm = Rm @ ct.exp_rotation(a_mean)
        if len(self.buffer) == n_beat:
            vel, rates, Rm = self._unlagged(vel, rates, Rm)
        t_ctrl = self.every * dt
        wind = self.wind(vel, Rm, rates, d.userdata[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS].copy(), t_ctrl)
        target, altitude_asked, asked = self.references(flight, pos, wind)
        # the altitude asked moves toward the target's at most MAX_CLIMB_M_S: a climb, not a step
        if self.altitude is None:
            self.altitude = float(pos[2])
        dz_max = MAX_CLIMB_M_S * t_ctrl
        climb = float(np.clip(altitude_asked - self.altitude, -dz_max, dz_max))
        altitude = self.altitude = self.altitude + climb
        climb_rate = climb / t_ctrl
        if self.airspeed is None:
            self.airspeed = asked
        dv = MAX_SPEED_CHANGE_M_S2 * self.every * dt
        airspeed = self.airspeed = self.airspeed + float(np.clip(asked - self.airspeed, -dv, dv))
        if self.heading is None:
            self.heading = math.atan2(Rm[1, 0], Rm[0, 0])
        step = MAX_TURN_RATE_RAD_S * t_ctrl
        turn = float(np.clip(_wrap(target - self.heading), -step, step))
        heading = self.heading = _wrap(self.heading + turn)
        turn_rate = turn / t_ctrl  # the heading asked turns at this rate (rad/s, left > 0): a coordinated turn
        pitch0 = float(self._at(airspeed, "body_angle_rad"))
        v0 = self._at(airspeed, "v0_body_m_s")
        K = self._at(airspeed, "K")
        trim_cmd = self._at(airspeed, "command")
        trim_u = ct.controls_of(trim_cmd)
        yaw = math.atan2(Rm[1, 0], Rm[0, 0])
        herr = float(np.clip(_wrap(yaw - heading), -MAX_HEADING_ERROR_RAD, MAX_HEADING_ERROR_RAD))
        # the trim attitude at the heading asked (the error clipped), banked into the turn asked: tan(bank) = v r / g
        bank = -math.atan(airspeed * turn_rate / 9.81)
        R0 = ct.rotation(bank, pitch0, yaw - herr)
        a = _log(R0.T @ Rm)
        v_air = Rm.T @ (vel - wind - np.array([0.0, 0.0, climb_rate]))  # the air velocity less the climb asked
        x = np.zeros(N_AUG)
        x[0:3] = np.clip(v_air - v0, -MAX_SPEED_ERROR_M_S, MAX_SPEED_ERROR_M_S)
        x[3:6] = np.clip(rates - R0.T @ np.array([0.0, 0.0, turn_rate]), -MAX_RATE_RAD_S, MAX_RATE_RAD_S)
        x[6:9] = np.clip(a, -MAX_ATTITUDE_ERROR_RAD, MAX_ATTITUDE_ERROR_RAD)
        ud = d.userdata
        nu = len(ct.CONTROLS)
        x[N_PLANT : N_PLANT + nu] = ct.controls_of(ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS]) - trim_u
        x[N_PLANT + nu :] = ct.controls_of(ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS])  # the controls' rates as flown
        zerr = float(np.clip(pos[2] - altitude, -MAX_ALTITUDE_ERROR_M, MAX_ALTITUDE_ERROR_M))
        x[9] = zerr
        x[10:13] = self.integral
        u = -K @ x + self.moment(rates, x, self._at(airspeed, "A"), self._at(airspeed, "B"), t_ctrl)
        change = np.clip(trim_u + u, self.lo, self.hi) - trim_u
        fwd = float(np.array([math.cos(heading), math.sin(heading), 0.0]) @ (vel - wind))
        self.integral = np.clip(self.integral + t_ctrl * np.array([zerr, fwd - airspeed, herr]), -INTEGRAL_LIMITS,
                                INTEGRAL_LIMITS)
        self.last = {"t": flight.time, "wind": wind.copy(), "heading": heading, "airspeed": airspeed,
                     "altitude": altitude, "pos": pos.copy(), "x": x, "u": change}
        return KinematicsCommand(*ct.command_from_controls(trim_cmd, change))

    def moment(self, rates: np.ndarray, x: np.ndarray, A: np.ndarray, B: np.ndarray, dt: float) -> np.ndarray:
        """The controls' change (Hz, rad) that cancels the angular acceleration the model does not predict (module
        docstring): one step of the moment observer, ``d <- d + min(1, dt / tau) (dw/dt - A_w x - B_w u - d)`` with
        ``dw/dt`` the rates' change over the control step ``dt`` (s), ``x`` the regulator's state (model states, then
        the controls as flown from :data:`N_PLANT`), ``A_w``, ``B_w`` the model's rows of the angular acceleration,
        then the least change ``W B_w^T (B_w W B_w^T)^-1 d_l`` (``W`` the squared :data:`MOMENT_WEIGHTS`), negated,
        with ``d_l`` the estimate's roll and yaw (its pitch set to zero: the change leaves the pitch alone)."""
        Aw, Bw = A[3:6, 0:9], B[3:6]
        if self.rates_before is None:
            self.rates_before = rates.copy()
        else:
            measured = (rates - self.rates_before) / dt
            self.rates_before = rates.copy()
            predicted = Aw @ x[0:9] + Bw @ x[N_PLANT : N_PLANT + Bw.shape[1]]
            self.moment_hat = self.moment_hat + min(1.0, dt / MOMENT_TAU_S) * (measured - predicted - self.moment_hat)
        W = np.diag(MOMENT_WEIGHTS ** 2)
        lateral = self.moment_hat * np.array([1.0, 0.0, 1.0])  # the roll and yaw only (module docstring)
        return -(W @ Bw.T @ np.linalg.solve(Bw @ W @ Bw.T, lateral))

    def wind(self, vel: np.ndarray, Rm: np.ndarray, rates: np.ndarray, flown: np.ndarray, dt: float) -> np.ndarray:
        """The wind estimate (world, m/s): one step of the observer (module docstring). The model's acceleration is
        taken about the trim at the airspeed the estimate implies (its body angle, kinematics and derivatives), from
        the controls as flown (``flown``: the kinematics parameters now) and the body's attitude and rates; the wind is
        the observer's second state, ``dw/dt = -k A_vv^-1 e`` with ``e`` the velocity's error, which with
        ``dv/dt = A_vv (v - w - v0) + ... + l e`` makes the errors' poles those of ``s^2 + (l - A_vv) s + k``. Only the
        horizontal wind is estimated: an error of the model's lift would look like a vertical wind, which the
        altitude's integral takes up instead."""
        if self.v_hat is None:
            self.v_hat = vel.copy()
            return self.w_hat.copy()
        air = (self.v_hat - self.w_hat)[:2]
        speed = float(np.linalg.norm(air))
        A = self._at(speed, "A")
        B = self._at(speed, "B")
        v0 = self._at(speed, "v0_body_m_s")
        pitch0 = float(self._at(speed, "body_angle_rad"))
        trim_cmd = self._at(speed, "command")
        yaw = math.atan2(Rm[1, 0], Rm[0, 0])
        a = _log(ct.rotation(0.0, pitch0, yaw).T @ Rm)
        u = ct.controls_of(flown) - ct.controls_of(trim_cmd)
        v_b = Rm.T @ (self.v_hat - self.w_hat)
        acc = Rm @ (A[0:3, 0:3] @ (v_b - v0) + A[0:3, 3:6] @ rates + A[0:3, 6:9] @ a + B[0:3] @ u)
        Avv = Rm @ A[0:3, 0:3] @ Rm.T
        e = vel - self.v_hat
        wn = 2.0 * math.pi * OBSERVER_HZ
        self.v_hat = self.v_hat + dt * (acc + 2.0 * OBSERVER_ZETA * wn * e)
        dw = -wn * wn * np.linalg.solve(Avv, e)
        dw[2] = 0.0
        self.w_hat = self.w_hat + dt * dw
        return self.w_hat.copy()


#: Bounds of a designed controller file: speeds in its schedule (at least two), the size of any number in it.
MAX_SCHEDULE, MAX_VALUE = 64, 1.0e7


def json_schema() -> dict:
    """The JSON Schema of a designed controller file (``docs/schemas/butterfly3d-designed.schema.json``): the 3D
    controller file's format with ``"kind": "designed"``, what :func:`controller_from_dict` enforces before it builds
    the controller."""
    from lifelike_mj.butterfly.flight3d.animals import ANIMALS
    from lifelike_mj.butterfly.flight3d.controllers import FORCE_LAWS_FLOWN, FORMAT
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.schema import document_schema, number

    def vector(n: int, what: str = "") -> dict:
        return {"type": "array", "minItems": n, "maxItems": n, "items": number("", -MAX_VALUE, MAX_VALUE),
                **({"description": what} if what else {})}

    def matrix(rows: int, cols: int, what: str) -> dict:
        return {"type": "array", "minItems": rows, "maxItems": rows, "items": vector(cols), "description": what}

    nx, nu, nc = len(ct.STATES), len(ct.CONTROLS), len(KinematicsCommand.names())
    point = {"type": "object", "additionalProperties": False,
             "required": ["speed_m_s", "body_angle_rad", "command", "v0_body_m_s", "A", "B", "K"],
             "properties": {
                 "speed_m_s": number("m/s: the trim's airspeed", 0.05, 10.0),
                 "body_angle_rad": number("rad: the trim's body angle, nose up", -math.pi / 2, math.pi / 2),
                 "command": vector(nc, "the trim's kinematics (KinematicsCommand's order)"),
                 "v0_body_m_s": vector(3, "m/s: the trim's air velocity in body axes"),
                 "A": matrix(nx, nx, "the averaged model's state matrix (states u v w p q r a_x a_y a_z)"),
                 "B": matrix(nx, nu, "the averaged model's control matrix"),
                 "K": matrix(nu, N_AUG, "the LQR gain, u = -K x of the augmented state"),
                 "slowest_pole_per_s": number("1/s: the closed loop's slowest pole"),
             }}
    tracked = {"states": {"type": "array", "maxItems": 2001,
                          "description": "the nominal's state at each control step and its end"},
               "commands": {"type": "array", "maxItems": 2000, "description": "its kinematics at each control step"},
               "gains": {"type": "array", "maxItems": 2000, "description": "the tracking's gain at each control step"}}
    props = {
        "kind": {"const": "designed", "description": "a controller designed from the averaged model"},
        "animal": {"enum": list(ANIMALS), "description": "the butterfly it flies"},
        "force_law": {"enum": list(FORCE_LAWS_FLOWN), "description": "the wing-force law of its model"},
        "schedule": {"type": "array", "minItems": 2, "maxItems": MAX_SCHEDULE, "items": point,
                     "description": "per level trim, by rising airspeed: the trim, its linear model and the gain"},
        "q_scales": vector(N_PLANT, "Bryson's scales of the states it was designed with"),
        "r_scales": vector(nu, "Bryson's scales of the controls it was designed with"),
        "landing": {"type": "object", "required": ["manoeuvres"], "description":
                    "the landing: manoeuvres shot per phase of the wing beat and their tracking (flight3d.perching)",
                    "properties": {"manoeuvres": {"type": "array", "maxItems": 64, "items": {
                        "type": "object", "required": ["phase_rad", "start_m", "states", "commands", "gains"],
                        "properties": {
                            "phase_rad": number("rad: the wing beat's phase at the start", 0.0, 2 * math.pi),
                            "start_m": number("m: the start's distance before the flower's axis", 0.0, 10.0),
                            **tracked}}},
                        "take_off": {"type": "object", "required": ["states", "commands", "gains"], "description":
                                     "the take-off: a manoeuvre shot from perched states and its tracking",
                                     "properties": tracked}}},
        "provenance": {"type": "object"},
    }
    return document_schema(FORMAT, "lifelike-mj 3D butterfly controller, designed", props,
                           ["kind", "animal", "force_law", "schedule"],
                           "A flight controller designed from the wing-beat-averaged model: level trims by airspeed, "
                           "their linear models and LQR gains.")


def controller_from_dict(data: object, name: str = "") -> DesignedController:
    """A :class:`DesignedController` from a parsed designed controller file; one sentence for anything wrong
    (the header, then :func:`json_schema` with the lengths of its lists first, then the schedule's airspeeds, which
    must rise, and each trim's kinematics)."""
    from lifelike_mj.butterfly.flight3d.controllers import FORMAT
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.errors import UserError
    from lifelike_mj.schema import check_header, too_long, validate

    where = f"designed 3D controller {name}" if name else "designed 3D controller"
    d = check_header(data, FORMAT, f"file {name}" if name else "the data", kind="3D controller file")
    schema = json_schema()
    too_long(d, schema, where)
    validate(d, schema, where)
    speeds = [p["speed_m_s"] for p in d["schedule"]]
    if any(b <= a for a, b in zip(speeds, speeds[1:])):
        raise UserError(f"{where}: the schedule's airspeeds must rise from one trim to the next, got {speeds}.")
    for p in d["schedule"]:
        KinematicsCommand(*p["command"])  # its own sentence for a command out of bounds
    if "landing" in d:
        from lifelike_mj.butterfly.flight3d.perch_layout import check_landing

        check_landing(d["landing"], where)
    return DesignedController(d, name=name, provenance=d.get("provenance"))


def model_schema() -> dict:
    """The JSON Schema of what :func:`design` reads of an averaged model file (``lifelike-mj butterfly model3d``'s
    output): its animal, force law and points, each with its speed, climb, body angle, kinematics and linear model."""
    from lifelike_mj.butterfly.flight3d.animals import ANIMALS
    from lifelike_mj.butterfly.flight3d.controllers import FORCE_LAWS_FLOWN
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.schema import number

    nx, nu = len(ct.STATES), len(ct.CONTROLS)
    row = {"type": "array", "items": number("", -MAX_VALUE, MAX_VALUE)}
    point = {"type": "object", "required": ["speed_m_s", "climb_m_s", "body_angle_deg", "command", "A", "B"],
             "properties": {
                 "speed_m_s": number("m/s", 0.05, 10.0), "climb_m_s": number("m/s", -10.0, 10.0),
                 "body_angle_deg": number("deg", -90.0, 90.0),
                 "command": {"type": "object", "additionalProperties": False,
                             "required": list(KinematicsCommand.names()),
                             "properties": {k: number("", -MAX_VALUE, MAX_VALUE) for k in KinematicsCommand.names()}},
                 "A": {"type": "array", "minItems": nx, "maxItems": nx, "items": {**row, "minItems": nx, "maxItems": nx}},
                 "B": {"type": "array", "minItems": nx, "maxItems": nx, "items": {**row, "minItems": nu, "maxItems": nu}}}}
    return {"type": "object", "required": ["animal", "force_law", "points"],
            "properties": {"animal": {"enum": list(ANIMALS)}, "force_law": {"enum": list(FORCE_LAWS_FLOWN)},
                           "points": {"type": "array", "minItems": 2, "maxItems": 4 * MAX_SCHEDULE, "items": point}}}


def check_model(data: object, where: str) -> dict:
    """``data`` (a parsed averaged model file) checked against :func:`model_schema`, with at least two level trims
    of different speeds; else one sentence."""
    from lifelike_mj.errors import UserError
    from lifelike_mj.schema import too_long, validate

    schema = model_schema()
    too_long(data, schema, where)
    validate(data, schema, where)
    level = sorted({p["speed_m_s"] for p in data["points"] if p["climb_m_s"] == 0.0})
    if len(level) < 2:
        raise UserError(f"{where} has {len(level)} level trims (climb 0 m/s); a designed controller needs at least two "
                        "speeds (lifelike-mj butterfly model3d --climbs 0).")
    return data


def load_any(name_or_path):
    """A 3D controller of either kind (:data:`~lifelike_mj.butterfly.flight3d.controllers.KINDS`) by name or path: a
    :class:`DesignedController` for a file of ``"kind": "designed"``, else a network
    (:class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D`)."""
    from lifelike_mj.butterfly.flight3d import controllers

    data, name = controllers.read_controller_file(name_or_path)
    if isinstance(data, dict) and data.get("kind") == "designed":
        return controller_from_dict(data, name)
    return controllers.controller_from_dict(data, name)
