"""Evolving 3D controllers: tasks, the batch evaluation on MuJoCo, and the problem the optimisers solve.

A **task** (:class:`Task3D`) is what a flight is asked to do: a schedule of references (heading, altitude,
speed from given times: level flight, turns, climbs) or a course of waypoints. :class:`FlightProblem3D`
scores a controller's weights on a set of tasks at once: every (candidate, task) pair is one butterfly on
its own ``mjData``, all flown by :func:`~lifelike_mj.butterfly.control3d.fly_batch` on every core. The
score of a flight is the mean reward per second (:func:`~lifelike_mj.butterfly.control3d.reward`, in
``[0, 1]``); a flight that tumbles or diverges earns nothing after that.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly import control3d as c3
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

#: A task's most rows, and the largest number in a row (m, s, rad, m/s): far beyond a garden, finite in the loop.
MAX_TASK_ROWS = 10_000
MAX_TASK_NUMBER = 1.0e6


@dataclass(frozen=True)
class Task3D:
    """A task: ``kind="schedule"`` with rows ``(t_start_s, heading_rad, altitude_m, speed_m_s)`` (the
    reference from each row's time on; the first row's time is 0), or ``kind="waypoints"`` with rows
    ``(x, y, z)`` in m, visited in order at ``speed_m_s``, each passed when within ``radius_m``, or
    ``kind="target"``, a moving target (:func:`moving_target`).

    The weather: a mean wind ``wind_m_s`` (world frame, m/s, where it blows to) plus gusts, a first-order
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
    wind_m_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gust_m_s: float = 0.0
    gust_tau_s: float = 1.0
    flutter: float = 0.0
    flutter_tau_s: float = 0.2
    seed: int = 0
    gust_vertical_m_s: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in ("schedule", "waypoints", "target"):
            raise UserError(f"a task is a schedule, waypoints or a target, got {self.kind!r}.")
        width = 3 if self.kind == "waypoints" else 4
        if not self.rows or len(self.rows) > MAX_TASK_ROWS or any(len(r) != width for r in self.rows):
            raise UserError(f"a {self.kind} task needs 1 to {MAX_TASK_ROWS:,} rows of {width} numbers.")
        for r in self.rows:
            for v in r:
                checks.number("a task's number", v, -MAX_TASK_NUMBER, MAX_TASK_NUMBER)
        if self.kind == "schedule" and self.rows[0][0] != 0.0:
            raise UserError("a schedule's first row starts at 0 s.")
        checks.number("radius_m", self.radius_m, 0.0, 1000.0, lo_open=True, unit="m")
        checks.number("speed_m_s", self.speed_m_s, 0.0, 100.0, lo_open=True, unit="m/s")
        object.__setattr__(self, "wind_m_s", checks.vector("wind_m_s", self.wind_m_s, 3, "m/s"))
        for w in self.wind_m_s:
            checks.number("each component of wind_m_s", w, -100.0, 100.0, unit="m/s")
        checks.number("gust_m_s", self.gust_m_s, 0.0, 10.0, unit="m/s")
        checks.number("gust_tau_s", self.gust_tau_s, 0.0, 1e4, lo_open=True, unit="s")
        if self.gust_vertical_m_s is not None:
            checks.number("gust_vertical_m_s", self.gust_vertical_m_s, 0.0, 10.0, unit="m/s")
        checks.number("flutter", self.flutter, 0.0, 1.0)
        checks.number("flutter_tau_s", self.flutter_tau_s, 0.0, 1e4, lo_open=True, unit="s")
        checks.whole("seed", self.seed, 0, 2**32 - 1)

    def with_weather(self, wind_m_s=(0.0, 0.0, 0.0), gust_m_s: float = 0.0, gust_tau_s: float = 1.0,
                     flutter: float = 0.0, flutter_tau_s: float = 0.2, seed: int | None = None,
                     gust_vertical_m_s: float | None = None) -> Task3D:
        """The same task in other weather (and flutter); the seed defaults to the task's."""
        from dataclasses import replace

        return replace(self, wind_m_s=tuple(wind_m_s), gust_m_s=gust_m_s, gust_tau_s=gust_tau_s, flutter=flutter,
                       flutter_tau_s=flutter_tau_s, seed=self.seed if seed is None else seed,
                       gust_vertical_m_s=gust_vertical_m_s)

    @property
    def vertical_gust_m_s(self) -> float:
        """The vertical gusts' standard deviation (m/s)."""
        return self.gust_m_s if self.gust_vertical_m_s is None else self.gust_vertical_m_s

    def as_array(self, max_rows: int) -> np.ndarray:
        """The compiled loop's task array (:data:`~lifelike_mj.butterfly.control3d.T_KIND` ...), padded to
        ``max_rows`` rows."""
        out = np.zeros(c3.T_ROW0 + 4 * max_rows)
        out[c3.T_KIND] = {"schedule": c3.TASK_SCHEDULE, "waypoints": c3.TASK_WAYPOINTS, "target": c3.TASK_TARGET}[self.kind]
        out[c3.T_ROWS] = len(self.rows)
        out[c3.T_RADIUS] = self.radius_m
        out[c3.T_SPEED] = self.speed_m_s
        out[c3.T_WIND : c3.T_WIND + 3] = self.wind_m_s
        out[c3.T_GUST], out[c3.T_GUST_TAU], out[c3.T_GUST_W] = self.gust_m_s, self.gust_tau_s, self.vertical_gust_m_s
        out[c3.T_FLUTTER], out[c3.T_FLUTTER_TAU], out[c3.T_SEED] = self.flutter, self.flutter_tau_s, self.seed
        for i, r in enumerate(self.rows):
            out[c3.T_ROW0 + 4 * i : c3.T_ROW0 + 4 * i + len(r)] = r
        return out


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
    off the previous leg's, at altitudes within ``+-altitude_span_m / 2`` of the start."""
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


