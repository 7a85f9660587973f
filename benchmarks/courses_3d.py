"""Random calm courses for every shipped 3D controller (issue 27's robustness): does any tumble or fall?

Run: ``python benchmarks/courses_3d.py [--controllers monarch,steer] [--courses 100] [--first 1000]`` (about 10
minutes on 2 cores for the four shipped controllers). Writes ``benchmarks/results/courses_3d.json``.

Each course: 10 waypoints drawn by its seed (``tasks.course``; seeds from ``--first`` on, none of them a training
course), calm air, at most ``MAX_S`` seconds. Recorded per course: the waypoints passed, the time, whether the
butterfly **tumbled** (its roll or pitch beyond 90 deg at any 10 ms sample) and whether it **fell** (more than
``FALL_M`` below the course's lowest waypoint).
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from lifelike_mj.butterfly import flight3d
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

MAX_S = 40.0
FALL_M = 1.0
#: The shipped controller and the two withdrawn after this benchmark (loaded from their kept files).
CONTROLLERS = ("monarch", "steer", "wind")


def fly(controller: str, seed: int) -> dict:
    task = flight3d.course(seed)
    kept = controller in flight3d.WITHDRAWN
    f = flight3d.Flight3D(controller=str(flight3d.withdrawn_file(controller)) if kept else controller, task=task)
    lowest = min(r[2] for r in task.rows)
    tumbled = fell = False
    every = max(1, round(0.01 / f.dt))
    while f.time < MAX_S and f.waypoints_passed < len(task.rows):
        f.step(every)
        roll, pitch, _ = f.state()["attitude_rad"]
        tumbled |= abs(roll) > math.pi / 2 or abs(pitch) > math.pi / 2
        fell |= f.data.qpos[2] < lowest - FALL_M
        if fell:
            break
    return {"seed": seed, "passed": int(f.waypoints_passed), "time_s": float(f.time), "tumbled": bool(tumbled),
            "fell": bool(fell)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--controllers", default=",".join(CONTROLLERS))
    ap.add_argument("--courses", type=int, default=100)
    ap.add_argument("--first", type=int, default=1000)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "courses_3d.json"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    out = {}
    for name in args.controllers.split(","):
        runs = [fly(name, s) for s in range(args.first, args.first + args.courses)]
        passed = np.array([r["passed"] for r in runs])
        out[name] = {"courses": len(runs), "completed": int((passed == 10).sum()),
                     "tumbled": int(sum(r["tumbled"] for r in runs)), "fell": int(sum(r["fell"] for r in runs)),
                     "waypoints_mean": float(passed.mean()), "runs": runs}
        s = out[name]
        print(f"{name}: {s['completed']} of {s['courses']} completed, {s['tumbled']} tumbled, {s['fell']} fell",
              flush=True)
    write_json(args.out, {"provenance": provenance(benchmark="courses_3d", max_s=MAX_S, fall_m=FALL_M,
                                                   first_seed=args.first, courses=args.courses),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start, "controllers": out})


if __name__ == "__main__":
    main()
