"""What level flight costs the monarch under each wing-force law (issue 27): the drive's mechanical power against
the sink rate, over a grid of wing kinematics with the body's attitude held.

Run: ``python benchmarks/monarch_power.py`` (about 5 minutes on 2 cores). Writes
``benchmarks/results/monarch_power.json``.

Each point: the monarch's base kinematics (``controllers.default_base("monarch")``) with the flap frequency, the
stroke amplitude and the feathering amplitude of the grid, the body held at a pitch of the grid (roll and yaw 0:
the reduction's attitude hold, an outside torque, so this is an energy budget, not free flight), from rest; after
``SETTLE_S`` the flight is measured over ``WINDOW_S`` (``flight3d.measures``): the speed through the air, the mean
vertical speed (the sink, negative, or the climb) and the drive's positive power per kg (no elastic storage). A
point **carries the weight** where its mean vertical speed is at least ``LEVEL_M_S``. The summary gives, per law, the
cheapest point that carries the weight, beside Dudley's (1991) 12.5-20.2 W/kg.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from lifelike_mj.butterfly.flight3d import measures as M
from lifelike_mj.butterfly.flight3d.controllers import default_base
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.parts import Butterfly
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

LAWS = ("exact", "quasi_steady")
FREQUENCIES_HZ = (8.0, 10.0, 12.0)
AMPLITUDES_DEG = (40.0, 50.0, 60.0)
PITCHES_DEG = (10.0, 25.0, 40.0)
FEATHERING_RAD = (0.4, 0.68, 0.9)
SETTLE_S, WINDOW_S = 1.0, 0.6
#: The vertical speed (m/s) a point must keep to count as carrying the weight: level within a slow sink.
LEVEL_M_S = -0.1


def point(law: str, f: float, amp: float, pitch: float, feather: float, settle_s: float = SETTLE_S,
          window_s: float = WINDOW_S) -> dict:
    """One grid point (module docstring): the flight measured over ``window_s`` after ``settle_s``."""
    cmd = replace(default_base("monarch"), frequency_hz=f, amplitude_left=math.radians(amp),
                  amplitude_right=math.radians(amp), feather_amplitude_left=feather, feather_amplitude_right=feather)
    fl = Flight3D(cmd, butterfly=Butterfly("monarch", force_law=law), assist="hold",
                  pitch_law=lambda _f: math.radians(pitch))
    fl.step(int(round(settle_s / fl.dt)))
    s = M.sample(fl, window_s)
    m = M.measures(s, **M.body_numbers(fl))
    vz = float(np.gradient(s["position_m"][:, 2], s["t_s"]).mean())
    return {"force_law": law, "frequency_hz": f, "amplitude_deg": amp, "pitch_deg": pitch, "feather_rad": feather,
            "air_speed_m_s": m["air_speed_m_s"], "vertical_speed_m_s": vz, "power_W_kg": m["power_W_kg"],
            "power_net_W_kg": m["power_net_W_kg"], "advance_ratio": m["advance_ratio"], "carries_weight": vz >= LEVEL_M_S}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "monarch_power.json"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    points = []
    for law, f, amp, pitch, feather in itertools.product(LAWS, FREQUENCIES_HZ, AMPLITUDES_DEG, PITCHES_DEG,
                                                         FEATHERING_RAD):
        points.append(point(law, f, amp, pitch, feather))
        p = points[-1]
        print(f"{law:12s} {f:4.0f} Hz {amp:3.0f} deg pitch {pitch:3.0f} feather {feather:.2f}: "
              f"U {p['air_speed_m_s']:+.2f} m/s, vz {p['vertical_speed_m_s']:+.2f} m/s, {p['power_W_kg']:5.1f} W/kg",
              flush=True)
    summary = {}
    for law in LAWS:
        ok = [p for p in points if p["force_law"] == law and p["carries_weight"]]
        best = min(ok, key=lambda p: p["power_W_kg"]) if ok else None
        summary[law] = {"points_carrying_weight": len(ok), "cheapest": best}
    write_json(args.out, {"provenance": provenance(benchmark="monarch_power", level_m_s=LEVEL_M_S, settle_s=SETTLE_S,
                                                   window_s=WINDOW_S),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start,
                          "dudley_1991_W_kg": [12.5, 20.2], "summary": summary, "points": points})
    for law, s in summary.items():
        b = s["cheapest"]
        print(f"{law}: {s['points_carrying_weight']} points carry the weight; cheapest "
              + (f"{b['power_W_kg']:.1f} W/kg at {b['frequency_hz']:g} Hz, {b['amplitude_deg']:g} deg, pitch "
                 f"{b['pitch_deg']:g} deg, feathering {b['feather_rad']:g} rad" if b else "none"))


if __name__ == "__main__":
    main()
