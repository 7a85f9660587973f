"""nlopt's stochastic global optimisers CRS2-LM, ESCH and ISRES, resumable by replaying an evaluation log.

* Bounds: the problem's ``lower``/``upper``; ``x0`` = the middle of the bounds; ``nlopt.srand(seed)``
  before the optimiser is created; ``set_population(N)`` always (with nlopt's own default when the user
  gives none, so the "generation" length is known); ``set_maxeval(budget)``; ``set_max_objective`` when
  maximising. No tolerances are set, so nlopt stops only on the budget.
* nlopt asks for one point at a time and waits for its value, so each point is evaluated as a batch of
  one: nlopt cannot use parallel workers (use ``rcga`` or ``cmaes`` for that).
* A "generation" is a block of ``population`` evaluations (the last one may be shorter); a budget in
  generations means ``generations * population`` evaluations.
* Populations (from nlopt's sources): CRS2 needs at least ``dim + 1`` points (a simplex; default
  ``10 (dim + 1)``); ESCH takes ``N`` parents and ``int(1.5 N)`` offspring, ``N >= 1`` (default 40);
  ISRES ``N >= 1`` (default ``20 (dim + 1)``).
* CRS2 may ask for a few points beyond ``maxeval`` (its successful trials skip the check); we stop it
  with ``nlopt.ForcedStop`` at the budget instead, so exactly ``budget`` points are evaluated.
* nlopt's state cannot be saved. The checkpoint holds the log of every point and value so far; on
  resume nlopt is rerun with the same seed and its first calls are answered from the log (each requested
  point must equal the logged one bit for bit, else :class:`UserError`: the replay diverged), then new
  points are evaluated.
* Ctrl-C (KeyboardInterrupt) inside the objective stops nlopt; later calls nlopt still makes before it
  notices are answered with NaN without evaluating, and the KeyboardInterrupt propagates.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.evolve.driver import Run

ALGORITHMS = {"crs2": "GN_CRS2_LM", "esch": "GN_ESCH", "isres": "GN_ISRES"}


def default_population(name: str, dim: int) -> int:
    """nlopt's default population for ``name`` in ``dim`` dimensions."""
    return {"crs2": 10 * (dim + 1), "esch": 40, "isres": 20 * (dim + 1)}[name]


def min_population(name: str, dim: int) -> int:
    """Smallest population nlopt accepts for ``name``: ``dim + 1`` for CRS2, 1 for ESCH and ISRES."""
    return dim + 1 if name == "crs2" else 1


def run_nlopt(run: Run, name: str, lower: np.ndarray, upper: np.ndarray, max_evals: int) -> None:
    """Run nlopt's ``name`` for ``max_evals`` evaluations (replaying ``run.state``'s log when resuming)."""
    import nlopt

    dim, block = run.dim, run.population
    if run.state is None:
        log_x: list[np.ndarray] = []
        log_f: list[float] = []
    else:
        log_x = [np.array(x, dtype=np.float64) for x in run.state["X"]]
        log_f = [float(v) for v in run.state["F"]]
        if len(log_x) != len(log_f):
            raise UserError(f"checkpoint {run.checkpoint} is damaged (its log has {len(log_x)} points and "
                            f"{len(log_f)} values).")
    replay = len(log_f)
    status = {"calls": 0, "stopping": False, "budget_spent": False, "recorded": replay}

    def state() -> dict[str, Any]:
        return {"X": np.array(log_x, dtype=np.float64).reshape(-1, dim), "F": np.array(log_f, dtype=np.float64),
                "nlopt_version": _version(nlopt)}

    def record_block() -> None:
        calls = status["calls"]
        start = ((calls - 1) // block) * block
        status["recorded"] = calls
        run.end_generation(float(np.mean(log_f[start:calls])), state())

    def objective(x: np.ndarray, grad: np.ndarray) -> float:
        if status["stopping"]:
            return math.nan
        try:
            i = status["calls"]
            if i >= max_evals:
                status["budget_spent"] = True
                raise nlopt.ForcedStop("budget spent")
            x = np.array(x, dtype=np.float64, copy=True)
            if i < replay:
                if x.tobytes() != log_x[i].tobytes():
                    raise UserError(f"checkpoint {run.checkpoint} cannot be resumed: the replay diverged at evaluation "
                                    f"{i + 1} (nlopt asked for a different point than the logged run; another nlopt version?).")
                status["calls"] = i + 1
                return log_f[i]
            value = float(run.evaluate(x[None, :])[0])
            log_x.append(x)
            log_f.append(value)
            status["calls"] = i + 1
            if status["calls"] % block == 0 or status["calls"] == max_evals:
                record_block()
            return value
        except BaseException:
            status["stopping"] = True
            raise

    nlopt.srand(int(run.seed))
    opt = nlopt.opt(getattr(nlopt, ALGORITHMS[name]), dim)
    opt.set_lower_bounds(lower.tolist())
    opt.set_upper_bounds(upper.tolist())
    opt.set_population(int(block))
    opt.set_maxeval(int(max_evals))
    if run.maximize:
        opt.set_max_objective(objective)
    else:
        opt.set_min_objective(objective)
    try:
        opt.optimize((0.5 * (lower + upper)).tolist())
    except nlopt.ForcedStop:
        if not status["budget_spent"]:
            raise
    if status["calls"] < replay:
        raise UserError(f"checkpoint {run.checkpoint} cannot be resumed: nlopt stopped after {status['calls']} of "
                        f"the {replay} logged evaluations (another nlopt version?).")
    if status["calls"] > status["recorded"]:
        record_block()
    run.finish(state())


def _version(nlopt: Any) -> str:
    try:
        return f"{nlopt.version_major()}.{nlopt.version_minor()}.{nlopt.version_bugfix()}"
    except Exception:
        return "unknown"
