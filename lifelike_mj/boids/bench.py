"""``lifelike-mj bench boids``: agent-steps per second of the cell-list engine at the paper's settings,
its scaling from 10^3 to 10^6 agents at the paper's density, and two peers measured in the same run:
a vectorised NumPy all-pairs version of the same model, and Mesa's boid flockers example (2D, equal n
and radius; Mesa is not a dependency of lifelike-mj: it is imported if installed, or run with the
Python interpreter given as ``mesa_python``).

Goals (issue 5): >= 2 x 10^6 agent-steps/s at n = 300 on 2 cores, >= 100x Mesa, scaling exponent
<= 1.1, 10^6 agents >= 1 step/s.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from dataclasses import replace

import numba
import numpy as np

from lifelike_mj.boids import engine
from lifelike_mj.boids.engine import BOX, N_AGENTS, BoidParams, initial_state, step_grid
from lifelike_mj.boids.presets import PATTERNS, load_preset
from lifelike_mj.boids.sim import simulate
from lifelike_mj.machine import machine_info

#: Steps timed from the random start in the scaling runs.
SCALING_STEPS = 20
#: Mesa's example model, timed in whichever interpreter has Mesa (argv: n, width, vision, steps, repeats).
MESA_SCRIPT = r"""
import json, sys, time, statistics
from mesa.examples.basic.boid_flockers.model import BoidFlockers
n, width, vision, steps, repeats = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
rates = []
for r in range(repeats):
    m = BoidFlockers(population_size=n, width=width, height=width, vision=vision, separation=1.0, seed=r)
    m.step()
    t = time.perf_counter()
    for _ in range(steps):
        m.step()
    rates.append(n * steps / (time.perf_counter() - t))
