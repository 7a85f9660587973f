"""Train the free 3D butterfly with stable-baselines3 PPO (CPU), then export the policy as a 3D controller file
that `lifelike-mj butterfly fly3d` flies.

    pip install torch==2.13.0 "lifelike-mj[rl]"     # the CPU build of torch, then SB3 (an optional extra)
    python examples/gym_sb3_flight3d.py               # a quick run (about a minute; it does not fly well yet)
    python examples/gym_sb3_flight3d.py --steps 800000 --out ppo3d.json
    lifelike-mj butterfly fly3d --controller ppo3d.json --task turn

The environment is `lifelike_mj/ButterflyFlight3D-v0` on the tasks `evolve3d --tasks steer` evolves on (level
flight at 1 and 2 m/s, a 90 deg turn, a 180 deg turn with a 0.3 m climb; one drawn per episode of 4 s), acting
every `--every` time steps (default 12 steps of 1/800 s: about 67 decisions per second). The policy is a network
of the 3D controller file's own kind, so that it can leave the RL library: its inputs are the observation scaled as a controller's
network scales them (`NetworkInputs3D`), its hidden layers are tanh, and its actions go through tanh
(`NetworkActions3D`), as a controller's output layer does. PPO's deterministic action is then exactly the
controller's output; `network_controller3d` writes the actor's weights out, with the environment's base command,
scales and rate. The episode return is the evolution's fitness of the task, so the printed score compares with
`evolve3d`'s.
"""

from __future__ import annotations

import argparse
import sys
import time
from datetime import datetime, timezone

import numpy as np

import lifelike_mj
from lifelike_mj.butterfly import flight3d
from lifelike_mj.envs.butterfly3d import ButterflyFlight3DEnv, NetworkActions3D, NetworkInputs3D, network_controller3d
from lifelike_mj.errors import UserError
from lifelike_mj.io import write_json
from lifelike_mj.paths import check_output_file


def build_parser() -> argparse.ArgumentParser:
    """The command line (built before the rl extra is imported, so that ``--help`` and a bad option answer without
    it)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=16_000, help="environment steps to train (each --every time steps)")
    ap.add_argument("--every", type=int, default=12, help="time steps (1/800 s each) between two decisions (default 12)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="gym_sb3_flight3d.json")
    ap.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    return ap


if __name__ == "__main__":
    build_parser().parse_args()  # --help, or a bad option, answers here, before the optional imports below

try:
    import torch  # noqa: E402 (after the command line)
    from stable_baselines3 import PPO  # noqa: E402 (after the command line)
    from stable_baselines3.common.env_util import make_vec_env  # noqa: E402 (after the command line)
except ImportError as exc:  # the rl extra is optional
    print(f"gym_sb3_flight3d.py: error: this example needs the rl extra ({exc.name} is missing): "
          "pip install torch==2.13.0 'lifelike-mj[rl]'", file=sys.stderr)
    raise SystemExit(2) from None


#: Seconds of each training flight: the evolution's.
DURATION_S = 4.0


def make_env(every: int, task_set: str = "steer", controller: flight3d.Controller3D | None = None) -> NetworkActions3D:
    """The environment on ``task_set``'s tasks (one drawn per episode), acting every ``every`` steps, seen and
    acted on as a controller's network; ``controller``: the template whose butterfly, wing law, base command and
    scales it flies (default a new controller's)."""
    return NetworkActions3D(NetworkInputs3D(ButterflyFlight3DEnv(task=flight3d.TASK_SETS[task_set](),
                                                                 duration_s=DURATION_S, every=every,
                                                                 controller=controller)))


def train(steps: int, seed: int, every: int = 12, hidden=(32,), n_envs: int = 8, verbose: int = 0,
          task_set: str = "steer", controller: flight3d.Controller3D | None = None, callback=None):
    """PPO for ``steps`` environment steps (each ``every`` time steps) on :func:`make_env`'s environment; returns
    the model and the wall time (s). ``callback``: stable-baselines3's, to watch or stop the training."""
    torch.manual_seed(seed)
    venv = make_vec_env(lambda: make_env(every, task_set, controller), n_envs=n_envs, seed=seed)
    model = PPO("MlpPolicy", venv, n_steps=400, batch_size=400, gamma=0.995, gae_lambda=0.95, learning_rate=3e-4,
                ent_coef=0.0, seed=seed, verbose=verbose, device="cpu",
                policy_kwargs={"activation_fn": torch.nn.Tanh, "log_std_init": -1.0,
                               "net_arch": {"pi": list(hidden), "vf": [64, 64]}})
    t = time.perf_counter()
    model.learn(total_timesteps=steps, callback=callback)
    return model, time.perf_counter() - t


def export(model, template: flight3d.Controller3D, provenance: dict | None = None) -> flight3d.Controller3D:
    """The actor (its tanh hidden layers and its mean-action layer) as a 3D controller."""
    linears = [m for m in model.policy.mlp_extractor.policy_net if isinstance(m, torch.nn.Linear)]
    linears.append(model.policy.action_net)
    layers = [(m.weight.detach().double().numpy(), m.bias.detach().double().numpy()) for m in linears]
    return network_controller3d(layers, template, provenance)


def fitness(ctl: flight3d.Controller3D, task_set: str = "steer") -> float:
    """The evolution's fitness of ``ctl`` on ``task_set`` (what ``evolve3d`` maximises)."""
    problem = flight3d.FlightProblem3D(tuple(flight3d.TASK_SETS[task_set]()), ctl, duration_s=DURATION_S)
    return float(problem.evaluate(np.zeros((1, problem.dim)))[0])


def main() -> int:
    ap = build_parser()
    args = ap.parse_args()
    try:  # before any work: never replace a file unasked
        check_output_file(args.out, "--out", suffixes=(".json",), overwrite=args.overwrite)
        if not (1 <= args.every <= 1200 and args.steps >= 1):
            raise UserError("--every is 1 to 1200 and --steps at least 1.")
    except UserError as exc:
        ap.exit(2, f"{ap.prog}: error: {exc}\n")
    model, wall = train(args.steps, args.seed, args.every, verbose=1)
    template = make_env(args.every).unwrapped.controller
    prov = {"source": "examples/gym_sb3_flight3d.py (stable-baselines3 PPO through ButterflyFlight3D-v0)",
            "command": "python " + " ".join(sys.argv), "steps": args.steps, "time_steps": args.steps * args.every,
            "seed": args.seed, "every": args.every, "task_set": "steer", "train_wall_s": wall,
            "package_version": lifelike_mj.__version__,
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    ctl = export(model, template, prov)
    prov["fitness_steer"] = fitness(ctl)
    ctl.provenance = prov
    write_json(args.out, ctl.to_dict())
    steer = fitness(flight3d.load_controller(flight3d.withdrawn_file("steer")))
    print(f"trained {args.steps} steps ({args.steps * args.every:,} time steps) in {wall:.0f} s; fitness on the steer "
          f"tasks {prov['fitness_steer']:.3f} (evolve3d's steer, since withdrawn: {steer:.3f}); "
          f"controller written to {args.out} (fly it: lifelike-mj butterfly fly3d --controller {args.out})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
