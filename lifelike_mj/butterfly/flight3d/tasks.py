"""What a 3D flight is asked to do: the task type, its builders (level flight, turns, courses, a moving target),
and the two array layouts the compiled loop reads and writes.

A **task** (:class:`Task3D`) is a schedule of references (heading, altitude, speed from given times: level
flight, turns, climbs), a course of waypoints, or a moving target, in some weather (a mean wind, gusts) and
with the butterfly's own irregularity (flutter). The compiled loop (:mod:`~lifelike_mj.butterfly.flight3d.loop`)
reads a task as a flat array (:meth:`Task3D.as_array`, layout ``T_*``) and writes each flight's **run record**
(:func:`new_record`, layout ``R_*``): its reward, steps flown, how it ended, and the waypoints passed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError

# task array: kind, then either a schedule (rows of t_start, heading, altitude, speed) or waypoints; a landing is two
# rows, (x, y, surface z, standing height) and how it is flown (flare pitch, flare distance, sink, slowing), and turns
# into a perch (kept by the loop) when the butterfly touches down
TASK_SCHEDULE, TASK_WAYPOINTS, TASK_TARGET, TASK_LAND, TASK_PERCH = 0, 1, 2, 3, 4
#: Task header: kind, rows, pass radius (m), cruise speed (m/s), mean wind (3, m/s), gusts' standard deviation
#: (m/s, horizontal) and correlation time (s), flutter's standard deviation (action units) and correlation time
#: (s), the seed of both, the vertical gusts' standard deviation (m/s); then 4 numbers per row.
T_KIND, T_ROWS, T_RADIUS, T_SPEED, T_WIND = 0, 1, 2, 3, 4
T_GUST, T_GUST_TAU, T_FLUTTER, T_FLUTTER_TAU, T_SEED, T_GUST_W, T_ROW0 = 7, 8, 9, 10, 11, 12, 13

# per-copy run record (float64): fitness, steps flown, diverged step, waypoints passed, tumble step, the gust
# (3, m/s) and the flutter (one per action) now, the style integrals (R_STYLE, below), then the closest approach to
# each waypoint
R_FIT, R_STEPS, R_DIVERGED, R_PASSED, R_TUMBLED, R_GUST, R_FLUTTER = 0, 1, 2, 3, 4, 5, 8
R_STYLE = R_FLUTTER + 9
#: The style integrals over the flight after its first :data:`STYLE_FROM_S` (each ``int x dt``), from which the
#: naturalness of a flight is judged (:mod:`~lifelike_mj.butterfly.flight3d.evolution`): roll (rad s), pitch (rad s),
#: the two wings' stroke amplitudes' difference ``|A_l - A_r|`` and stroke offsets' difference (rad s), the sum over
#: whole beats of the top of the stroke as flown (rad: the higher wing's largest flap angle in the beat), the drive's
#: positive work summed over the joints (J: ``sum_j max(tau_j dq_j/dt, 0)``, torques of the step's last stage),
#: ``(A_l + A_r) f`` (rad: the mean stroke times the frequency), the time they cover (s); then the loop's own
#: bookkeeping of the beats: the running beat's top so far, whether counting began, the beat's index (whole turns of
#: the flap phase), and the whole beats added up.
STYLE_NAMES = ("roll", "pitch", "amplitude_difference", "offset_difference", "stroke_tops", "positive_work_J",
               "stroke_frequency", "time_s", "beat_top", "counting", "beat_index", "beats")
#: The style integrals leave out the flight's first second: the start from rest, not the way it flies.
STYLE_FROM_S = 1.0
N_STYLE = len(STYLE_NAMES)
#: A landing's bookkeeping: when it touched down (s; -1: not yet), at what speed (m/s, over the ground), the heading
#: aimed at last (rad: kept when right above the flower), until when the wings clap (s; a take-off's first beats) and
#: when the last take-off began (s; ``-inf``: none, the flight began in the air).
R_LANDED_AT = R_STYLE + N_STYLE
R_TOUCH_SPEED, R_AIM, R_CLAP_UNTIL, R_TOOK_OFF_AT = R_LANDED_AT + 1, R_LANDED_AT + 2, R_LANDED_AT + 3, R_LANDED_AT + 4
#: The speed boost now (m/s): what the loop adds to the speed asked that an eleven-input network sees, grown while the
#: ground speed toward the heading asked falls short of the speed asked (a controller's ``speed_gain_per_s``).
R_BOOST = R_LANDED_AT + 5
R_WP = R_BOOST + 1
#: A landing keeps its closest approach to the point where it would stand (m) in ``R_WP`` and its speed over the ground
#: then (m/s) in ``R_NEAR_SPEED`` (a landing task has two rows, so both are there).
R_NEAR_SPEED = R_WP + 1

#: How a landing is flown (:func:`land`; the loop's reference): the butterfly aims at the flower from at most
#: ``LAND_ABOVE_M`` above the point where it will stand, coming down ``LAND_GLIDE`` m per m it closes; within
#: ``LAND_HOLD_M`` of the flower's axis it keeps its heading. It **touches down** when its thorax is within the task's
#: radius of the flower's axis and its lowest foot within ``TOUCH_MARGIN_M`` of the landing surface.
LAND_ABOVE_M, LAND_GLIDE, LAND_HOLD_M, TOUCH_MARGIN_M = 0.3, 0.5, 0.03, 0.003
#: A landing's own settings (:func:`land`'s defaults, each in the task): the flare, the body raised by up to
#: ``flare_deg`` over the flower from ``flare_m`` out (:func:`~lifelike_mj.butterfly.flight3d.loop.flare`); the
#: altitude asked ending ``sink_m`` below the standing point (the flower is a floor the butterfly settles on); the
#: speed asked, ``slow_per_s`` m/s per m of horizontal distance (at most the task's speed).
LANDING = {"flare_deg": 40.0, "flare_m": 0.5, "sink_m": 0.02, "slow_per_s": 1.5}
#: The touchdown speed a landing keeps within (m/s, chosen: no measured landing speed of butterflies was found). A
#: monarch's legs (about 7 mm) stop 0.5 m/s within their length at 1.8 g, a third of the 5-6 g its own take-offs reach
#: (:func:`~lifelike_mj.butterfly.flight3d.landing.take_off_measures`).
TOUCHDOWN_M_S = 0.5
#: A perch: the wings closed over the back (each flap angle, rad; 90 deg is upright), still; a take-off claps the wings
#: for ``CLAP_S`` s: about the offset the network asks, each wing's stroke amplitude is raised so that the top of its
#: stroke is ``CLAP_TOP_RAD`` (the wings meet over the back), as butterflies taking off do (Johansson and
#: Henningsson 2021). The larger stroke is our choice: raising the offset instead turns this model's body over.
PERCH_FLAP_RAD, CLAP_TOP_RAD, CLAP_S = math.radians(85.0), math.radians(88.0), 0.3

#: A task's most rows, and the largest number in a row (m, s, rad, m/s): far beyond a garden, finite in the loop.
MAX_TASK_ROWS = 10_000
MAX_TASK_NUMBER = 1.0e6


@dataclass(frozen=True, init=False)
class Task3D:
    """A task: ``kind="schedule"`` with rows ``(t_start_s, heading_rad, altitude_m, speed_m_s)`` (the
    reference from each row's time on; the first row's time is 0), or ``kind="waypoints"`` with rows
    ``(x, y, z)`` in m, visited in order at ``speed_m_s``, each passed when within ``radius_m``, or
    ``kind="target"``, a moving target (:func:`moving_target`).

    The weather: a mean wind ``wind_to_m_s`` (world frame, m/s, where it blows to: the air's velocity; or
    ``wind_from_m_s``, where it comes from; ``wind_m_s`` is the older spelling of ``wind_to_m_s``) plus gusts, a first-order
    Gauss-Markov (Ornstein-Uhlenbeck) process on each axis with standard deviation ``gust_m_s`` (the two
    horizontal axes) and ``gust_vertical_m_s`` (the vertical; ``None``: the same as ``gust_m_s``) and
    correlation time ``gust_tau_s``, starting from calm. Near the ground the vertical gusts are weaker:
    :data:`DRYDEN_VERTICAL_RATIO`. ``flutter``: the butterfly's own irregularity, the
    same process added to each of the controller's actions (standard deviation ``flutter`` in action units,
    where 1 is the action's full scale; correlation time ``flutter_tau_s``). Both are drawn from ``seed``."""

    kind: str
    rows: tuple[tuple[float, ...], ...]
    radius_m: float = 0.3
    speed_m_s: float = 1.5
    name: str = ""
    wind_to_m_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gust_m_s: float = 0.0
    gust_tau_s: float = 1.0
    flutter: float = 0.0
    flutter_tau_s: float = 0.2
    seed: int = 0
    gust_vertical_m_s: float | None = None

    def __init__(self, kind: str, rows, radius_m: float = 0.3, speed_m_s: float = 1.5, name: str = "",
                 wind_to_m_s=None, gust_m_s: float = 0.0, gust_tau_s: float = 1.0, flutter: float = 0.0,
                 flutter_tau_s: float = 0.2, seed: int = 0, gust_vertical_m_s: float | None = None, *,
                 wind_from_m_s=None, wind_m_s=None) -> None:
        wind = checks.one_wind("Task3D", wind_to_m_s, wind_from_m_s, wind_m_s, "to")
        given = {"kind": kind, "rows": rows, "radius_m": radius_m, "speed_m_s": speed_m_s, "name": name,
                 "wind_to_m_s": (0.0, 0.0, 0.0) if wind is None else wind, "gust_m_s": gust_m_s,
                 "gust_tau_s": gust_tau_s, "flutter": flutter, "flutter_tau_s": flutter_tau_s, "seed": seed,
                 "gust_vertical_m_s": gust_vertical_m_s}
        for k, v in given.items():
            object.__setattr__(self, k, v)
        self.__post_init__()

    @property
    def wind_from_m_s(self) -> tuple[float, float, float]:
        """The mean wind as where it comes from (m/s, world frame)."""
        return tuple(0.0 - w for w in self.wind_to_m_s)

    @property
    def wind_m_s(self) -> tuple[float, float, float]:
        """The older name of :attr:`wind_to_m_s` (with a note)."""
        checks.renamed("Task3D.wind_m_s", "Task3D.wind_to_m_s", "where the wind blows to")
        return self.wind_to_m_s

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise UserError(f"a task is a schedule, waypoints, a target or a landing, got {self.kind!r}.")
        width = 3 if self.kind == "waypoints" else 4
        if self.kind == "land" and len(self.rows) != 2:
            raise UserError("a landing task has two rows: the flower's x, y, its surface's z and the standing height; "
                            "the flare's pitch (rad) and distance (m), the sink (m) and the slowing (1/s).")
        if not self.rows or len(self.rows) > MAX_TASK_ROWS or any(len(r) != width for r in self.rows):
            raise UserError(f"a {self.kind} task needs 1 to {MAX_TASK_ROWS:,} rows of {width} numbers.")
        for r in self.rows:
            for v in r:
                checks.number("a task's number", v, -MAX_TASK_NUMBER, MAX_TASK_NUMBER)
        if self.kind == "schedule" and self.rows[0][0] != 0.0:
            raise UserError("a schedule's first row starts at 0 s.")
        checks.number("radius_m", self.radius_m, 0.0, 1000.0, lo_open=True, unit="m")
        checks.number("speed_m_s", self.speed_m_s, 0.0, 100.0, lo_open=True, unit="m/s")
        object.__setattr__(self, "wind_to_m_s", checks.vector("wind_to_m_s", self.wind_to_m_s, 3, "m/s"))
        for w in self.wind_to_m_s:
            checks.number("each component of the wind", w, -100.0, 100.0, unit="m/s")
        checks.number("gust_m_s", self.gust_m_s, 0.0, 10.0, unit="m/s")
        checks.number("gust_tau_s", self.gust_tau_s, 0.0, 1e4, lo_open=True, unit="s")
        if self.gust_vertical_m_s is not None:
            checks.number("gust_vertical_m_s", self.gust_vertical_m_s, 0.0, 10.0, unit="m/s")
        checks.number("flutter", self.flutter, 0.0, 1.0)
        checks.number("flutter_tau_s", self.flutter_tau_s, 0.0, 1e4, lo_open=True, unit="s")
        checks.whole("seed", self.seed, 0, 2**32 - 1)

    def with_weather(self, wind_to_m_s=None, gust_m_s: float = 0.0, gust_tau_s: float = 1.0,
                     flutter: float = 0.0, flutter_tau_s: float = 0.2, seed: int | None = None,
                     gust_vertical_m_s: float | None = None, *, wind_from_m_s=None, wind_m_s=None) -> Task3D:
        """The same task in other weather (and flutter): the mean wind as ``wind_to_m_s`` or ``wind_from_m_s``
        (default calm; ``wind_m_s``: the older spelling of ``wind_to_m_s``); the seed defaults to the task's."""
        from dataclasses import replace

        wind = checks.one_wind("with_weather", wind_to_m_s, wind_from_m_s, wind_m_s, "to")
        return replace(self, wind_to_m_s=(0.0, 0.0, 0.0) if wind is None else wind, gust_m_s=gust_m_s,
                       gust_tau_s=gust_tau_s, flutter=flutter, flutter_tau_s=flutter_tau_s,
                       seed=self.seed if seed is None else seed, gust_vertical_m_s=gust_vertical_m_s)

    @property
    def start_speed_m_s(self) -> float:
        """The speed asked first (m/s): a schedule's first row's, else the task's cruise speed."""
        return float(self.rows[0][3]) if self.kind == "schedule" else self.speed_m_s

    @property
    def vertical_gust_m_s(self) -> float:
        """The vertical gusts' standard deviation (m/s)."""
        return self.gust_m_s if self.gust_vertical_m_s is None else self.gust_vertical_m_s

    def as_array(self, max_rows: int) -> np.ndarray:
        """The compiled loop's task array (layout ``T_*`` above), padded to
        ``max_rows`` rows."""
        out = np.zeros(T_ROW0 + 4 * max_rows)
        out[T_KIND] = KINDS[self.kind]
        out[T_ROWS] = len(self.rows)
        out[T_RADIUS] = self.radius_m
        out[T_SPEED] = self.speed_m_s
        out[T_WIND : T_WIND + 3] = self.wind_to_m_s
        out[T_GUST], out[T_GUST_TAU], out[T_GUST_W] = self.gust_m_s, self.gust_tau_s, self.vertical_gust_m_s
        out[T_FLUTTER], out[T_FLUTTER_TAU], out[T_SEED] = self.flutter, self.flutter_tau_s, self.seed
        for i, r in enumerate(self.rows):
            out[T_ROW0 + 4 * i : T_ROW0 + 4 * i + len(r)] = r
        return out


