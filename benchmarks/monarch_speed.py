"""Can the monarch fly the speed it is asked, and does that carry it through wind? (issue 27's speed and wind)

Run: ``python benchmarks/monarch_speed.py`` (about 5 minutes on 2 cores). Writes
``benchmarks/results/monarch_speed.json``.

Controllers, each built from the shipped ``monarch`` or read from its kept file:

* ``monarch``: as shipped (ten inputs: it sees only its speed error);
* ``schedule 10`` and ``schedule 25``: the same network given the speed asked as an eleventh input through a pitch
  schedule (``Controller3D.with_speed_input(k, about_m_s=1.0)``): it sees its pitch ``k`` deg higher per m/s asked
  above 1 m/s, so that, holding its pitch, it flies its body lower the faster it is asked to fly; no evolution;
* ``attempt: schedule 10 + boost``, ``benchmarks/results/attempts/monarch_speed_boost_2026-11-26.json``: the
  schedule of 10 deg per m/s with a speed boost (0.5/s, at most 1.5 m/s: the speed asked that the network sees
  rises while the ground speed falls short), evolved on the ``fast`` task set with ``--natural`` (its provenance
  holds the run).

Each is flown level at 1, 1.5, 2 and 2.5 m/s asked (``measures.level_measures``, 5 s settling, 5 s measured) and on
the held-out courses 100-109 (as ``validate.course_check`` flies them: 10 waypoints, at most 60 s; with the
altitude's range and how far the first waypoint missed was missed, across and up or down) in calm air, in a 1 m/s wind
with gusts of 0.5 m/s on every axis, and in a steady 1.5 m/s wind, both blowing towards +x (``assess3d``'s courses).
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from lifelike_mj.butterfly import flight3d
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

ROOT = Path(__file__).parent
ATTEMPT = ROOT / "results" / "attempts" / "monarch_speed_boost_2026-11-26.json"
SPEEDS = (1.0, 1.5, 2.0, 2.5)
COURSES = tuple(range(100, 110))
MAX_S = 60.0
WEATHER = {"calm": None,
           "gusty 1 m/s": {"wind_m_s": (1.0, 0.0, 0.0), "gust_m_s": 0.5, "gust_vertical_m_s": 0.5},
           "1.5 m/s": {"wind_m_s": (1.5, 0.0, 0.0)}}
#: name -> (pitch schedule deg per m/s or None for the file, the file or None)
CONTROLLERS = {"monarch": (0.0, None), "schedule 10": (10.0, None), "schedule 25": (25.0, None),
               "attempt: schedule 10 + boost": (None, ATTEMPT)}
#: Which controllers fly the courses (the level flights show the rest).
ON_COURSES = ("monarch", "schedule 10", "attempt: schedule 10 + boost")


def controller(name: str):
    k, path = CONTROLLERS[name]
    if path is not None:
        return flight3d.load_controller(path)
    ctl = flight3d.load_controller("monarch")
    return ctl if k == 0.0 else ctl.with_speed_input(k, about_m_s=1.0)


def level(name: str, speed: float) -> dict:
    from lifelike_mj.butterfly.flight3d.measures import level_measures

    m = level_measures(controller(name), speed)
    keep = ("air_speed_m_s", "body_angle_deg", "stroke_left_deg", "stroke_right_deg", "dorsal_gap_deg",
            "flap_frequency_hz", "roll_mean_deg", "power_W_kg", "advance_ratio")
    return {"controller": name, "speed_asked_m_s": speed, **{k: float(m[k]) for k in keep}}


def course(name: str, weather: str, seed: int) -> dict:
    """One held-out course, flown as ``validate.course_check`` flies it (at most ``MAX_S``, in steps of 120), with
    what a miss looks like: the altitude's range (m) and the closest approach to the first waypoint not passed, split
    into horizontal and vertical (m; sampled every 5 steps)."""
    import math

    import numpy as np

    w = WEATHER[weather]
    task = flight3d.course(seed)
    if w is not None:
        task = task.with_weather(w["wind_m_s"], gust_m_s=w.get("gust_m_s", 0.0),
                                 gust_vertical_m_s=w.get("gust_vertical_m_s"), seed=seed)
    f = flight3d.Flight3D(controller=controller(name), task=task)
    rows = np.array(task.rows)
    z_lo = z_hi = float(f.data.qpos[2])
    miss = [math.inf, math.inf, -1]
    while f.time < MAX_S and f.waypoints_passed < len(rows):
        for _ in range(24):
            f.step(5)
            i = f.waypoints_passed
            if i >= len(rows):
                break
            z = float(f.data.qpos[2])
            z_lo, z_hi = min(z_lo, z), max(z_hi, z)
            d = rows[i] - f.data.qpos[:3]
            h, v = math.hypot(d[0], d[1]), float(d[2])
            if i != miss[2] or math.hypot(h, v) < math.hypot(miss[0], miss[1]):
                miss = [h, v, i]
    passed = int(f.waypoints_passed)
    return {"controller": name, "weather": weather, "seed": seed, "passed": passed, "time_s": float(f.time),
            "altitude_range_m": z_hi - z_lo,
            "first_missed": None if passed == len(rows) else {"waypoint": int(miss[2]), "horizontal_m": miss[0],
                                                              "vertical_m": miss[1]}}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "results" / "monarch_speed.json"))
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    start = time.perf_counter()
    with ProcessPoolExecutor(args.workers) as pool:
        lv = [pool.submit(level, n, v) for n in CONTROLLERS for v in SPEEDS]
        cs = [pool.submit(course, n, w, s) for n in ON_COURSES for w in WEATHER for s in COURSES]
        levels = [f.result() for f in lv]
        courses = [f.result() for f in cs]
    for r in levels:
        print(f"{r['controller']:30s} asked {r['speed_asked_m_s']:.1f}: {r['air_speed_m_s']:.2f} m/s through the air, "
              f"body {r['body_angle_deg']:5.1f} deg, strokes {r['stroke_left_deg']:.0f}/{r['stroke_right_deg']:.0f} "
              f"deg, {r['flap_frequency_hz']:.1f} Hz, {r['power_W_kg']:.1f} W/kg, J {r['advance_ratio']:.2f}")
    summary = {}
    for n in ON_COURSES:
        for w in WEATHER:
            runs = [c for c in courses if c["controller"] == n and c["weather"] == w]
            missed = [c["first_missed"] for c in runs if c["first_missed"]]
            summary[f"{n} / {w}"] = {"completed": sum(c["passed"] == 10 for c in runs),
                                     "passed": [c["passed"] for c in runs],
                                     "altitude_range_m": [min(c["altitude_range_m"] for c in runs),
                                                          max(c["altitude_range_m"] for c in runs)],
                                     "missed_by_horizontal_m": [min((m["horizontal_m"] for m in missed), default=None),
                                                                max((m["horizontal_m"] for m in missed), default=None)],
                                     "missed_by_vertical_m": [min((abs(m["vertical_m"]) for m in missed), default=None),
                                                              max((abs(m["vertical_m"]) for m in missed), default=None)]}
            s = summary[f"{n} / {w}"]
            def span(v):
                return "-" if v[0] is None else f"{v[0]:.2f}-{v[1]:.2f} m"

            print(f"{n:30s} {w:12s}: {s['completed']} of {len(runs)} completed, waypoints {s['passed']}, altitude "
                  f"range {span(s['altitude_range_m'])}, first miss by {span(s['missed_by_horizontal_m'])} across, "
                  f"{span(s['missed_by_vertical_m'])} up or down")
    write_json(args.out, {"provenance": provenance(benchmark="monarch_speed", speeds_m_s=list(SPEEDS),
                                                   courses=list(COURSES), weather=WEATHER),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start,
                          "levels": levels, "courses": courses, "summary": summary})


if __name__ == "__main__":
    main()
