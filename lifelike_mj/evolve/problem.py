"""What an optimiser needs to know about a problem: genes, bounds, direction, and a batch fitness function.

The optimisers in :mod:`lifelike_mj.evolve` know nothing of butterflies: anything with the attributes and
methods of :class:`Problem` can be optimised.
"""

from __future__ import annotations

import math
from typing import Protocol, runtime_checkable

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError


@runtime_checkable
class Problem(Protocol):
    """An optimisation problem.

    Attributes:
        dim: number of genes (length of one candidate ``x``).
        lower, upper: ``(dim,)`` bounds of the genes; used by nlopt and CMA-ES (``rcga`` ignores them,
            as the paper's GA has no bounds).
        maximize: ``True`` if a larger fitness is better, ``False`` if a smaller one is.

    The object must be picklable (the process and ray executors send it to their workers), and
    :meth:`evaluate` must be pure and deterministic: the same row always gives the same fitness,
    whatever else is in the batch.
    """

    dim: int
    lower: np.ndarray
    upper: np.ndarray
    maximize: bool

    def fingerprint(self) -> str:
        """Stable text identifying the problem (compared when a run resumes from a checkpoint)."""
        ...

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """Fitness of each row of ``X`` (shape ``(n, dim)``, float64) as an ``(n,)`` float64 array."""
        ...


def check_problem(problem: object, *, needs_bounds: bool) -> tuple[int, np.ndarray, np.ndarray]:
    """Check ``problem`` against :class:`Problem`; return ``(dim, lower, upper)`` as float64 arrays.

    With ``needs_bounds`` the bounds must be finite with ``lower < upper``. Raises :class:`UserError`.
    """
    missing = [a for a in ("dim", "lower", "upper", "maximize", "fingerprint", "evaluate") if not hasattr(problem, a)]
    if missing:
        raise UserError(f"the problem {type(problem).__name__} lacks {', '.join(missing)} (see lifelike_mj.evolve.Problem).")
    dim = problem.dim
    if not checks.is_whole(dim) or dim < 1:
        raise UserError(f"the problem's dim must be a positive integer, not {dim!r}.")
    dim = int(dim)
    lower = np.asarray(problem.lower, dtype=np.float64).reshape(-1)
    upper = np.asarray(problem.upper, dtype=np.float64).reshape(-1)
    if lower.shape != (dim,) or upper.shape != (dim,):
        raise UserError(f"the problem's bounds must have {dim} entries each, not {lower.size} and {upper.size}.")
    if needs_bounds:
        if not (np.all(np.isfinite(lower)) and np.all(np.isfinite(upper))):
            raise UserError("the problem's bounds must be finite for this optimizer.")
        if not np.all(lower < upper):
            i = int(np.argmin(upper - lower))
            raise UserError(f"the problem's bounds must have lower < upper, but gene {i} has [{lower[i]}, {upper[i]}].")
    return dim, lower, upper


def worst_value(maximize: bool) -> float:
    """The fitness that every other value beats: ``-inf`` when maximising, ``+inf`` when minimising."""
    return -math.inf if maximize else math.inf
