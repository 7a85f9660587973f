"""PPO from scratch on the calibrated monarch (issue 42 point 5): the reinforcement-learning column of the side-by-side
table, beside the designed controller and the evolved ``monarch``.

Run: ``python benchmarks/ppo_monarch3d.py --minutes 85 --seed 1`` (4.2 million decisions in 85 min here, 2026-11-29)
(the ``rl`` extra: ``pip install torch==2.13.0 "lifelike-mj[rl]"``), then fly what it wrote on the side-by-side
flights: ``python benchmarks/designed_courses.py --controller benchmarks/results/ppo_monarch3d_controller.json``.

Stable-baselines3's PPO (CPU, one torch thread, 8 copies of ``ButterflyFlight3D-v0`` in one process) trains a
network with one tanh hidden layer of 32 (as issue 26's) through ``examples/gym_sb3_flight3d.py``'s ``train`` (its
PPO settings and wrappers), from random weights, on ``evolve3d``'s ``fast`` task set (``--tasks``; level flight from
1 to 3 m/s, a 90 deg turn, a calm course, a course in 1 m/s wind with 0.5 m/s gusts on every axis and one in a
steady 1.5 m/s wind; one drawn per 4 s episode). The butterfly is the monarch on the calibrated wing law (the
designed controller's), acting every 12 time steps of 1/800 s (67 Hz) around the filmed monarch's gait (10.2 Hz, 120
deg) with the evolved ``monarch``'s action scales. Training stops after ``--steps`` decisions or ``--minutes`` of
wall time, whichever comes first; the actor is written out every ``--every-minutes`` and at the end as a 3D
controller file (``--controller-out``), and the run's record (provenance, machine, the mean return of each update)
to ``--out``.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=75.0, help="wall-time limit of the training (min)")
    ap.add_argument("--steps", type=int, default=10_000_000, help="decisions to train at most")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--tasks", default="fast", help="the evolution's task set drawn from (default fast)")
    ap.add_argument("--every-minutes", type=float, default=10.0, help="write the actor out this often (min)")
    ap.add_argument("--out", default=str(HERE / "results" / "ppo_monarch3d.json"))
    ap.add_argument("--controller-out", default=str(HERE / "results" / "ppo_monarch3d_controller.json"))
    return ap


def _example():
    spec = importlib.util.spec_from_file_location("gym_sb3_flight3d",
                                                  HERE.parent / "examples" / "gym_sb3_flight3d.py")
    ex = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ex)
    return ex


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    ex = _example()  # the rl extra, or one sentence and status 2
    import torch
    from stable_baselines3.common.callbacks import BaseCallback

    from lifelike_mj.butterfly import flight3d
    from lifelike_mj.butterfly.flight3d.controllers import load_controller
    from lifelike_mj.io import write_json
    from lifelike_mj.machine import machine_info
    from lifelike_mj.provenance import provenance

    torch.set_num_threads(1)
    monarch = load_controller("monarch")
    layers = [flight3d.N_OBS, flight3d.N_ACT]
    template = flight3d.Controller3D(layers, np.zeros(flight3d.n_weights(layers)), animal="monarch",
                                     force_law="calibrated", every=12,
                                     scale=dict(zip(flight3d.ACTION_NAMES, monarch.scale)))
    record = {"provenance": provenance(**vars(args)), "machine": machine_info(), "hidden": [32], "n_envs": 8,
              "every_time_steps": 12, "animal": "monarch", "force_law": "calibrated", "history": []}
    t0 = time.perf_counter()
    last_write = [t0]

    def write_out(model, final: bool) -> None:
        wall = time.perf_counter() - t0
        prov = {"source": "benchmarks/ppo_monarch3d.py (stable-baselines3 PPO through ButterflyFlight3D-v0)",
                "command": "python " + " ".join(sys.argv), "decisions": int(model.num_timesteps),
                "time_steps": int(model.num_timesteps) * 12, "seed": args.seed, "task_set": args.tasks,
                "train_wall_s": wall, "final": final}
        ctl = ex.export(model, template, prov)
        write_json(args.controller_out, ctl.to_dict())
        record.update(decisions=int(model.num_timesteps), train_wall_s=wall, final=final)
        write_json(args.out, record)

    class Clock(BaseCallback):
        def _on_step(self) -> bool:
            return time.perf_counter() - t0 < 60.0 * args.minutes

        def _on_rollout_end(self) -> None:
            ep = [e["r"] for e in self.model.ep_info_buffer]
            record["history"].append([int(self.model.num_timesteps), round(time.perf_counter() - t0, 1),
                                      float(np.mean(ep)) if ep else None])
            if time.perf_counter() - last_write[0] > 60.0 * args.every_minutes:
                last_write[0] = time.perf_counter()
                write_out(self.model, False)
                print(f"{record['history'][-1]}", flush=True)

    # the example's PPO (its hyperparameters, seeding and vector of 8 environments), on this butterfly and task set
    model, _ = ex.train(args.steps, args.seed, 12, task_set=args.tasks, controller=template, callback=Clock())
    write_out(model, True)
    print(f"PPO: {model.num_timesteps} decisions in {time.perf_counter() - t0:.0f} s; controller written to "
          f"{args.controller_out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
