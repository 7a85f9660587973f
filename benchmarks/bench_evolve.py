"""Evolution benchmark (issue 3): the paper-scale RCGA run, evaluations per second for each optimiser,
the process-pool speed-up, and the MuJoCo backend against its bare-engine floor.

Run: ``python benchmarks/bench_evolve.py [--repeats 3] [--quick]``; writes
``benchmarks/results/evolve.json`` and prints the Markdown table for docs/performance.md.

* paper-scale run: ``rcga``, population 40, 1000 generations, 24,000 steps (20 s at 1/1200 s) per
  evaluation, on the paper backend with the default executor (process pool, all cores); wall time,
  median of ``repeats`` runs;
* evaluations per second of each optimiser on the paper task (same budget each, default executor,
  except nlopt, which evaluates one point at a time in-process);
* pool speed-up: the same short RCGA run in-process on one thread vs a 2-worker process pool (each
  worker one thread); ratio per repeat, median reported;
* MuJoCo backend: a few generations timed and extrapolated to 1000; the floor is the bare
  ``mj_step`` (RK4, no callback) for the same number of steps spread over all cores.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import time
from pathlib import Path

import numba

from lifelike_mj.butterfly.evolution import make_problem
from lifelike_mj.evolve import make_evaluator, optimize
from lifelike_mj.io import write_json

STEPS = 24000


def _run(problem, optimizer, executor, workers=None, **kw):
    with make_evaluator(problem, executor=executor, workers=workers) as ev:
        t0 = time.perf_counter()
        res = optimize(problem, optimizer, seed=0, evaluator=ev, progress=False, **kw)
        return time.perf_counter() - t0, res


def bare_step_us(n: int = 24000, repeats: int = 3) -> float:
    """Bare RK4 ``mj_step`` of models/butterfly.xml (no callback), us per step from a native loop
    (the measurement of ``lifelike-mj bench butterfly``), median of ``repeats``."""
    from lifelike_mj.butterfly import bench, controllers
    from lifelike_mj.butterfly.backends import mj as mjbackend

    m = mjbackend.build_model()
    m.opt.timestep = 1.0 / 1200.0
    ctrl = controllers.load("simple_rule")
    bench._time_mujoco(m, ctrl, None, 100)  # compile
    return 1e6 * statistics.median(bench._time_mujoco(m, ctrl, None, n) for _ in range(repeats))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="shorter runs (smoke test of the script)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "evolve.json"))
    ap.add_argument("--only-mujoco", action="store_true", help="redo the MuJoCo part, keep the rest of --out")
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    if args.only_mujoco:
        import json

        res = json.loads(Path(args.out).read_text())
        res["mujoco"] = mujoco_part(args.quick, cores)
        finish(res, args.out, res["paper_scale"]["generations"], res["evals_per_s"])
        return
    prob = make_problem("paper")
    gens = 20 if args.quick else 1000
    res: dict = {"machine": f"{platform.platform()}, {cores} cores", "python": platform.python_version(),
                 "numba_threads": numba.get_num_threads(), "date": time.strftime("%Y-%m-%d")}

    # 1. paper-scale RCGA
    walls = []
    for _ in range(args.repeats):
        w, r = _run(prob, "rcga", "process", generations=gens)
        walls.append(w)
    res["paper_scale"] = {"generations": gens, "population": 40, "steps_per_eval": STEPS, "evaluations": r.evaluations,
                          "wall_s": walls, "median_wall_s": statistics.median(walls),
                          "ns_per_step": 1e9 * statistics.median(walls) / (r.evaluations * STEPS), "best_fitness": r.best_f}

    # 2. evaluations per second per optimiser, equal budgets
    budget = 400 if args.quick else 4000
    eps = {}
    for opt in ("rcga", "cmaes", "crs2", "esch", "isres"):
        executor = "serial" if opt in ("crs2", "esch", "isres") else "process"
        w, r = _run(prob, opt, executor, evaluations=budget)
        eps[opt] = {"evaluations": r.evaluations, "wall_s": w, "evals_per_s": r.evaluations / w, "executor": executor}
    res["evals_per_s"] = eps

    # 3. pool speed-up: one thread in-process vs 2 worker processes (one thread each)
    ratios, one, pool = [], [], []
    g = 10 if args.quick else 50
    for _ in range(args.repeats):
        numba.set_num_threads(1)
        w1, _ = _run(prob, "rcga", "serial", generations=g)
        numba.set_num_threads(res["numba_threads"])
        w2, _ = _run(prob, "rcga", "process", workers=cores, generations=g)
        one.append(w1)
        pool.append(w2)
        ratios.append(w1 / w2)
    res["pool_speedup"] = {"generations": g, "serial_1thread_s": one, "process_s": pool, "workers": cores,
                           "median_speedup": statistics.median(ratios)}

    res["mujoco"] = mujoco_part(args.quick, cores)
    finish(res, args.out, gens, eps)


def mujoco_part(quick: bool, cores: int) -> dict:
    """MuJoCo backend: generations timed after a warm-up generation (which JIT-compiles the native
    loop in every worker), extrapolated to the paper's 1000."""
    mj = make_problem("paper", backend="mujoco")
    mg = 2 if quick else 5
    with make_evaluator(mj, executor="process") as ev:
        optimize(mj, "rcga", seed=0, generations=1, evaluator=ev, progress=False)
        t0 = time.perf_counter()
        r = optimize(mj, "rcga", seed=0, generations=mg, evaluator=ev, progress=False)
        w = time.perf_counter() - t0
    full_evals = 40 + 39 * 999
    per_eval = w / r.evaluations
    bare = bare_step_us()
    return {"generations_timed": mg, "evaluations": r.evaluations, "wall_s": w, "s_per_eval": per_eval,
            "us_per_step_per_core": 1e6 * per_eval * cores / STEPS,
            "extrapolated_1000_gen_min": per_eval * full_evals / 60.0, "bare_step_us": bare,
            "bare_floor_1000_gen_min": bare * 1e-6 * STEPS * full_evals / cores / 60.0}


def finish(res: dict, out: str, gens: int, eps: dict) -> None:
    """Write the JSON and print the Markdown table."""
    write_json(out, res)
    cores = int(res["machine"].rsplit(",", 1)[1].split()[0])
    mg = res["mujoco"]["generations_timed"]
    ps = res["paper_scale"]
    print("| measure | value | goal |\n|---|---|---|")
    print(f"| paper-scale RCGA (40 x {gens} x 24,000 steps), paper backend | {ps['median_wall_s']:.0f} s "
          f"({ps['ns_per_step']:.0f} ns per butterfly-step) | <= 180 s |")
    m = res["mujoco"]
    print(f"| same on the MuJoCo backend (extrapolated from {mg} generations) | {m['extrapolated_1000_gen_min']:.0f} min | "
          f"<= 35 min |")
    print(f"| bare-engine floor for the same steps on {cores} cores | {m['bare_floor_1000_gen_min']:.0f} min | |")
    for k, v in eps.items():
        print(f"| {k}: evaluations per second ({v['executor']}) | {v['evals_per_s']:.0f} | |")
    print(f"| process-pool speed-up ({cores} workers vs 1 thread) | x{res['pool_speedup']['median_speedup']:.2f} | |")


if __name__ == "__main__":
    main()