def new_record(n: int, max_rows: int) -> np.ndarray:
    """Empty run records (:data:`~lifelike_mj.butterfly.control3d.R_FIT` ...) for ``n`` flights."""
    rec = np.zeros((n, c3.R_WP + max_rows))  # the gusts and the flutter start from zero
    rec[:, c3.R_DIVERGED] = -1.0
    rec[:, c3.R_TUMBLED] = -1.0
    rec[:, c3.R_WP :] = np.inf
    return rec


@dataclass
class FlightProblem3D:
    """Evolve a 3D controller's weights (genes = weights less the ``prior``'s) to fly ``tasks`` well: the
    fitness is the mean over the tasks of the mean reward per second (``[0, 1]``, larger is better)."""

    tasks: tuple[Task3D, ...]
    template: c3.Controller3D
    duration_s: float = 4.0
    dt_s: float = 1.0 / 1200.0
    gene_bound: float = 3.0
    params: ButterflyParams = field(default_factory=ButterflyParams)
    n_strips: int = 8
    n_chord: int = 2
    force_law: str = "exact"
    prior: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        if not self.tasks:
            raise UserError("an evolution needs at least one task.")
        checks.number("duration_s", self.duration_s, 0.0, 3600.0, lo_open=True, unit="s")
        checks.number("dt_s", self.dt_s, 0.0, 0.01, lo_open=True, unit="s")
        checks.number("gene_bound", self.gene_bound, 0.0, 1e6, lo_open=True)
        checks.work(f"a training flight of {self.duration_s:g} s at {self.dt_s:g} s", checks.steps_of(self.duration_s,
                    self.dt_s), checks.MAX_BODY_STEPS, "time steps")
        if not self.prior:
            self.prior = tuple(float(v) for v in self.template.weights)
        if len(self.prior) != self.dim:
            raise UserError(f"the prior has {len(self.prior)} weights, the network {self.dim}.")
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
        return {"problem": "butterfly3d-flight", "tasks": [asdict(k) for k in self.tasks], "duration_s": self.duration_s,
                "dt_s": self.dt_s, "gene_bound": self.gene_bound, "params": asdict(self.params),
                "force_law": self.force_law, "n_strips": self.n_strips, "n_chord": self.n_chord, "layers": t["layers"],
                "base": t["base"],
                "scale": t["scale"], "every": t["every"], "omega_c_rad_s": t["omega_c_rad_s"],
                "prior_sha256": hashlib.sha256(np.asarray(self.prior).tobytes()).hexdigest()}

    def fingerprint(self) -> str:
        return hashlib.sha256(json.dumps(self.describe(), sort_keys=True).encode()).hexdigest()

    def weights(self, x: np.ndarray) -> np.ndarray:
        """The network weights of the genes ``x``."""
        return np.asarray(self.prior) + np.asarray(x, dtype=np.float64)

    def model(self):
        if self._model is None:
            from lifelike_mj.butterfly.backends import mj3d

            self._model = mj3d.build_model(self.params)
            self._model.opt.timestep = self.dt_s
        return self._model

    def fly(self, W: np.ndarray) -> np.ndarray:
        """Run records ``(n, len(tasks), ...)`` of the weights ``W`` (rows) on every task."""
        from lifelike_mj.butterfly.backends import mj3d
        from lifelike_mj.butterfly.kinematics3d import Kinematics
        from lifelike_mj.physics import mjabi
        from lifelike_mj.physics.callbacks import passive_callback
        from lifelike_mj.physics.stability import watching

        m = self.model()
        W = np.atleast_2d(np.asarray(W, dtype=np.float64))
        k = len(self.tasks)
        n = len(W) * k
        max_rows = max(len(t.rows) for t in self.tasks)
        tasks = np.tile(np.array([t.as_array(max_rows) for t in self.tasks]), (len(W), 1))
        ctl = self.template
        datas = [mj3d.setup_data(m, Kinematics(ctl.base, ctl.omega_c_rad_s), self.params, force_law=self.force_law,
                                 n_strips=self.n_strips, n_chord=self.n_chord) for _ in range(n)]
        ptrs = np.array([d._address for d in datas], dtype=np.int64)
        recs = new_record(n, max_rows)
        with passive_callback(mj3d.COMPILED_PASSIVE), watching():
            c3.fly_batch(m._address, ptrs, mjabi.offsets_tuple(), m.nq, m.nv, int(round(self.duration_s / self.dt_s)),
                         self.dt_s, ctl.every, ctl.layers, np.ascontiguousarray(np.repeat(W, k, axis=0)),
                         ctl.base.as_array(), ctl.scale, tasks, recs, c3.TUMBLE_RAD, ctl.air_inputs)
        return recs.reshape(len(W), k, -1)

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        X = np.atleast_2d(np.asarray(X, dtype=np.float64))
        recs = self.fly(np.asarray(self.prior)[None, :] + X)
        return recs[:, :, c3.R_FIT].mean(axis=1) / self.duration_s


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
}


