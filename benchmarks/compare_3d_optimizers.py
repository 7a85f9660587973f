"""The paper's RCGA, CMA-ES and reinforcement learning (PPO) on the 3D butterfly's ``steer`` tasks (issues 15, 26).

Run: ``python benchmarks/compare_3d_optimizers.py [--generations 100] [--seeds 1] [--rl-seeds 1]``. Each optimizer
evolves a linear 3D controller from the same hand-made starting law (population 16); PPO (stable-baselines3, the
optional ``rl`` extra; ``examples/gym_sb3_flight3d.py``) trains a network with one hidden layer of 32 from scratch
through ``ButterflyFlight3D-v0`` on the same tasks, acting every 12 time steps, for as many time steps as the
evolutions fly (16 x generations x 4 tasks x 4 s at 1/1200 s). The best of each is measured alike: fitness on the
tasks, wall time, level flight at 2 m/s for 20 s, a 90 deg turn and courses 100-102. Writes
``benchmarks/results/3d_optimizers.json`` (``--out``).
"""

from __future__ import annotations

import argparse
import importlib.util
import time
from pathlib import Path

import numpy as np

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


def measured(ctl) -> dict:
    """What every optimizer's best is measured by."""
    level = level_check(ctl, 2.0, 20.0)
    turn = turn_check(ctl, 90.0)
    problem = flight3d.FlightProblem3D(flight3d.TASK_SETS["steer"](), ctl, duration_s=4.0)
    return {"fitness_steer": float(problem.evaluate(np.zeros((1, problem.dim)))[0]),
            "level_2m_s_altitude_m": [level["altitude_min_m"], level["altitude_max_m"]],
            "level_2m_s_speed_m_s": [level["speed_min_m_s"], level["speed_max_m_s"]],
            "turn_90_held_error_deg": turn["held_error_max_deg"],
            "courses_100_102_passed": [course_check(ctl, s, max_s=30.0)["passed"] for s in (100, 101, 102)]}


def run_rl(generations: int, seed: int, every: int = 12) -> dict:
    """PPO for the time steps of an evolution of ``generations`` generations of 16 on the 4 steer tasks."""
    spec = importlib.util.spec_from_file_location("gym_sb3_flight3d",
                                                  Path(__file__).parents[1] / "examples" / "gym_sb3_flight3d.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    time_steps = 16 * generations * 4 * int(round(4.0 * 1200))
    steps = time_steps // every
    model, wall = ex.train(steps, seed, every)
    ctl = ex.export(model, ex.make_env(every).unwrapped.controller)
    return {"optimizer": "ppo", "seed": seed, "env_steps": steps, "time_steps": steps * every, "every": every,
            "hidden": [32], "wall_s": wall, **measured(ctl), "weights": [float(w) for w in ctl.weights]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--generations", type=int, default=100)
    ap.add_argument("--seeds", type=int, nargs="*", default=[1], help="RCGA and CMA-ES runs")
    ap.add_argument("--rl-seeds", type=int, nargs="*", default=[], help="PPO runs (needs the rl extra)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "3d_optimizers.json"))
    args = ap.parse_args()
    rows = [run(opt, args.generations, s) for s in args.seeds for opt in ("rcga", "cmaes")]
    rows += [run_rl(args.generations, s) for s in args.rl_seeds]
    write_json(args.out, {"provenance": provenance(**vars(args)), "machine": machine_info(), "runs": rows})
    for r in rows:
        print(f"{r['optimizer']:6s} seed {r['seed']}: best {r.get('best_fitness', r.get('fitness_steer')):.3f} in "
              f"{r['wall_s']:.0f} s; courses "
              f"{r['courses_100_102_passed']}")


if __name__ == "__main__":
    main()
