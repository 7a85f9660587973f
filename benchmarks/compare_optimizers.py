"""Compare the five optimisers on the paper's task (Oe 2010 section 6.3) at equal budgets.

Run: ``python benchmarks/compare_optimizers.py [--evaluations 4000] [--seeds 0 1 2]``; writes
``benchmarks/results/optimizers.json`` and ``docs/figures/optimizer_convergence.png`` and prints the
Markdown table for docs/results.md.

Each optimiser gets the same number of fitness evaluations (20 s flights, eq. 13) per seed, with its
default population (rcga: the paper's 40; cmaes: pycma's 4 + 3 ln 49 = 15 with IPOP restarts;
crs2: nlopt's 10 (n + 1) = 500; esch: 40; isres: 20 (n + 1) = 1000). RCGA and CMA-ES evaluate whole
generations on the process pool; nlopt's algorithms call one point at a time and run in-process.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from lifelike_mj.butterfly.evolution import make_problem
from lifelike_mj.evolve import OPTIMIZERS, make_evaluator, optimize
from lifelike_mj.io import write_json

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--evaluations", type=int, default=4000)
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "optimizers.json"))
    ap.add_argument("--figure", default=str(ROOT / "docs" / "figures" / "optimizer_convergence.png"))
    args = ap.parse_args()
    prob = make_problem("paper")
    runs: dict = {}
    for opt in OPTIMIZERS:
        executor = "serial" if opt in ("crs2", "esch", "isres") else "process"
        runs[opt] = []
        with make_evaluator(prob, executor=executor) as ev:
            for seed in args.seeds:
                t0 = time.perf_counter()
                r = optimize(prob, opt, seed=seed, evaluations=args.evaluations, evaluator=ev, progress=False)
                wall = time.perf_counter() - t0
                runs[opt].append({"seed": seed, "best": float(r.best_f), "evaluations": r.evaluations, "wall_s": wall,
                                  "population": r.population, "history": [dict(h) for h in r.history]})
                print(f"{opt} seed {seed}: best H = {r.best_f:.0f} after {r.evaluations} evaluations, {wall:.1f} s",
                      flush=True)
    write_json(args.out, {"task": "paper (section 6.3)", "evaluations": args.evaluations, "seeds": args.seeds,
                          "runs": runs})
    from lifelike_mj.butterfly.ann_figures import fig_optimizer_convergence

    fig_optimizer_convergence({k: [r["history"] for r in v] for k, v in runs.items()}, args.figure)
    print("\n| optimiser | population | best H, median over seeds | min – max | evaluations/s |\n|---|---|---|---|---|")
    for opt, rs in runs.items():
        bests = [r["best"] for r in rs]
        eps = statistics.median(r["evaluations"] / r["wall_s"] for r in rs)
        print(f"| {opt} | {rs[0]['population']} | {statistics.median(bests):.0f} | {min(bests):.0f} – {max(bests):.0f} | "
              f"{eps:.0f} |")


if __name__ == "__main__":
    main()
