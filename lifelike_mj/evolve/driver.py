"""Book-keeping shared by every optimiser: evaluations, best so far, history, progress bar, checkpoints."""

from __future__ import annotations

import copy
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lifelike_mj.evolve.checkpoint import check_compatible, load_checkpoint, save_checkpoint
from lifelike_mj.evolve.problem import worst_value


@dataclass(frozen=True, eq=False)
class OptimizationResult:
    """Outcome of :func:`lifelike_mj.evolve.optimize`.

    Attributes:
        optimizer, seed: as requested.
        population: the population size used (for ``cmaes`` the first run's; IPOP restarts double it).
        best_x: best genes found, ``(dim,)`` (all NaN if nothing was evaluated).
        best_f: their fitness in the problem's own sign (NaN if nothing was evaluated).
        evaluations: calls of the fitness function on one candidate, summed over sessions.
        generations: completed generations (for nlopt: blocks of ``population`` evaluations).
        history: one dict per generation: ``generation`` (1-based), ``best`` (best so far), ``mean``
            (mean fitness of that generation), ``evaluations`` (cumulative), ``elapsed_s`` (optimisation
            seconds since the run started, summed over sessions).
        wall_time_s: seconds spent in this call.
        interrupted: stopped by Ctrl-C/SIGTERM (or a KeyboardInterrupt from ``on_generation``).
        resumed: continued from a checkpoint.
    """

    optimizer: str
    seed: int
    population: int
    best_x: np.ndarray
    best_f: float
    evaluations: int
    generations: int
    history: list[dict[str, Any]] = field(repr=False)
    wall_time_s: float
    interrupted: bool
    resumed: bool

    def to_dict(self) -> dict[str, Any]:
        """JSON-able dict of every field (``best_x`` as a list; non-finite floats stay floats)."""
        return {
            "optimizer": self.optimizer,
            "seed": int(self.seed),
            "population": int(self.population),
            "best_x": [float(v) for v in np.asarray(self.best_x).reshape(-1)],
            "best_f": float(self.best_f),
            "evaluations": int(self.evaluations),
            "generations": int(self.generations),
            "history": [{k: (float(v) if isinstance(v, (float, np.floating)) else int(v) if isinstance(v, (int, np.integer))
                             else v) for k, v in rec.items()} for rec in self.history],
            "wall_time_s": float(self.wall_time_s),
            "interrupted": bool(self.interrupted),
            "resumed": bool(self.resumed),
        }


@dataclass(frozen=True)
class Budget:
    """How long to run: ``kind`` is ``"generations"`` or ``"evaluations"``, ``value`` a positive int."""

    kind: str
    value: int

    def as_dict(self) -> dict[str, Any]:
        return {"kind": self.kind, "value": int(self.value)}


