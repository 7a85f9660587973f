"""How a garden's butterflies take off: every take-off of the default garden (``Garden(n, controller, seed=...)``),
the body's height sampled every 25 ms (issue 42; ``docs/results.md``, "Take-off: designed").

For each take-off (a butterfly perched at one sample and in the air at the next) within the run's last 1.5 s: the
**drop**, how far the thorax went below its perched height within 1.5 s; the height at 0.45 s (the shipped take-off
manoeuvre's end); the largest roll within 1 s. For each butterfly, whether it ever went 0.3 m below the lowest
blossom. Touchdowns and those within 0.5 m/s (``Garden.visits``).

    python benchmarks/garden_take_off.py --seeds 2,3,4                       # the shipped designed controller
    python benchmarks/garden_take_off.py --seeds 2,3,4 --without-take-off    # the same, its take-off left out

Writes ``benchmarks/results/garden_take_off_NAME.json`` (``--out`` to choose) and prints one line. Seeds run in
parallel (``--workers``, default 2); each is 20 butterflies for 20 s (about 1-2 min a seed here).
"""

from __future__ import annotations

import argparse
from multiprocessing import Pool
from pathlib import Path

import numpy as np

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
#: The sampling interval (s), the window a drop is looked for in after a take-off (s), and the roll's window (s).
SAMPLE_S, DROP_S, ROLL_S = 0.025, 1.5, 1.0


def one(job: tuple) -> dict:
    """One garden (``seed``): its take-offs' drops (m), heights at 0.45 s (m) and largest rolls (deg), the
    butterflies that went 0.3 m below the lowest blossom, touchdowns and those within 0.5 m/s."""
    from lifelike_mj.butterfly.flight3d.garden import Garden

    seed, controller, n, duration, without = job
    if without:  # the designed controller with its take-off's manoeuvre left out: the regulator takes off, with a clap
        from lifelike_mj.butterfly.flight3d.designed import load_any
        from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned

        spec = load_any(controller).to_dict()
        spec["landing"].pop("take_off", None)
        controller = CompiledDesigned(spec)
    g = Garden(n, controller, seed=seed)
    every = int(round(SAMPLE_S / g.dt))
    z, roll, perched = [], [], []
    while g.time < duration - 1e-9:
        g.step(every)
        s = g.state()
        z.append(s["position_m"][:, 2].copy())
        roll.append(np.degrees(np.abs(s["attitude_rad"][:, 0])))
        perched.append(s["perched"].copy())
    z, roll, perched = np.array(z), np.array(roll), np.array(perched)
    n_drop, n_roll, n_end = (int(round(t / SAMPLE_S)) for t in (DROP_S, ROLL_S, 0.45))
    drops, ends, rolls = [], [], []
    for i in range(n):
        for k in np.flatnonzero(perched[:-n_drop, i] & ~perched[1:-n_drop + 1, i]) + 1:
            z0 = z[k - 1, i]
            drops.append(float(z0 - z[k : k + n_drop, i].min()))
            ends.append(float(z[k + n_end - 1, i] - z0))
            rolls.append(float(roll[k : k + n_roll, i].max()))
    low = int((z.min(axis=0) < g.blossoms[:, 2].min() - 0.3).sum())
    speeds = [v["touchdown_speed_m_s"] for vs in g.visits() for v in vs if v["touchdown_speed_m_s"] is not None]
    return {"seed": seed, "drops_m": drops, "height_at_0_45_s_m": ends, "largest_roll_deg": rolls,
            "below_lowest_blossom": low, "butterflies": n, "touchdowns": len(speeds),
            "touchdowns_within_0_5_m_s": sum(v <= 0.5 for v in speeds)}


def main(argv: list[str] | None = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", default="2,3,4", help="gardens, comma separated (default 2,3,4: held out)")
    p.add_argument("--controller", default="designed", help="a controller's name or file (default designed)")
    p.add_argument("--without-take-off", action="store_true",
                   help="a designed controller's take-off manoeuvre left out (its regulator takes off, with a clap)")
    p.add_argument("--n", type=int, default=20, help="butterflies a garden (default 20)")
    p.add_argument("--duration", type=float, default=20.0, help="seconds a garden (default 20)")
    p.add_argument("--workers", type=int, default=2, help="gardens at once (default 2)")
    p.add_argument("--out", default=None, help="the JSON written (default benchmarks/results/garden_take_off_NAME.json)")
    args = p.parse_args(argv)
    try:
        seeds = [int(s) for s in args.seeds.split(",") if s.strip()]
    except ValueError:
        p.exit(2, f"--seeds is a comma-separated list of whole numbers, got {args.seeds!r}.\n")
    if not seeds or args.n < 1 or args.duration <= DROP_S or args.workers < 1:
        p.exit(2, "--seeds names one garden or more, --n is 1 or more, --duration over 1.5 s, --workers 1 or more.\n")
    jobs = [(s, args.controller, args.n, args.duration, args.without_take_off) for s in seeds]
    with Pool(min(args.workers, len(jobs))) as pool:
        gardens = pool.map(one, jobs)
    drops = np.concatenate([g["drops_m"] for g in gardens])
    rolls = np.concatenate([g["largest_roll_deg"] for g in gardens])
    summary = {"take_offs": len(drops), "median_drop_m": float(np.median(drops)),
               "drop_90th_percentile_m": float(np.percentile(drops, 90)), "drops_over_0_1_m": int((drops > 0.1).sum()),
               "drops_over_0_3_m": int((drops > 0.3).sum()), "median_largest_roll_deg": float(np.median(rolls)),
               "rolls_over_60_deg": int((rolls > 60).sum()),
               "below_lowest_blossom": sum(g["below_lowest_blossom"] for g in gardens),
               "butterflies": sum(g["butterflies"] for g in gardens),
               "touchdowns": sum(g["touchdowns"] for g in gardens),
               "touchdowns_within_0_5_m_s": sum(g["touchdowns_within_0_5_m_s"] for g in gardens)}
    name = Path(args.controller).stem + ("_without_take_off" if args.without_take_off else "")
    out = Path(args.out) if args.out else HERE / "results" / f"garden_take_off_{name}.json"
    write_json(out, {"provenance": provenance(seeds=seeds, controller=args.controller, n=args.n,
                                              duration_s=args.duration, without_take_off=args.without_take_off),
                     "machine": machine_info(), "summary": summary, "gardens": gardens})
    s = summary
    print(f"{name}, gardens {seeds}: {s['take_offs']} take-offs, median drop {s['median_drop_m']:.3f} m "
          f"(90th percentile {s['drop_90th_percentile_m']:.2f}), over 0.1 m {s['drops_over_0_1_m']}, over 0.3 m "
          f"{s['drops_over_0_3_m']}; largest roll in 1 s median {s['median_largest_roll_deg']:.0f} deg, over 60 "
          f"{s['rolls_over_60_deg']}; {s['below_lowest_blossom']} of {s['butterflies']} butterflies 0.3 m below the "
          f"lowest blossom; touchdowns {s['touchdowns']}, within 0.5 m/s {s['touchdowns_within_0_5_m_s']}; wrote {out}")


if __name__ == "__main__":
    main()
