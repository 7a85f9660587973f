"""The designed controller (issue 42, in progress) on courses, beside what the shipped ``monarch`` did.

Run: ``python benchmarks/designed_courses.py`` (about 2 minutes on 2 cores; the averaged model first, if
``benchmarks/results/monarch_model.json`` is missing: ``lifelike-mj butterfly model3d --out
benchmarks/results/monarch_model.json``). Writes ``benchmarks/results/designed_courses.json``.

Each seed's course (``tasks.course``: ten waypoints) is flown four times by ``designed.DesignedController`` built from
the model's level trims (``designed.design``), on the calibrated wing law, for at most 60 s:
- in calm air;
- in a 1 m/s wind toward +x with gusts of 0.5 m/s and vertical gusts at Dryden's ratio near the ground (0.25 m/s);
- in the same wind with vertical gusts as strong as the horizontal ones (0.5 m/s);
- in a steady 1.5 m/s wind from one of four sides (toward +x, +y, -x, -y by the seed's remainder by 4).
The controller was tuned on seeds 100-107; the default seeds, 200-209, were never flown while tuning.
"""

from __future__ import annotations

import argparse
import json
import time
from multiprocessing import Pool
from pathlib import Path

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
MODEL = HERE / "results" / "monarch_model.json"
DIRECTIONS = ((1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0))
WEATHER = {"calm": None,
           "gusts_dryden": {"wind_to_m_s": [1.0, 0.0, 0.0], "gust_m_s": 0.5, "gust_vertical_m_s": 0.25},
           "gusts_every_axis": {"wind_to_m_s": [1.0, 0.0, 0.0], "gust_m_s": 0.5, "gust_vertical_m_s": 0.5}}


def fly(job: tuple[str, int]) -> dict:
    """One seed's four courses (module docstring)."""
    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.butterfly.flight3d.validate import course_check

    model_path, seed = job
    spec = D.design(json.loads(Path(model_path).read_text()))
    start = KinematicsCommand(*D._interp(spec["schedule"], 1.5, "command"))
    dx, dy = DIRECTIONS[seed % 4]
    weather = dict(WEATHER, steady_1_5={"wind_to_m_s": [1.5 * dx, 1.5 * dy, 0.0]})
    out = {"seed": seed}
    for name, w in weather.items():
        r = course_check(D.DesignedController(spec), seed, weather=w, animal="monarch", force_law="calibrated",
                         command=start)
        out[name] = {"passed": r["passed"], "time_s": r["time_s"]}
    return out


def picture(model_path: str, seed: int, out: str) -> None:
    """The course of ``seed`` in the gusts of Dryden's ratio, drawn (``figures.fig_wind_course``): the path, the altitude
    against the waypoints', and the wind estimate against the wind met."""
    import numpy as np

    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.figures import fig_wind_course
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.butterfly.flight3d.tasks import course

    spec = D.design(json.loads(Path(model_path).read_text()))
    ctl = D.DesignedController(spec)
    task = course(seed).with_weather(**WEATHER["gusts_dryden"])
    fl = Flight3D(KinematicsCommand(*D._interp(spec["schedule"], 1.5, "command")), animal="monarch",
                  force_law="calibrated", controller=ctl, task=task)
    t, pos, true, est, passed_at = [], [], [], [], []
    while fl.time < 60.0 and fl.waypoints_passed < len(task.rows):
        before = fl.waypoints_passed
        fl.step(8)
        if fl.waypoints_passed > before:
            passed_at.append(fl.time)
        t.append(fl.time)
        pos.append(fl.data.qpos[:3].copy())
        true.append(fl.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3].copy())
        est.append(ctl.last["wind"])
    fig_wind_course(np.array(t), np.array(pos), [r[:3] for r in task.rows], passed_at, np.array(true), np.array(est),
                    out, title=f"course {seed}: 1 m/s wind to +x, gusts 0.5 m/s (vertical 0.25)")
    print(f"{out}: {len(passed_at)} of {len(task.rows)} waypoints in {fl.time:.1f} s")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default=str(MODEL))
    ap.add_argument("--seeds", default="200-209", help="first-last")
    ap.add_argument("--out", default=str(HERE / "results" / "designed_courses.json"))
    ap.add_argument("--picture", default=None, help="also draw one course in gusts (Dryden's ratio) here (.png)")
    ap.add_argument("--picture-seed", type=int, default=200)
    args = ap.parse_args(argv)
    if args.picture:
        picture(args.model, args.picture_seed, args.picture)
    lo, hi = (int(v) for v in args.seeds.split("-"))
    start = time.perf_counter()
    with Pool(2) as pool:
        rows = pool.map(fly, [(args.model, s) for s in range(lo, hi + 1)])
    summary = {name: {"completed": sum(r[name]["passed"] == 10 for r in rows), "of": len(rows),
                      "waypoints": [r[name]["passed"] for r in rows]}
               for name in ("calm", "gusts_dryden", "gusts_every_axis", "steady_1_5")}
    write_json(args.out, {"provenance": provenance(benchmark="designed_courses", model=args.model, seeds=[lo, hi]),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start,
                          "summary": summary, "courses": rows})
    for name, s in summary.items():
        print(f"{name}: {s['completed']} of {s['of']} completed; waypoints {s['waypoints']}")


if __name__ == "__main__":
    main()