class Run:
    """State common to all optimisers within one :func:`optimize` call.

    Optimisers call :meth:`evaluate` (or :meth:`observe` for values they already know) and, after each
    generation, :meth:`end_generation` with the generation's mean fitness and their own state; this
    appends the history record, writes the checkpoint, advances the progress bar and calls
    ``on_generation``. ``state`` holds the optimiser state read from a checkpoint (``None`` on a fresh run).
    """

    def __init__(self, problem: Any, evaluator: Callable[[np.ndarray], np.ndarray] | None, *, dim: int, optimizer: str,
                 seed: int, population: int, budget: Budget, checkpoint: str | Path | None, progress: bool,
                 on_generation: Callable[[dict[str, Any]], object] | None) -> None:
        self.problem = problem
        self.evaluator = evaluator
        self.dim = dim
        self.maximize = bool(problem.maximize)
        self.fingerprint = str(problem.fingerprint())
        self.optimizer = optimizer
        self.seed = seed
        self.population = population
        self.budget = budget
        self.checkpoint = Path(checkpoint) if checkpoint is not None else None
        self.progress = progress
        self.on_generation = on_generation
        self.history: list[dict[str, Any]] = []
        self.best_x: np.ndarray | None = None
        self.best_f = math.nan
        self.evaluations = 0
        self.elapsed_before = 0.0
        self.state: dict[str, Any] | None = None
        self.resumed = False
        self.finished = False
        self._t0 = time.perf_counter()
        self._bar: Any = None

    # --- fitness ---------------------------------------------------------------------------------

    def better(self, a: float, b: float) -> bool:
        """``a`` strictly better than ``b`` in the problem's direction."""
        return a > b if self.maximize else a < b

    def sanitize(self, f: np.ndarray) -> np.ndarray:
        """NaN fitness counts as the worst possible value (``-inf`` when maximising, ``+inf`` otherwise)."""
        bad = np.isnan(f)
        if bad.any():
            f = f.copy()
            f[bad] = worst_value(self.maximize)
        return f

    def best_index(self, f: np.ndarray) -> int:
        """Index of the best value of ``f`` (the first one on ties)."""
        return int(np.argmax(f) if self.maximize else np.argmin(f))

    def observe(self, X: np.ndarray, f: np.ndarray) -> None:
        """Count ``len(f)`` evaluations and update the best so far (a tie keeps the older one)."""
        if len(f) == 0:
            return
        self.evaluations += len(f)
        i = self.best_index(f)
        if self.best_x is None or self.better(float(f[i]), self.best_f):
            self.best_f = float(f[i])
            self.best_x = np.array(X[i], dtype=np.float64, copy=True)

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """Evaluate the rows of ``X`` through the evaluator; count them and track the best."""
        X = np.ascontiguousarray(X, dtype=np.float64)
        f = np.asarray(self.evaluator(X), dtype=np.float64)
        if f.shape != (X.shape[0],):
            raise ValueError(f"the evaluator returned shape {f.shape} for {X.shape[0]} candidates")
        f = self.sanitize(f)
        self.observe(X, f)
        return f

    # --- generations -----------------------------------------------------------------------------

    @property
    def generations(self) -> int:
        return len(self.history)

    def elapsed(self) -> float:
        """Optimisation seconds since the run started, summed over sessions."""
        return self.elapsed_before + (time.perf_counter() - self._t0)

    def budget_reached(self) -> bool:
        if self.budget.kind == "generations":
            return self.generations >= self.budget.value
        return self.evaluations >= self.budget.value

    def end_generation(self, mean: float, state: dict[str, Any]) -> None:
        """Record a finished generation, checkpoint ``state``, advance the progress bar, call ``on_generation``."""
        record = {"generation": self.generations + 1, "best": float(self.best_f), "mean": float(mean),
                  "evaluations": int(self.evaluations), "elapsed_s": float(self.elapsed())}
        self.history.append(record)
        self.finished = self.budget_reached()
        self.save(state)
        if self._bar is not None:
            done = self.generations if self.budget.kind == "generations" else min(self.evaluations, self.budget.value)
            self._bar.update(done - self._bar.n)
            self._bar.set_postfix(best=f"{record['best']:.6g}", mean=f"{record['mean']:.6g}", evals=record["evaluations"],
                                  refresh=False)
        if self.on_generation is not None:
            self.on_generation(dict(record))

    def finish(self, state: dict[str, Any]) -> None:
        """Mark the run finished (an optimiser that stopped on its own) and checkpoint it."""
        if not self.finished:
            self.finished = True
            self.save(state)

    # --- checkpoints -----------------------------------------------------------------------------

    def save(self, state: dict[str, Any]) -> None:
        """Write the checkpoint (if a path was given) with the optimiser's ``state``."""
        if self.checkpoint is None:
            return
        save_checkpoint(self.checkpoint, {
            "fingerprint": self.fingerprint, "dim": self.dim, "maximize": self.maximize,
            "optimizer": self.optimizer, "seed": self.seed, "population": self.population,
            "budget": self.budget.as_dict(), "state": state, "history": self.history,
            "best_x": self.best_x, "best_f": self.best_f, "evaluations": self.evaluations,
            "generations": self.generations, "elapsed_s": self.elapsed(), "finished": self.finished,
        })

    def load(self) -> bool:
        """Continue from the checkpoint if it exists (``True``); a missing file means a fresh start (``False``)."""
        if self.checkpoint is None or not self.checkpoint.exists():
            return False
        data = load_checkpoint(self.checkpoint)
        check_compatible(self.checkpoint, data, fingerprint=self.fingerprint, dim=self.dim, maximize=self.maximize,
                         optimizer=self.optimizer, seed=self.seed, population=self.population, budget=self.budget.as_dict())
        self.state = data["state"]
        self.history = [dict(r) for r in data["history"]]
        self.best_x = None if data["best_x"] is None else np.array(data["best_x"], dtype=np.float64)
        self.best_f = float(data["best_f"])
        self.evaluations = int(data["evaluations"])
        self.elapsed_before = float(data["elapsed_s"])
        self.finished = bool(data["finished"])
        self.resumed = True
        self._t0 = time.perf_counter()
        return True

    # --- progress bar ----------------------------------------------------------------------------

    def open_progress(self) -> None:
        if not self.progress:
            return
        from lifelike_mj.progress import bar

        done = self.generations if self.budget.kind == "generations" else min(self.evaluations, self.budget.value)
        unit = "gen" if self.budget.kind == "generations" else "eval"
        self._bar = bar(self.budget.value, self.optimizer, unit=unit, initial=done, leave=True)

    def close_progress(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    # --- result ----------------------------------------------------------------------------------

    def result(self, *, interrupted: bool, wall_time_s: float) -> OptimizationResult:
        best_x = np.full(self.dim, np.nan) if self.best_x is None else self.best_x.copy()
        return OptimizationResult(
            optimizer=self.optimizer, seed=self.seed, population=self.population, best_x=best_x,
            best_f=float(self.best_f), evaluations=int(self.evaluations), generations=self.generations,
            history=copy.deepcopy(self.history), wall_time_s=float(wall_time_s), interrupted=interrupted,
            resumed=self.resumed)