#: The task kinds and their codes in the task array (a perch is the loop's own, after a landing).
KINDS = {"schedule": TASK_SCHEDULE, "waypoints": TASK_WAYPOINTS, "target": TASK_TARGET, "land": TASK_LAND}


#: The vertical gusts' standard deviation over the horizontal ones near the ground: the low-altitude Dryden
#: model (MIL-F-8785C; MIL-HDBK-1797) gives ``sigma_w / sigma_u = (0.177 + 0.000823 h)^0.4`` with ``h`` in
#: feet, 0.50 at 1 m.
DRYDEN_VERTICAL_RATIO = 0.5


def level(speed_m_s: float = 1.5, heading_rad: float = 0.0, altitude_m: float = 0.0) -> Task3D:
    """Straight level flight at ``speed_m_s`` (the start altitude 0 m)."""
    return Task3D("schedule", ((0.0, heading_rad, altitude_m, speed_m_s),), name=f"level {speed_m_s:g} m/s")


def turn(angle_deg: float, at_s: float = 2.0, speed_m_s: float = 1.5, climb_m: float = 0.0) -> Task3D:
    """Level flight, then at ``at_s`` a new heading ``angle_deg`` to the left (negative: right), and a new
    altitude ``climb_m`` above the start."""
    return Task3D("schedule", ((0.0, 0.0, 0.0, speed_m_s), (at_s, math.radians(angle_deg), climb_m, speed_m_s)),
                  name=f"turn {angle_deg:g} deg")


