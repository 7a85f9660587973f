"""How fast the designed controller flies (issue 42): in the compiled loop (``designed_kernel.CompiledDesigned``)
against its Python twin (``designed.DesignedController``), on the same calm course.

Run: ``python benchmarks/designed_speed.py`` (under a minute). Writes ``benchmarks/results/designed_speed.json``.

Each form flies course seed 201 for 10 s (8,000 steps) from the start, ``--repeats`` times in one process after a
warm-up (the compiled loop's first run compiles it); the median wall time of each and their ratio, measured in the
same run.

With ``--predictive S`` (seconds, 0: not measured) also the compiled designed controller under predictive sampling
(``predictive.Planner``, its defaults) on the same course in 1 m/s wind with 0.5 m/s gusts on every axis, ``S`` s
from the start, ``--repeats`` times: the seconds of compute per second flown, on the threads ``NUMBA_NUM_THREADS``
allows (recorded).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
STEPS, SEED = 8000, 201


def main(argv=None) -> None:
    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d import designed_kernel as DK
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.tasks import course

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--model", default=str(HERE / "results" / "monarch_model.json"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--predictive", type=float, default=0.0, help="seconds flown under predictive sampling (0: none)")
    ap.add_argument("--out", default=str(HERE / "results" / "designed_speed.json"))
    args = ap.parse_args(argv)
    spec = D.design(json.loads(Path(args.model).read_text()))
    task = course(SEED)
    Flight3D(controller=DK.CompiledDesigned(spec), task=task).step(100)  # compiles (or loads) the loop
    forms = {"python": lambda: D.DesignedController(spec), "compiled": lambda: DK.CompiledDesigned(spec)}
    times: dict[str, list[float]] = {k: [] for k in forms}
    for _ in range(args.repeats):
        for name, make in forms.items():
            f = Flight3D(controller=make(), task=task)
            t0 = time.perf_counter()
            f.step(STEPS)
            times[name].append(time.perf_counter() - t0)
    med = {k: float(np.median(v)) for k, v in times.items()}
    flown_s = STEPS * f.dt
    out = {"provenance": provenance(benchmark="designed_speed", model=args.model, repeats=args.repeats, steps=STEPS,
                                    seed=SEED, predictive_s=args.predictive),
           "machine": machine_info(), "flight_s": flown_s, "seconds": times, "median_s": med,
           "real_time_factor": {k: flown_s / v for k, v in med.items()}, "speedup": med["python"] / med["compiled"]}
    if args.predictive > 0:
        import os

        from lifelike_mj.butterfly.flight3d.predictive import Planner

        gusty = task.with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5)
        Planner(Flight3D(controller=DK.CompiledDesigned(spec), task=gusty)).fly(0.2)  # compiles the copies' loop
        walls = []
        for _ in range(args.repeats):
            p = Planner(Flight3D(controller=DK.CompiledDesigned(spec), task=gusty))
            t0 = time.perf_counter()
            p.fly(args.predictive)
            walls.append(time.perf_counter() - t0)
        out["predictive"] = {"flight_s": args.predictive, "seconds": walls, "median_s": float(np.median(walls)),
                             "compute_per_second_flown": float(np.median(walls)) / args.predictive,
                             "numba_threads": os.environ.get("NUMBA_NUM_THREADS", "all cores")}
        print(f"predictive sampling: {out['predictive']['compute_per_second_flown']:.1f} s of compute per second "
              f"flown (threads: {out['predictive']['numba_threads']})")
    write_json(args.out, out)
    print(f"{flown_s:g} s of flight: Python twin {med['python']:.2f} s, compiled {med['compiled']:.2f} s "
          f"({out['speedup']:.1f} times faster); wrote {args.out}")


if __name__ == "__main__":
    main()
