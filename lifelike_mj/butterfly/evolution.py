"""The butterfly's pitch-controller search as an optimisation problem (Oe 2010 section 6).

A genome is the 49 weights of the network of ``butterfly/ann.py``; its fitness is ``H`` of eq. 13
summed over the steps of a 20 s flight (dt = 1/1200 s, flap 10 Hz over [-60, 75] degrees), to be
maximised. :class:`PitchProblem` implements the ``evolve.Problem`` protocol: it is a small,
picklable value whose ``evaluate`` flies a whole population as one batch (parallel threads on the
paper backend, one ``mjData`` per individual on parallel threads on the MuJoCo backend).

With several :class:`Condition` s (start altitudes, winds), the fitness is the mean of ``H`` over
them: the "training over varied conditions" that section 7 proposes as future work. With
``inputs="both"`` every windy condition is flown twice, once with air-relative and once with ground
velocity inputs (section 7.2's two readings), so that one network is trained for both; the
controller file then reads relative velocities by default.

Eq. 13 rewards ground speed, so a flight into a head wind ``a`` scores at most about
``(V_REF - a)/V_REF`` of a still-air flight however well it holds, and a plain mean over winds lets
the search neglect head winds. ``weighting="ground_speed"`` divides each flight's ``H`` by that
factor (:func:`flight_weight`), so that every flight counts for about the same when it holds.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from lifelike_mj.butterfly import ann
from lifelike_mj.butterfly.backends import check_backend
from lifelike_mj.butterfly.backends.paper import constants_row, run_batch
from lifelike_mj.butterfly.controllers import ButterflyController, ann_controller
from lifelike_mj.butterfly.flight import Condition, check_timing
from lifelike_mj.butterfly.params import ButterflyParams, FlapPattern
from lifelike_mj.errors import UserError

#: Gene bounds for optimisers that need them (nlopt, CMA-ES); the RCGA starts in [-1, 1] and is
#: unbounded, as in the paper.
GENE_BOUND = 5.0
#: Eq. 13's speed scale (m/s), and the smallest ground speed a flight weight assumes (m/s).
V_REF_M_S = 3.0
V_MIN_M_S = 0.5
WEIGHTINGS = ("none", "ground_speed")
PAPER_FLAP = FlapPattern(10.0, -60.0, 75.0)


@dataclass(frozen=True)
class PitchProblem:
    """Evolve the 49 weights of the section-6 network to maximise the mean ``H`` (eq. 13)."""

    backend: str = "paper"
    conditions: tuple[Condition, ...] = (Condition(),)
    inputs: str = "relative"
    duration_s: float = 20.0
    dt_s: float = 1.0 / 1200.0
    flap: FlapPattern = PAPER_FLAP
    params: ButterflyParams = field(default_factory=ButterflyParams)
    gene_bound: float = GENE_BOUND
    weighting: str = "none"
    layers: tuple[int, ...] = ann.PAPER_LAYERS

    def __post_init__(self) -> None:
        check_backend(self.backend)
        try:
            object.__setattr__(self, "layers", ann.check_layers(self.layers))
        except ValueError as exc:
            raise UserError(f"{exc}.") from None
        if self.weighting not in WEIGHTINGS:
            raise UserError(f"weighting must be one of {', '.join(WEIGHTINGS)}, got {self.weighting!r}.")
        if self.inputs not in (*ann.INPUT_KINDS, "both"):
            raise UserError(f"inputs must be one of {', '.join(ann.INPUT_KINDS)} or both, got {self.inputs!r}.")
        if not self.conditions:
            raise UserError("an evolution needs at least one flight condition.")
        check_timing(self.duration_s, self.dt_s)

    # ---- the evolve.Problem protocol ----
    @property
    def dim(self) -> int:
        return ann.n_weights(self.layers)

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
        """Simulation steps one evaluation of a candidate takes (every flight of the task): what an evolution's
        budget is checked against (:func:`~lifelike_mj.evolve.optimizers.check_work`)."""
        return len(self.flights()) * check_timing(self.duration_s, self.dt_s)

    def describe(self) -> dict:
        """Plain-data description (what the fingerprint hashes; ``weighting`` only when not
        ``none`` and ``layers`` only when not the paper's, so that fingerprints made before either
        existed are unchanged)."""
        d = {
            "problem": "butterfly-pitch-ann",
            "backend": self.backend,
            # the key keeps its first name so that the fingerprints of earlier problems (and checkpoints) hold
            "conditions": [{"y0_m": c.y0_m, "wind_m_s": list(c.wind_from_m_s)} for c in self.conditions],
            "inputs": self.inputs,
            "duration_s": self.duration_s,
            "dt_s": self.dt_s,
            "flap": asdict(self.flap),
            "params": asdict(self.params),
            "gene_bound": self.gene_bound,
            "n_weights": self.dim,
        }
        if self.weighting != "none":
            d["weighting"] = self.weighting
        if self.layers != ann.PAPER_LAYERS:
            d["layers"] = list(self.layers)
        return d

    def fingerprint(self) -> str:
        text = json.dumps(self.describe(), sort_keys=True)
        return "butterfly-pitch-ann:" + hashlib.sha256(text.encode()).hexdigest()[:16]

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """Mean eq. 13 fitness of each row of ``X`` (n, :attr:`dim`) over the flights (weighted by
        :meth:`weights`). A flight that diverges keeps the fitness it had gathered up to then."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.dim:
            raise UserError(f"a genome has {self.dim} weights, got {X.shape[1]}.")
        n = X.shape[0]
        kind, template = self.controller(np.zeros(self.dim)).compiled()
        cp = np.repeat(template[None, :], n, axis=0)
        w0 = ann.weights_offset(self.layers)
        cp[:, w0 : w0 + self.dim] = X
        n_steps = check_timing(self.duration_s, self.dt_s)
        flights = self.flights()
        nf = len(flights)
        if self.backend == "paper":
            cps = np.tile(cp, (nf, 1))
            cps[:, ann.A_RELATIVE] = np.repeat([1.0 if rel else 0.0 for _, rel in flights], n)
            kinds = np.full(n * nf, kind, dtype=np.int64)
            flaps = np.repeat(self.flap.as_array()[None, :], n * nf, axis=0)
            airs = np.repeat(np.array([c.air_velocity() for c, _ in flights]), n, axis=0)
            y0s = np.repeat(np.array([c.y0_m for c, _ in flights], dtype=float), n)
            consts = np.repeat(constants_row(self.params)[None, :], n * nf, axis=0)
            _, _, fit = run_batch(kinds, cps, flaps, airs, y0s, consts, n_steps, self.dt_s, n_steps)
            return self.weights() @ fit.reshape(nf, n)
        from lifelike_mj.butterfly.backends.mj import fitness_batch

        fits = []
        for cond, rel in flights:
            c = cp.copy()
            c[:, ann.A_RELATIVE] = 1.0 if rel else 0.0
            fits.append(fitness_batch(c, self.flap, self.params, cond, n_steps, self.dt_s, kind=kind))
        return self.weights() @ np.asarray(fits)

    def weights(self) -> np.ndarray:
        """Weights of :meth:`flights` in the fitness, summing to 1: equal, or with
        ``weighting="ground_speed"`` proportional to :func:`flight_weight`."""
        w = np.array([flight_weight(c.wind_from_m_s[0]) if self.weighting == "ground_speed" else 1.0
                      for c, _ in self.flights()])
        return w / w.sum()

    def flights(self) -> list[tuple[Condition, bool]]:
        """The flights of one evaluation: ``(condition, air-relative inputs?)``."""
        out = []
        for c in self.conditions:
            windy = any(w != 0.0 for w in c.wind_from_m_s)
            if self.inputs == "both" and windy:
                out += [(c, True), (c, False)]
            else:
                out.append((c, self.inputs != "ground"))
        return out

    # ---- helpers ----
    def controller(self, weights, provenance: dict | None = None, name: str = "") -> ButterflyController:
        """The controller file content of a genome."""
        return ann_controller(weights, self.flap, "ground" if self.inputs == "ground" else "relative", provenance, name,
                              self.layers)


