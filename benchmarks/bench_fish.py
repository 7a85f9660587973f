"""Fish speed benchmark: writes benchmarks/results/fish.json and prints the table for docs/performance.md.

Run: ``python benchmarks/bench_fish.py [--repeats 5]`` (same numbers as ``lifelike-mj bench fish --json``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from lifelike_mj.fish import bench
from lifelike_mj.io import write_json


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--long-minutes", type=float, default=10.0)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "fish.json"))
    args = ap.parse_args()
    r = bench.run(repeats=args.repeats, long_minutes=args.long_minutes)
    write_json(args.out, r)
    ten, thou, rend = r["ten"], r["thousand"], r.get("render", {})
    print("| measure | median | goal |\n|---|---|---|")
    print(f"| 10 fish, simulated s per wall s | x{ten['realtime_factor']:.0f} | >= x200 |")
    print(f"| 1,000 fish, simulated s per wall s | x{thou['realtime_factor']:.2f} | >= x1 |")
    print(f"| 1,000 fish, building the scene | {thou['build_s']:.2f} s | |")
    sch = r["thousand_school"]
    print(f"| 1,000 `school` fish (interacting), simulated s per wall s | x{sch['realtime_factor']:.2f} | >= x1 |")
    if "fps" in rend:
        print(f"| rendering 640x480, frames per s | {rend['fps']:.0f} | >= 60 |")
    else:
        print(f"| rendering 640x480 | {rend.get('error', 'not measured')} | >= 60 |")
    if "long_run" in r:
        lr = r["long_run"]
        print(f"| {lr['fish']} fish for {lr['simulated_s'] / 60:.0f} min: fish outside the tank | "
              f"{lr['fish_outside_tank']} (finite: {lr['all_finite']}) | 0 |")


if __name__ == "__main__":
    main()
