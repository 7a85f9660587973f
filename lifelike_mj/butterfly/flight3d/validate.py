"""Checks of the 3D butterfly against the planar one: the reduction to the paper's flight.

With both wings flapping alike, the paper's mass layout (all of the 0.319 g in the thorax), the paper's
tip-speed law (Oe 2010 eq. 7-9), body drag on the world's axes (eq. 10) and the body's pitch set once per
step by the paper's pitch law (section 5.1; roll and yaw held at 0), the 3D model must fly the planar
MuJoCo model's flight: the motion stays in the sagittal plane and the path is the same.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import pitch_command
from lifelike_mj.butterfly.flight3d.measures import MAX_CHECK_S, check_window
from lifelike_mj.butterfly.flight3d.parts import Butterfly


def kinematics_of(controller: ButterflyController):
    """The :class:`~lifelike_mj.butterfly.flight3d.kinematics.KinematicsCommand` of a planar controller's flap
    pattern (Oe 2010 section 4.3: ``theta_c + theta_a cos(2 pi f t)`` on both wings, no feathering)."""
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

    fl = controller.flap
    return KinematicsCommand(frequency_hz=fl.frequency_hz, offset_left=fl.theta_c, offset_right=fl.theta_c,
                             amplitude_left=fl.theta_a, amplitude_right=fl.theta_a)


def reduction(controller: ButterflyController | str = "simple_rule", duration_s: float = 20.0,
              dt_s: float = 1.0 / 1200.0) -> dict:
    """Fly ``controller`` on the planar MuJoCo model (``config="paper"``, tip-speed law) and on the 3D
    model reduced to it (module docstring) for ``duration_s``; return the largest differences of the
    paths (m) and the largest sideways excursion of the 3D flight (m), with both end points."""
    from lifelike_mj.butterfly import controllers as _controllers
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.sim import Flight

    ctrl = controller if isinstance(controller, ButterflyController) else _controllers.load(controller)
    planar = Flight(ctrl, backend="mujoco", config="paper", force_mode="tip", dt_s=dt_s).record(duration_s=duration_s)
    kind, cp = ctrl.compiled()
    kind = int(kind)
    last = [0.0]

    def law(f) -> float:
        # the planar loop's pitch law with the 3D state: flap reference, altitude, climb and forward speed
        ref = f.kinematics.joint_references()
        q, v = f.data.qpos, f.data.qvel
        last[0] = pitch_command(kind, cp, f.time, ref[0, 0], ref[0, 1], q[2], 0.0, v[2], v[0], 0.0, 0.0, last[0])
        return last[0]

    flight = Flight3D(kinematics_of(ctrl), butterfly=Butterfly(masses="paper", force_law="tip", drag_frame="world"),
                      assist="hold", pitch_law=law, dt_s=dt_s)
    path = np.empty((len(planar.t), 3))
    path[0] = flight.state()["position_m"]
    for k in range(1, len(planar.t)):
        flight.step(1)
        path[k] = flight.data.qpos[:3]
    return {"duration_s": float(planar.t[-1]),
            "max_forward_difference_m": float(np.abs(path[:, 0] - planar.z).max()),
            "max_altitude_difference_m": float(np.abs(path[:, 2] - planar.y).max()),
            "max_sideways_m": float(np.abs(path[:, 1]).max()),
            "planar_end_m": [float(planar.z[-1]), float(planar.y[-1])],
            "reduced_end_m": [float(path[-1, 0]), float(path[-1, 2])]}


# ---- what a 3D controller does: level flight, turns, courses ----------------------------------


def _beat_means(t: np.ndarray, x: np.ndarray, period_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Means of ``x`` over consecutive windows of ``period_s`` (one wing beat): the flapping averaged out."""
    per = max(1, int(round(period_s / (t[1] - t[0]))))
    n = (len(t) - 1) // per
    xs = x[1 : 1 + n * per].reshape((n, per) + x.shape[1:]).mean(axis=1)
    ts = t[1 : 1 + n * per].reshape(n, per).mean(axis=1)
    return ts, xs




def _every_10_ms(flight) -> int:
    """Steps between two samples 10 ms apart (12 at 1/1200 s), as :meth:`Flight3D.record` samples by default."""
    return max(1, round(0.01 / flight.dt))


