"""Fish measured as a group (issue 28): the paper's ten ``B-D`` fish, which ignore each other, the same fish with
the kick rhythm, and the ``school`` and ``shoal`` presets.

Run: ``python benchmarks/fish_group.py`` (about a minute). Writes ``benchmarks/results/fish_group.json``.

Ten fish for 120 s, seeds 11-14 (none used in choosing the settings, which were chosen on seeds 1-4), measured from
the tracks alone by ``fish.shoal.group_measures`` (what ``lifelike-mj fish swim --fish 10 --duration 120 --seed 11
--json`` reports under ``group`` for ``B-D``), the first 10 s left out but for ``B-D`` (the others start scattered
and gather):

* ``B-D``: the paper's preset, in the filmed tank;
* ``B-D + rhythm``: the kick rhythm (a floor of 0.25 s, a gamma wait of shape 4, a mean interval of 0.55 s) and yaw
  noise of +-25 deg in place of +-80 (``RHYTHM``), in the filmed tank;
* ``school`` in the filmed tank and in an open tank (``OPEN_TANK``), ``shoal`` in the open tank;
* ``school`` in the open tank again on 16 more seeds (``MORE_SEEDS``), for how often it meets issue 28's bounds.

A startle cascade (``fish.aquarium``, ``cascade=True``): ten ``school`` fish in the open tank, seeds 5-12, swim until
they are a school (seven fish or more joined, polarisation above 0.8, looked at every half second from 20 s on).
Then the fish at the front of the school is startled alone, and the benchmark records which fish escape within 1 s,
and when. The school: the largest group of fish joined by chains of fish, each within ``LINK_BL`` body lengths of
the next; a fish swimming apart is not its front.

Food (``fish.aquarium``): on the same seeds, ten ``school`` fish swim 20 s, and a pellet is dropped on the surface
0.3 m ahead of their centroid; the benchmark records when it is eaten (s after the drop, within 30 s), which fish ate
it (its rank by distance to the pellet at the drop, 0 the nearest) and how many fish were within 3 body lengths of the
pellet when it was eaten: with the fish competing (``compete=True``) and without, and for one fish alone.

And the paper's kick intervals again for kick thresholds from 0.1 to 1.5 body lengths per second, since a kick's
definition (a speed rise of at least that much) sets how many small rises count.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from lifelike_mj import fish
from lifelike_mj.fish.scene import BODY_LENGTH_M
from lifelike_mj.fish.shoal import group_measures, nearest_neighbour_m
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

SEEDS = (11, 12, 13, 14)
DURATION_S = 120.0
RHYTHM = {"kick_gamma_shape": 4.0, "kick_floor_s": 0.25, "kick_mean_s": 0.55, "phi_range_deg": 25.0}
#: An open tank (m): the filmed one is 0.5 m (7 body lengths) deep, and a school of ten turning at its walls breaks.
OPEN_TANK = (3.0, 3.0, 1.0)
#: name -> (preset, changes to it, tank (None: the filmed 5 x 0.5 x 1 m), seconds left out at the start)
VARIANTS = {"B-D": ("B-D", {}, None, 0.0), "B-D + rhythm": ("B-D", RHYTHM, None, 10.0),
            "school, filmed tank": ("school", {}, None, 10.0), "school, open tank": ("school", {}, OPEN_TANK, 10.0),
            "shoal, open tank": ("shoal", {}, OPEN_TANK, 10.0)}
THRESHOLDS_BL_S = (0.1, 0.3, 0.5, 0.8, 1.0, 1.5)


CASCADE_SEEDS = tuple(range(5, 13))
#: More seeds for the ``school`` in the open tank alone: how often it meets issue 28's bounds.
MORE_SEEDS = tuple(range(31, 47))
#: Two fish are in one school when a chain of fish, each within this many body lengths of the next, joins them.
LINK_BL = 3.0


def cascade(seed: int) -> dict:
    """A startle at the front of a school (module docstring): when each fish first escapes (s after the startle)."""
    import numpy as np

    from lifelike_mj.fish.aquarium import Aquarium
    from lifelike_mj.fish.shoal import front_of_group, is_school

    a = Aquarium(fish.Tank(fish.load_preset("school"), n_fish=10, seed=seed, size=OPEN_TANK), cascade=True)
    a.step(60 * 20)
    for _ in range(240):
        if is_school((st := a.tank.state())["position_m"], st["velocity_m_s"], LINK_BL * BODY_LENGTH_M, 7):
            break
        a.step(30)
    else:
        raise RuntimeError(f"seed {seed}: the fish did not form a school within two minutes")
    front, group = front_of_group(st["position_m"], st["velocity_m_s"], LINK_BL * BODY_LENGTH_M)
    t0 = a.time
    a.startle(front)
    first = np.full(10, np.inf)
    for _ in range(60):
        a.step(1)
        new = (a.startled_at >= t0 - 1e-9) & np.isinf(first)
        first[new] = a.startled_at[new] - t0
    return {"seed": seed, "startled_at_s": t0, "reached": int(np.isfinite(first).sum()),
            "school": [int(i) for i in group], "reached_in_school": int(np.isfinite(first[group]).sum()),
            "first_escape_s": [float(v) if np.isfinite(v) else None for v in first]}


def feeding(seed: int, n_fish: int, compete: bool) -> dict:
    """A pellet dropped ahead of ``n_fish`` ``school`` fish (module docstring)."""
    import numpy as np

    from lifelike_mj.fish.aquarium import Aquarium

    a = Aquarium(fish.Tank(fish.load_preset("school"), n_fish=n_fish, seed=seed, size=OPEN_TANK), cascade=True,
                 compete=compete)
    a.step(60 * 20)
    st = a.tank.state()
    v = st["velocity_m_s"][:, :2].mean(axis=0)
    x, y = np.clip(st["position_m"][:, :2].mean(axis=0) + 0.3 * v / max(float(np.linalg.norm(v)), 1e-9), -1.2, 1.2)
    H = a.tank.scene.size[2]
    rank = np.argsort(np.argsort(np.linalg.norm(st["position_m"] - np.array([x, y, H]), axis=1)))
    a.drop_food(float(x), float(y))
    for k in range(1, 60 * 30 + 1):
        pellet = a.pellets_m[0].copy()
        a.step(1)
        if a.eaten:
            near = np.linalg.norm(a.tank.snapshot()[0] - pellet, axis=1) <= 3 * BODY_LENGTH_M
            return {"seed": seed, "fish": n_fish, "compete": compete, "eaten_after_s": k * a.dt,
                    "eater_rank": int(rank[a.eaters[0]]), "within_3bl": int(near.sum())}
    return {"seed": seed, "fish": n_fish, "compete": compete, "eaten_after_s": None, "eater_rank": None,
            "within_3bl": None}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "fish_group.json"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    runs, sweep = [], []
    for name, (preset, changes, tank, skip) in VARIANTS.items():
        params = replace(fish.load_preset(preset), **changes)
        for seed in SEEDS:
            r = fish.Tank(params, n_fish=10, seed=seed, size=tank).record(duration_s=DURATION_S)
            nn = nearest_neighbour_m(r.positions[r.times_s >= skip])
            runs.append({"variant": name, "seed": seed, "closest_bl": float(nn.min() / BODY_LENGTH_M),
                         **group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m, skip_s=skip)})
    more = []
    for seed in MORE_SEEDS:
        r = fish.Tank(fish.load_preset("school"), n_fish=10, seed=seed, size=OPEN_TANK).record(duration_s=DURATION_S)
        g = group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m, skip_s=10.0)
        more.append({"seed": seed, "nn_distance_bl_median": g["nn_distance_bl"]["median"],
                     "polarisation": g["polarisation"]})
    print("school, open tank, seeds 31-46: nearest neighbour " + ", ".join(f"{m['nn_distance_bl_median']:.2f}" for m in more)
          + " BL; polarisation " + ", ".join(f"{m['polarisation']:.2f}" for m in more))
    for seed in SEEDS:
        r = fish.Tank(fish.load_preset("B-D"), n_fish=10, seed=seed).record(duration_s=DURATION_S)
        for th in THRESHOLDS_BL_S:
            k = group_measures(r.times_s, r.positions, BODY_LENGTH_M, r.tank_m, kick_rise_bl_s=th)["kick_interval_s"]
            sweep.append({"seed": seed, "threshold_bl_s": th, **k})
    for g in runs:
        k = g["kick_interval_s"]
        print(f"{g['variant']}, seed {g['seed']}: nearest neighbour {g['nn_distance_bl']['median']:.1f} BL (median), "
              f"{100 * g['near_fraction_2bl']:.1f} % within 2 BL, polarisation {g['polarisation']:.2f}, milling "
              f"{g['milling']:.2f}, cohesion {g['cohesion_bl']:.1f} BL, closest {g['closest_bl']:.2f} BL, kicks every "
              f"{k['mean']:.2f} s (CV {k['cv']:.2f}, 5th percentile {k['p5']:.2f} s)")
    cascades = [cascade(seed) for seed in CASCADE_SEEDS]
    for c in cascades:
        last = max(v for v in c["first_escape_s"] if v is not None)
        print(f"cascade, seed {c['seed']}: {c['reached_in_school']} of the school's {len(c['school'])} ({c['reached']} of "
              f"10) escaped within 1 s (the last after {last:.2f} s)")
    feeds = [feeding(seed, n, compete) for n, compete in ((10, True), (10, False), (1, True)) for seed in CASCADE_SEEDS]
    for f in feeds:
        print(f"food, {f['fish']} fish, {'competing' if f['compete'] else 'not competing'}, seed {f['seed']}: " + (
            f"eaten after {f['eaten_after_s']:.1f} s by the fish ranked {f['eater_rank']} by distance, "
            f"{f['within_3bl']} fish within 3 BL" if f["eaten_after_s"] is not None else "not eaten within 30 s"))
    for s in sweep:
        if s["seed"] == SEEDS[0]:
            print(f"threshold {s['threshold_bl_s']:.1f} BL/s: mean {s['mean']:.2f} s, CV {s['cv']:.2f}, 5th percentile "
                  f"{s['p5']:.2f} s, minimum {s['min']:.3f} s")
    write_json(args.out, {"provenance": provenance(benchmark="fish_group", seeds=list(SEEDS), duration_s=DURATION_S,
                                                   thresholds_bl_s=list(THRESHOLDS_BL_S), variants=VARIANTS),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start, "runs": runs,
                          "kick_threshold_sweep": sweep, "cascades": cascades,
                          "feeding": feeds, "school_more_seeds": more})


if __name__ == "__main__":
    main()
