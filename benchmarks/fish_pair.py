"""One fish and two fish, measured as Calovi et al. (2018) measured their tetras (issue 28).

Run: ``python benchmarks/fish_pair.py`` (about half a minute). Writes ``benchmarks/results/fish_pair.json`` and
``docs/figures/fish_pair.png``.

The ``pair`` preset, one fish alone and two fish together, each for 300 s on seeds 11-18 (the preset's settings are
the ``school``'s, chosen on seeds 1-4), in a shallow box tank 16 body lengths across and 4 deep
(``PAIR_TANK``: Calovi et al.'s circular tank is 25 cm in radius for 3.1 cm fish, 16 body lengths across). The
paper's ``B-D`` fish, alone and two together (fish that ignore each other), in the same tank. The first 10 s are left
out. Measured from the tracks alone by ``fish.shoal.pair_quantities`` (pooled over the seeds) and ``pair_measures``
(per run).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from lifelike_mj import fish
from lifelike_mj.fish.figures import pair_figure
from lifelike_mj.fish.scene import BODY_LENGTH_M
from lifelike_mj.fish.shoal import pair_measures, pair_quantities
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

SEEDS = tuple(range(11, 19))
DURATION_S = 300.0
SKIP_S = 10.0
#: (length, depth, height) m: 16 x 16 x 4.3 body lengths of 7 cm.
PAIR_TANK = (1.12, 1.12, 0.3)
#: name -> (preset, number of fish)
RUNS = {"pair, one fish": ("pair", 1), "pair, two fish": ("pair", 2), "B-D, one fish": ("B-D", 1),
        "B-D, two fish": ("B-D", 2)}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "fish_pair.json"))
    ap.add_argument("--figure", default=str(Path(__file__).parents[1] / "docs" / "figures" / "fish_pair.png"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    runs, pooled = [], {}
    for name, (preset, n) in RUNS.items():
        qs = []
        for seed in SEEDS:
            r = fish.Tank(fish.load_preset(preset), n_fish=n, seed=seed, size=PAIR_TANK).record(duration_s=DURATION_S)
            qs.append(pair_quantities(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m, skip_s=SKIP_S))
            runs.append({"run": name, "seed": seed, **pair_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m,
                                                                    skip_s=SKIP_S)})
        pooled[name] = {k: np.concatenate([q[k] for q in qs]) for k in qs[0]}
    summary = {}
    for name, q in pooled.items():
        d = q["kick_duration_s"]
        s = {"wall_distance_bl_median": float(np.median(q["wall_distance_bl"])),
             "within_1bl_of_wall": float(np.mean(q["wall_distance_bl"] < 1.0)),
             "wall_angle_deg_median": float(np.median(q["wall_angle_deg"])),
             "along_wall_60_120_deg": float(np.mean(np.abs(q["wall_angle_deg"] - 90.0) <= 30.0)),
             "kick_duration_s": {"mean": float(d.mean()), "cv": float(d.std() / d.mean()),
                                 "p5": float(np.percentile(d, 5)), "min": float(d.min())},
             "kick_length_bl": {"mean": float(q["kick_length_bl"].mean()),
                                "median": float(np.median(q["kick_length_bl"]))},
             "speed_bl_s_median": float(np.median(q["speed_bl_s"])),
             "glide_tau_s_median": float(np.median(q["glide_tau_s"])),
             "glide_exponential_fraction": float(np.mean(q["glide_power"] == 1))}
        if "distance_bl" in q:
            s.update(distance_bl_median=float(np.median(q["distance_bl"])),
                     within_2bl=float(np.mean(q["distance_bl"] <= 2.0)),
                     heading_difference_deg_median=float(np.median(q["heading_difference_deg"])),
                     heading_within_45_deg=float(np.mean(q["heading_difference_deg"] <= 45.0)),
                     viewing_angle_deg_median=float(np.median(q["viewing_angle_deg"])))
        summary[name] = s
        print(name + ": " + ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else
                                      f"{k} " + "/".join(f"{kk} {vv:.3g}" for kk, vv in v.items())
                                      for k, v in s.items()))
    pair_figure(pooled["pair, one fish"], pooled["pair, two fish"], args.figure,
                title=f"the pair preset: one fish and two fish, {DURATION_S:g} s x {len(SEEDS)} seeds, in a "
                      f"{PAIR_TANK[0]:g} x {PAIR_TANK[1]:g} x {PAIR_TANK[2]:g} m tank")
    write_json(args.out, {"provenance": provenance(benchmark="fish_pair", seeds=list(SEEDS), duration_s=DURATION_S,
                                                   skip_s=SKIP_S, tank_m=list(PAIR_TANK), runs=RUNS),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start, "summary": summary,
                          "runs": runs})


if __name__ == "__main__":
    main()
