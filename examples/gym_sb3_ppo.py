"""Train the butterfly's pitch with stable-baselines3 PPO (CPU), then export the policy as a controller
file that `lifelike-mj butterfly fly` and the viewer fly.

    pip install torch==2.13.0 "lifelike-mj[rl]"     # the CPU build of torch, then SB3 (an optional extra)
    python examples/gym_sb3_ppo.py                    # a quick run (about 20 s; it does not fly yet)
    python examples/gym_sb3_ppo.py --steps 500000 --out ppo_pitch.json
    lifelike-mj butterfly fly --controller ppo_pitch.json

The policy is a network of the controller file's own kind, so that it can leave the RL library: its
inputs are the observation scaled as the paper's network scales them (`NetworkInputs`), its hidden
layers use the paper's transfer function G (Oe 2010 eq. 12) as activation, and its single output u
changes the pitch by max_dphi x G(u) (`NetworkActions`). PPO's deterministic action is then exactly
the controller's output neuron; `network_controller` writes the actor's weights out. The environment
acts every `--frame-skip` simulation steps (default 12: 100 decisions per second, 2000 per 20 s
episode) with the paper's pitch rate limit, 3 deg per simulation step (36 deg per decision). The
exported controller acts every step (1200 per second) with the file's 3 deg per step, as the paper's
network does: it flies the same law sampled 12 times as often, not the same flight.
"""

from __future__ import annotations

import argparse
import sys
import time
from datetime import datetime, timezone

import gymnasium as gym

import lifelike_mj
from lifelike_mj.envs.butterfly import ButterflyPitchEnv, ButterflyPitchWindEnv
from lifelike_mj.envs.policies import NetworkActions, NetworkInputs, network_controller
from lifelike_mj.errors import UserError
from lifelike_mj.io import write_json
from lifelike_mj.paths import check_output_file


def build_parser() -> argparse.ArgumentParser:
    """The command line (built before the rl extra is imported, so that ``--help`` and a bad option answer without
    it)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=20_000, help="environment steps to train (each --frame-skip simulation steps)")
    ap.add_argument("--frame-skip", type=int, default=12)
    ap.add_argument("--wind", action="store_true", help="train on ButterflyPitchWind-v0 (winds and start altitudes drawn)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="gym_sb3_ppo.json")
    ap.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    return ap


if __name__ == "__main__":
    build_parser().parse_args()  # --help, or a bad option, answers here, before the optional imports below

try:
    import torch  # noqa: E402 (after the command line)
    from stable_baselines3 import PPO  # noqa: E402 (after the command line)
    from stable_baselines3.common.env_util import make_vec_env  # noqa: E402 (after the command line)
    from stable_baselines3.common.vec_env import VecNormalize  # noqa: E402 (after the command line)
except ImportError as exc:  # the rl extra is optional
    print(f"gym_sb3_ppo.py: error: this example needs the rl extra ({exc.name} is missing): "
          "pip install torch==2.13.0 'lifelike-mj[rl]'", file=sys.stderr)
    raise SystemExit(2) from None


class PaperTransfer(torch.nn.Module):
    """G(u) = 1/(1+exp(-12(u+0.5))) + 1/(1+exp(-12(u-0.5))) - 1 (Oe 2010 eq. 12) as a torch activation."""

    def forward(self, u: torch.Tensor) -> torch.Tensor:
        return torch.sigmoid(12.0 * (u + 0.5)) + torch.sigmoid(12.0 * (u - 0.5)) - 1.0


def make_env(wind: bool, frame_skip: int, inputs: str = "air") -> gym.Env:
    """The environment acting every ``frame_skip`` steps with the paper's pitch rate limit (3 deg per
    simulation step, so ``3 x frame_skip`` deg per decision)."""
    cls = ButterflyPitchWindEnv if wind else ButterflyPitchEnv
    return NetworkActions(NetworkInputs(cls(frame_skip=frame_skip, max_dphi_deg=3.0 * frame_skip, inputs=inputs)))


def train(steps: int, seed: int, wind: bool = False, frame_skip: int = 12, hidden=(16, 16), n_envs: int = 8,
          verbose: int = 0) -> tuple[PPO, float]:
    """PPO for ``steps`` environment steps; returns the model and the wall time (s)."""
    torch.manual_seed(seed)
    venv = make_vec_env(lambda: make_env(wind, frame_skip), n_envs=n_envs, seed=seed)
    venv = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=0.995)  # inputs are scaled already
    model = PPO("MlpPolicy", venv, n_steps=1024, batch_size=256, gamma=0.995, gae_lambda=0.95, learning_rate=3e-4,
                ent_coef=0.0, seed=seed, verbose=verbose, device="cpu",
                policy_kwargs={"activation_fn": PaperTransfer, "net_arch": {"pi": list(hidden), "vf": [64, 64]}})
    t = time.perf_counter()
    model.learn(total_timesteps=steps)
    return model, time.perf_counter() - t


def export(model: PPO, provenance: dict | None = None):
    """The actor (its hidden layers and its mean-action layer) as a network controller."""
    linears = [m for m in model.policy.mlp_extractor.policy_net if isinstance(m, torch.nn.Linear)]
    linears.append(model.policy.action_net)
    layers = [(m.weight.detach().double().numpy(), m.bias.detach().double().numpy()) for m in linears]
    return network_controller(layers, "air", provenance)


def main() -> int:
    ap = build_parser()
    args = ap.parse_args()
    try:  # before any work: never replace a file unasked
        check_output_file(args.out, "--out", suffixes=(".json",), overwrite=args.overwrite)
    except UserError as exc:
        ap.exit(2, f"{ap.prog}: error: {exc}\n")
    model, wall = train(args.steps, args.seed, args.wind, args.frame_skip, verbose=1)
    env = make_env(False, args.frame_skip)
    obs, _ = env.reset()
    total, done = 0.0, False
    while not done:
        action, _ = model.predict(obs, deterministic=True)
        obs, r, term, trunc, _ = env.step(action)
        total, done = total + r, term or trunc
    ctrl = export(model, {"source": "examples/gym_sb3_ppo.py (stable-baselines3 PPO through ButterflyPitch-v0)",
                          "command": "python " + " ".join(sys.argv), "steps": args.steps, "seed": args.seed,
                          "frame_skip": args.frame_skip, "wind": args.wind, "train_wall_s": wall,
                          "fitness_H_in_env": total, "package_version": lifelike_mj.__version__,
                          "created": datetime.now(timezone.utc).isoformat(timespec="seconds")})
    write_json(args.out, ctrl.to_dict())
    print(f"trained {args.steps} steps in {wall:.0f} s; H = {total:.1f} in the env (still air, 0 m); controller "
          f"written to {args.out} (fly it: lifelike-mj butterfly fly --controller {args.out})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