def flight_weight(head_wind_m_s: float) -> float:
    """``V_REF / max(V_REF - a, V_MIN)`` for a wind ``a`` (m/s, > 0 from the front): the inverse of the
    share of eq. 13's speed term left to a flight that holds its altitude at about ``V_REF`` air speed."""
    return V_REF_M_S / max(V_REF_M_S - head_wind_m_s, V_MIN_M_S)


def robust_conditions() -> tuple[Condition, ...]:
    """Training conditions for ``ann_robust``: start altitudes from -10 to +10 m in still air, and
    2 m/s winds from 0 m: the four of section 7.2 and two tail winds combined with wind from above
    and from below (the paper's weak corner of the E11 map)."""
    alts = (-10.0, -4.0, 0.0, 4.0, 10.0)
    winds = ((2.0, 0.0), (-2.0, 0.0), (0.0, 2.0), (0.0, -2.0), (-2.0, 1.0), (-2.0, -1.0))
    return tuple(Condition(a) for a in alts) + tuple(Condition(0.0, w) for w in winds)


def robust_wide_conditions() -> tuple[Condition, ...]:
    """:func:`robust_conditions` widened to the edge of the E11 map: 3 m/s winds from each side, and
    the tail-plus-vertical winds at 1.5 m/s vertical."""
    alts = (-10.0, -4.0, 0.0, 4.0, 10.0)
    winds = ((2.0, 0.0), (-2.0, 0.0), (0.0, 2.0), (0.0, -2.0), (3.0, 0.0), (-3.0, 0.0), (0.0, 3.0), (0.0, -3.0),
             (-2.0, 1.5), (-2.0, -1.5))
    return tuple(Condition(a) for a in alts) + tuple(Condition(0.0, w) for w in winds)