import mesa
print(json.dumps({"agent_steps_per_s": statistics.median(rates), "samples": rates, "mesa": mesa.__version__}))
"""


def _rate(params: BoidParams, n: int, steps: int, warmup: int, repeats: int, seed: int = 0,
          parallel: bool | None = None) -> list[float]:
    """Agent-steps per second over ``steps`` steps after ``warmup`` steps, ``repeats`` times; with
    ``parallel`` True (False) the forces run on all threads (one thread) whatever ``n``."""
    saved = engine.PARALLEL_FROM
    if parallel is not None:
        engine.PARALLEL_FROM = 0 if parallel else 1 << 62
    try:
        x, v, t = initial_state(params, n, seed)
        step_grid(x, v, t, params, warmup)
        rates = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            step_grid(x, v, t, params, steps)
            rates.append(n * steps / (time.perf_counter() - t0))
    finally:
        engine.PARALLEL_FROM = saved
    return rates


def numpy_all_pairs_step(x, v, types, params: BoidParams) -> None:
    """The same model (eq. 1-9, walls) vectorised over all pairs with NumPy: O(n^2) memory."""
    wa, wc = np.array(params.wa), np.array(params.wc)
    xi = x[:, None, :] - x[None, :, :]
    d2 = np.einsum("ijk,ijk->ij", xi, xi)
    np.fill_diagonal(d2, np.inf)
    mc, ma, ms = d2 < params.r_c ** 2, d2 < params.r_a ** 2, d2 < params.r_s ** 2
    nc, na = mc.sum(1), ma.sum(1)
    Wc = wc[types[:, None], types[None, :]] * mc
    Wa = wa[types[:, None], types[None, :]] * ma
    fc = -np.einsum("ij,ijk->ik", Wc, xi) / np.maximum(nc, 1)[:, None]
    fa = (Wa @ v - Wa.sum(1)[:, None] * v) / np.maximum(na, 1)[:, None]
    inv = np.where(ms, params.w_s / np.sqrt(np.where(ms, d2, 1.0)), 0.0)
    fs = np.einsum("ij,ijk->ik", inv, xi)
    fs += params.w_s * ((x < params.r_s).astype(float) - (params.box - x < params.r_s))
    v += params.dt / params.mass * (fs + fa + fc)
    x += params.dt * v
    low, high = x < 0, x > params.box
    x[low], v[low] = -x[low], -v[low]
    x[high], v[high] = 2 * params.box - x[high], -v[high]


def _numpy_rate(params: BoidParams, n: int, steps: int, repeats: int) -> list[float]:
    x, v, t = initial_state(params, n, 0)
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(steps):
            numpy_all_pairs_step(x, v, t, params)
        rates.append(n * steps / (time.perf_counter() - t0))
    return rates


def _mesa(n: int, width: float, vision: float, steps: int, repeats: int, mesa_python: str | None) -> dict:
    exe = mesa_python or sys.executable
    try:
        out = subprocess.run([exe, "-c", MESA_SCRIPT, str(n), str(width), str(vision), str(steps), str(repeats)],
                             capture_output=True, text=True, timeout=1800)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}
    if out.returncode != 0:
        return {"error": (out.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def run(repeats: int = 3, max_n: int = 1_000_000, mesa_python: str | None = None, preset: str = "5a") -> dict:
    base = load_preset(preset)
    out: dict = {"preset": preset}
    # n = 300, the paper's settings, 3D, once the flock has formed (after 1,000 steps): the default
    # path (one thread at this size), and the same on all threads, timed in turn
    r300, r300_par = [], []
    for _ in range(repeats):
        r300 += _rate(base, N_AGENTS, 2000, 1000, 1)
        r300_par += _rate(base, N_AGENTS, 2000, 1000, 1, parallel=True)
    out["agent_steps_per_s_n300"] = statistics.median(r300)
    out["n300_samples"] = r300
    out["agent_steps_per_s_n300_all_threads"] = statistics.median(r300_par)
    out["n300_all_threads_samples"] = r300_par
    out["threads"] = numba.get_num_threads()
    # whole runs of the paper (10,000 steps from the random start, seed 0), each of the eight patterns
    whole = {}
    for name in PATTERNS:
        p = load_preset(name)
        t0 = time.perf_counter()
        simulate(p, N_AGENTS, 10_000, seed=0, record_every=10_000)
        whole[name] = N_AGENTS * 10_000 / (time.perf_counter() - t0)
    out["agent_steps_per_s_n300_whole_runs"] = whole
    out["agent_steps_per_s_n300_whole_runs_median"] = statistics.median(whole.values())
    # scaling at the paper's density: the box grows as n^(1/3); the first 20 steps from the random
    # start (the flocks have not formed yet, so every n is timed at the same density), repeated
    # from the same start until at least 3e6 agent-steps are timed
    scale = []
    n = 1000
    while n <= max_n:
        p = replace(base, box=BOX * (n / N_AGENTS) ** (1 / 3))
        steps = SCALING_STEPS
        blocks = max(1, int(3e6 // (n * steps)))
        rates = []
        for _ in range(repeats):
            elapsed = 0.0
            for _ in range(blocks):
                x, v, t = initial_state(p, n, 0)
                step_grid(x, v, t, p, 1)  # compiled, cells warm
                t0 = time.perf_counter()
                step_grid(x, v, t, p, steps)
                elapsed += time.perf_counter() - t0
            rates.append(n * steps * blocks / elapsed)
        scale.append({"n": n, "box": p.box, "steps": steps * blocks, "agent_steps_per_s": statistics.median(rates),
                      "steps_per_s": statistics.median(rates) / n, "samples": rates})
        n *= 10
    out["scaling"] = scale
    if len(scale) >= 2:
        ns = np.log([s["n"] for s in scale])
        ts = np.log([1.0 / s["steps_per_s"] for s in scale])  # wall seconds per step
        out["scaling_exponent"] = float(np.polyfit(ns, ts, 1)[0])
    # peers, 2D, n = 300, box 20, radius R_c = 4.5
    p2 = replace(base, dims=2)
    ours2d = _rate(p2, N_AGENTS, 2000, 1000, repeats)
    out["agent_steps_per_s_n300_2d"] = statistics.median(ours2d)
    out["numpy_all_pairs_agent_steps_per_s_n300"] = statistics.median(_numpy_rate(base, N_AGENTS, 200, repeats))
    mesa = _mesa(N_AGENTS, BOX, base.r_c, 100, repeats, mesa_python)
    out["mesa"] = mesa
    if "agent_steps_per_s" in mesa:
        out["mesa_ratio"] = out["agent_steps_per_s_n300_2d"] / mesa["agent_steps_per_s"]
    out["numpy_ratio"] = out["agent_steps_per_s_n300"] / out["numpy_all_pairs_agent_steps_per_s_n300"]
    out["goals"] = {"agent_steps_per_s_n300": 2e6, "mesa_ratio": 100.0, "scaling_exponent": 1.1,
                    "steps_per_s_at_1e6": 1.0}
    out["repeats"] = repeats
    out["machine"] = machine_info()
    return out
