"""Optimisers behind one interface, knowing nothing of butterflies.

* :func:`optimize` runs ``rcga`` (the GA of Oe et al. 2010), ``cmaes`` (pycma, IPOP restarts), or nlopt's
  ``crs2``, ``esch``, ``isres`` on any :class:`Problem`, with progress bar, checkpoints after every
  generation, bit-identical resume, and clean Ctrl-C.
* :func:`make_evaluator` evaluates batches serially, on local processes, or on ray; all give identical
  fitness.
* :mod:`lifelike_mj.evolve.testproblems` has small picklable benchmarks (:class:`Sphere`, :class:`Rastrigin`).
"""

from __future__ import annotations

from lifelike_mj.evolve import checkpoint, cmaes, driver, evaluators, nloptalgs, optimizers, problem, rcga, testproblems
from lifelike_mj.evolve.driver import OptimizationResult
from lifelike_mj.evolve.evaluators import EXECUTORS, Evaluator, make_evaluator
from lifelike_mj.evolve.optimizers import DEFAULT_GENERATIONS, OPTIMIZERS, default_population, minimum_population, optimize
from lifelike_mj.evolve.problem import Problem
from lifelike_mj.evolve.testproblems import Rastrigin, Sphere

__all__ = [
    "DEFAULT_GENERATIONS", "EXECUTORS", "OPTIMIZERS", "Evaluator", "OptimizationResult", "Problem", "Rastrigin",
    "Sphere", "default_population", "make_evaluator", "minimum_population", "optimize",
    # the submodules, for the API reference
    "checkpoint", "cmaes", "driver", "evaluators", "nloptalgs", "optimizers", "problem", "rcga", "testproblems",
]
