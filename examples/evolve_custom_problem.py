"""Evolve a problem of your own with the optimisers of lifelike_mj.evolve (the paper's GA, CMA-ES, nlopt).

The problem: find the simple rule's upstroke and downstroke pitches (Oe 2010 section 5.1) that fly
level at the start altitude for 5 s, scored by the eq. 13 fitness H (forward speed near the target
altitude). Any class with ``dim``, ``lower``, ``upper``, ``maximize``, ``evaluate(X)`` and
``fingerprint()`` is a problem; it lives in a module, so a process pool can run it.

    python examples/evolve_custom_problem.py [--executor process]
"""

import argparse
import hashlib
import math

import numpy as np

from lifelike_mj import butterfly, evolve


class SimpleRulePitches:
    """Genome: (phi_up, phi_down) in degrees; fitness: H of eq. 13 over a 5 s flight (paper backend)."""

    dim = 2
    lower = np.array([0.0, -20.0])
    upper = np.array([30.0, 20.0])
    maximize = True

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        rule = butterfly.load_controller("simple_rule")
        ctrls = [rule.with_parameters(phi_up_deg=float(a), phi_down_deg=float(b)) for a, b in X]
        flights = butterfly.simulate("paper", ctrls, duration_s=5.0)
        return np.array([f.fitness if math.isfinite(f.fitness) else -1e9 for f in flights])

    def fingerprint(self) -> str:
        return "simple-rule-pitches:" + hashlib.sha256(b"v1 5s paper").hexdigest()[:12]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--executor", default="serial", help="serial, process or ray")
    ap.add_argument("--optimizer", default="cmaes", help="rcga, cmaes, crs2, esch or isres")
    args = ap.parse_args()
    result = evolve.optimize(SimpleRulePitches(), args.optimizer, seed=0, evaluations=120, executor=args.executor,
                             progress=False)
    up, down = result.best_x
    print(f"{args.optimizer}: best H = {result.best_f:.1f} at phi_up = {up:.2f} deg, phi_down = {down:.2f} deg "
          f"after {result.evaluations} evaluations")


if __name__ == "__main__":
    main()