def level_check(controller, speed_m_s: float = 1.5, duration_s: float = 60.0, settle_s: float = 5.0, **flight) -> dict:
    """Fly ``controller`` level at ``speed_m_s`` for ``duration_s`` and measure it: the speed over ground
    each second after ``settle_s`` (m/s), the altitude throughout (m; the reference is the start, 0 m), and
    the body's roll and pitch throughout (deg)."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    check_window("the level check", duration_s, settle_s, 1.0, "it measures the speed each second after settling")
    f = Flight3D(controller=controller, task=tasks.level(speed_m_s), **flight)
    rec = f.record(duration_s=duration_s, every=_every_10_ms(f))
    t, pos, att = rec["t_s"], rec["position_m"], rec["attitude_rad"]
    per_s = int(round(1.0 / (t[1] - t[0])))
    after = t >= settle_s - 1e-9
    p = pos[after][::per_s]
    speeds = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1) / (per_s * (t[1] - t[0]))
    return {"speed_command_m_s": speed_m_s, "duration_s": float(t[-1]), "settle_s": settle_s,
            "speed_min_m_s": float(speeds.min()), "speed_max_m_s": float(speeds.max()),
            "speed_mean_m_s": float(speeds.mean()),
            "speed_within_10_percent": bool(np.all(np.abs(speeds / speed_m_s - 1.0) <= 0.1)),
            "altitude_min_m": float(pos[:, 2].min()), "altitude_max_m": float(pos[:, 2].max()),
            "altitude_within_0_3_m": bool(np.abs(pos[:, 2]).max() <= 0.3),
            "roll_max_deg": float(np.degrees(np.abs(att[:, 0]).max())),
            "pitch_min_deg": float(np.degrees(att[:, 1].min())), "pitch_max_deg": float(np.degrees(att[:, 1].max())),
            "distance_m": float(np.linalg.norm(pos[-1, :2] - pos[0, :2]))}


def turn_check(controller, angle_deg: float, at_s: float = 2.0, hold_s: float = 10.0, speed_m_s: float = 1.5,
               **flight) -> dict:
    """Fly ``controller`` level, command a new heading ``angle_deg`` (left > 0) at ``at_s`` and hold it for
    ``hold_s``; measure when the course over ground (beat-averaged) first comes within 10 deg of it, the
    largest error over the last half of the hold (deg), the turn's radius (m, speed over the mean rate of
    turn while turning) and its mean bank (roll, deg)."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    checks.number("at_s", at_s, 0.0, MAX_CHECK_S, unit="s")
    check_window("the turn check", at_s + hold_s, at_s, 1.0, "it measures the course over the hold after the command")
    f = Flight3D(controller=controller, task=tasks.turn(angle_deg, at_s, speed_m_s), **flight)
    period = 1.0 / f.command.frequency_hz
    rec = f.record(duration_s=at_s + hold_s, every=_every_10_ms(f))
    t, pos, att = rec["t_s"], rec["position_m"], rec["attitude_rad"]
    ts, ps = _beat_means(t, pos, period)
    _, rolls = _beat_means(t, att[:, 0], period)
    vel = np.diff(ps[:, :2], axis=0) / period
    tv = 0.5 * (ts[1:] + ts[:-1])
    course = np.unwrap(np.arctan2(vel[:, 1], vel[:, 0]))
    target = math.radians(angle_deg)
    err = np.degrees(np.abs((course - target + np.pi) % (2 * np.pi) - np.pi))
    after = tv > at_s
    reached = np.nonzero(after & (err <= 10.0))[0]
    done_at = float(tv[reached[0]]) if len(reached) else float("nan")
    hold = tv >= at_s + 0.5 * hold_s
    turning = after & (tv <= (done_at if len(reached) else tv[-1]))
    rate = float(np.abs(np.diff(course)[turning[1:]]).mean() / period) if turning[1:].any() else float("nan")
    speed = float(np.linalg.norm(vel[turning], axis=1).mean()) if turning.any() else float("nan")
    return {"angle_deg": angle_deg, "command_at_s": at_s, "reached_within_10_deg_at_s": done_at,
            "turn_time_s": done_at - at_s, "held_error_max_deg": float(err[hold].max()),
            "held_within_10_deg": bool(len(reached) > 0 and err[hold].max() <= 10.0),
            "radius_m": speed / rate if rate and rate > 0 else float("nan"),
            "bank_mean_deg": float(np.degrees(rolls[(ts > at_s) & (ts <= done_at)].mean())) if len(reached) else float("nan"),
            "altitude_min_m": float(pos[:, 2].min()), "altitude_max_m": float(pos[:, 2].max())}


