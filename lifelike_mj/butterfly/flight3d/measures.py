"""How natural a 3D flight is, measured: the numbers biologists report for real butterflies, computed from a
simulated flight beside them.

:func:`level_measures` flies a controller straight and level and measures, over whole wing beats after it has
settled (every quantity from the simulation's own state at every time step):

* **attitude**: the mean roll (deg, a circular mean; straight flight needs none: ``tan(bank) = v omega / g`` with ``omega = 0``)
  and the body angle, the thorax's long axis above the horizontal (deg; Dudley 1990 measured it falling with
  speed);
* **strokes**: each wing's stroke (deg, top to bottom of its flap angle within a beat), their difference, the
  flap frequency, and the **dorsal gap**: the angle between the two wing tips seen from between the hinges at
  the top of each stroke (deg; a filmed cruising monarch: 35-50 deg, no clap);
* **bobbing**: the thorax's rise and fall within a beat (mm, top to bottom; about 10 mm in the monarch);
* **abdomen**: its mean angle to the thorax (deg, tip up > 0), its swing (deg, half top to bottom) and when it is
  most flexed (tip lowest), as a fraction of the beat after the top of the stroke;
* **power**: the joints' drive, ``P_j = tau_j dq_j/dt`` for each driven joint (both wings' flap and feathering,
  the abdomen). Per kg of the whole butterfly: ``power_W_kg``, the positive work of each joint per second with
  no elastic storage (what a muscle must do when nothing stores the wing's energy: Dudley 1991's 20.2 W/kg
  bound), and ``power_net_W_kg``, the net work per second (perfect storage: Dudley's 12.5 W/kg bound);
* **advance ratio** over both wings, ``J = U / (2 Phi f R)`` (``Phi`` the mean of the two strokes in rad, ``f``
  the flap frequency, ``R`` the wing length, ``U`` the speed through the air), and the mean vertical force
  coefficient the flight needs, ``m g / (1/2 rho S (2 Phi f R)^2)`` with ``S`` both wings' area (Sunada et al.
  1993 estimate about 4 for a cabbage white taking off).
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: The longest flight a check flies (s).
MAX_CHECK_S = 3600.0


def check_window(what: str, duration_s: float, settle_s: float, least_s: float, why: str) -> None:
    """Before a check flies: :class:`UserError` unless its ``duration_s`` is finite, at most :data:`MAX_CHECK_S`,
    and leaves at least ``least_s`` after its own settling time ``settle_s`` (``why``: what it measures then)."""
    checks.number(f"{what}'s settling time", settle_s, 0.0, MAX_CHECK_S, unit="s")
    d = checks.number(f"{what}'s duration", duration_s, 0.0, MAX_CHECK_S, lo_open=True, unit="s")
    if d < settle_s + least_s:
        raise UserError(f"{what} needs a duration of at least {settle_s + least_s:g} s ({settle_s:g} s of settling "
                        f"and {least_s:g} s to measure{'; ' + why if why else ''}), got {d:g} s.")



def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    c = np.sum(u * v, axis=-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def sample(flight, duration_s: float) -> dict:
    """Fly ``flight`` on for ``duration_s`` and return, at every time step: ``t_s``, the thorax's position (m),
    attitude (rad) and air velocity (m/s), the driven joints' angles (rad), rates (rad/s) and drive torques
    (N m), both wing tips' positions relative to the point between the hinges (m), and the air's whole force on the
    wings and the body (N, world frame)."""
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.flight import euler_from_quat

    m = flight.model
    n = int(round(duration_s / flight.dt))
    tips = [m.site("wing_left_tip").id, m.site("wing_right_tip").id]
    wings = [m.body("wing_left").id, m.body("wing_right").id]
    out = {k: [] for k in ("t_s", "position_m", "attitude_rad", "air_velocity_m_s", "joints_rad", "rates_rad_s",
                           "torques_N_m", "tips_m", "air_force_N")}
    for k in range(n + 1):
        if k:
            flight.step(1)
        d = flight.data
        f = flight.forces()  # one mj_forward at this state: torques, site positions
        q, v = flight._q, flight._driven[:5]
        hinge = 0.5 * (d.xpos[wings[0]] + d.xpos[wings[1]])
        out["t_s"].append(flight.time)
        out["position_m"].append(d.qpos[0:3].copy())
        out["attitude_rad"].append(euler_from_quat(d.qpos[3:7]))
        out["air_velocity_m_s"].append(d.qvel[0:3] - d.userdata[mj3d.U_AIR : mj3d.U_AIR + 3])
        out["joints_rad"].append(d.qpos[q].copy())
        out["rates_rad_s"].append(d.qvel[v].copy())
        out["torques_N_m"].append(f["drive_torque_N_m"])
        out["tips_m"].append(np.stack([d.site_xpos[tips[0]] - hinge, d.site_xpos[tips[1]] - hinge]))
        out["air_force_N"].append(f["wing_force_N"].sum(axis=0) + f["body_drag_N"])
    return {k: np.array(v) for k, v in out.items()}


def beats(flap: np.ndarray) -> list[tuple[int, int]]:
    """Whole wing beats of a flap-angle series: ``(start, end)`` sample pairs from one top of the stroke to the
    next (the tops: each beat's highest flap angle, between upward crossings of the mid angle)."""
    mid = 0.5 * (flap.max() + flap.min())
    ups = np.nonzero((flap[:-1] < mid) & (flap[1:] >= mid))[0]
    tops = [a + int(np.argmax(flap[a:b])) for a, b in zip(ups[:-1], ups[1:])]
    return list(zip(tops[:-1], tops[1:]))


def measures(s: dict, mass_kg: float, span_m: float, area_m2: float, rho: float, gravity: float) -> dict:
    """The measures of the module docstring from a :func:`sample` ``s`` of a flight (``mass_kg``: the whole
    butterfly's; ``span_m`` and ``area_m2``: one wing's length and area)."""
    t, joints = s["t_s"], s["joints_rad"]
    flap = 0.5 * (joints[:, 0] + joints[:, 1])
    bb = beats(flap)
    if len(bb) < 3:
        raise UserError(f"the flight shows {len(bb)} whole wing beats; the measures need at least 3.")
    a0, b1 = bb[0][0], bb[-1][1]
    period = (t[b1] - t[a0]) / len(bb)
    freq = 1.0 / period
    strokes = np.array([[np.ptp(joints[a:b, 0]), np.ptp(joints[a:b, 1])] for a, b in bb])
    stroke_l, stroke_r = np.degrees(strokes.mean(axis=0))
    tops = np.array([a for a, _ in bb])
    gap = _angle(s["tips_m"][tops, 0], s["tips_m"][tops, 1])
    pos, att = s["position_m"], s["attitude_rad"]
    bob = np.mean([np.ptp(pos[a:b, 2] - np.linspace(pos[a, 2], pos[b, 2], b - a)) for a, b in bb])
    ab = joints[:, 4]
    lows = [a + int(np.argmin(ab[a:b])) for a, b in bb]
    lag = np.mean([(t[lo] - t[a]) / period for lo, (a, _) in zip(lows, bb)])
    win = slice(a0, b1)
    power = s["torques_N_m"][win] * s["rates_rad_s"][win]  # per joint, W
    air = s["air_velocity_m_s"][win]
    heading = np.stack([np.cos(att[win, 2]), np.sin(att[win, 2])], axis=1)
    u = float(np.mean(np.sum(air[:, :2] * heading, axis=1)))  # forward speed through the air
    phi = math.radians(0.5 * (stroke_l + stroke_r))
    tip = 2.0 * phi * freq * span_m
    ground = np.linalg.norm(pos[b1, :2] - pos[a0, :2]) / (t[b1] - t[a0])
    return {
        "beats": len(bb), "flap_frequency_hz": float(freq),
        "roll_mean_deg": float(np.degrees(np.angle(np.exp(1j * att[win, 0]).mean()))),  # a circular mean
        "body_angle_deg": float(np.degrees(att[win, 1].mean())),
        "body_pitch_swing_deg": float(np.degrees(np.mean([np.ptp(att[a:b, 1]) for a, b in bb]))),
        "stroke_left_deg": float(stroke_l), "stroke_right_deg": float(stroke_r),
        "stroke_difference_deg": float(abs(stroke_l - stroke_r)),
        "dorsal_gap_deg": float(gap.mean()), "dorsal_gap_min_deg": float(gap.min()),
        "bobbing_mm": float(1e3 * bob),
        "abdomen_mean_deg": float(np.degrees(ab[win].mean())),
        "abdomen_swing_deg": float(np.degrees(0.5 * np.mean([np.ptp(ab[a:b]) for a, b in bb]))),
        "abdomen_lowest_after_top": float(lag),
        "power_W_kg": float(np.clip(power, 0.0, None).mean(axis=0).sum() / mass_kg),
        "power_net_W_kg": float(power.sum(axis=1).mean() / mass_kg),
        "power_per_joint_W_kg": [float(v) for v in np.clip(power, 0.0, None).mean(axis=0) / mass_kg],
        "air_speed_m_s": u, "ground_speed_m_s": float(ground),
        "advance_ratio": u / tip,
        "vertical_force_coefficient": float(mass_kg * gravity / (0.5 * rho * 2.0 * area_m2 * tip**2)),
    }


def body_numbers(flight) -> dict:
    """The whole butterfly's mass (kg), one wing's length (m) and area (m^2), the air's density and gravity of a
    :class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D`: the measured species' own, else the paper's
    triangle (``W L / 2``)."""
    from lifelike_mj.butterfly.flight3d.animals import animal

    a, p = animal(flight.animal), flight.params
    mass = float(flight.model.body_subtreemass[flight.model.body("butterfly").id])
    if a.measured:
        span, area = a.span_m, float(a.moments["area_m2"])
    else:
        span, area = p.span_m, 0.5 * p.width_m * p.span_m
    return {"mass_kg": mass, "span_m": span, "area_m2": area, "rho": p.rho, "gravity": p.gravity}


def level_measures(controller, speed_m_s: float = 1.5, settle_s: float = 5.0, window_s: float = 5.0,
                   **flight) -> dict:
    """:func:`measures` of ``controller`` flying straight and level at ``speed_m_s`` (the task
    :func:`~lifelike_mj.butterfly.flight3d.tasks.level`), over ``window_s`` after ``settle_s``; ``flight``: more
    options of :class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D`. With the flight's settings."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    check_window("the level-flight measures", settle_s + window_s, settle_s, 0.5, "they measure whole wing beats in "
                 "the window after settling")
    f = Flight3D(controller=controller, task=tasks.level(speed_m_s), **flight)
    f.step(int(round(settle_s / f.dt)))
    out = measures(sample(f, window_s), **body_numbers(f))
    return {"animal": f.animal, "speed_command_m_s": speed_m_s, "settle_s": settle_s, "window_s": window_s,
            "dt_s": f.dt, **out}