def pd_prior(layers) -> np.ndarray:
    """The hand-made starting point of a linear controller: the feathering follows the body's pitch (1 rad of
    feathering, leading edge down, per rad nose up), which alone keeps the body upright for seconds.
    Networks with hidden layers start from zero."""
    w = np.zeros(c3.n_weights(layers))
    if len(layers) == 2:
        w[c3.ACTION_NAMES.index("feather_sym") * (c3.N_OBS + 1) + c3.OBS_NAMES.index("pitch_rad")] = 1.0
    return w


@checks.known_keywords
def evolve(tasks=None, out: str | Path = "butterfly3d.json", *, optimizer: str = "cmaes", seed: int = 0,
           layers=(10, 9), population: int | None = 16, generations: int = 300, duration_s: float = 4.0,
           gene_bound: float = 0.4, checkpoint: str | Path | None = None, resume: bool = False, progress: bool = True,
           overwrite: bool = False, task_set: str = "custom", on_generation=None, start: c3.Controller3D | None = None,
           inputs: str | None = None):
    """Evolve a 3D controller on ``tasks`` (default: the ``steer`` set) with ``optimizer`` and write it to
    ``out`` with its provenance (the problem, the optimiser, the budget, the time it took, the fitness
    history). Returns ``(result, controller)``; nothing is overwritten unasked (the checks and locks of the
    planar ``butterfly evolve``). ``start``: a controller to start from (its network, base and scales; the genes
    are then changes of its weights and ``layers`` is ignored), recorded in the provenance. ``inputs``: what the
    network's speeds are measured against (``"ground"`` or ``"air"``; default: the start's, else the ground)."""
    from lifelike_mj import provenance as _prov
    from lifelike_mj.evolve import optimize
    from lifelike_mj.evolve.checkpoint import guarded_run_files
    from lifelike_mj.io import write_json
    from lifelike_mj.machine import machine_info

    if tasks is None:
        task_set = "steer"
        tasks = TASK_SETS["steer"]()
    if start is not None:
        template = start
        layers = [int(v) for v in start.layers]
        if inputs is not None:
            template = start.with_weights(start.weights, inputs=inputs)
    else:
        layers = [int(v) for v in layers]
        template = c3.Controller3D(layers, pd_prior(layers) if len(layers) >= 2 and layers[0] == c3.N_OBS else [],
                                   inputs=inputs or "ground")
    problem = FlightProblem3D(tuple(tasks), template, duration_s=duration_s, gene_bound=gene_bound)
    out = Path(out)
    with guarded_run_files(out, checkpoint, resume=resume, overwrite=overwrite) as ckpt:
        res = optimize(problem, optimizer, seed=seed, population=population, generations=generations,
                       checkpoint=ckpt, resume=resume, progress=progress, overwrite=overwrite,
                       on_generation=on_generation)
        if not np.all(np.isfinite(res.best_x)):
            return res, None
        prov = _prov.provenance(task_set=task_set, optimizer=res.optimizer, seed=res.seed, population=res.population,
                                generations=generations, duration_s=duration_s, gene_bound=gene_bound, layers=layers)
        prov.update({"source": "lifelike-mj butterfly evolve3d", "problem": problem.describe(),
                     "problem_fingerprint": problem.fingerprint(), "generations_done": res.generations,
                     "evaluations_done": res.evaluations, "best_fitness": float(res.best_f),
                     "interrupted": bool(res.interrupted), "resumed": bool(res.resumed),
                     "evolution_wall_time_s": float(res.wall_time_s),
                     "machine": machine_info(),
                     "started_from": None if start is None else {
                         "name": start.name, **{k: v for k, v in start.provenance.items() if k != "fitness_history"}},
                     "fitness_history": [dict(h) for h in res.history]})
        ctrl = template.with_weights(problem.weights(res.best_x))
        ctrl.name = ""
        ctrl.provenance = prov
        ctrl.name = out.stem
        write_json(out, ctrl.to_dict())
    return res, ctrl
