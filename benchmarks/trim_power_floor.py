"""The cheapest level flight the monarch's natural envelope allows on the calibrated wing law (issue 42): how far the
designed controller's power can fall toward Dudley's (1991) 12.5 W/kg with perfect elastic storage.

Run: ``python benchmarks/trim_power_floor.py`` (about 5 minutes on 2 cores). Writes
``benchmarks/results/trim_power_floor.json``.

At each speed, ``averaged.trim`` is solved with the power weighed ever more heavily against the filmed gait
(``averaged.POWER_SCALE_W_KG``: 3 W/kg, the shipped model's, down to 0.02, where the power is all but the only
preference), over the whole envelope of the top of the stroke (69-75 deg); each trim is then flown open loop in the
simulator (``averaged.flown``) for its power with and without perfect storage and its dorsal gap. A trim whose
residual force is beyond ``averaged.TRIMMED_RESIDUAL`` of the weight does not balance and is marked so.
"""

from __future__ import annotations

import argparse
import math
import time
from multiprocessing import Pool
from pathlib import Path

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
SPEEDS_M_S = (1.0, 1.5)
POWER_SCALES_W_KG = (3.0, 0.5, 0.1, 0.02)
#: Dudley's (1991) mechanical power with perfect elastic storage, and issue 42's bound, 1.5 times it (W/kg).
DUDLEY_W_KG, BOUND_W_KG = 12.5, 18.75


def point(job: tuple[float, float]) -> dict:
    """One trim (module docstring) at ``speed`` with the power scale ``scale``."""
    from lifelike_mj.butterfly.flight3d import averaged as A

    speed, scale = job
    A.POWER_SCALE_W_KG = scale
    A.TOP_FLOOR_DEG = ((1.0, math.degrees(A.TOP_RANGE[0])), (2.0, math.degrees(A.TOP_RANGE[0])))
    av = A.Averager(force_law="calibrated")
    t = A.trim(av, speed, 0.0)
    f = A.flown(av, t)
    g = A._gait(t.command)
    return {"speed_m_s": speed, "power_scale_W_kg": scale, "balanced": bool(t.residual_force <= A.TRIMMED_RESIDUAL),
            "residual_force_per_weight": t.residual_force, "body_angle_deg": math.degrees(t.pitch_rad),
            "frequency_hz": float(g[0]), "top_deg": math.degrees(g[1]), "stroke_deg": 2.0 * math.degrees(g[2]),
            "power_W_kg": f["power_W_kg"], "power_perfect_storage_W_kg": f["power_net_W_kg"],
            "dorsal_gap_deg": f["dorsal_gap_deg"]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(HERE / "results" / "trim_power_floor.json"))
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args(argv)
    t0 = time.time()
    jobs = [(v, s) for v in SPEEDS_M_S for s in POWER_SCALES_W_KG]
    with Pool(args.workers) as pool:
        points = pool.map(point, jobs)
    floor = {str(v): min(p["power_perfect_storage_W_kg"] for p in points if p["speed_m_s"] == v and p["balanced"])
             for v in SPEEDS_M_S}
    prov = provenance(benchmark="trim_power_floor", speeds_m_s=list(SPEEDS_M_S),
                      power_scales_W_kg=list(POWER_SCALES_W_KG), force_law="calibrated", workers=args.workers)
    out = {"provenance": prov, "machine": machine_info(), "wall_time_s": time.time() - t0,
           "dudley_perfect_storage_W_kg": DUDLEY_W_KG, "issue_42_bound_W_kg": BOUND_W_KG,
           "cheapest_balanced_perfect_storage_W_kg": floor, "points": points}
    write_json(args.out, out)
    print(f"{'speed':>6} {'scale':>6} {'balanced':>8} {'f Hz':>5} {'top':>5} {'stroke':>6} {'P':>5} {'P stored':>8} "
          f"{'gap':>5}")
    for p in points:
        print(f"{p['speed_m_s']:6.2f} {p['power_scale_W_kg']:6.2f} {p['balanced']!s:>8} {p['frequency_hz']:5.2f} "
              f"{p['top_deg']:5.1f} {p['stroke_deg']:6.1f} {p['power_W_kg']:5.1f} "
              f"{p['power_perfect_storage_W_kg']:8.1f} {p['dorsal_gap_deg']:5.1f}")
    print(f"cheapest balanced, perfect storage: {floor} W/kg (issue 42: at most {BOUND_W_KG}); wrote {args.out}")


if __name__ == "__main__":
    main()
