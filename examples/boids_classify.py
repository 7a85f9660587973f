"""Run a boids pattern (Nakamura 2013) and classify it; change the flock while it runs.

    python examples/boids_classify.py [PRESET]
"""

import argparse

from lifelike_mj import boids


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("preset", nargs="?", default="4c", help="a boids preset's name or file (default 4c)")
    name = ap.parse_args().preset
    params = boids.load_preset(name)
    run, measures, label, reasons = boids.classified_run(params, n=300, seed=0)
    print(f"{name}: classified {label} (segregation index {measures['segregation_index']:.2f}, "
          f"{measures['n_groups']} group(s)): {reasons['state']}")

    flock = boids.Flock(params, n=300, seed=0)
    flock.step(1000)
    flock.set_weights(wa=((0.5, 0.5), (0.5, 0.5)), wc=((0.01, 0.01), (0.01, 0.01)))  # one type, as far as they know
    flock.step(2000)
    m = boids.measures(flock.record(600, every=20), window=600)
    print(f"after switching to homogeneous weights: segregation index {m['segregation_index']:.2f}")


if __name__ == "__main__":
    main()
