"""Small picklable benchmark problems for tests and demonstrations.

Each row is evaluated on its own (a loop over rows), so a fitness never depends on which other rows
share the batch: serial, process and ray evaluation give bit-identical results.
"""

from __future__ import annotations

import math
import time

import numpy as np


class _Benchmark:
    """Shared plumbing: bounds, direction, optional delay, row-by-row evaluation."""

    name = "benchmark"

    def __init__(self, dim: int = 4, shift: float = 0.3, maximize: bool = False, delay_s: float = 0.0,
                 low: float = -2.0, high: float = 2.0) -> None:
        """``dim`` genes, optimum at ``x = shift`` in every gene, bounds ``[low, high]``.

        ``maximize=True`` negates the fitness (so larger is better); ``delay_s`` (seconds) is slept once
        per :meth:`evaluate` call, to make slow problems for interruption tests.
        """
        self.dim = int(dim)
        self.shift = float(shift)
        self.maximize = bool(maximize)
        self.delay_s = float(delay_s)
        self.low = float(low)
        self.high = float(high)
        self.lower = np.full(self.dim, self.low)
        self.upper = np.full(self.dim, self.high)

    def fingerprint(self) -> str:
        """Text naming the function, its size, optimum, direction and bounds (not the delay)."""
        return (f"{self.name}(dim={self.dim}, shift={self.shift!r}, maximize={self.maximize}, "
                f"bounds=[{self.low!r}, {self.high!r}])")

    def _value(self, z: np.ndarray) -> float:  # pragma: no cover - overridden
        raise NotImplementedError

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """Fitness of each row of ``X`` ``(n, dim)``: the function value, negated if ``maximize``."""
        X = np.asarray(X, dtype=np.float64).reshape(-1, self.dim)
        if self.delay_s > 0:
            time.sleep(self.delay_s)
        sign = -1.0 if self.maximize else 1.0
        return np.array([sign * self._value(row - self.shift) for row in X], dtype=np.float64)

    def __repr__(self) -> str:
        return self.fingerprint()


class Sphere(_Benchmark):
    """``sum((x - shift)^2)``: minimum 0 at ``x = shift``."""

    name = "Sphere"

    def _value(self, z: np.ndarray) -> float:
        total = 0.0
        for v in z:
            total += float(v) * float(v)
        return total


class Rastrigin(_Benchmark):
    """``10 dim + sum(z^2 - 10 cos(2 pi z))`` with ``z = x - shift``: minimum 0 at ``x = shift``, many local minima."""

    name = "Rastrigin"

    def _value(self, z: np.ndarray) -> float:
        total = 10.0 * self.dim
        for v in z:
            v = float(v)
            total += v * v - 10.0 * math.cos(2.0 * math.pi * v)
        return total
