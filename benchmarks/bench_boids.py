"""Boids speed benchmark: writes benchmarks/results/boids.json and prints the table for docs/performance.md.

Run: ``python benchmarks/bench_boids.py [--mesa-python PY]`` (same numbers as ``lifelike-mj bench boids
--json``). Mesa is the peer, not a dependency: install it for the benchmark only (``pip install mesa``,
in this environment or another whose interpreter ``--mesa-python`` names).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from lifelike_mj.boids import bench
from lifelike_mj.io import write_json


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--max-n", type=int, default=1_000_000)
    ap.add_argument("--mesa-python", default=None)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "boids.json"))
    args = ap.parse_args()
    r = bench.run(repeats=args.repeats, max_n=args.max_n, mesa_python=args.mesa_python)
    write_json(args.out, r)
    print("| measure | median | goal |\n|---|---|---|")
    print(f"| n = 300, 3D, preset {r['preset']}, agent-steps per s | {r['agent_steps_per_s_n300']:.3g} | >= 2e6 |")
    print(f"| n = 300, 3D, same, all {r['threads']} threads | {r['agent_steps_per_s_n300_all_threads']:.3g} | |")
    whole = r["agent_steps_per_s_n300_whole_runs"]
    print(f"| n = 300, whole 10,000-step runs of the eight patterns, median (min-max) | "
          f"{r['agent_steps_per_s_n300_whole_runs_median']:.3g} ({min(whole.values()):.3g}-{max(whole.values()):.3g}) | |")
    print(f"| n = 300, 2D, agent-steps per s | {r['agent_steps_per_s_n300_2d']:.3g} | |")
    print(f"| NumPy all-pairs peer, n = 300, 3D | {r['numpy_all_pairs_agent_steps_per_s_n300']:.3g} "
          f"(engine x{r['numpy_ratio']:.1f}) | |")
    mesa = r["mesa"]
    if "agent_steps_per_s" in mesa:
        print(f"| Mesa {mesa['mesa']} boid flockers, n = 300, 2D | {mesa['agent_steps_per_s']:.3g} "
              f"(engine x{r['mesa_ratio']:.0f}) | >= x100 |")
    else:
        print(f"| Mesa | {mesa.get('error')} | >= x100 |")
    for s in r["scaling"]:
        print(f"| n = {s['n']:,} (box {s['box']:.0f}) | {s['agent_steps_per_s']:.3g} agent-steps/s, "
              f"{s['steps_per_s']:.3g} steps/s | |")
    print(f"| scaling exponent (wall time per step ~ n^x) | {r.get('scaling_exponent', float('nan')):.2f} | <= 1.1 |")


if __name__ == "__main__":
    main()
