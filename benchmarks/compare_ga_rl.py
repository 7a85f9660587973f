"""The paper's RCGA, CMA-ES and PPO at equal environment steps (issue 14): writes
benchmarks/results/ga_vs_rl.json and prints the table for docs/results.md.

Run: ``python benchmarks/compare_ga_rl.py [--steps 1000000] [--seeds 3] [--ppo-seeds 1]`` (needs the
``rl`` extra: ``pip install torch==2.13.0 "lifelike-mj[rl]"``).

Every method learns through the same environment and spends the same number of environment steps:
``ButterflyPitch-v0`` (the paper task: still air from 0 m) or ``ButterflyPitchWind-v0`` (the
``robust_map`` distribution: a start altitude or a wind drawn per episode), 20 s episodes, one decision
every ``--frame-skip`` simulation steps (12: 2000 decisions per episode) with the paper's pitch rate
limit, 3 deg per simulation step (36 deg per decision).

* RCGA (the paper's GA) and CMA-ES evolve the paper's 6-6-1 network (49 weights within +-5); one
  evaluation is one episode (a fresh condition per episode on the wind task, as the RL agent sees them),
  its fitness the episode's return, eq. 13's H. All candidates of a generation fly in one vector env.
* PPO (stable-baselines3, CPU) trains a 6-16-16-1 network of the same kind (the paper's inputs and
  transfer function G, the pitch changed by 3 deg x G(output)), see ``examples/gym_sb3_ppo.py``.

Each trained network is then measured the same way: H of one 20 s flight from 0 m in still air through
the environment (the paper task's score), and the cells of the wind map (winds within +-3 m/s every
0.5 m/s, 169 cells, from 0 m) it passes: the last 10 s within +-1 m of 0 m, moving forward.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import json
import platform
import time
from pathlib import Path

import numpy as np

import lifelike_mj
from lifelike_mj import evolve
from lifelike_mj.butterfly import PAPER_FLAP, ann, controllers
from lifelike_mj.butterfly.controllers import KIND_ANN, KIND_MLP
from lifelike_mj.envs.policies import episode_returns, pitch_actions
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv
from lifelike_mj.io import write_json
from lifelike_mj.provenance import provenance

EPISODE_S = 20.0
MAP_STEP, MAP_MAX = 0.5, 3.0


def network(weights: np.ndarray, frame_skip: int) -> np.ndarray:
    """The compiled paper network with the pitch rate limit of one decision every ``frame_skip`` steps."""
    return ann.compile_params("relative", ann.default_scales(PAPER_FLAP), weights, 3.0 * frame_skip)


class EnvEpisodes:
    """Problem for lifelike_mj.evolve: the paper's network's weights -> the return of one episode of the
    environment each (all candidates of a call in one vector env)."""

    dim = ann.N_WEIGHTS
    lower = np.full(ann.N_WEIGHTS, -5.0)
    upper = np.full(ann.N_WEIGHTS, 5.0)
    maximize = True

    def __init__(self, wind: bool, frame_skip: int, seed: int) -> None:
        self.wind, self.frame_skip, self.seed = wind, frame_skip, seed
        self.episodes = 0

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        n = len(X)
        env = ButterflyPitchVectorEnv(n, wind=self.wind, action_mode="phi", frame_skip=self.frame_skip,
                                      duration_s=EPISODE_S, max_dphi_deg=3.0 * self.frame_skip)
        cps = np.array([network(w, self.frame_skip) for w in X])
        seed = self.seed * 1_000_003 + self.episodes  # a fresh condition per episode
        self.episodes += n
        return episode_returns(env, np.full(n, KIND_ANN), cps, seed=seed)

    def fingerprint(self) -> str:
        return "env-episodes:" + hashlib.sha256(f"{self.wind} {self.frame_skip} {self.seed}".encode()).hexdigest()[:12]


def measure(kinds: np.ndarray, cps: np.ndarray, frame_skip: int) -> dict:
    """H from 0 m in still air, and the wind-map cells passed, of one network (compiled ``cps[0]``)."""
    grid = np.arange(-round(MAP_MAX / MAP_STEP), round(MAP_MAX / MAP_STEP) + 1) * MAP_STEP
    conds = [(0.0, (0.0, 0.0))] + [(0.0, (float(a), float(b))) for b in grid for a in grid]
    n = len(conds)
    env = ButterflyPitchVectorEnv(n, action_mode="phi", frame_skip=frame_skip, duration_s=EPISODE_S,
                                  max_dphi_deg=3.0 * frame_skip)
    obs, _ = env.reset(seed=0, options={"conditions": conds})
    k, c = np.repeat(kinds[:1], n), np.repeat(cps[:1], n, axis=0)
    air_fwd = np.array([-a for _, (a, _b) in conds])
    total, done = np.zeros(n), np.zeros(n, dtype=bool)
    ys, vzs = [], []
    while not done.all():
        obs, r, term, trunc, _ = env.step(pitch_actions(k, c, obs))
        total += np.where(done, 0.0, r)
        ys.append(np.where(done | term, np.inf, obs[:, 4]))  # a flight that ended early never passes
        vzs.append(obs[:, 5] + air_fwd)
        done |= term | trunc
    y, vz = np.array(ys), np.array(vzs)
    last = slice(len(y) // 2, None)  # the last 10 s of 20 s
    passed = (np.abs(y[last]) <= 1.0).all(axis=0) & (vz[last].mean(axis=0) >= 0.0)
    return {"H_still_air_0m": float(total[0]), "windmap_cells_passed": int(passed[1:].sum()),
            "windmap_cells": n - 1}


def run_ga(optimizer: str, wind: bool, steps: int, frame_skip: int, seed: int) -> dict:
    per_episode = int(round(EPISODE_S * 1200 / frame_skip))
    population = evolve.default_population(optimizer, ann.N_WEIGHTS)
    generations = steps // per_episode // population  # whole generations within the budget
    problem = EnvEpisodes(wind, frame_skip, seed)
    t = time.perf_counter()
    res = evolve.optimize(problem, optimizer, seed=seed, generations=generations, population=population,
                          progress=False)
    wall = time.perf_counter() - t
    cps = network(res.best_x, frame_skip)[None, :]
    return {"method": optimizer, "seed": seed, "train_wall_s": wall, "env_steps": problem.episodes * per_episode,
            "episodes": problem.episodes, "population": population, "generations": generations,
            "best_training_return": float(res.best_f),
            **measure(np.array([KIND_ANN]), cps, frame_skip)}


def run_ppo(wind: bool, steps: int, frame_skip: int, seed: int) -> dict:
    spec = importlib.util.spec_from_file_location("gym_sb3_ppo", Path(__file__).parents[1] / "examples" / "gym_sb3_ppo.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    model, wall = ex.train(steps, seed, wind, frame_skip)
    ctrl = ex.export(model)  # the controller file's network; measured here at the env's rate limit
    cp = ann.compile_mlp("relative", ctrl.input_scale(), ctrl.parameters["weights"], ctrl.layers, 3.0 * frame_skip)
    kind = KIND_MLP
    return {"method": "ppo", "seed": seed, "train_wall_s": wall, "env_steps": steps,
            "episodes": steps // int(round(EPISODE_S * 1200 / frame_skip)), "best_training_return": None,
            **measure(np.array([kind]), cp[None, :], frame_skip)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1_000_000, help="environment steps per method and task")
    ap.add_argument("--frame-skip", type=int, default=12)
    ap.add_argument("--seeds", type=int, default=3, help="seeds of RCGA and CMA-ES")
    ap.add_argument("--ppo-seeds", type=int, default=1)
    ap.add_argument("--first-seed", type=int, default=0, help="seeds run from this one on (to add seeds to a result)")
    ap.add_argument("--merge", default=None, help="a result of an earlier run whose rows join this one's (other seeds)")
    ap.add_argument("--reference", default="ann_paper,ann_robust",
                    help="controller files measured as they fly in `butterfly fly` (frame skip 1, 3 deg per step)")
    ap.add_argument("--tasks", default="paper,wind")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "ga_vs_rl.json"))
    args = ap.parse_args()
    rows, merged_from = [], None
    if args.merge:
        earlier = json.loads(Path(args.merge).read_text())
        rows, merged_from = earlier["rows"], earlier["provenance"]
    for task in args.tasks.split(","):
        wind = task == "wind"
        for opt in ("rcga", "cmaes"):
            for s in range(args.first_seed, args.first_seed + args.seeds):
                rows.append({"task": task, **run_ga(opt, wind, args.steps, args.frame_skip, s)})
                print(rows[-1], flush=True)
        for s in range(args.first_seed, args.first_seed + args.ppo_seeds):
            rows.append({"task": task, **run_ppo(wind, args.steps, args.frame_skip, s)})
            print(rows[-1], flush=True)
    references = []
    for name in filter(None, args.reference.split(",")):
        kind, cp = controllers.load(name).compiled()
        references.append({"controller": name, **measure(np.array([kind]), cp[None, :], 1)})
        print(references[-1], flush=True)
    write_json(args.out, {"rows": rows, "references_frame_skip_1": references, "merged_from": merged_from,
                          "steps": args.steps, "frame_skip": args.frame_skip,
                          "machine": f"{platform.processor() or platform.machine()}",
                          "version": lifelike_mj.__version__,
                          "provenance": provenance(steps=args.steps, frame_skip=args.frame_skip, seeds=args.seeds,
                                                   ppo_seeds=args.ppo_seeds, tasks=args.tasks,
                                                   first_seed=args.first_seed, merge=args.merge,
                                                   reference=args.reference)})
    print("| task | method | seeds | H from 0 m, still air: median (min-max) | wind-map cells passed of 169: median "
          "(min-max) | training wall time, median |\n|---|---|---|---|---|---|")
    for task in args.tasks.split(","):
        for m in ("rcga", "cmaes", "ppo"):
            sel = [r for r in rows if r["task"] == task and r["method"] == m]
            if not sel:
                continue
            h = [r["H_still_air_0m"] for r in sel]
            c = [r["windmap_cells_passed"] for r in sel]
            w = [r["train_wall_s"] for r in sel]
            print(f"| {task} | {m} | {len(sel)} | {np.median(h):.0f} ({min(h):.0f}-{max(h):.0f}) | {np.median(c):.0f} "
                  f"({min(c)}-{max(c)}) | {np.median(w):.0f} s |")
    for r in references:
        print(f"| (reference, frame skip 1) | {r['controller']} | | {r['H_still_air_0m']:.0f} | "
              f"{r['windmap_cells_passed']} | |")


if __name__ == "__main__":
    main()
