"""Train a pitch policy through the Gymnasium API with pycma, then export it as a controller file that
`lifelike-mj butterfly fly` flies: the paper's 6-6-1 network, or a linear policy.

    python examples/gym_cmaes_network.py                      # a quick run (a few seconds)
    python examples/gym_cmaes_network.py --generations 60 --duration 20 --out my_net.json
    python examples/gym_cmaes_network.py --policy linear --generations 60 --duration 20 --out my_linear.json
    lifelike-mj butterfly fly --controller my_net.json        # then fly what you trained

The linear policy is the network's output neuron alone (`"layers": [6, 1]`, 7 weights): the pitch
changes by 3 deg x G(w . x + b) per step, x the network's scaled inputs (Oe 2010 eq. 12's G).

Each generation, CMA-ES asks for `popsize` weight vectors; one vector environment holds one butterfly
per candidate (`ButterflyPitchVectorEnv`, all stepped in one native call), each network chooses its
butterfly's pitch from the observation every step (action mode "phi"), and a candidate's fitness is
its episode return: the fitness H of Oe 2010 eq. 13.
"""

from __future__ import annotations

import argparse
import sys
from datetime import datetime, timezone

import cma
import numpy as np

import lifelike_mj
from lifelike_mj.butterfly import PAPER_FLAP, ann, ann_controller
from lifelike_mj.envs import policies
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv
from lifelike_mj.errors import UserError
from lifelike_mj.io import write_json
from lifelike_mj.paths import check_output_file

POLICIES = {"network": list(ann.PAPER_LAYERS), "linear": [ann.N_INPUTS, 1]}


def episode_returns(weights: np.ndarray, duration_s: float, layers=ann.PAPER_LAYERS) -> np.ndarray:
    """The summed reward (eq. 13's H) of one episode per row of ``weights``, all flown together."""
    n = len(weights)
    env = ButterflyPitchVectorEnv(n, action_mode="phi", duration_s=duration_s)
    compiled = [ann_controller(w, PAPER_FLAP, "relative", layers=layers).compiled() for w in weights]
    kinds = np.array([k for k, _ in compiled])
    cps = np.array([cp for _, cp in compiled])
    # each network reads its copy's observation and sets the pitch (one compiled loop for all)
    return policies.episode_returns(env, kinds, cps, seed=0)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--policy", choices=sorted(POLICIES), default="network")
    ap.add_argument("--generations", type=int, default=3)
    ap.add_argument("--popsize", type=int, default=16)
    ap.add_argument("--duration", type=float, default=2.0, help="seconds per episode (the paper: 20)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="gym_cmaes_network.json")
    ap.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    args = ap.parse_args()
    try:  # before any work: never replace a file unasked
        check_output_file(args.out, "--out", suffixes=(".json",), overwrite=args.overwrite)
    except UserError as exc:
        ap.exit(2, f"{ap.prog}: error: {exc}\n")
    layers = POLICIES[args.policy]
    es = cma.CMAEvolutionStrategy(np.zeros(ann.n_weights(layers)), 0.5, {
        "popsize": args.popsize, "seed": args.seed, "bounds": [-5.0, 5.0], "verbose": -9})
    best_w, best_h = None, -np.inf
    for g in range(args.generations):
        X = np.array(es.ask())
        H = episode_returns(X, args.duration, layers)
        es.tell(list(X), list(-H))
        i = int(np.argmax(H))
        if H[i] > best_h:
            best_w, best_h = X[i].copy(), float(H[i])
        print(f"generation {g + 1}: best H {H[i]:.1f} (so far {best_h:.1f})", flush=True)
    ctrl = ann_controller(best_w, PAPER_FLAP, "relative", layers=layers)
    data = ctrl.to_dict()
    data["provenance"] = {"source": "examples/gym_cmaes_network.py (pycma through ButterflyPitchVectorEnv)",
                          "command": "python " + " ".join(sys.argv), "best_fitness": best_h,
                          "policy": args.policy, "layers": layers, "generations": args.generations,
                          "popsize": args.popsize, "seed": args.seed,
                          "episode_duration_s": args.duration, "package_version": lifelike_mj.__version__,
                          "created": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    write_json(args.out, data)
    print(f"best H = {best_h:.1f}; controller written to {args.out} (fly it: lifelike-mj butterfly fly "
          f"--controller {args.out})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
