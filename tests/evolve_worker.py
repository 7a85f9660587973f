"""Run one checkpointed optimisation in a subprocess, for the signal tests of test_evolve.py.

Usage: python evolve_worker.py CHECKPOINT OPTIMIZER SEED POPULATION GENERATIONS DELAY_S EXECUTOR WORKERS

Prints the result (``OptimizationResult.to_dict()``) as one JSON line on stdout.
"""

from __future__ import annotations

import json
import signal
import sys

from lifelike_mj.evolve import Rastrigin, make_evaluator, optimize


def main(argv: list[str]) -> int:
    # Behave like a program started from a terminal even when the test run itself was started in the
    # background (a non-interactive shell then sets SIGINT to "ignore", and children inherit that).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    checkpoint, optimizer, seed, population, generations, delay_s, executor, workers = argv
    problem = Rastrigin(dim=3, delay_s=float(delay_s))
    with make_evaluator(problem, executor, workers=int(workers)) as evaluator:
        print("started", flush=True)
        result = optimize(problem, optimizer, seed=int(seed), population=int(population), generations=int(generations),
                          evaluator=evaluator, checkpoint=checkpoint, progress=False)
    print(json.dumps(result.to_dict()), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
