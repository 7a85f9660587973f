"""Gymnasium environments' speed (issue 14): writes benchmarks/results/envs.json and prints the table
for docs/performance.md.

Run: ``python benchmarks/bench_envs.py [--repeats 5]``. Everything is measured in one run, interleaved
(each repeat measures every case once), so that the ratios compare like with like on a noisy machine:

* environment steps per second of one ``ButterflyPitch-v0`` (Python ``step`` loop, constant action;
  paper and MuJoCo backends) next to Gymnasium's own ``HalfCheetah-v5`` and ``Swimmer-v5`` in the same
  loop (reset when an episode ends);
* the vector environment (:class:`~lifelike_mj.envs.vector.ButterflyPitchVectorEnv`) at N = 64 and
  1024 copies, both backends: ``N x`` vector steps per second;
* the floor on the MuJoCo backend: bare ``mj_step`` of the same model (with its compiled wing-force
  callback, which is the model's physics, and without it) on N ``mjData``, every core, no controller,
  no environment: what one native call per step cannot beat.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import gymnasium as gym
import mujoco
import numpy as np
from numba import njit, prange

import lifelike_mj
import lifelike_mj.envs  # noqa: F401  (registers the environments)
from lifelike_mj.butterfly import PAPER_FLAP, ButterflyController, ButterflyParams
from lifelike_mj.butterfly.backends import mj
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv
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


def _bare_calls(mptr, dptrs, n_steps):
    for _ in range(n_steps):  # one step of every data per call: the vector env's pattern
        _bare(mptr, dptrs, 1)


def single_steps_per_s(env, n: int) -> float:
    env.reset(seed=0)
    a = np.zeros(env.action_space.shape)
    t = time.perf_counter()
    for _ in range(n):
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            env.reset()
    return n / (time.perf_counter() - t)


def vector_steps_per_s(env, n: int) -> float:
    env.reset(seed=0)
    a = np.zeros((env.num_envs, 1))
    env.step(a)
    t = time.perf_counter()
    for _ in range(n):
        env.step(a)
    return n * env.num_envs / (time.perf_counter() - t)


def floor_steps_per_s(n_envs: int, n_steps: int, callback: bool, per_call: bool) -> float:
    p = ButterflyParams()
    m = mj.build_model(p, "paper")
    m.opt.timestep = 1.0 / 1200.0
    ctrl = ButterflyController("constant", PAPER_FLAP, {"phi_deg": 0.0})
    datas = [mj.setup_data(m, ctrl, p) for _ in range(n_envs)]
    ptrs = np.array([d._address for d in datas], dtype=np.int64)
    cb = mj.COMPILED_PASSIVE if callback else None
    with passive_callback(cb):
        _bare(m._address, ptrs, 1)
        t = time.perf_counter()
        (_bare_calls if per_call else _bare)(m._address, ptrs, n_steps)
        dt = time.perf_counter() - t
    return n_envs * n_steps / dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "envs.json"))
    args = ap.parse_args()
    with watching():  # MuJoCo's compiler warns about HalfCheetah's XML (settotalmass): not into MUJOCO_LOG.TXT here
        singles = {
            "ButterflyPitch-v0 (paper)": (gym.make("lifelike_mj/ButterflyPitch-v0"), 20000),
            "ButterflyPitch-v0 (mujoco)": (gym.make("lifelike_mj/ButterflyPitch-v0", backend="mujoco"), 5000),
            "HalfCheetah-v5": (gym.make("HalfCheetah-v5"), 5000),
            "Swimmer-v5": (gym.make("Swimmer-v5"), 5000),
        }
    vectors = {}
    for backend, steps in (("paper", (2000, 400)), ("mujoco", (100, 20))):
        for n, k in zip((64, 1024), steps):
            vectors[f"{backend}, N = {n}"] = (ButterflyPitchVectorEnv(n, backend=backend), k)
    # frame skip 10: each copy stepped 10 times in a row per call (env-steps x 10 = simulation steps)
    vectors["mujoco, N = 1024, frame skip 10"] = (ButterflyPitchVectorEnv(1024, backend="mujoco", frame_skip=10), 2)
    floors = {f"{'callback' if cb else 'no callback'}, N = {n}, {'one step per call' if pc else 'all steps in one call'}":
              (n, k, cb, pc) for n, k in ((64, 100), (1024, 20)) for cb in (True, False) for pc in (False, True)}
    for env, _ in singles.values():  # warm-up (compilation, first allocations)
        single_steps_per_s(env, 200)
    for env, _ in vectors.values():
        vector_steps_per_s(env, 3)
    runs: dict[str, list[float]] = {k: [] for k in [*singles, *(f"vector {k}" for k in vectors),
                                                    *(f"floor {k}" for k in floors)]}
    ratio_runs: dict[str, list[float]] = {"single / HalfCheetah": []}
    for n in (64, 1024):
        for pattern in ("one step per call", "all steps in one call"):
            ratio_runs[f"mujoco vector N={n}: floor ({pattern}) / env"] = []
    ratio_runs["mujoco vector N=1024, frame skip 10: floor (all steps in one call) / env simulation steps"] = []
    for r in range(args.repeats):
        for name, (env, n) in singles.items():
            runs[name].append(single_steps_per_s(env, n))
        for name, (env, n) in vectors.items():
            runs[f"vector {name}"].append(vector_steps_per_s(env, n))
        for name, (n, k, cb, pc) in floors.items():
            runs[f"floor {name}"].append(floor_steps_per_s(n, k, cb, pc))
        ratio_runs["single / HalfCheetah"].append(runs["ButterflyPitch-v0 (paper)"][-1] / runs["HalfCheetah-v5"][-1])
        for n in (64, 1024):
            for pattern in ("one step per call", "all steps in one call"):
                ratio_runs[f"mujoco vector N={n}: floor ({pattern}) / env"].append(
                    runs[f"floor callback, N = {n}, {pattern}"][-1] / runs[f"vector mujoco, N = {n}"][-1])
        ratio_runs["mujoco vector N=1024, frame skip 10: floor (all steps in one call) / env simulation steps"].append(
            runs["floor callback, N = 1024, all steps in one call"][-1]
            / (10 * runs["vector mujoco, N = 1024, frame skip 10"][-1]))
        print(f"repeat {r + 1}/{args.repeats} done", flush=True)
    med = {k: float(np.median(v)) for k, v in runs.items()}
    ratios = {k: float(np.median(v)) for k, v in ratio_runs.items()}
    result = {"env_steps_per_s_median": med, "env_steps_per_s_runs": runs, "ratios_median_of_paired_runs": ratios,
              "repeats": args.repeats, "threads": int(os.environ.get("NUMBA_NUM_THREADS", os.cpu_count() or 1)),
              "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
              "mujoco": mujoco.__version__, "gymnasium": gym.__version__, "version": lifelike_mj.__version__,
              "provenance": provenance(repeats=args.repeats)}
    write_json(args.out, result)
    print("| measure | env-steps per s (median) | goal |\n|---|---|---|")
    for k in singles:
        goal = ">= HalfCheetah-v5" if k == "ButterflyPitch-v0 (paper)" else ""
        print(f"| single env, {k} | {med[k]:.3g} | {goal} |")
    print(f"| ButterflyPitch-v0 (paper) / HalfCheetah-v5, paired | x{ratios['single / HalfCheetah']:.2f} | >= x1 |")
    for k in vectors:
        goal = ">= 1e6" if k.startswith("paper") else ""
        print(f"| vector env, {k} | {med['vector ' + k]:.3g} | {goal} |")
    for k in floors:
        print(f"| floor: bare mj_step, {k}, all cores | {med['floor ' + k]:.3g} | |")
    for k, v in ratios.items():
        if k.startswith("mujoco"):
            print(f"| {k} (with callback), paired | x{v:.2f} | <= x1.3 |")


if __name__ == "__main__":
    main()
