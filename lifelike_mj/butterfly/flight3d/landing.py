"""A butterfly that visits flowers by landing on them, one after another: :func:`visit_flowers`, and its picture,
:func:`landing_picture` (``lifelike-mj butterfly land3d``).

The butterfly starts perched on the first flower. For each next flower it takes off (the wings open and clap,
:meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.take_off`), flies the landing task
(:func:`~lifelike_mj.butterfly.flight3d.tasks.land`: lower, slower and more nose up as it closes), touches down on
the blossom, and perches there with its wings closed for ``perch_s``, held by its legs' contact and grip. Each visit is
measured: the touchdown's speed against :data:`~lifelike_mj.butterfly.flight3d.tasks.TOUCHDOWN_M_S`, how far the
butterfly moved while perched, and whether it left the flower again.
"""

from __future__ import annotations

import math

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d.tasks import TOUCHDOWN_M_S

#: A visit's bounds: the most a landing may take (s), and the most the thorax may move while perched (m) for the
#: butterfly to count as sitting still.
MAX_LANDING_S, STILL_M = 20.0, 0.005
#: A take-off's acceleration is averaged over this long (s), as a film at 200 frames per second resolves it.
SMOOTH_S = 0.005
#: A perched body counts as upright while its dorsal axis's vertical component (:func:`up`) is above this (within
#: 60 deg of the vertical); below, it lies on its side or back.
UPRIGHT = 0.5


def up(data) -> float:
    """How upright the thorax of the flight's ``data`` (``MjData``, the butterfly's free joint first) is: its dorsal
    axis's vertical component (1 upright, 0 on its side, -1 on its back)."""
    _w, x, y, _z = data.qpos[3:7]
    return float(1.0 - 2.0 * (x * x + y * y))


def on_blossom(thorax_m, blossom_m) -> bool:
    """Whether a thorax at ``thorax_m`` (m) sits on the blossom centred at ``blossom_m``: within the blossom's radius
    of its axis and above its centre (:data:`~lifelike_mj.butterfly.flight3d.flowers.BLOSSOM_SIZE_M`)."""
    from lifelike_mj.butterfly.flight3d.flowers import BLOSSOM_SIZE_M

    d = np.asarray(thorax_m, dtype=float) - np.asarray(blossom_m, dtype=float)
    return bool(math.hypot(d[0], d[1]) <= BLOSSOM_SIZE_M[0] and d[2] > 0.0)


def visit_flowers(controller, flowers, perch_s: float = 2.0, *, dt_s: float | None = None, record_every_s: float = 0.0,
                  ground_m: float | None = None) -> dict:
    """Fly ``controller`` (a 3D controller; none shipped lands yet) from perched on ``flowers[0]`` to each next flower in
    turn (``(n, 3)`` blossom centres, m), landing on each and perching ``perch_s`` s. Returns ``visits`` (one per
    flower after the first: ``flower``, ``landed``, ``flight_s`` (take-off to touchdown), ``touchdown_speed_m_s``,
    ``within_bound`` (:data:`TOUCHDOWN_M_S`), ``perch_moved_m``, ``still`` (:data:`STILL_M`), ``stayed`` (still
    perched on the blossom at the end: :func:`on_blossom`), ``upright`` (perched upright at the end:
    :data:`UPRIGHT`), ``tilt_max_deg`` (the largest roll or pitch in flight)),
    ``landed`` (how many), and with ``record_every_s`` the path: ``t_s``, ``position_m``, ``attitude_rad``,
    ``perched`` and the flight itself (``flight``)."""
    from lifelike_mj.butterfly.flight3d.flight import DT_S, Flight3D
    from lifelike_mj.butterfly.flight3d.parts import World

    perch_s = checks.number("perch_s", perch_s, 0.0, 600.0, unit="s")
    f = Flight3D(controller=controller, world=World(flowers=flowers, ground_m=ground_m),
                 dt_s=DT_S if dt_s is None else dt_s)
    n = len(f.flowers)
    if n < 2:
        from lifelike_mj.errors import UserError

        raise UserError("visiting flowers needs at least two flowers.")
    f.perch_on(0)
    every = max(1, int(round(0.01 / f.dt)))
    rec_every = max(1, int(round(record_every_s / f.dt))) if record_every_s > 0 else 0
    path: list[tuple] = []

    def fly(steps: int) -> tuple[float, float]:
        tilt, start = 0.0, f.state()["position_m"]
        moved = 0.0
        k = 0
        while k < steps:
            f.step(every)
            k += every
            s = f.state()
            tilt = max(tilt, float(np.abs(s["attitude_rad"][:2]).max()))
            moved = max(moved, float(np.linalg.norm(s["position_m"] - start)))
            if rec_every and (f.steps % rec_every) < every:
                path.append((f.time, s["position_m"], s["attitude_rad"], f.perched))
        return tilt, moved

    f.step(int(round(min(perch_s, 0.5) / f.dt)))
    visits = []
    for k in range(1, n):
        t0 = f.time
        f.take_off(f.land_on(k))
        tilt = 0.0
        while not f.perched and f.time - t0 < MAX_LANDING_S:
            t, _ = fly(every * 5)
            tilt = max(tilt, t)
        td = f.touchdown
        v = {"flower": k, "landed": td is not None, "flight_s": None if td is None else td["time_s"] - t0,
             "touchdown_speed_m_s": None if td is None else td["speed_m_s"],
             "within_bound": td is not None and td["speed_m_s"] <= TOUCHDOWN_M_S, "tilt_max_deg": math.degrees(tilt)}
        if td is None:
            visits.append(v | {"perch_moved_m": None, "still": False, "stayed": False, "upright": False})
            break
        _, moved = fly(int(round(perch_s / f.dt)))
        visits.append(v | {"perch_moved_m": moved, "still": moved <= STILL_M and f.perched,
                           "stayed": f.perched and on_blossom(f.state()["position_m"], f.flowers[k]),
                           "upright": f.perched and up(f.data) > UPRIGHT})
    out = {"visits": visits, "landed": sum(v["landed"] for v in visits), "flowers": n, "perch_s": perch_s,
           "touchdown_bound_m_s": TOUCHDOWN_M_S}
    if rec_every:
        out.update(t_s=np.array([p[0] for p in path]), position_m=np.array([p[1] for p in path]),
                   attitude_rad=np.array([p[2] for p in path]), perched=np.array([p[3] for p in path]), flight=f)
    return out


