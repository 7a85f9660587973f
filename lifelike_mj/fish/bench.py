"""``lifelike-mj bench fish``: simulated seconds per wall second for 10 and 1,000 fish (and 1,000 fish of the
interacting ``school`` preset), the long no-escape run, and offscreen rendering frames per second.

Goals (issue 4): 10 fish at least 200x real time, 1,000 fish at least real time at 60 Hz control,
rendering at least 60 frames per second at 640 x 480; issue 28: 1,000 interacting fish at least real time.
Simulation is headless and does not record tracks; times are medians of ``repeats`` runs of a warmed-up
:class:`~lifelike_mj.fish.sim.Tank` (scene building is timed separately).
"""

from __future__ import annotations

import statistics
import time

import numpy as np

from lifelike_mj.fish.params import load_preset
from lifelike_mj.fish.sim import Tank, swim
from lifelike_mj.machine import machine_info


def _realtime(n_fish: int, sim_s: float, repeats: int, preset: str = "B-D", size=None) -> dict:
    p = load_preset(preset)
    t0 = time.perf_counter()
    sw = Tank(p, n_fish, seed=0, size=size)
    build = time.perf_counter() - t0
    sw.run(int(p.control_hz), record=False)  # warm-up: compile, settle
    k = int(round(sim_s * p.control_hz))
    samples = []
    for _ in range(repeats):
        t = time.perf_counter()
        sw.run(k, record=False)
        samples.append(sim_s / (time.perf_counter() - t))
    return {"fish": n_fish, "preset": preset, "tank_m": list(sw.scene.size), "sim_s_per_repeat": sim_s, "build_s": build,
            "realtime_factor": statistics.median(samples), "samples": samples, "control_hz": p.control_hz,
            "physics_hz": p.control_hz * p.substeps}


def long_run(minutes: float = 10.0, n_fish: int = 10, seed: int = 0) -> dict:
    """The acceptance's long run: ``n_fish`` B-D fish for ``minutes`` of simulated time."""
    t = time.perf_counter()
    r = swim(load_preset("B-D"), n_fish, 60.0 * minutes, seed)
    return {"fish": n_fish, "simulated_s": 60.0 * minutes, "seed": seed, "fish_outside_tank": int(r.outside_tank().sum()),
            "all_finite": bool(np.all(np.isfinite(r.positions))), "wall_s": time.perf_counter() - t}


#: The tank of the 1,000-fish school (m): ten times the open tank's floor.
SCHOOL_TANK_M = (10.0, 10.0, 2.0)


def run(repeats: int = 5, max_fish: int = 1000, long_minutes: float = 10.0, render: bool = True) -> dict:
    out = {"ten": _realtime(10, 30.0, repeats)}
    if max_fish >= 1000:
        out["thousand"] = _realtime(1000, 2.0, max(3, repeats // 2))
        # interacting fish (issue 28): the school preset, each fish looking at every other at each of its kicks (no
        # neighbour grid: about 1.6 kicks per fish per second), in a tank large enough to hold them
        out["thousand_school"] = _realtime(1000, 2.0, max(3, repeats // 2), "school", SCHOOL_TANK_M)
    if long_minutes > 0:
        out["long_run"] = long_run(long_minutes)
    if render:
        try:
            from lifelike_mj.fish.render import render_benchmark

            out["render"] = render_benchmark()
        except Exception as exc:  # no GL on this machine: say so in the JSON
            out["render"] = {"error": f"{type(exc).__name__}: {exc}"}
    out["goals"] = {"ten_realtime_factor": 200.0, "thousand_realtime_factor": 1.0, "render_fps_640x480": 60.0,
                    "thousand_school_realtime_factor": 1.0}
    out["repeats"] = repeats
    out["machine"] = machine_info()
    return out
