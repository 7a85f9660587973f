"""The designed controller (issue 42, in progress) on courses, and any 3D network controller on the same ones.

Run: ``python benchmarks/designed_courses.py`` (45-55 s on 2 cores, measured 2026-11-28; the averaged model first, if
``benchmarks/results/monarch_model.json`` is missing: ``lifelike-mj butterfly model3d --out
benchmarks/results/monarch_model.json``). Writes ``benchmarks/results/designed_courses.json``.

Each seed's course (``tasks.course``: ten waypoints) is flown four times by the designed controller built from
the model's level trims (``designed.design``), in the compiled loop (``designed_kernel.CompiledDesigned``, the same
flights as its Python twin, ``designed.DesignedController``, which draws the picture), on the calibrated wing law, for
at most 60 s:
- in calm air;
- in a 1 m/s wind toward +x with gusts of 0.5 m/s and vertical gusts at Dryden's ratio near the ground (0.25 m/s);
- in the same wind with vertical gusts as strong as the horizontal ones (0.5 m/s);
- in a steady 1.5 m/s wind from one of four sides (toward +x, +y, -x, -y by the seed's remainder by 4).
With ``--controller NAME`` (a shipped 3D network, such as ``monarch``, or its file) the same flights are flown by that
network, on its own wing law and animal, started from its own base gait, into
``benchmarks/results/designed_courses_NAME.json``: the side-by-side table of ``docs/results.md``.
The designed controller was tuned on seeds 100-107 (and calm courses 100-119); the default seeds, 200-209, were never flown
while tuning.

Also measured: level flight in calm air at 1, 1.5 and 2 m/s (``measures.level_measures``: 6 s after 5 s, with the
altitude's rms over the same window), and ``--calm`` random calm courses (seeds 1000 on, those of
``courses_3d.py``; 100 by default) for tumbles (roll or pitch beyond 90 deg at any 10 ms sample) and falls (1 m below
the course's lowest waypoint), at most 40 s each.
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


def _spec(model_path: str) -> dict:
    """The designed controller's schedule from the averaged model file (``designed.design``), made once per run."""
    from lifelike_mj.butterfly.flight3d import designed as D

    return D.design(json.loads(Path(model_path).read_text()))


def _flight(spec) -> tuple[object, dict]:
    """The controller to fly and the flight's keywords: ``spec`` a designed controller's schedule (the calibrated
    monarch, started from the 1.5 m/s trim) or a network controller's name or file (its own animal, law and base)."""
    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d import designed_kernel as DK
    from lifelike_mj.butterfly.flight3d.controllers import load_controller
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.butterfly.flight3d.parts import Butterfly

    if isinstance(spec, str):
        return load_controller(spec), {}
    return DK.CompiledDesigned(spec), {"command": KinematicsCommand(*D._interp(spec["schedule"], 1.5, "command")),
                                       "butterfly": Butterfly("monarch", force_law="calibrated")}


def fly(job: tuple) -> dict:
    """One seed's courses (module docstring): ``(spec, seed)``, or ``(spec, seed, weathers, planner)`` for some of
    them (names of :data:`WEATHER` and ``steady_1_5``) and predictive sampling on top (``Planner``'s keywords, or
    ``None``: the controller alone)."""
    from lifelike_mj.butterfly.flight3d.validate import course_check

    spec, seed, names, planner = (*job, None, None)[:4]
    dx, dy = DIRECTIONS[seed % 4]
    weather = dict(WEATHER, steady_1_5={"wind_to_m_s": [1.5 * dx, 1.5 * dy, 0.0]})
    out = {"seed": seed}
    ctl, kw = _flight(spec)  # read once: a controller keeps no state between flights
    for name, w in weather.items():
        if names and name not in names:
            continue
        t0 = time.perf_counter()
        r = course_check(ctl, seed, weather=w, planner=None if planner is None else dict(planner, seed=seed), **kw)
        out[name] = {"passed": r["passed"], "time_s": r["time_s"], "wall_s": round(time.perf_counter() - t0, 1)}
    return out


def calm(job: tuple[dict, int]) -> dict:
    """One random calm course (module docstring): waypoints passed, time, tumbled, fell, the largest roll or pitch."""
    import math

    import numpy as np

    from lifelike_mj.butterfly.flight3d.flight import Flight3D, euler_from_quat
    from lifelike_mj.butterfly.flight3d.tasks import course

    spec, seed = job
    task = course(seed)
    ctl, kw = _flight(spec)
    f = Flight3D(controller=ctl, task=task, **kw)
    lowest = min(r[2] for r in task.rows)
    worst, fell = 0.0, False
    while f.time < 40.0 and f.waypoints_passed < len(task.rows) and not fell:
        f.step(8)  # 10 ms
        worst = max(worst, float(np.abs(euler_from_quat(f.data.qpos[3:7])[:2]).max()))
        fell = bool(f.data.qpos[2] < lowest - 1.0)
    return {"seed": seed, "passed": int(f.waypoints_passed), "time_s": float(f.time),
            "tumbled": worst > math.pi / 2, "fell": fell, "largest_attitude_deg": math.degrees(worst)}


