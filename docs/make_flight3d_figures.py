"""Make the 3D flight figures of ``docs/results.md`` that show the shipped default controller (``designed``): its turns,
a course it never flew while it was tuned, and a course in gusty wind, through the public API.

    python docs/make_flight3d_figures.py

Writes ``docs/figures/butterfly3d_turns.png``, ``butterfly3d_course200.png`` and ``butterfly3d_wind_course201.png``
and prints what each shows. The designed controller was tuned on courses 100-107 (and calm courses 100-119); courses
200 and 201 are among the held-out seeds of ``benchmarks/designed_courses.py``.
"""

from pathlib import Path

import numpy as np

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.figures import fig_paths

OUT = Path(__file__).resolve().parent / "figures"
CONTROLLER = "designed"


def _fly(task, duration_s: float) -> dict:
    """``task`` flown by the default controller for ``duration_s``, its path every 10 ms."""
    f = flight3d.Flight3D(controller=CONTROLLER, task=task)
    return f.record(duration_s=duration_s, every=max(1, round(0.01 / f.dt)))


def turns() -> None:
    recs, labels = [], []
    for angle, label in ((90.0, "turn 90 deg left"), (-90.0, "turn 90 deg right"), (180.0, "turn 180 deg")):
        rec = _fly(flight3d.turn(angle, 2.0, 1.5), 8.0)
        recs.append(rec)
        labels.append(label)
        late = rec["t_s"] > 6.0
        off = np.degrees(np.angle(np.exp(1j * (rec["attitude_rad"][late, 2] - np.radians(angle)))))
        print(f"{label}: heading within {np.abs(off).max():.1f} deg of the one asked over 6-8 s, altitude "
              f"[{rec['position_m'][:, 2].min():+.3f}, {rec['position_m'][:, 2].max():+.3f}] m")
    fig_paths(recs, labels, path=OUT / "butterfly3d_turns.png",
              title=f"{CONTROLLER}: turns at 1.5 m/s, commanded at 2 s")


def course(seed: int, weather: dict | None, name: str, what: str, max_s: float) -> None:
    """A course of 10 waypoints flown until its last is passed (or ``max_s``), drawn from above and from the side."""
    task = flight3d.course(seed)
    if weather:
        task = task.with_weather(**weather)
    f = flight3d.Flight3D(controller=CONTROLLER, task=task)
    every = max(1, round(0.01 / f.dt))  # 10 ms
    pos = [f.data.qpos[0:3].copy()]
    while f.time < max_s and f.waypoints_passed < len(task.rows):
        f.step(every)
        pos.append(f.data.qpos[0:3].copy())
    pos = np.array(pos)
    fig_paths([{"position_m": pos}], waypoints=[r[:3] for r in task.rows], path=OUT / name,
              title=f"{CONTROLLER}: course seed {seed} ({what}),\n{f.waypoints_passed} of {len(task.rows)} "
                    f"waypoints in {f.time:.1f} s")
    print(f"{name}: {f.waypoints_passed} of {len(task.rows)} waypoints in {f.time:.1f} s, altitude "
          f"[{pos[:, 2].min():+.2f}, {pos[:, 2].max():+.2f}] m")


def main() -> None:
    turns()
    course(200, None, "butterfly3d_course200.png", "calm, never flown while tuning", 60.0)
    course(201, {"wind_to_m_s": (1.0, 0.0, 0.0), "gust_m_s": 0.5, "gust_vertical_m_s": 0.25},
           "butterfly3d_wind_course201.png", "1 m/s wind to +x, gusts 0.5 m/s, vertical 0.25", 60.0)


if __name__ == "__main__":
    main()