def take_off_measures(controller, beats: int = 3, *, dt_s: float | None = None) -> dict:
    """A take-off from a flower measured as Sunada et al. (1993) filmed butterflies taking off: the butterfly
    ``controller`` perches on a flower, then takes off for another 1.2 m ahead. Over its first ``beats`` wing beats,
    every time step: the whole butterfly's centre of mass (wings and abdomen included) and its acceleration
    (averaged over :data:`SMOOTH_S`), and the force of the air and the legs (the total force less the weight).
    Returns ``peak_acceleration_m_s2`` and ``peak_at_beat`` (when it peaks, in beats from the first downstroke's
    start: 0.25 is the first downstroke's middle), ``lift_off_s`` (the legs' last contact), and per half-stroke
    (``downstroke``, ``upstroke``: the flap angle falling or rising) the mean force's ``vertical_N`` and
    ``horizontal_N`` components and its angle above the horizontal (``angle_deg``), over the beats after lift-off."""
    import mujoco

    from lifelike_mj.butterfly.flight3d.controllers import Controller3D
    from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned, load_compiled
    from lifelike_mj.butterfly.flight3d.flight import DT_S, Flight3D
    from lifelike_mj.butterfly.flight3d.flowers import blossom_under
    from lifelike_mj.butterfly.flight3d.model import standing_height_m
    from lifelike_mj.butterfly.flight3d.parts import World

    beats = checks.whole("beats", beats, 1, 100)
    ctl = controller if isinstance(controller, (Controller3D, CompiledDesigned)) else load_compiled(controller)
    start = blossom_under((0.0, 0.0, -standing_height_m(ctl.animal)))
    f = Flight3D(controller=ctl, world=World(flowers=[start, start + (1.2, 0.0, 0.0)]),
                 dt_s=DT_S if dt_s is None else dt_s)
    f.perch_on(0)
    f.step(int(round(0.3 / f.dt)))
    m, d = f.model, f.data
    root = m.joint("root").id
    body = int(m.jnt_bodyid[root])
    mass = float(m.body_subtreemass[body])
    g = np.array(m.opt.gravity, dtype=float)
    f.take_off(f.land_on(1))
    t0 = f.time
    n = int(round(beats / float(f.kinematics.p[0]) / f.dt))
    rows = []
    mujoco.mj_subtreeVel(m, d)
    v_prev = d.subtree_linvel[body].copy()
    for _ in range(n):
        f.step(1)
        mujoco.mj_subtreeVel(m, d)
        v = d.subtree_linvel[body].copy()
        a = (v - v_prev) / f.dt
        v_prev = v
        rows.append((f.time - t0, *a, *(mass * (a - g)), float(f.state()["joints_rad"][0]), d.ncon))
    r = np.array(rows)
    t, acc, force, flap, ncon = r[:, 0], r[:, 1:4], r[:, 4:7], r[:, 7], r[:, 8]
    period = 1.0 / float(f.kinematics.p[0])
    window = max(1, int(round(SMOOTH_S / f.dt)))  # as film resolves it: the acceleration over 5 ms
    smooth = np.array([np.convolve(acc[:, i], np.ones(window) / window, mode="same") for i in range(3)]).T
    k = int(np.argmax(np.linalg.norm(smooth, axis=1)))
    touching = np.nonzero(ncon > 0)[0]
    lift = float(t[touching[-1]]) if len(touching) else 0.0
    airborne = t > lift
    falling = np.gradient(flap) < 0
    out = {"peak_acceleration_m_s2": float(np.linalg.norm(smooth[k])), "peak_at_beat": float(t[k] / period),
           "lift_off_s": lift, "beats": beats, "mass_kg": mass}
    heading = np.array([1.0, 0.0])
    for name, sel in (("downstroke", falling & airborne), ("upstroke", ~falling & airborne)):
        if not sel.any():
            out[name] = None
            continue
        mean = force[sel].mean(axis=0)
        horizontal = float(mean[:2] @ heading)
        out[name] = {"vertical_N": float(mean[2]), "horizontal_N": horizontal,
                     "angle_deg": math.degrees(math.atan2(float(mean[2]), horizontal))}
    return out
