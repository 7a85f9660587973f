"""The paper's fish measured as a group (issue 28's starting point): ten ``B-D`` fish, which ignore each other.

Run: ``python benchmarks/fish_group.py`` (about 20 s). Writes ``benchmarks/results/fish_group.json``.

One swim of ten ``B-D`` fish for 120 s (seed 11 and seeds 12-14), measured from the tracks alone by
``fish.shoal.group_measures`` (what ``lifelike-mj fish swim --fish 10 --duration 120 --seed 11 --json`` reports under
``group``), and the kick intervals again for kick thresholds from 0.1 to 1.5 body lengths per second, since a kick's
definition (a speed rise of at least that much) sets how many small rises count.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from lifelike_mj import fish
from lifelike_mj.fish.scene import BODY_LENGTH_M
from lifelike_mj.fish.shoal import group_measures
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

SEEDS = (11, 12, 13, 14)
DURATION_S = 120.0
THRESHOLDS_BL_S = (0.1, 0.3, 0.5, 0.8, 1.0, 1.5)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "fish_group.json"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    runs, sweep = [], []
    for seed in SEEDS:
        r = fish.Tank(fish.load_preset("B-D"), n_fish=10, seed=seed).record(duration_s=DURATION_S)
        runs.append({"seed": seed, **group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m)})
        for th in THRESHOLDS_BL_S:
            k = group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m, kick_rise_bl_s=th)["kick_interval_s"]
            sweep.append({"seed": seed, "threshold_bl_s": th, **k})
    for g in runs:
        k = g["kick_interval_s"]
        print(f"seed {g['seed']}: nearest neighbour {g['nn_distance_bl']['median']:.1f} BL (median), "
              f"{100 * g['near_fraction_2bl']:.1f} % within 2 BL, polarisation {g['polarisation']:.2f}, milling "
              f"{g['milling']:.2f}, kicks every {k['mean']:.2f} s (CV {k['cv']:.2f}, 5th percentile {k['p5']:.2f} s)")
    for s in sweep:
        if s["seed"] == SEEDS[0]:
            print(f"threshold {s['threshold_bl_s']:.1f} BL/s: mean {s['mean']:.2f} s, CV {s['cv']:.2f}, 5th percentile "
                  f"{s['p5']:.2f} s, minimum {s['min']:.3f} s")
    write_json(args.out, {"provenance": provenance(benchmark="fish_group", seeds=list(SEEDS), duration_s=DURATION_S,
                                                   thresholds_bl_s=list(THRESHOLDS_BL_S)),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start, "runs": runs,
                          "kick_threshold_sweep": sweep})


if __name__ == "__main__":
    main()