def robust_map_conditions() -> tuple[Condition, ...]:
    """Start altitudes -10 to +10 m in still air, and from 0 m winds spread over the E11 map
    (+-3 m/s): 2 and 3 m/s from each side and 2 m/s along both diagonals (12 winds)."""
    alts = (-10.0, -4.0, 0.0, 4.0, 10.0)
    winds = ((2.0, 0.0), (-2.0, 0.0), (0.0, 2.0), (0.0, -2.0), (3.0, 0.0), (-3.0, 0.0), (0.0, 3.0), (0.0, -3.0),
             (2.0, 2.0), (2.0, -2.0), (-2.0, 2.0), (-2.0, -2.0))
    return tuple(Condition(a) for a in alts) + tuple(Condition(0.0, w) for w in winds)


TASKS = ("paper", "robust", "robust_wide", "robust_map")


def make_problem(task: str = "paper", backend: str = "paper", inputs: str | None = None,
                 params: ButterflyParams | None = None, hidden=None) -> PitchProblem:
    """The network's shape is the paper's 6-6-1, or 6 inputs, the ``hidden`` layer sizes (a list, or
    text like ``"8,8"``) and one output. ``paper``: section 6.3's task (still air, from 0 m; inputs default ``relative``);
    ``robust`` / ``robust_wide``: :func:`robust_conditions` / :func:`robust_wide_conditions`
    (inputs default ``both``); ``robust_map``: :func:`robust_map_conditions`, inputs ``both``, flights
    weighted by ground speed (:func:`flight_weight`)."""
    if task not in TASKS:
        raise UserError(f"unknown task {task!r}; choose one of: {', '.join(TASKS)}.")
    conds = {"paper": (Condition(),), "robust": robust_conditions(), "robust_wide": robust_wide_conditions(),
             "robust_map": robust_map_conditions()}[task]
    if inputs is None:
        inputs = "relative" if task == "paper" else "both"
    weighting = "ground_speed" if task == "robust_map" else "none"
    return PitchProblem(backend=backend, conditions=conds, inputs=inputs, params=params or ButterflyParams(),
                        weighting=weighting, layers=_layers(hidden))


