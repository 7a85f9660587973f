"""The real-coded GA of Oe et al. 2010, section 6.2: elite / tournament / random, BLX-alpha, x U[-2, 2] mutation.

One generation, from an evaluated population ``P`` (``N`` rows) with fitness ``f``:

1. **Selection**, by index ``j = 0..N-1``: ``j % 3 == 0`` a copy of the elite (best individual, first on
   ties); ``j % 3 == 1`` the winner of a size-2 tournament (two indices drawn uniformly with replacement,
   the better wins, the first drawn on ties); ``j % 3 == 2`` a fresh individual with genes U[-1, 1].
2. **BLX-alpha crossover** (alpha = 0.45, probability 1). Our pairing: index 0 (an elite copy) is kept
   unchanged; indices ``1..N-1`` are put in a random permutation, consecutive pairs ``(a, b)`` each produce
   two children that replace them, every child gene drawn independently from
   ``U[min - alpha d, max + alpha d]`` with ``d = |a - b|``. If ``N - 1`` is odd, the last one of the
   permutation is crossed with a uniformly chosen other member (any index but itself, index 0 included)
   and replaced by one child. Parents are always taken from the selected population, before crossover.
3. **Mutation**: every gene of every individual except index 0, with probability 0.01, is multiplied by
   U[-2, 2].

There is no bounds clipping (the paper has none). Index 0 is the unchanged elite, so its fitness is
reused, not re-evaluated: generation 1 costs ``N`` evaluations, later ones ``N - 1``; the best of each
generation never gets worse. One ``numpy.random.Generator(PCG64(seed))`` drives every draw, in the order
written above (selection draws by index; crossover: permutation, then pairs in order, then the odd one;
mutation: an ``(N-1, dim)`` array of uniforms for the mask, then one of factors).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lifelike_mj.evolve.driver import Run

DEFAULT_POPULATION = 40
MIN_POPULATION = 3
ALPHA = 0.45
MUTATION_RATE = 0.01
MUTATION_SCALE = 2.0
GENE_LOW, GENE_HIGH = -1.0, 1.0


def elite_index(f: np.ndarray, maximize: bool) -> int:
    """Index of the best fitness (the first on ties)."""
    return int(np.argmax(f) if maximize else np.argmin(f))


def select(P: np.ndarray, f: np.ndarray, rng: np.random.Generator, maximize: bool) -> np.ndarray:
    """Selection step: elite copies at ``j % 3 == 0``, tournament winners at 1, fresh U[-1, 1] at 2."""
    N, dim = P.shape
    elite = P[elite_index(f, maximize)]
    Q = np.empty_like(P)
    for j in range(N):
        kind = j % 3
        if kind == 0:
            Q[j] = elite
        elif kind == 1:
            a, b = rng.integers(0, N, size=2)
            wins_b = f[b] > f[a] if maximize else f[b] < f[a]
            Q[j] = P[b] if wins_b else P[a]
        else:
            Q[j] = rng.uniform(GENE_LOW, GENE_HIGH, size=dim)
    return Q


def _blx(a: np.ndarray, b: np.ndarray, rng: np.random.Generator, alpha: float, n: int) -> np.ndarray:
    lo = np.minimum(a, b)
    hi = np.maximum(a, b)
    d = hi - lo
    return rng.uniform(lo - alpha * d, hi + alpha * d, size=(n, a.shape[0]))


def crossover(Q: np.ndarray, rng: np.random.Generator, alpha: float = ALPHA) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """BLX-alpha crossover of indices ``1..N-1`` (index 0 untouched); returns the children and the pairs.

    Each pair ``(i, j)`` lists the two parents' indices in ``Q``; both are replaced by children, except
    for the odd one out (last pair when ``N - 1`` is odd), where only ``i`` is replaced and ``j`` is its
    partner.
    """
    N = Q.shape[0]
    C = Q.copy()
    order = rng.permutation(N - 1) + 1
    pairs: list[tuple[int, int]] = []
    for k in range(0, len(order) - 1, 2):
        i, j = int(order[k]), int(order[k + 1])
        C[[i, j]] = _blx(Q[i], Q[j], rng, alpha, 2)
        pairs.append((i, j))
    if len(order) % 2 == 1:
        i = int(order[-1])
        r = int(rng.integers(0, N - 1))
        j = r if r < i else r + 1  # uniform over every index but i
        C[i] = _blx(Q[i], Q[j], rng, alpha, 1)[0]
        pairs.append((i, j))
    return C, pairs


def mutate(C: np.ndarray, rng: np.random.Generator, rate: float = MUTATION_RATE,
           scale: float = MUTATION_SCALE) -> tuple[np.ndarray, np.ndarray]:
    """Multiply each gene of rows ``1..N-1`` by U[-scale, scale] with probability ``rate``; returns (M, mask)."""
    M = C.copy()
    mask = rng.random((C.shape[0] - 1, C.shape[1])) < rate
    factors = rng.uniform(-scale, scale, size=mask.shape)
    body = M[1:]
    body[mask] *= factors[mask]
    full = np.zeros(C.shape, dtype=bool)
    full[1:] = mask
    return M, full


def next_generation(P: np.ndarray, f: np.ndarray, rng: np.random.Generator, maximize: bool) -> np.ndarray:
    """Selection, crossover and mutation: the next (unevaluated) population; row 0 is the elite."""
    Q = select(P, f, rng, maximize)
    C, _ = crossover(Q, rng)
    M, _ = mutate(C, rng)
    return M


def _state(P: np.ndarray, f: np.ndarray, rng: np.random.Generator) -> dict[str, Any]:
    return {"P": P.copy(), "f": f.copy(), "rng": rng.bit_generator.state}


def run_rcga(run: Run) -> None:
    """Run the GA until ``run``'s budget is spent (continuing from ``run.state`` when resuming)."""
    N, dim = run.population, run.dim
    if run.state is None:
        rng = np.random.Generator(np.random.PCG64(run.seed))
        P = rng.uniform(GENE_LOW, GENE_HIGH, size=(N, dim))
        f = run.evaluate(P)
        run.end_generation(float(np.mean(f)), _state(P, f, rng))
    else:
        P = np.array(run.state["P"], dtype=np.float64)
        f = np.array(run.state["f"], dtype=np.float64)
        rng = np.random.Generator(np.random.PCG64())
        rng.bit_generator.state = run.state["rng"]
    while not run.budget_reached():
        elite_f = f[elite_index(f, run.maximize)]
        P_next = next_generation(P, f, rng, run.maximize)
        f_next = np.empty(N)
        f_next[0] = elite_f
        f_next[1:] = run.evaluate(P_next[1:])
        P, f = P_next, f_next
        run.end_generation(float(np.mean(f)), _state(P, f, rng))
