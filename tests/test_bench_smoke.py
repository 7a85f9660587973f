"""The benchmark code runs (tiny sizes; the measurements themselves are in benchmarks/ and
docs/performance.md, never timed asserts)."""

from __future__ import annotations

import math


def test_butterfly_bench_runs():
    from lifelike_mj.butterfly import bench

    r = bench.run(repeats=1, batch=2, steps=240, naive_steps=24, mujoco_steps=240)
    assert all(math.isfinite(r[k]) and r[k] > 0 for k in ("paper_ns_per_step", "mujoco_us_per_step"))


def test_fish_bench_runs():
    from lifelike_mj.fish import bench

    r = bench.run(repeats=1, max_fish=3, long_minutes=0.01, render=False)
    assert r["ten"]["realtime_factor"] > 0
