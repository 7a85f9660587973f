"""The paper's RCGA against CMA-ES on the 3D butterfly's ``steer`` tasks (issue 15).

Run: ``python benchmarks/compare_3d_optimizers.py [--generations 100] [--seeds 1]``. Each optimizer evolves a
linear 3D controller from the same hand-made starting law (population 16), then the best is measured:
fitness, wall time, level flight at 2 m/s for 20 s, a 90 deg turn and courses 100-102. Writes
``benchmarks/results/3d_optimizers.json``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.validate import course_check, level_check, turn_check
from lifelike_mj.evolve import optimize
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance


def run(optimizer: str, generations: int, seed: int) -> dict:
    layers = [10, 9]
    template = flight3d.Controller3D(layers, flight3d.pd_prior(layers))
    problem = flight3d.FlightProblem3D(flight3d.TASK_SETS["steer"](), template, duration_s=4.0, gene_bound=0.4)
    t = time.perf_counter()
    res = optimize(problem, optimizer, seed=seed, population=16, generations=generations, progress=False)
    wall = time.perf_counter() - t
    ctl = template.with_weights(problem.weights(res.best_x))
    level = level_check(ctl, 2.0, 20.0)
    turn = turn_check(ctl, 90.0)
    return {"optimizer": optimizer, "seed": seed, "generations": generations, "population": 16,
            "best_fitness": float(res.best_f), "wall_s": wall, "history_best": [h["best"] for h in res.history],
            "level_2m_s_altitude_m": [level["altitude_min_m"], level["altitude_max_m"]],
            "level_2m_s_speed_m_s": [level["speed_min_m_s"], level["speed_max_m_s"]],
            "turn_90_held_error_deg": turn["held_error_max_deg"],
            "courses_100_102_passed": [course_check(ctl, s, max_s=30.0)["passed"] for s in (100, 101, 102)]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--generations", type=int, default=100)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "3d_optimizers.json"))
    args = ap.parse_args()
    rows = [run(opt, args.generations, s) for s in args.seeds for opt in ("rcga", "cmaes")]
    write_json(args.out, {"provenance": provenance(**vars(args)), "machine": machine_info(), "runs": rows})
    for r in rows:
        print(f"{r['optimizer']:6s} seed {r['seed']}: best {r['best_fitness']:.3f} in {r['wall_s']:.0f} s; courses "
              f"{r['courses_100_102_passed']}")


if __name__ == "__main__":
    main()