def course(seed: int, n: int = 10, spacing_m: float = 1.5, altitude_span_m: float = 0.6, speed_m_s: float = 1.5,
           radius_m: float = 0.3) -> Task3D:
    """``n`` waypoints drawn by ``seed``: each ``spacing_m`` from the last in a direction at most 90 deg
    off the previous leg's, at altitudes within ``+-altitude_span_m / 2`` of the start. ``seed``: 0 to 2^32-1."""
    seed = checks.whole("seed", seed, 0, 2**32 - 1)
    n = checks.whole("the number of waypoints n", n, 1, 10_000)
    rng = np.random.default_rng(seed)
    pts, heading, p = [], 0.0, np.zeros(3)
    for _ in range(n):
        heading += rng.uniform(-math.pi / 2, math.pi / 2)
        p = p + spacing_m * np.array([math.cos(heading), math.sin(heading), 0.0])
        p[2] = rng.uniform(-0.5, 0.5) * altitude_span_m
        pts.append(tuple(float(v) for v in p))
    return Task3D("waypoints", tuple(pts), radius_m=radius_m, speed_m_s=speed_m_s, name=f"course seed {seed}",
                  seed=seed)


def moving_target(centre_m=(3.0, 0.0, 0.0), radius_m: float = 2.0, speed_m_s: float = 0.5, bob_m: float = 0.2,
                  cruise_m_s: float = 1.5, phase_rad: float = 0.0) -> Task3D:
    """A target moving at ``speed_m_s`` round a circle of ``radius_m`` about ``centre_m`` (counter-clockwise
    seen from above), bobbing ``bob_m`` up and down twice a lap; the butterfly flies at ``cruise_m_s`` towards
    where it is now (slower when close)."""
    w = speed_m_s / checks.positive("radius_m", radius_m, "m")
    return Task3D("target", (tuple(float(v) for v in centre_m) + (float(radius_m),), (w, phase_rad, bob_m, 0.0)),
                  radius_m=0.3, speed_m_s=cruise_m_s, name=f"moving target {speed_m_s:g} m/s")


