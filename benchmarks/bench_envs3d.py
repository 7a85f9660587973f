"""ButterflyFlight3D-v0's speed (issue 26): writes benchmarks/results/envs3d.json and prints the table for
docs/performance.md.

Run: ``python benchmarks/bench_envs3d.py [--repeats 5]``. Measured in one run, interleaved (each repeat measures
every case once), so that the ratios compare like with like on a noisy machine. Speeds are in **time steps** (of
1/1200 s) per second, so that environments acting every step and every 12 steps compare:

* one ``ButterflyFlight3D-v0`` (a Python ``step`` loop, constant action), acting every time step and every 12;
* the vector environment (:class:`~lifelike_mj.envs.butterfly3d.ButterflyFlight3DVectorEnv`) at N = 16 and 64,
  acting every 12 steps: N x 12 x vector steps per second;
* the floor: bare ``mj_step`` of the same 3D model with its compiled air-force callback on N ``mjData`` (the
  kinematics not advanced, no controller, no environment), every core, all steps in one native call.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import mujoco
import numpy as np
from numba import njit, prange

import lifelike_mj
from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.envs.butterfly3d import ButterflyFlight3DEnv, ButterflyFlight3DVectorEnv
from lifelike_mj.io import write_json
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.stability import watching
from lifelike_mj.provenance import provenance

_step = mjabi.mj_step
_vp = mjabi.voidptr_from_int


@njit(parallel=True)
def _bare(mptr, dptrs, n_steps):
    for b in prange(len(dptrs)):
        for _ in range(n_steps):
            _step(_vp(mptr), _vp(dptrs[b]))


def single(env: ButterflyFlight3DEnv, n: int) -> float:
    """Time steps per second of ``n`` environment steps."""
    env.reset(seed=0)
    a = np.zeros(flight3d.N_ACT)
    steps = 0
    t = time.perf_counter()
    for _ in range(n):
        _, _, term, trunc, _ = env.step(a)
        steps += env.controller.every
        if term or trunc:
            env.reset()
    return steps / (time.perf_counter() - t)


def vector(env: ButterflyFlight3DVectorEnv, n: int) -> float:
    env.reset(seed=0)
    a = np.zeros((env.num_envs, flight3d.N_ACT))
    env.step(a)
    t = time.perf_counter()
    for _ in range(n):
        env.step(a)
    return n * env.num_envs * env.single.controller.every / (time.perf_counter() - t)


def floor(n_envs: int, n_steps: int) -> float:
    m = flight3d.build_model()
    c = flight3d.load_controller(flight3d.withdrawn_file("steer"))  # the swallowtail's (withdrawn) controller
    datas = [mj3d.setup_data(m, flight3d.Kinematics(c.base, c.omega_c_rad_s)) for _ in range(n_envs)]
    ptrs = np.array([d._address for d in datas], dtype=np.int64)
    with passive_callback(mj3d.COMPILED_PASSIVE), watching():
        _bare(m._address, ptrs, 1)
        t = time.perf_counter()
        _bare(m._address, ptrs, n_steps)
        dt = time.perf_counter() - t
    return n_envs * n_steps / dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "envs3d.json"))
    args = ap.parse_args()
    long = {"duration_s": 3600.0}  # no episode ends inside a measurement
    singles = {"single, acting every time step": (ButterflyFlight3DEnv(**long), 2400),
               "single, acting every 12 time steps": (ButterflyFlight3DEnv(every=12, **long), 400)}
    vectors = {f"vector, N = {n}, acting every 12": (ButterflyFlight3DVectorEnv(n, every=12, **long), k)
               for n, k in ((16, 40), (64, 10))}
    floors = {f"floor, N = {n}": (n, k) for n, k in ((16, 480), (64, 120))}
    for env, _ in singles.values():
        single(env, 20)
    for env, _ in vectors.values():
        vector(env, 2)
    runs: dict[str, list[float]] = {k: [] for k in [*singles, *vectors, *floors]}
    ratio_runs: dict[str, list[float]] = {f"floor / vector, N = {n}": [] for n in (16, 64)}
    for r in range(args.repeats):
        for name, (env, n) in singles.items():
            runs[name].append(single(env, n))
        for name, (env, n) in vectors.items():
            runs[name].append(vector(env, n))
        for name, (n, k) in floors.items():
            runs[name].append(floor(n, k))
        for n in (16, 64):
            ratio_runs[f"floor / vector, N = {n}"].append(runs[f"floor, N = {n}"][-1]
                                                          / runs[f"vector, N = {n}, acting every 12"][-1])
        print(f"repeat {r + 1}/{args.repeats} done", flush=True)
    med = {k: float(np.median(v)) for k, v in runs.items()}
    ratios = {k: float(np.median(v)) for k, v in ratio_runs.items()}
    write_json(args.out, {"time_steps_per_s_median": med, "runs": runs, "ratios_median_of_paired_runs": ratios,
                          "repeats": args.repeats, "dt_s": flight3d.DT_S,
                          "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
                          "mujoco": mujoco.__version__, "version": lifelike_mj.__version__,
                          "provenance": provenance(repeats=args.repeats)})
    print("| measure | time steps per s (median) | x real time |\n|---|---|---|")
    for k, v in med.items():
        print(f"| {k} | {v:.3g} | {v * flight3d.DT_S:.1f} |")
    for k, v in ratios.items():
        print(f"| {k}, paired | x{v:.2f} | |")


if __name__ == "__main__":
    main()
