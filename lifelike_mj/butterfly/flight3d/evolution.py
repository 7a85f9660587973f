"""Evolving 3D controllers: the problem the optimisers solve, the task sets, and :func:`evolve`.

:class:`FlightProblem3D` scores a controller's weights on a set of tasks
(:class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`) at once: every (candidate, task) pair is one butterfly
on its own ``mjData``, all flown by one :class:`~lifelike_mj.butterfly.flight3d.loop.Batch` on every core. The
score of a flight is the mean reward per second (:func:`~lifelike_mj.butterfly.flight3d.loop.reward`, in
``[0, 1]``); a flight that tumbles or diverges earns nothing after that.

With ``natural=True`` the fitness also asks the flight to look like a butterfly's (issue 27): each measure of
:data:`NATURAL` beyond its bound adds to a cost, computed from the flight's style integrals
(:data:`~lifelike_mj.butterfly.flight3d.tasks.STYLE_NAMES`) by :func:`style` and :func:`unnatural`, and each
flight's score is multiplied by ``exp(-cost)``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d import controllers as c3
from lifelike_mj.butterfly.flight3d.flight import DT_S, check_time_step
from lifelike_mj.butterfly.flight3d.loop import TUMBLE_RAD, Batch
from lifelike_mj.butterfly.flight3d.tasks import (
    DRYDEN_VERTICAL_RATIO,
    N_STYLE,
    R_FIT,
    R_LANDED_AT,
    R_NEAR_SPEED,
    R_STYLE,
    R_TOUCH_SPEED,
    R_TUMBLED,
    R_WP,
    TOUCHDOWN_M_S,
    Task3D,
    course,
    land,
    level,
    new_record,
    start_take_off,
    turn,
)
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

#: What a natural flight keeps within (issue 27), each ``(bound, cost)``: the cost per unit beyond the bound (a
#: flight's score is multiplied by ``exp(-cost)``). Sources: a filmed cruising monarch beats both wings within about 4 deg of each
#: other and stops them 35-50 deg apart at the top (the FWUAV group's fit); straight flight needs no bank; Dudley
#: (1991) puts the mechanical power of neotropical butterflies at 12.5-20.2 W/kg (perfect to no elastic storage).
#: ``stroke_top_deg``: the higher wing's top of the stroke, 67-74 deg, where the monarch's measured dorsal gap is
#: 35-50 deg (``measures``: 48.5 deg at a 68 deg top; the gap falls 2 deg per degree). ``body_angle_deg``: within
#: the bound of :func:`body_angle_target_deg` at the task's speed, on straight tasks.
NATURAL = {
    "roll_deg": (3.0, 0.05),
    "stroke_difference_deg": (4.0, 0.05),
    "offset_difference_deg": (3.0, 0.05),
    "stroke_top_deg": ((67.0, 74.0), 0.05),
    "power_W_kg": (20.2, 0.02),
    "body_angle_deg": (5.0, 0.02),
}


def body_angle_target_deg(speed_m_s: float) -> float:
    """The body angle (deg, the thorax's long axis above the horizontal) asked of straight flight at ``speed_m_s``:
    20 deg at 1 m/s, falling by 10 deg per m/s, never below 5 deg. Our choice: through the filmed monarch (18.6 deg
    at 1.3 m/s, in a slow climb) and falling towards the near-horizontal body Dudley (1990) reports in fast forward
    flight; his regression itself is not restated here."""
    return float(min(25.0, max(5.0, 20.0 - 10.0 * (speed_m_s - 1.0))))


def straight(task: Task3D) -> bool:
    """Whether ``task`` asks for straight flight: a schedule whose rows keep one heading."""
    return task.kind == "schedule" and len({round(r[1], 12) for r in task.rows}) == 1


def style(rec: np.ndarray, dt_s: float, mass_kg: float) -> dict:
    """The means of a flight's style integrals (a run record's ``R_STYLE`` slots, over the time they cover: the
    flight after its first second; a flight that ended sooner has none, and costs nothing here): mean roll
    and pitch (deg), stroke difference (deg, top to bottom: twice the amplitudes' difference), offset difference
    (deg), the higher wing's top of the stroke (deg), the drive's positive power per kg (W/kg) and the mean stroke
    times frequency (rad/s; ``2 Phi f`` in the advance ratio). The top of the stroke is the flown one, the higher
    wing's largest flap angle in each whole beat, averaged (a network that lowers the stroke's offset just as the
    wings reach the top flies a lower top than its command's mean)."""
    r = rec[R_STYLE : R_STYLE + N_STYLE]
    t = max(r[7], dt_s)  # the time the integrals cover
    m = r / t
    deg = float(np.degrees(1.0))
    top = r[4] / r[11] * deg if r[11] > 0 else 0.0
    return {"roll_deg": m[0] * deg, "pitch_deg": m[1] * deg, "stroke_difference_deg": 2.0 * m[2] * deg,
            "offset_difference_deg": m[3] * deg, "stroke_top_deg": top, "power_W_kg": m[5] / mass_kg,
            "stroke_frequency_rad_s": m[6]}


#: Straight flight slower than this (m/s) is slow flight, not cruise: asked only for level wings and even strokes. The
#: cruise's bounds (the dorsal gap, Dudley's power, the body angle) were measured in cruise; slow flight costs more
#: power, claps in climbs and raises the body (Dudley 1990), by amounts we have no measurement of.
CRUISE_FROM_M_S = 1.0


def unnatural(st: dict, task: Task3D) -> float:
    """The cost of a flight of style ``st`` (:func:`style`) on ``task`` under :data:`NATURAL` (its score is multiplied
    by ``exp(-cost)``); slow straight flight (:data:`CRUISE_FROM_M_S`) is asked only for level wings and even
    strokes."""
    def over(key: str, value: float) -> float:
        bound, c = NATURAL[key]
        return c * max(0.0, value - bound)

    (lo, hi), c_top = NATURAL["stroke_top_deg"]
    slow = straight(task) and task.rows[0][3] < CRUISE_FROM_M_S
    terms = [over("stroke_difference_deg", st["stroke_difference_deg"]),
             over("offset_difference_deg", st["offset_difference_deg"])]
    if not slow:
        terms += [c_top * (max(0.0, lo - st["stroke_top_deg"]) + max(0.0, st["stroke_top_deg"] - hi)),
                  over("power_W_kg", st["power_W_kg"])]
    if straight(task):
        terms.append(over("roll_deg", abs(st["roll_deg"])))
        if not slow:
            terms.append(over("body_angle_deg", abs(st["pitch_deg"] - body_angle_target_deg(task.rows[0][3]))))
    return sum(terms, 0.0)


def _short(v: object) -> str:
    """``repr(v)`` shortened for a sentence."""
    import reprlib

    return reprlib.repr(v)


def check_tasks(tasks: object) -> tuple[Task3D, ...]:
    """``tasks`` as a tuple of at least one :class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`, or a
    :class:`~lifelike_mj.errors.UserError` (a task set is given by its tasks: ``TASK_SETS["steer"]()``)."""
    name = tasks if isinstance(tasks, str) and tasks in TASK_SETS else "steer"
    given = None
    if not isinstance(tasks, (str, bytes, dict)):
        try:
            given = tuple(tasks)  # type: ignore[arg-type]
        except TypeError:
            pass
    if given is None or not all(isinstance(t, Task3D) for t in given):
        raise UserError(f"tasks are Task3D objects (flight3d.level, turn, course, land; a task set's are "
                        f"TASK_SETS[{name!r}]()), got {_short(tasks)}.")
    if not given:
        raise UserError("an evolution needs at least one task.")
    return given


def exercising_sets(mode: str) -> list[str]:
    """The names of the :data:`TASK_SETS` whose flights fly the behaviour ``mode`` (without ``take_off``)."""
    return [name for name, make in TASK_SETS.items() if exercised(mode, make(), False)]


def exercised(mode: str, tasks, take_off: bool) -> bool:
    """Whether a training flight on ``tasks`` (with ``take_off``: each starting perched and taking off) can fly the
    behaviour network ``mode`` (:data:`~lifelike_mj.butterfly.flight3d.controllers.MODES`; ``""``, the flight network,
    always): ``land`` flies only near a landing task's flower, ``take_off`` only after a take-off."""
    if mode == "land":
        return any(t.kind == "land" for t in tasks)
    if mode == "take_off":
        return bool(take_off)
    return True


def check_exercised(mode: str, tasks, take_off: bool, task_set: str = "") -> None:
    """Before an evolution of the behaviour ``mode``: a :class:`~lifelike_mj.errors.UserError` unless its flights
    (the task set ``task_set``, or ``tasks`` as given) fly that behaviour's network (:func:`exercised`): one that never
    flies would score every candidate alike and come out changed and untested."""
    if exercised(mode, tasks, take_off):
        return
    named = task_set and task_set != "custom"
    if mode == "take_off":
        raise UserError(f"the take_off behaviour (--mode take_off) flies only after a take-off, and no flight of "
                        f"{f'the task set {task_set!r}' if named else 'the tasks given'} takes off: add take_off=True "
                        "(--take-off), with which every task set exercises it.")
    raise UserError(f"the {mode} behaviour (--mode {mode}) flies only on landing tasks, and "
                    f"{f'the task set {task_set!r} has' if named else 'the tasks given have'} none: evolve it on a task "
                    f"set with landings ({', '.join(exercising_sets(mode))}).")


def start_blossom(animal: str) -> tuple[float, float, float]:
    """The centre of the flower a :class:`FlightProblem3D` with ``take_off`` starts on (m): right under the start, its
    butterfly's thorax at the origin standing on it."""
    from lifelike_mj.butterfly.flight3d.flowers import blossom_under
    from lifelike_mj.butterfly.flight3d.model import standing_height_m

    return tuple(float(v) for v in blossom_under((0.0, 0.0, -standing_height_m(animal))))


#: How a landing is scored (:func:`landing_score`): the scale (m) of the closest approach short of a touchdown, and the
#: scale (m/s) of the speed beyond :data:`~lifelike_mj.butterfly.flight3d.tasks.TOUCHDOWN_M_S` at the touchdown or,
#: short of one, at the closest approach.
LANDING_SCALES_M = (0.1, 0.5)


def landing_score(rec: np.ndarray) -> float:
    """A landing flight's score in ``[0, 1]`` from its run record. A touchdown scores at least 0.5, all of 1 within the
    touchdown speed bound ``TOUCHDOWN_M_S`` and less the faster beyond it (a crash at 2 m/s: 0.53); one that then
    tips over on the flower (a tumble while perched) only 0.5. A flight that
    does not touch down scores at most 0.5: by its closest approach to the point where it would stand, and half of
    that by its speed there (none after a tumble, which stops it dead), so that closing slowly pays before a
    touchdown does (:data:`LANDING_SCALES_M`)."""
    near, fast = LANDING_SCALES_M

    def slow(v: float) -> float:
        return float(np.exp(-max(0.0, v - TOUCHDOWN_M_S) / fast)) if np.isfinite(v) else 0.0

    if rec[R_LANDED_AT] >= 0.0:
        return 0.5 + (0.0 if rec[R_TUMBLED] >= 0 else 0.5 * slow(rec[R_TOUCH_SPEED]))
    near_speed = np.inf if rec[R_TUMBLED] >= 0 else rec[R_NEAR_SPEED]
    return 0.5 * float(np.exp(-rec[R_WP] / near)) * (0.5 + 0.5 * slow(near_speed))


@dataclass
class FlightProblem3D:
    """Evolve a 3D controller's weights (genes = weights less the ``prior``'s) to fly ``tasks`` well: the
    fitness is the mean over the tasks of the mean reward per second (``[0, 1]``, larger is better). With
    ``take_off`` every flight starts standing on a flower at the start (:func:`start_blossom`), its wings at the top
    of the stroke, and takes off clapping, as a garden's perched butterflies do
    (:meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.take_off`); the flowers of the landing tasks are in its
    world too, touched by its legs (:meth:`flowers`). With ``mode`` (a behaviour,
    :data:`~lifelike_mj.butterfly.flight3d.controllers.MODES`) the genes are that behaviour network's weights (less the
    prior: the template's own for it, else its flight network's), the template's other networks flying as they are."""

    tasks: tuple[Task3D, ...]
    template: c3.Controller3D
    duration_s: float = 4.0
    dt_s: float = DT_S
    gene_bound: float = 3.0
    params: ButterflyParams = field(default_factory=ButterflyParams)
    n_strips: int = 8
    n_chord: int = 2
    force_law: str = "exact"
    prior: tuple[float, ...] = ()
    natural: bool = False
    take_off: bool = False
    mode: str = ""

    def __post_init__(self) -> None:
        from lifelike_mj.butterfly.flight3d.model import _check_panels

        self.tasks = check_tasks(self.tasks)
        if not isinstance(self.template, c3.Controller3D):
            raise UserError(f"the template is a 3D controller (Controller3D, load_controller), got "
                            f"{_short(self.template)}.")
        if not isinstance(self.params, ButterflyParams):
            raise UserError(f"params is a ButterflyParams, got {_short(self.params)}.")
        if self.force_law not in c3.FORCE_LAWS_FLOWN:
            raise UserError(f"force_law is {', '.join(repr(v) for v in c3.FORCE_LAWS_FLOWN)}, got {_short(self.force_law)}.")
        _check_panels(self.n_strips, self.n_chord)
        self.natural = checks.flag("natural", self.natural)
        self.take_off = checks.flag("take_off", self.take_off)
        if not isinstance(self.mode, str) or (self.mode and self.mode not in c3.MODES):
            raise UserError(f"mode is '' (the flight network) or one of {', '.join(c3.MODES)}, got {_short(self.mode)}.")
        if self.mode and self.mode not in self.template.modes:
            raise UserError(f"the {self.mode} behaviour to evolve is not in the controller (give it with_mode first).")
        check_exercised(self.mode, self.tasks, self.take_off)
        checks.number("duration_s", self.duration_s, 0.0, 3600.0, lo_open=True, unit="s")
        checks.number("dt_s", self.dt_s, 0.0, 0.01, lo_open=True, unit="s")
        check_time_step(self.dt_s, self.template.base.frequency_hz, "dt_s")
        checks.number("gene_bound", self.gene_bound, 0.0, 1e6, lo_open=True)
        checks.work(f"a training flight of {self.duration_s:g} s at {self.dt_s:g} s", checks.steps_of(self.duration_s,
                    self.dt_s), checks.MAX_BODY_STEPS, "time steps")
        if self.prior is None or (hasattr(self.prior, "__len__") and len(self.prior) == 0):
            self.prior = tuple(float(v) for v in (self.template.mode_weights(self.mode) if self.mode
                                                  else self.template.weights))
        try:
            prior = np.asarray(self.prior, dtype=np.float64)
        except (TypeError, ValueError):
            prior = np.full(1, np.nan)
        if prior.ndim != 1 or len(prior) != self.dim or not np.all(np.abs(prior) <= c3.MAX_WEIGHT):
            raise UserError(f"the prior must be the network's {self.dim} weights, each a finite number within "
                            f"+-{c3.MAX_WEIGHT:g}, got {_short(self.prior)}.")
        self.prior = tuple(float(v) for v in prior)
        self._model = None

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_model"] = None  # a compiled model is rebuilt in each process
        return state

    @property
    def dim(self) -> int:
        return c3.n_weights(self.template.layers)

    @property
    def lower(self) -> np.ndarray:
        return np.full(self.dim, -self.gene_bound)

    @property
    def upper(self) -> np.ndarray:
        return np.full(self.dim, self.gene_bound)

    @property
    def maximize(self) -> bool:
        return True

    @property
    def steps_per_candidate(self) -> int:
        """Simulation steps one evaluation of a candidate takes (one flight per task): what an evolution's budget
        is checked against (:func:`~lifelike_mj.evolve.optimizers.check_work`)."""
        return len(self.tasks) * checks.steps_of(self.duration_s, self.dt_s)

    def describe(self) -> dict:
        t = self.template.to_dict()
        # each task's wind keeps its first key, wind_m_s (where it blows to), so that the fingerprints of earlier
        # problems (and their checkpoints) hold
        tasks = [{("wind_m_s" if k == "wind_to_m_s" else k): v for k, v in asdict(t).items()} for t in self.tasks]
        return {"problem": "butterfly3d-flight", "tasks": tasks, "duration_s": self.duration_s,
                "dt_s": self.dt_s, "gene_bound": self.gene_bound, "params": asdict(self.params),
                "force_law": self.force_law, "n_strips": self.n_strips, "n_chord": self.n_chord, "layers": t["layers"],
                "base": t["base"],
                "scale": t["scale"], "every": t["every"], "omega_c_rad_s": t["omega_c_rad_s"],
                "prior_sha256": hashlib.sha256(np.asarray(self.prior).tobytes()).hexdigest(),
                # the butterfly and the naturalness asked, named where they are new (earlier fingerprints hold)
                **({"animal": self.template.animal} if self.template.animal != "swallowtail" else {}),
                **({"take_off": True} if self.take_off else {}),
                **({"mode": self.mode, "reach": self.template.modes[self.mode][c3.MODES[self.mode]],
                    "all_weights_sha256": hashlib.sha256(self.template.all_weights().tobytes()).hexdigest()}
                   if self.mode else {}),
                **({"natural": {k: list(v) if isinstance(v, tuple) else v for k, v in NATURAL.items()}}
                   if self.natural else {})}

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.describe(), sort_keys=True).encode()).hexdigest()

    def weights(self, x: np.ndarray) -> np.ndarray:
        """The network weights of the genes ``x`` (of the behaviour ``mode``, with one)."""
        return np.asarray(self.prior) + np.asarray(x, dtype=np.float64)

    def controller(self, x: np.ndarray) -> c3.Controller3D:
        """The controller of the genes ``x``: the template with the evolved network's weights."""
        w = self.weights(x)
        return self.template.with_mode(self.mode, w) if self.mode else self.template.with_weights(w)

    def all_weights(self, W: np.ndarray) -> np.ndarray:
        """The compiled loop's weights (the template's ``all_weights`` layout), one row per row of network weights
        ``W`` (of the behaviour ``mode``, with one)."""
        k = c3.NETWORKS.index(self.mode or "flight")
        n = self.dim
        rows = np.tile(self.template.all_weights(), (len(W), 1))
        rows[:, k * n : (k + 1) * n] = W
        return rows

    def model(self):
        if self._model is None:
            from lifelike_mj.butterfly.flight3d import model as mj3d

            self._model = mj3d.build_model(self.params, animal=self.template.animal, flowers=self.flowers())
            self._model.opt.timestep = self.dt_s
        return self._model

    def flowers(self) -> list[tuple[float, float, float]] | None:
        """The flowers of the training flights' world (blossom centres, m): with ``take_off``, the one they start
        on and those the landing tasks land on, which their legs touch as in a garden; else none."""
        if not self.take_off:
            return None
        from lifelike_mj.butterfly.flight3d.flowers import blossom_under

        return [start_blossom(self.template.animal)] + [tuple(float(v) for v in blossom_under(t.rows[0][:3]))
                                                        for t in self.tasks if t.kind == "land"]

    def fly(self, W: np.ndarray, steps: int | None = None) -> np.ndarray:
        """Run records ``(n, len(tasks), ...)`` of the weights ``W`` (rows) on every task (``steps``: that many
        steps of each flight instead of its whole duration)."""
        from lifelike_mj.butterfly.flight3d import model as mj3d
        from lifelike_mj.butterfly.flight3d.kinematics import Kinematics

        m = self.model()
        W = np.atleast_2d(np.asarray(W, dtype=np.float64))
        k = len(self.tasks)
        n = len(W) * k
        max_rows = max(len(t.rows) for t in self.tasks)
        tasks = np.tile(np.array([t.as_array(max_rows) for t in self.tasks]), (len(W), 1))
        ctl = self.template
        datas = [mj3d.setup_data(m, Kinematics(ctl.base, ctl.omega_c_rad_s), self.params, force_law=self.force_law,
                                 n_strips=self.n_strips, n_chord=self.n_chord, animal=ctl.animal) for _ in range(n)]
        records = new_record(n, max_rows)
        if self.take_off:
            start_take_off(records, 0.0)
        batch = Batch(m, datas, tasks, ctl, weights=np.repeat(self.all_weights(W), k, axis=0), dt_s=self.dt_s,
                      records=records, tumble_rad=TUMBLE_RAD)
        batch.advance(int(round(self.duration_s / self.dt_s)) if steps is None else int(steps))
        return batch.records.reshape(len(W), k, -1)

    def compile_here(self) -> None:
        """Compile the flights' kernels in this process, saying so on a first run (a cold cache): two candidates flown
        one step. A pool's workers started after it load them from the cache instead of each compiling its own in
        silence (about 20-40 s each on two cores)."""
        self.fly(np.zeros((2, len(self.prior))), steps=1)

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        recs = self.fly(np.asarray(self.prior)[None, :] + X)
        landing = [t.kind == "land" for t in self.tasks]
        if not self.natural and not any(landing):
            return recs[:, :, R_FIT].mean(axis=1) / self.duration_s
        # each flight's score shrinks by exp(-cost): a flight that ends early (a tumble) keeps the little it earned,
        # so that falling is never a way out of looking unnatural; a landing is scored by landing_score alone
        mass = float(self.model().body_subtreemass[1])

        def score(r, t, lands):
            if lands:
                return landing_score(r)
            cost = unnatural(style(r, self.dt_s, mass), t) if self.natural else 0.0
            return r[R_FIT] / self.duration_s * np.exp(-cost)

        return np.array([np.mean([score(r, t, k) for r, t, k in zip(row, self.tasks, landing)]) for row in recs])