def land(flower_m, standing_m: float, radius_m: float = 0.035, speed_m_s: float = 1.0, name: str = "", *,
         flare_deg: float = LANDING["flare_deg"], flare_m: float = LANDING["flare_m"], sink_m: float = LANDING["sink_m"],
         slow_per_s: float = LANDING["slow_per_s"]) -> Task3D:
    """Land on the flower whose landing surface is at ``flower_m`` (x, y, z in m: its centre's top), standing
    ``standing_m`` above it (the thorax's height on its legs: :func:`~lifelike_mj.butterfly.flight3d.model.standing_height_m`),
    touching down within ``radius_m`` of its axis, approaching at up to ``speed_m_s``. The loop's reference lowers and
    slows the butterfly as it closes and raises its body (:data:`LANDING`: ``flare_deg``, ``flare_m``, ``sink_m``,
    ``slow_per_s``); at touchdown it perches: the network stops and the wings close over the back
    (:data:`PERCH_FLAP_RAD`) until a take-off (:meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.take_off`)."""
    x, y, z = checks.vector("flower_m", flower_m, 3, "m")
    checks.number("standing_m", standing_m, 0.0, 0.1, unit="m")
    checks.number("flare_deg", flare_deg, 0.0, 80.0, unit="deg")
    checks.number("flare_m", flare_m, 0.0, 10.0, lo_open=True, unit="m")
    checks.number("sink_m", sink_m, 0.0, 1.0, unit="m")
    checks.number("slow_per_s", slow_per_s, 0.0, 100.0, lo_open=True, unit="1/s")
    return Task3D("land", ((float(x), float(y), float(z), float(standing_m)),
                           (math.radians(flare_deg), float(flare_m), float(sink_m), float(slow_per_s))),
                  radius_m=radius_m, speed_m_s=speed_m_s, name=name or f"land at {x:.2f}, {y:.2f}, {z:.2f} m")


def new_record(n: int, max_rows: int) -> np.ndarray:
    """Empty run records (layout ``R_*`` above) for ``n`` flights."""
    rec = np.zeros((n, R_WP + max_rows))  # the gusts and the flutter start from zero
    rec[:, R_DIVERGED] = -1.0
    rec[:, R_TUMBLED] = -1.0
    rec[:, R_LANDED_AT] = -1.0
    rec[:, R_TOOK_OFF_AT] = -np.inf
    rec[:, R_WP :] = np.inf
    return rec


def start_take_off(rec: np.ndarray, t_s: float, clap_s: float = CLAP_S) -> None:
    """Mark in the run record ``rec`` (one flight's, or ``(n, ...)``) that a take-off begins at ``t_s`` (s): the wings
    clap until ``clap_s`` s later, and a controller's take-off network (if it has one) flies from now on for its
    time."""
    rec[..., R_CLAP_UNTIL] = t_s + clap_s
    rec[..., R_TOOK_OFF_AT] = t_s
