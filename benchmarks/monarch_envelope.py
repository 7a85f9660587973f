"""How fast the filmed monarch's wing envelope can carry it (issue 27's speed): the base kinematics
(``controllers.default_base("monarch")``: 120 deg strokes at 10.2 Hz) with the body held at a range of body angles.

Run: ``python benchmarks/monarch_envelope.py`` (about a minute on 2 cores). Writes
``benchmarks/results/monarch_envelope.json``.

Each body angle: the attitude held (the reduction's hold, an outside torque: an envelope, not free flight), the
quasi-steady wing-force law, from rest; after ``SETTLE_S`` the flight is measured over ``WINDOW_S``
(``flight3d.measures``), as ``monarch_power.point`` measures a grid point: the speed through the air, the mean
vertical speed (climb > 0), the drive's positive power per kg and the advance ratio over both wings.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

from lifelike_mj.butterfly.flight3d.controllers import default_base
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

sys.path.insert(0, str(Path(__file__).parent))
import monarch_power  # noqa: E402  (the sibling benchmark's grid point)

BODY_ANGLES_DEG = (20.0, 10.0, 0.0, -10.0, -20.0)
SETTLE_S, WINDOW_S = 2.0, 2.0


def point(pitch_deg: float) -> dict:
    """The filmed envelope (its frequency, stroke and feathering: ``default_base("monarch")``) with the body held at
    ``pitch_deg``: ``monarch_power.point`` over this benchmark's window."""
    base = default_base("monarch")
    return monarch_power.point("quasi_steady", base.frequency_hz, math.degrees(base.amplitude_left), pitch_deg,
                               base.feather_amplitude_left, settle_s=SETTLE_S, window_s=WINDOW_S)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "monarch_envelope.json"))
    args = ap.parse_args(argv)
    start = time.perf_counter()
    points = []
    for a in BODY_ANGLES_DEG:
        points.append(point(a))
        p = points[-1]
        print(f"body {a:+5.0f} deg: U {p['air_speed_m_s']:.2f} m/s, vz {p['vertical_speed_m_s']:+.2f} m/s, "
              f"{p['power_W_kg']:.1f} W/kg", flush=True)
    write_json(args.out, {"provenance": provenance(benchmark="monarch_envelope", settle_s=SETTLE_S, window_s=WINDOW_S,
                                                   body_angles_deg=list(BODY_ANGLES_DEG)),
                          "machine": machine_info(), "wall_time_s": time.perf_counter() - start, "points": points})


if __name__ == "__main__":
    main()