def level(job: tuple[dict, float]) -> dict:
    """Level flight in calm air at one speed (module docstring)."""
    import numpy as np

    from lifelike_mj.butterfly.flight3d import measures as M
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    spec, speed = job
    ctl, kw = _flight(spec)
    f = Flight3D(controller=ctl, task=tasks.level(speed), **kw)
    f.step(int(round(5.0 / f.dt)))
    s = M.sample(f, 6.0)
    m = M.measures(s, **M.body_numbers(f))
    keep = ("roll_mean_deg", "stroke_left_deg", "stroke_right_deg", "flap_frequency_hz", "dorsal_gap_deg",
            "body_angle_deg", "power_W_kg", "power_net_W_kg", "air_speed_m_s")
    return {"speed_m_s": speed, "altitude_rms_m": float(np.sqrt(np.mean(s["position_m"][:, 2] ** 2))),
            **{k: m[k] for k in keep}}


def picture(model_path: str, seed: int, out: str) -> None:
    """The course of ``seed`` in the gusts of Dryden's ratio, drawn (``figures.fig_wind_course``): the path, the altitude
    against the waypoints', and the wind estimate against the wind met."""
    import numpy as np

    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.figures import fig_wind_course
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.butterfly.flight3d.parts import Butterfly
    from lifelike_mj.butterfly.flight3d.tasks import course

    spec = _spec(model_path)
    ctl = D.DesignedController(spec)
    task = course(seed).with_weather(**WEATHER["gusts_dryden"])
    fl = Flight3D(KinematicsCommand(*D._interp(spec["schedule"], 1.5, "command")),
                  butterfly=Butterfly("monarch", force_law="calibrated"), controller=ctl, task=task)
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
    ap.add_argument("--controller", default="designed", help="designed (from --model), or a 3D network's name or file")
    ap.add_argument("--out", default=None, help="default: results/designed_courses.json, or "
                    "results/designed_courses_NAME.json for a network")
    ap.add_argument("--picture", default=None, help="also draw one course in gusts (Dryden's ratio) here (.png)")
    ap.add_argument("--picture-seed", type=int, default=200)
    ap.add_argument("--calm", type=int, default=100, help="random calm courses from seed 1000 on (0: none)")
    ap.add_argument("--weathers", default="calm,gusts_dryden,gusts_every_axis,steady_1_5",
                    help="which of the four courses each seed flies (comma-separated)")
    ap.add_argument("--no-level", action="store_true", help="skip level flight at 1, 1.5 and 2 m/s")
    ap.add_argument("--predictive", action="store_true",
                    help="fly the courses with predictive sampling on the designed controller (predictive.Planner, "
                         "its defaults, the course's seed); about 12 s of compute per second flown on one core")
    args = ap.parse_args(argv)
    if args.picture:
        picture(args.model, args.picture_seed, args.picture)
    lo, hi = (int(v) for v in args.seeds.split("-"))
    start = time.perf_counter()
    designed = args.controller == "designed"
    spec = _spec(args.model) if designed else args.controller
    names = [w.strip() for w in args.weathers.split(",") if w.strip()]
    if args.predictive and not designed:
        ap.error("--predictive flies the designed controller (--controller designed)")
    default = "designed_courses_predictive.json" if args.predictive else "designed_courses.json"
    out = args.out or str(HERE / "results" / (default if designed else
                                              f"designed_courses_{Path(args.controller).stem}.json"))
    planner = {} if args.predictive else None
    with Pool(2) as pool:
        rows = pool.map(fly, [(spec, s, names, planner) for s in range(lo, hi + 1)], chunksize=1)
        levels = [] if args.no_level else pool.map(level, [(spec, v) for v in (1.0, 1.5, 2.0)])
        calms = pool.map(calm, [(spec, s) for s in range(1000, 1000 + args.calm)])
    summary = {name: {"completed": sum(r[name]["passed"] == 10 for r in rows), "of": len(rows),
                      "waypoints": [r[name]["passed"] for r in rows]}
               for name in ("calm", "gusts_dryden", "gusts_every_axis", "steady_1_5") if name in names}
    write_json(out, {"provenance": provenance(benchmark="designed_courses", controller=args.controller,
                                              model=args.model if designed else None, seeds=[lo, hi], calm=args.calm,
                                              weathers=names, predictive=args.predictive, level=not args.no_level),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start,
                          "summary": summary, "courses": rows, "level": levels,
                          "calm_courses": {"completed": sum(r["passed"] == 10 for r in calms),
                                           "tumbled": sum(r["tumbled"] for r in calms),
                                           "fell": sum(r["fell"] for r in calms), "of": len(calms), "runs": calms}})
    for name, s in summary.items():
        print(f"{name}: {s['completed']} of {s['of']} completed; waypoints {s['waypoints']}")
    for r in levels:
        print(", ".join(f"{k} {v:.3g}" for k, v in r.items()))
    if calms:
        worst = [r["largest_attitude_deg"] for r in calms]
        print(f"random calm courses: {sum(r['passed'] == 10 for r in calms)} of {len(calms)} completed, "
              f"{sum(r['tumbled'] for r in calms)} tumbled, {sum(r['fell'] for r in calms)} fell; largest roll or "
              f"pitch: median {sorted(worst)[len(worst) // 2]:.0f} deg, most {max(worst):.0f} deg")


if __name__ == "__main__":
    main()
