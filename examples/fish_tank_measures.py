"""Script a fish tank (Satoi 2015) and read its measures; give one fish a behaviour of your own.

Ten fish swim 20 s with the calibrated B-D preset. Then the same tank again, where fish 0 follows a
rule of our own instead of the Markov chain (accelerate when slower than one body length per second,
else coast), and the other nine swim exactly as before.

    python examples/fish_tank_measures.py
"""

import argparse

import numpy as np

from lifelike_mj import fish


def main() -> None:
    argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter).parse_args()
    preset = fish.load_preset("B-D")
    result = fish.Tank(preset, n_fish=10, seed=0).record(duration_s=20.0)
    m = fish.swim_summary(result)
    print(f"B-D, 10 fish, 20 s: a burst every {m['burst_interval_mean_s']:.2f} s, burstiness {m['burstiness']:.3f}, "
          f"turning entropy {m['turn_entropy']:.2f} bits, {m['fish_outside_tank']} outside the tank")

    body_length_m = 0.07

    def steady(tank: fish.Tank) -> np.ndarray:
        mu = np.full(tank.n_fish, -1)  # -1: the Markov chain decides
        speed = np.linalg.norm(tank.state()["velocity_m_s"][0])
        mu[0] = 0 if speed < body_length_m else 1  # 0 accelerate, 1 coast
        return mu

    mine = fish.Tank(preset, n_fish=10, seed=0, mu_policy=steady).record(duration_s=20.0)
    same = np.array_equal(mine.positions[:, 1:], result.positions[:, 1:])
    used = sorted({fish.MU_NAMES[int(u) % 4] for u in mine.mu[1:, 0]})
    print(f"with the rule: fish 0 used {', '.join(used)} only; the other nine swam the same: {same}")
    assert same


if __name__ == "__main__":
    main()