def course_check(controller, seed: int, n: int = 10, max_s: float = 60.0, weather: dict | None = None,
                 planner: dict | None = None, **flight) -> dict:
    """Fly ``controller`` along the course of ``n`` waypoints drawn by ``seed``
    (:func:`~lifelike_mj.butterfly.flight3d.tasks.course`) for at most ``max_s``; report the waypoints passed (in
    order, within the course's 0.3 m) and the closest approach to each (m). ``weather``: the wind, gusts and
    flutter (:meth:`~lifelike_mj.butterfly.flight3d.tasks.Task3D.with_weather`'s arguments; the seed defaults to
    the course's). ``planner``: fly a designed controller with predictive sampling on top
    (:class:`~lifelike_mj.butterfly.flight3d.predictive.Planner`'s keywords; ``{}``: its defaults)."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    checks.whole("the waypoints n", n, 1, 10_000)
    check_window("the course check", max_s, 0.0, 0.1, "")
    task = tasks.course(seed, n)
    if weather:
        task = task.with_weather(**weather)
    f = Flight3D(controller=controller, task=task, **flight)
    if planner is not None:
        from lifelike_mj.butterfly.flight3d.predictive import Planner

        Planner(f, **planner).fly(max_s)
    while f.time < max_s and f.waypoints_passed < n and not f.tumbled:
        f.step(120)
    closest = f.closest_approach_m
    return {"seed": seed, "waypoints": n, "passed": f.waypoints_passed, "time_s": f.time,
            "closest_m": [float(v) if np.isfinite(v) else None for v in closest],
            "all_within_radius": bool(f.waypoints_passed == n and np.all(closest <= task.radius_m))}


def kinematics_check(controller, speed_m_s: float = 1.5, settle_s: float = 5.0, window_s: float = 5.0,
                     force_law: str = "exact", **flight) -> dict:
    """The measures of free flight Dudley 1990 reports, from a level flight of ``controller`` at ``speed_m_s``
    (after ``settle_s``, over ``window_s``; :func:`~lifelike_mj.butterfly.flight3d.measures.level_measures`): the flap
    frequency (Hz) and stroke amplitude (deg, the angle each wing sweeps from top to bottom, the mean of the two),
    the speed over ground (m/s), the advance ratio over both wings ``J = U / (2 Phi f R)`` (``Phi`` the mean stroke
    in rad, ``R`` the wing length, ``U`` the speed through the air), the body's mean pitch and its swing within a
    beat (deg), the bobbing within a beat (m, top to bottom of the thorax, less the beat's mean climb), and the
    mean vertical force coefficient the flight needs, ``m g / (1/2 rho S (2 Phi f R)^2)`` with ``S`` both wings'
    area: the figure Sunada et al. 1993 estimate at about 4 for a cabbage white taking off. ``roll_mean_deg``:
    whether the flight stayed upright enough for these to mean anything."""
    from lifelike_mj.butterfly.flight3d.measures import level_measures
    from lifelike_mj.butterfly.flight3d.parts import with_force_law

    m = level_measures(controller, speed_m_s, settle_s, window_s, **with_force_law(flight, force_law))
    return {"force_law": force_law, "speed_command_m_s": speed_m_s, "flap_frequency_hz": m["flap_frequency_hz"],
            "stroke_amplitude_deg": 0.5 * (m["stroke_left_deg"] + m["stroke_right_deg"]),
            "speed_m_s": m["ground_speed_m_s"], "advance_ratio": m["advance_ratio"],
            "body_pitch_mean_deg": m["body_angle_deg"], "body_pitch_swing_deg": m["body_pitch_swing_deg"],
            "bobbing_m": 1e-3 * m["bobbing_mm"], "vertical_force_coefficient": m["vertical_force_coefficient"],
            "roll_mean_deg": m["roll_mean_deg"], "beats": m["beats"]}


def target_check(controller, duration_s: float = 40.0, catch_s: float = 10.0, **target) -> dict:
    """Follow a moving target (:func:`~lifelike_mj.butterfly.flight3d.tasks.moving_target`) for ``duration_s``; report
    when it first came within the task's 0.3 m, and the distance's median and 90th percentile after ``catch_s``."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.tasks import R_WP

    check_window("the target check", duration_s, catch_s, 0.1, "it measures the distance after the catch time")
    task = tasks.moving_target(**target)
    f = Flight3D(controller=controller, task=task)
    dist, times = [], []
    first = None
    while f.time < duration_s - 1e-9:
        f.step(_every_10_ms(f))
        d = float(f._rec[R_WP + 1])
        dist.append(d)
        times.append(f.time)
        if first is None and d < task.radius_m:
            first = f.time
    dist_a, t_a = np.array(dist), np.array(times)
    late = dist_a[t_a >= catch_s]
    return {"target_speed_m_s": target.get("speed_m_s", 0.5), "first_within_0_3_m_s": first,
            "distance_median_m": float(np.median(late)), "distance_p90_m": float(np.percentile(late, 90)),
            "closest_m": float(dist_a.min())}