def _layers(hidden) -> tuple[int, ...]:
    if hidden is None:
        return ann.PAPER_LAYERS
    if isinstance(hidden, str):
        try:
            hidden = [int(x) for x in hidden.split(",")]
        except ValueError:
            raise UserError(f"--hidden must be layer sizes like 8,8, got {hidden!r}.") from None
    try:
        return ann.check_layers((ann.N_INPUTS, *hidden, 1))
    except ValueError as exc:
        raise UserError(f"hidden layers {list(hidden)}: {exc}.") from None


def evolve_controller(problem: PitchProblem, optimizer: str, seed: int, out: str | Path,
                      population: int | None = None, generations: int | None = None, evaluations: int | None = None,
                      executor: str = "process", workers: int | None = None, ray_address: str | None = None,
                      checkpoint: str | Path | None = None, resume: bool = False, progress: bool = True,
                      task: str = "", command: str = "", overwrite: bool = False):
    """Run an optimiser on ``problem`` and write the best network as a controller file ``out``
    (atomically, also when stopped by Ctrl-C: then with ``"interrupted": true`` in its provenance).

    Returns ``(result, controller)``; the controller is ``None`` when the run was stopped before its
    first generation was evaluated (nothing is written then). The checkpoint (default ``out`` +
    ``.ckpt``) is written every generation; ``resume`` continues from it.

    Nothing is lost: before any work, an existing ``out`` or checkpoint is refused unless ``resume`` or
    ``overwrite`` is given, a checkpoint equal to ``out`` is refused, and both files are locked for the
    whole run, so a second run on the same files stops at once with a sentence.
    """
    from lifelike_mj import __version__
    from lifelike_mj.evolve import make_evaluator, optimize
    from lifelike_mj.evolve.checkpoint import guarded_run_files
    from lifelike_mj.io import write_json

    out = Path(out)
    with guarded_run_files(out, checkpoint, resume=resume, overwrite=overwrite) as ckpt:
        with make_evaluator(problem, executor=executor, workers=workers, ray_address=ray_address) as ev:
            res = optimize(problem, optimizer, seed=seed, population=population, generations=generations,
                           evaluations=evaluations, evaluator=ev, checkpoint=ckpt, resume=resume, progress=progress,
                           overwrite=overwrite)
        if not np.all(np.isfinite(res.best_x)):
            return res, None
        ctrl = _evolved_controller(problem, res, out, task, command, generations, evaluations, executor, __version__)
        write_json(out, ctrl.to_dict())
    return res, ctrl


def _evolved_controller(problem: PitchProblem, res, out: Path, task: str, command: str, generations: int | None,
                        evaluations: int | None, executor: str, version: str):
    prov = {
        "source": "lifelike-mj butterfly evolve",
        "command": command,
        "task": task or "custom",
        "problem": problem.describe(),
        "problem_fingerprint": problem.fingerprint(),
        "optimizer": res.optimizer,
        "seed": res.seed,
        "population": res.population,
        "budget": {"generations": generations, "evaluations": evaluations},
        "generations_done": res.generations,
        "evaluations_done": res.evaluations,
        "best_fitness": float(res.best_f),
        "interrupted": bool(res.interrupted),
        "resumed": bool(res.resumed),
        "executor": executor,
        "wall_time_s": float(res.wall_time_s),
        "package_version": version,
        "created": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "fitness_history": [dict(h) for h in res.history],
    }
    return problem.controller(res.best_x, prov, out.stem)
