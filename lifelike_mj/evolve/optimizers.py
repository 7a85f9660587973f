"""One entry point, :func:`optimize`, for five optimisers: ``rcga``, ``cmaes``, ``crs2``, ``esch``, ``isres``.

Common behaviour:

* Budget: exactly one of ``generations`` / ``evaluations`` (both ``None``: ``generations=100``).
  Generation-based optimisers (``rcga``, ``cmaes``) run whole generations, so with an ``evaluations``
  budget the last generation may overshoot it by less than one population. nlopt optimisers stop at
  exactly the budget (``generations * population`` evaluations for a generation budget).
* Progress bar (tqdm on stderr) unless ``progress=False``; ``on_generation(record)`` after each
  generation, once that generation's checkpoint is written.
* Checkpoint (``checkpoint=path``): written atomically after every generation (see
  :mod:`lifelike_mj.evolve.checkpoint`). ``resume=True`` continues from it; with no file there the run
  starts fresh; a checkpoint of a different problem, optimiser, seed, population or budget, or an
  unreadable file, raises :class:`UserError`; a finished checkpoint returns its result at once. Without
  ``resume`` an existing checkpoint is refused unless ``overwrite=True`` (and a file that is not a
  checkpoint is never replaced). Checkpoints hold data only (no pickle). A resumed run ends with
  exactly the result (best, history, evaluations) of an uninterrupted run with the same seed; only the times differ.
* Ctrl-C (KeyboardInterrupt, and SIGTERM while in the main thread) stops the run: the result has
  ``interrupted=True`` and the best so far; the checkpoint of the last finished generation stays valid.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lifelike_mj.checks import known_keywords
from lifelike_mj.errors import UserError
from lifelike_mj.evolve import cmaes, nloptalgs, rcga
from lifelike_mj.evolve.checkpoint import OPTIMIZERS, check_checkpoint_path
from lifelike_mj.evolve.driver import Budget, OptimizationResult, Run
from lifelike_mj.evolve.evaluators import Evaluator, make_evaluator
from lifelike_mj.evolve.problem import check_problem

#: Budget used when neither ``generations`` nor ``evaluations`` is given.
DEFAULT_GENERATIONS = 100

__all__ = ["DEFAULT_GENERATIONS", "OPTIMIZERS", "OptimizationResult", "default_population", "minimum_population",
           "optimize"]


def _check_optimizer(optimizer: str) -> str:
    if optimizer not in OPTIMIZERS:
        raise UserError(f"unknown optimizer {optimizer!r}; known optimizers are {', '.join(OPTIMIZERS)}.")
    return optimizer


def _is_int(value: object) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def minimum_population(optimizer: str, dim: int) -> int:
    """Smallest population ``optimizer`` accepts for ``dim`` genes.

    ``rcga`` 3 (one elite, one tournament winner, one random), ``cmaes`` 4, ``crs2`` ``dim + 1``,
    ``esch`` 1, ``isres`` 1 (the last three from nlopt's sources).
    """
    _check_optimizer(optimizer)
    if optimizer == "rcga":
        return rcga.MIN_POPULATION
    if optimizer == "cmaes":
        return cmaes.MIN_POPULATION
    return nloptalgs.min_population(optimizer, dim)


def default_population(optimizer: str, dim: int) -> int:
    """Population used when none is given: ``rcga`` 40 (the paper's), ``cmaes`` ``4 + floor(3 ln dim)``
    (pycma's), ``crs2`` ``10 (dim + 1)``, ``esch`` 40, ``isres`` ``20 (dim + 1)`` (nlopt's)."""
    _check_optimizer(optimizer)
    if optimizer == "rcga":
        return rcga.DEFAULT_POPULATION
    if optimizer == "cmaes":
        return max(cmaes.default_population(dim), cmaes.MIN_POPULATION)
    return nloptalgs.default_population(optimizer, dim)


def _budget(generations: int | None, evaluations: int | None) -> Budget:
    if generations is not None and evaluations is not None:
        raise UserError("give either generations or evaluations as the budget, not both.")
    if generations is None and evaluations is None:
        return Budget("generations", DEFAULT_GENERATIONS)
    kind, value = ("generations", generations) if generations is not None else ("evaluations", evaluations)
    if not _is_int(value) or value < 1:
        raise UserError(f"{kind} must be a positive integer, not {value!r}.")
    return Budget(kind, int(value))


class _SigtermAsInterrupt:
    """While active (main thread only), SIGTERM raises KeyboardInterrupt, so it stops a run like Ctrl-C."""

    def __enter__(self) -> _SigtermAsInterrupt:
        self._old: Any = None
        if threading.current_thread() is threading.main_thread():
            try:
                self._old = signal.signal(signal.SIGTERM, self._handler)
            except (ValueError, OSError):
                self._old = None
        return self

    @staticmethod
    def _handler(signum: int, frame: object) -> None:
        raise KeyboardInterrupt(f"signal {signum}")

    def __exit__(self, *exc: object) -> None:
        if self._old is not None:
            signal.signal(signal.SIGTERM, self._old)


def check_work(problem: Any, budget: Budget, population: int) -> None:
    """Before an evolution starts: a problem that says what one candidate costs (``steps_per_candidate``,
    simulation steps) is refused, in one sentence, when the whole budget would take more than
    :data:`~lifelike_mj.checks.MAX_EVOLUTION_STEPS` steps."""
    from lifelike_mj import checks

    per = getattr(problem, "steps_per_candidate", None)
    if per is None:
        return
    n = budget.value if budget.kind == "evaluations" else budget.value * population
    what = (f"an evolution of {n:,} evaluations" if budget.kind == "evaluations"
            else f"an evolution of {budget.value:,} generations of {population:,}")
    checks.work(f"{what} (each {per:,} simulation steps)", float(n) * per, checks.MAX_EVOLUTION_STEPS, "steps",
                "fewer generations, a smaller population or shorter flights")


@known_keywords
def optimize(problem: Any, optimizer: str, *, seed: int, population: int | None = None, generations: int | None = None,
             evaluations: int | None = None, evaluator: Evaluator | Callable[[np.ndarray], np.ndarray] | None = None,
             checkpoint: str | Path | None = None, resume: bool = False, progress: bool = True,
             on_generation: Callable[[dict[str, Any]], object] | None = None, executor: str = "serial",
             workers: int | None = None, overwrite: bool = False) -> OptimizationResult:
    """Optimise ``problem`` (see :class:`~lifelike_mj.evolve.problem.Problem`) with ``optimizer``.

    Args:
        problem: the problem; its ``maximize`` says which direction is better.
        optimizer: one of :data:`OPTIMIZERS`.
        seed: non-negative integer; the same seed gives the same result, bit for bit, on any executor.
        population: population size (``None``: :func:`default_population`); at least
            :func:`minimum_population`.
        generations, evaluations: the budget; at most one (both ``None``: ``DEFAULT_GENERATIONS``).
        evaluator: from :func:`~lifelike_mj.evolve.evaluators.make_evaluator` (left open), or ``None``
            for one made here on ``executor`` (``serial``, the default; ``process`` with ``workers``, where
            a problem the pool cannot take runs serially with a warning naming the cause; ``ray``) and
            closed at the end.
        checkpoint: file to write after every generation; ``resume=True`` continues from it.
        overwrite: replace an existing checkpoint when not resuming (otherwise refused).
        progress: show a tqdm progress bar on stderr.
        on_generation: called with each generation's record (a copy) after its checkpoint is written;
            raising KeyboardInterrupt there stops the run as Ctrl-C would.

    Returns:
        :class:`OptimizationResult`. Raises :class:`UserError` for bad arguments or checkpoints.
    """
    started = time.perf_counter()
    name = _check_optimizer(optimizer)
    if not _is_int(seed) or seed < 0:
        raise UserError(f"seed must be a non-negative integer, not {seed!r}.")
    seed = int(seed)
    budget = _budget(generations, evaluations)
    dim, lower, upper = check_problem(problem, needs_bounds=name != "rcga")
    least = minimum_population(name, dim)
    if population is None:
        population = default_population(name, dim)
    elif not _is_int(population):
        raise UserError(f"population must be an integer, not {population!r}.")
    elif population < least:
        raise UserError(f"population {population} is below the minimum {least} for {name}.")
    population = int(population)
    check_work(problem, budget, population)
    if resume and checkpoint is None:
        raise UserError("resume=True needs a checkpoint path.")
    if checkpoint is not None:
        check_checkpoint_path(checkpoint, resume=resume, overwrite=overwrite)
    own_evaluator = evaluator is None
    if evaluator is not None:
        other = getattr(evaluator, "problem", None)
        if other is not None and other is not problem and other.fingerprint() != problem.fingerprint():
            raise UserError("the evaluator was made for a different problem than the one being optimised.")

    run = Run(problem, evaluator, dim=dim, optimizer=name, seed=seed, population=population, budget=budget,
              checkpoint=checkpoint, progress=progress, on_generation=on_generation)
    if resume:
        run.load()
        if run.finished:
            return run.result(interrupted=False, wall_time_s=time.perf_counter() - started)

    interrupted = False
    with _SigtermAsInterrupt():
        try:
            if own_evaluator:
                run.evaluator = make_evaluator(problem, executor, workers=workers)
            run.open_progress()
            if name == "rcga":
                rcga.run_rcga(run)
            elif name == "cmaes":
                cmaes.run_cmaes(run, lower, upper)
            else:
                max_evals = budget.value if budget.kind == "evaluations" else budget.value * population
                nloptalgs.run_nlopt(run, name, lower, upper, max_evals)
        except KeyboardInterrupt:
            interrupted = True
        finally:
            run.close_progress()
            if own_evaluator and run.evaluator is not None:
                run.evaluator.close()
    return run.result(interrupted=interrupted, wall_time_s=time.perf_counter() - started)
