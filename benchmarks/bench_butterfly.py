"""Butterfly speed benchmark: writes benchmarks/results/butterfly.json and prints a Markdown table.

Run: ``python benchmarks/bench_butterfly.py [--repeats 5]`` (same numbers as
``lifelike-mj bench butterfly --json``). Paste the table into docs/performance.md.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from lifelike_mj.butterfly import bench
from lifelike_mj.io import write_json


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "butterfly.json"))
    args = ap.parse_args()
    r = bench.run(repeats=args.repeats)
    write_json(args.out, r)
    print("| measure | median | goal |\n|---|---|---|")
    print(f"| paper backend, 40 x 24,000 steps | {r['paper_ns_per_step']:.1f} ns/step | |")
    print(f"| naive Python loop | {r['naive_ns_per_step']:.0f} ns/step | |")
    print(f"| paper speed-up vs naive | x{r['paper_speedup_vs_naive']:.0f} | >= x100 |")
    print(f"| MuJoCo bare mj_step (RK4) | {r['mujoco_bare_us_per_step']:.2f} us/step | |")
    print(f"| MuJoCo + callback (tip) + controller | {r['mujoco_us_per_step']:.2f} us/step | |")
    print(f"| overhead over bare | +{100 * r['mujoco_callback_overhead']:.1f} % | <= +25 % |")
    print(f"| MuJoCo + callback (strip, 48 points/wing) + controller | {r['mujoco_strip_us_per_step']:.2f} us/step | |")
    print(f"| strip overhead over bare | +{100 * r['mujoco_strip_callback_overhead']:.1f} % | |")


if __name__ == "__main__":
    main()