#: The gusts of the ``wind`` task set: 0.5 m/s (horizontal), half that vertically (:data:`DRYDEN_VERTICAL_RATIO`).
_GUSTS = {"gust_m_s": 0.5, "gust_vertical_m_s": 0.5 * DRYDEN_VERTICAL_RATIO}

#: The task sets the shipped controllers are evolved on (``evolve3d --tasks``).
TASK_SETS = {
    "steer": lambda: (level(1.0), level(2.0), turn(90.0, 1.5, 1.5), turn(-180.0, 1.5, 1.5, 0.3)),
    "cruise": lambda: (level(1.5), level(2.0), turn(90.0, 1.5, 1.5), turn(-180.0, 1.5, 1.5, 0.3),
                       level(1.5).with_weather((0.0, 1.0, 0.0), gust_m_s=0.5, seed=1),
                       turn(-90.0, 1.5, 1.5).with_weather((-1.0, 0.0, 0.0), gust_m_s=0.5, seed=2)),
    "wind": lambda: (course(1).with_weather((1.0, 0.0, 0.0), **_GUSTS, seed=1),
                     course(2).with_weather((0.0, -1.0, 0.0), **_GUSTS, seed=2),
                     course(3).with_weather((-1.0, 0.0, 0.0), **_GUSTS, seed=3),
                     course(4).with_weather((0.0, 1.0, 0.0), **_GUSTS, seed=4),
                     course(5), turn(-180.0, 1.5, 1.5, 0.3),
                     level(1.5).with_weather((0.7, 0.7, 0.0), **_GUSTS, seed=6)),
    # the monarch's, with --natural: straight flight at three speeds (the body angle falling with them), the turns,
    # a calm course and one in 1 m/s wind with gusts of 0.5 m/s on every axis
    "natural": lambda: (level(1.0), level(1.5), level(2.0), turn(90.0, 1.5, 1.5), turn(-180.0, 1.5, 1.5, 0.3), course(5),
                        course(1).with_weather((1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5, seed=1)),
    # the monarch's fast cruise, with --natural: level from 1 to 3 m/s (J passes 0.9 near 2.3 m/s), the turn, a calm
    # course, one in 1 m/s wind with gusts on every axis, one in a steady 1.5 m/s wind
    "fast": lambda: (level(1.0), level(1.5), level(2.0), level(2.5), level(3.0), turn(90.0, 1.5, 1.5), course(5),
                     course(1).with_weather((1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5, seed=1),
                     course(3).with_weather((-1.5, 0.0, 0.0), seed=3)),
    # the steer set and three calm courses, whose sharp turns teach a controller to bank without tumbling
    "agile": lambda: (level(1.0), level(2.0), turn(90.0, 1.5, 1.5), turn(-180.0, 1.5, 1.5, 0.3), course(1), course(2),
                      course(3)),
    # everything a monarch in a garden does, with --natural: straight flight from slow (0.4 m/s, as before a landing)
    # to fast (2.5 m/s, where J passes 0.9), the turns, a calm course, a course in 1 m/s wind with gusts of 0.5 m/s on
    # every axis and one in a steady 1.5 m/s wind, and three landings on flowers (scored by landing_score)
    "garden": lambda: (level(0.4), level(1.0), level(2.0), level(2.5), turn(90.0, 1.5, 1.5), turn(-180.0, 1.5, 1.5, 0.3),
                       course(5),
                       course(1).with_weather((1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5, seed=1),
                       course(3).with_weather((-1.5, 0.0, 0.0), seed=3),
                       *_landings()),
    # a landing behaviour's (evolve3d --mode land; with --take-off, a take-off's): six flowers all round the start,
    # three near (0.9-1.4 m) and three far (2.7-3.5 m, reached at cruising speed), from 0.15 m below to 0.2 m above it
    "landings": lambda: _landings(_LANDING_POINTS),
    # the same and six more all round, 1.0-3.4 m away, from 0.25 m below to 0.3 m above: twice the flowers, for a
    # landing that must not learn six approaches by heart
    "landings12": lambda: _landings(_LANDING_POINTS + ((-0.3, -1.0, -0.25), (1.0, 1.2, 0.25), (-2.2, -0.4, -0.2),
                                                        (0.5, 2.8, 0.15), (2.0, -2.2, -0.05), (-3.0, 1.5, 0.3))),
}


#: The landing surfaces (m) of the ``garden`` set's flowers and of the ``landings`` set's.
_GARDEN_LANDING_POINTS = ((1.2, 0.3, -0.15), (0.7, -0.6, 0.05), (0.4, 1.0, -0.3))
_LANDING_POINTS = ((1.2, 0.3, -0.15), (0.7, -0.6, 0.05), (-0.8, 0.6, 0.0), (2.5, 1.0, -0.1), (-1.5, -2.5, 0.1),
                   (3.5, -0.5, 0.2))


def _landings(points=_GARDEN_LANDING_POINTS) -> tuple[Task3D, ...]:
    """Monarch landings on flowers whose landing surfaces are at ``points`` (m); by default the ``garden`` set's three,
    ahead, left and right, below and above the start, 0.9-1.4 m away."""
    from lifelike_mj.butterfly.flight3d.model import standing_height_m

    h = standing_height_m("monarch")
    return tuple(land(p, h) for p in points)


class _Spread:
    """An evaluator that passes each batch of candidates on to ``evaluator`` unchanged and keeps the lowest and the
    highest score it returned (NaN counted as the worst, as the optimisers count it), for :func:`evolve` to tell a run
    whose candidates all scored the same (:meth:`all_same`)."""

    def __init__(self, evaluator) -> None:
        self.evaluator = evaluator
        self.problem = getattr(evaluator, "problem", None)
        self.n, self.lo, self.hi = 0, np.inf, -np.inf

    def __call__(self, X: np.ndarray) -> np.ndarray:
        f = self.evaluator(X)
        g = np.asarray(f, dtype=np.float64).reshape(-1)
        if len(g):
            g = np.where(np.isnan(g), -np.inf, g)
            self.n += len(g)
            self.lo, self.hi = min(self.lo, float(g.min())), max(self.hi, float(g.max()))
        return f

    def all_same(self, history: list[dict]) -> float | None:
        """The score every candidate of the run got, if they all got the same one; else ``None``. The candidates this
        evaluator saw must all have scored alike, and every generation's record (those of a resumed run's earlier
        sessions too) must say the same: its best so far that score, its mean that score to the rounding of a mean."""
        import math

        if self.n and self.lo != self.hi:
            return None
        if not self.n and not history:
            return None
        v = self.hi if self.n else float(history[0]["best"])
        for h in history:
            if h["best"] != v or not math.isclose(h["mean"], v, rel_tol=1e-12, abs_tol=0.0):
                return None
        return v


def pd_prior(layers, animal: str = "swallowtail") -> np.ndarray:
    """The hand-made starting point of a linear controller. The swallowtail: the feathering follows the body's
    pitch (1 rad of feathering, leading edge down, per rad nose up), which alone keeps the body upright for
    seconds. The monarch, whose body turns about five times faster in pitch: the stroke's offset follows the
    pitch and its rate (3 per rad, 1.5 per 10 rad/s; a lower stroke pitches the body up), and the frequency the
    altitude and the climb (both -1), which keep it upright and flying for the 4 s of a training flight (it still
    sinks about 0.4 m/s). Networks with hidden layers start from zero."""
    w = np.zeros(c3.n_weights(layers))
    if len(layers) != 2:
        return w

    def at(action, obs):
        return c3.ACTION_NAMES.index(action) * (layers[0] + 1) + c3.OBS_NAMES.index(obs)

    if animal == "monarch":
        w[at("offset_sym", "pitch_rad")] = 3.0
        w[at("offset_sym", "pitch_rate_rad_s")] = 1.5
        w[at("frequency", "altitude_error_m")] = -1.0
        w[at("frequency", "climb_m_s")] = -1.0
    else:
        w[at("feather_sym", "pitch_rad")] = 1.0
    return w


@checks.known_keywords
def evolve(tasks=None, out: str | Path = "butterfly3d.json", *, optimizer: str = "cmaes", seed: int = 0,
           layers=(10, 9), population: int | None = 16, generations: int = 300, duration_s: float = 4.0,
           gene_bound: float = 0.4, checkpoint: str | Path | None = None, resume: bool = False, progress: bool = True,
           overwrite: bool = False, task_set: str = "custom", on_generation=None, start: c3.Controller3D | None = None,
           inputs: str | None = None, executor: str = "serial", workers: int | None = None,
           ray_address: str | None = None, dt_s: float = DT_S, animal: str | None = None, natural: bool = False,
           force_law: str | None = None, take_off: bool = False, mode: str | None = None,
           reach: float | None = None, speed_input: bool = False):
    """Evolve a 3D controller on ``tasks`` (default: the ``steer`` set) with ``optimizer`` and write it to
    ``out`` with its provenance (the problem, the optimiser, the budget, the time it took, the fitness
    history). Returns ``(result, controller)``; nothing is overwritten unasked (the checks and locks of the
    planar ``butterfly evolve``). ``start``: a controller to start from (its network, base and scales; the genes
    are then changes of its weights and ``layers`` is ignored), recorded in the provenance. ``inputs``: what the
    network's speeds are measured against (``"ground"`` or ``"air"``; default: the start's, else the ground).
    ``executor``: where a generation's flights run, as for the planar evolution
    (:func:`~lifelike_mj.evolve.make_evaluator`): ``"serial"`` (this process, which flies the whole generation on
    every core: the fastest on one machine), ``"process"`` (a pool of ``workers`` processes, one thread each) or
    ``"ray"`` (a Ray cluster, ``ray_address`` to join one). Every executor gives the same result for the same
    seed, bit for bit: each flight is independent of how the generation is split. ``dt_s``: the time step of the
    training flights (default :data:`~lifelike_mj.butterfly.flight3d.flight.DT_S`). ``animal``: the butterfly
    (:data:`~lifelike_mj.butterfly.flight3d.animals.ANIMALS`; default the start's, else the swallowtail); a new
    controller starts from that butterfly's base kinematics
    (:func:`~lifelike_mj.butterfly.flight3d.controllers.default_base`) and prior (:func:`pd_prior`). ``natural``:
    the fitness also asks for :data:`NATURAL` (module docstring). ``force_law``: the wing-force law of the training
    flights, recorded in the controller (default the start's, else ``"exact"``). ``take_off``: every training flight
    starts perched on a flower and takes off (:class:`FlightProblem3D`). ``mode``: evolve the start's behaviour network
    of that name (:data:`~lifelike_mj.butterfly.flight3d.controllers.MODES`; it starts from the start's own, else
    from its flight network) with the reach ``reach`` (m or s; default: the start's, else
    :data:`~lifelike_mj.butterfly.flight3d.controllers.MODE_REACH`); its other networks fly as they are.
    ``speed_input``: the networks also see the forward speed asked (the eleventh observation of
    :mod:`~lifelike_mj.butterfly.flight3d.controllers`): a new controller's ``layers`` then start at 11, a start's
    networks gain the input with zero weights (:meth:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D.
    with_speed_input`).

    Refused before any work, each with one sentence (:class:`~lifelike_mj.errors.UserError`): a flag (``natural``,
    ``take_off``, ``speed_input``, ``resume``, ``progress``, ``overwrite``) that is not ``True`` or ``False`` (a string
    such as ``"no"`` would switch it on), ``tasks`` that are not :class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`
    objects, and a ``mode`` whose network the tasks never fly (:func:`check_exercised`: ``land`` needs landing tasks,
    ``take_off`` needs ``take_off=True``). A run whose candidates all scored the same (changing the network evolved
    changed no score) ends in a :class:`~lifelike_mj.errors.UserError` saying so, not in a result: no controller is
    written, and the checkpoint it started is removed (a resumed one is kept)."""
    from lifelike_mj import provenance as _prov
    from lifelike_mj.evolve import make_evaluator, optimize
    from lifelike_mj.evolve.checkpoint import guarded_run_files
    from lifelike_mj.io import write_json
    from lifelike_mj.machine import machine_info

    # natural and take_off are FlightProblem3D's, checked there
    speed_input, resume, progress, overwrite = (checks.flag("speed_input", speed_input), checks.flag("resume", resume),
                                                checks.flag("progress", progress), checks.flag("overwrite", overwrite))
    if not isinstance(task_set, str):
        raise UserError(f"task_set is the name the provenance gives the tasks (a text), got {_short(task_set)}.")
    if on_generation is not None and not callable(on_generation):
        raise UserError(f"on_generation is a function of each generation's record, got {_short(on_generation)}.")
    for key, path in (("out", out), ("checkpoint", checkpoint)):
        if not (isinstance(path, (str, Path)) or (key == "checkpoint" and path is None)):
            raise UserError(f"{key} is the path of a file (a text or a Path), got {_short(path)}.")
    if start is not None and not isinstance(start, c3.Controller3D):
        raise UserError(f"start is a 3D controller (load_controller('monarch')), got {_short(start)}.")
    if tasks is None:
        task_set = "steer"
        tasks = TASK_SETS["steer"]()
    tasks = check_tasks(tasks)
    if mode is not None and mode not in c3.MODES:
        raise UserError(f"the behaviour to evolve is {' or '.join(c3.MODES)}, got {mode!r}.")
    if mode is not None and start is None:
        raise UserError(f"evolving the {mode} behaviour needs a controller to start from, whose flight network flies "
                        "the rest.")
    if mode is not None:
        check_exercised(mode, tasks, take_off, task_set)
    if start is not None:
        template = start.with_speed_input() if speed_input else start
        layers = [int(v) for v in template.layers]
        if inputs is not None or animal is not None or force_law is not None:
            template = template.replace(inputs=inputs or start.inputs, animal=animal or start.animal,
                                        force_law=force_law or start.force_law)
        if mode is not None:
            template = template.with_mode(mode, template.mode_weights(mode), reach)
    else:
        layers = c3._check_layers(layers, "3D controller")
        if speed_input and layers:
            layers[0] = c3.N_OBS
        animal = animal or "swallowtail"
        template = c3.Controller3D(layers, pd_prior(layers, animal) if len(layers) >= 2 and layers[0] in c3.INPUT_COUNTS
                                   else [], c3.default_base(animal), inputs=inputs or "ground", animal=animal,
                                   force_law=force_law or "exact")
    problem = FlightProblem3D(tasks, template, duration_s=duration_s, gene_bound=gene_bound, dt_s=dt_s,
                              natural=natural, force_law=template.force_law, take_off=take_off, mode=mode or "")
    out = Path(out)
    with guarded_run_files(out, checkpoint, resume=resume, overwrite=overwrite) as ckpt:
        started_here = not (resume and ckpt.exists())
        if executor != "serial":
            problem.compile_here()
        with make_evaluator(problem, executor=executor, workers=workers, ray_address=ray_address) as ev:
            spread = _Spread(ev)
            res = optimize(problem, optimizer, seed=seed, population=population, generations=generations,
                           evaluator=spread, checkpoint=ckpt, resume=resume, progress=progress, overwrite=overwrite,
                           on_generation=on_generation)
        if not np.all(np.isfinite(res.best_x)):
            return res, None
        same = spread.all_same(res.history)
        if same is not None:
            if started_here:
                ckpt.unlink(missing_ok=True)
            raise UserError(f"every one of the {res.evaluations:,} candidates of this evolution scored {same:.6g}: "
                            f"changing its {mode or 'flight'} network changed no score (are its flights, "
                            f"{duration_s:g} s each, long enough to fly it?), so "
                            + ("nothing was written." if started_here else "no controller was written."))
        prov = _prov.provenance(task_set=task_set, optimizer=res.optimizer, seed=res.seed, population=res.population,
                                generations=generations, duration_s=duration_s, gene_bound=gene_bound, layers=layers)
        prov.update({"source": "lifelike-mj butterfly evolve3d", "problem": problem.describe(),
                     "problem_fingerprint": problem.fingerprint(), "generations_done": res.generations,
                     "evaluations_done": res.evaluations, "best_fitness": float(res.best_f),
                     "interrupted": bool(res.interrupted), "resumed": bool(res.resumed),
                     "evolution_wall_time_s": float(res.wall_time_s), "executor": executor,
                     "machine": machine_info(),
                     "started_from": None if start is None else {
                         "name": start.name, **{k: v for k, v in start.provenance.items() if k != "fitness_history"}},
                     "fitness_history": [dict(h) for h in res.history]})
        ctrl = problem.controller(res.best_x)
        ctrl.name = ""
        ctrl.provenance = prov
        ctrl.name = out.stem
        write_json(out, ctrl.to_dict())
    return res, ctrl
