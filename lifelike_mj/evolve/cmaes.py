"""CMA-ES (pycma) with IPOP restarts, reproducible and resumable bit for bit.

* One generation is one ``ask``/``tell`` of ``cma.CMAEvolutionStrategy``.
* Bounds: pycma's ``bounds`` option with the problem's ``lower``/``upper`` (its default boundary
  transformation, so every candidate asked lies within them).
* ``sigma0 = 0.25 * mean(upper - lower)``; when the widths differ, ``CMA_stds = width / mean(width)``
  so each gene starts with a standard deviation of a quarter of its own width.
* ``x0``: the middle of the bounds for the first run, uniform in the bounds (drawn from our own
  ``Generator(PCG64(seed))``) for every restart.
* IPOP: when ``es.stop()`` reports any condition (pycma's own iteration/evaluation/time budgets are
  switched off, as the budget is ours), a new strategy starts with the population doubled.
* Randomness: pycma draws its samples through its ``randn`` option. We give it its own
  ``Generator(PCG64(SeedSequence([seed, restart])))`` (:class:`Randn`), which is pickled along with the
  strategy, so a pickled ``es`` continues exactly. (pycma's ``seed`` option would instead seed numpy's
  global RNG, and a pickled ``es`` would then sample from a detached copy of it.) For the few pycma
  paths that use numpy's global RNG directly, we seed it per restart from ``SeedSequence([seed,
  restart, 1])``, save its state in every checkpoint, and restore the caller's global state on return.
"""

from __future__ import annotations

import math
import pickle
from typing import Any

import numpy as np

from lifelike_mj.evolve.driver import Run

MIN_POPULATION = 4
#: ``es.stop()`` keys that are budgets rather than convergence (disabled anyway; never trigger a restart).
BUDGET_KEYS = frozenset({"maxiter", "maxfevals", "timeout"})


def default_population(dim: int) -> int:
    """pycma's default population ``4 + floor(3 ln dim)``."""
    return 4 + int(3 * math.log(dim))


class Randn:
    """Picklable ``randn(*shape)`` for pycma, drawing from its own PCG64 generator."""

    def __init__(self, seed_sequence: np.random.SeedSequence) -> None:
        self.rng = np.random.Generator(np.random.PCG64(seed_sequence))

    def __call__(self, *shape: int) -> np.ndarray:
        return self.rng.standard_normal(shape)


def _new_strategy(x0: np.ndarray, sigma0: float, stds: np.ndarray | None, lower: np.ndarray, upper: np.ndarray,
                  popsize: int, seed: int, restart: int) -> Any:
    import cma

    np.random.seed(np.random.SeedSequence([seed, restart, 1]).generate_state(1)[0])
    opts: dict[str, Any] = {
        "bounds": [lower.tolist(), upper.tolist()], "popsize": int(popsize),
        "randn": Randn(np.random.SeedSequence([seed, restart])), "seed": math.nan,
        "maxiter": math.inf, "maxfevals": math.inf, "timeout": math.inf,
        "verbose": -9, "verb_log": 0, "verb_disp": 0,
    }
    if stds is not None:
        opts["CMA_stds"] = stds.tolist()
    return cma.CMAEvolutionStrategy(x0.tolist(), sigma0, opts)


def _should_restart(es: Any) -> bool:
    return any(key not in BUDGET_KEYS for key in es.stop())


def run_cmaes(run: Run, lower: np.ndarray, upper: np.ndarray) -> None:
    """Run IPOP-CMA-ES until ``run``'s budget is spent (continuing from ``run.state`` when resuming)."""
    width = upper - lower
    sigma0 = 0.25 * float(np.mean(width))
    stds = None if np.all(width == width[0]) else width / np.mean(width)
    caller_state = np.random.get_state()
    try:
        if run.state is None:
            rng = np.random.Generator(np.random.PCG64(run.seed))
            es, restart = None, 0
        else:
            rng = np.random.Generator(np.random.PCG64())
            rng.bit_generator.state = run.state["rng"]
            es, restart = pickle.loads(run.state["es"]), int(run.state["restart"])
            np.random.set_state(run.state["np_random"])
        while not run.budget_reached():
            if es is None or _should_restart(es):
                if es is not None:
                    restart += 1
                x0 = 0.5 * (lower + upper) if restart == 0 else rng.uniform(lower, upper)
                es = _new_strategy(x0, sigma0, stds, lower, upper, run.population * 2**restart, run.seed, restart)
            asked = es.ask()
            f = run.evaluate(np.array(asked, dtype=np.float64))
            es.tell(asked, (-f if run.maximize else f).tolist())
            run.end_generation(float(np.mean(f)), {
                "es": pickle.dumps(es, protocol=pickle.HIGHEST_PROTOCOL), "restart": restart,
                "popsize": int(es.popsize), "rng": rng.bit_generator.state, "np_random": np.random.get_state()})
    finally:
        np.random.set_state(caller_state)
