"""Fly a pitch law of your own (Oe 2010 section 5.1), in Python and compiled with numba, on both backends.

The law is the paper's simple rule: pitch phi_up = 12.77 deg while the wings beat up, 0 while they
beat down. Written as a plain Python function it runs once per step from Python; compiled with numba
it runs inside the compiled stepping loop. Both fly exactly the trajectory of the built-in rule.

    python examples/own_pitch_law.py
"""

import argparse
import math

import numpy as np
from numba import njit

from lifelike_mj import butterfly

PHI_UP = math.radians(12.77)


def simple_rule(obs: butterfly.PitchObservation) -> float:
    """Pitch (rad) for the next step: phi_up on the upstroke (flap rate > 0), 0 on the downstroke."""
    return PHI_UP if obs.omega_rad_s > 1e-9 else 0.0


simple_rule_compiled = njit(simple_rule)


def main() -> None:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    for backend in ("paper", "mujoco"):
        builtin = butterfly.Flight("simple_rule", backend=backend).record(duration_s=5.0)
        for name, law in (("python", simple_rule), ("numba", simple_rule_compiled)):
            mine = butterfly.Flight("simple_rule", backend=backend, pitch_law=law).record(duration_s=5.0)
            diff = float(np.max(np.abs(mine.y - builtin.y)))
            print(f"{backend:6s} {name:6s}: altitude after 5 s {mine.y[-1]:+.4f} m, "
                  f"largest difference from the built-in rule {diff:.1e} m")
            assert diff <= 1e-12


if __name__ == "__main__":
    main()
