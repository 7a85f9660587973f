"""How the simulator answers a kick in the body's yaw rate, against the averaged linear model (issue 42): what the
beat-averaged model misses of a turn.

Run: ``python benchmarks/lateral_kick.py`` (about 3 s on 2 cores). Writes ``benchmarks/results/lateral_kick.json``.

At each speed the butterfly is settled in level flight by the shipped designed controller (4 s, plus a quarter, half or
three quarters of a beat, so that the kick falls at four phases of the beat), its state copied into a flight of its
own flown open loop on the trim's kinematics, and its body yaw rate (``qvel[5]``, body axes) raised by 1 rad/s. The
same flight unkicked is subtracted. Reported: the body rates (p, q, r; rad/s) averaged over each of the next six
beats, and the linear model's answer (``expm(A t)`` on the same kick, at each beat's middle); the largest roll rate in
the first beat, simulator and model.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import scipy.linalg as sl

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _beat import beat_means, open_loop, schedule_row, settled  # noqa: E402  (shared with beat_map, beat_regulator)

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
MODEL = HERE / "results" / "monarch_model.json"
PHASES = (0.0, 0.25, 0.5, 0.75)
BEATS = 6


def _after_kick(speed: float, snapshot: dict, kick: float, row: dict) -> tuple[np.ndarray, int, float]:
    """Body rates at every step for ``BEATS`` beats after the kick, open loop from ``snapshot`` (module docstring)."""
    g = open_loop(speed, row["command"], snapshot)
    g.data.qvel[5] += kick
    n = int(round(1.0 / (row["command"][0] * g.dt)))
    rates, _ = beat_means(g, n, BEATS)
    return rates, n, g.dt


def measure(speed: float, spec: dict) -> dict:
    row = schedule_row(spec, speed)
    A = np.array(row["A"])
    period = 1.0 / row["command"][0]
    x0 = np.zeros(9)
    x0[5] = 1.0
    model = [(sl.expm(A * (k + 0.5) * period) @ x0)[3:6].tolist() for k in range(BEATS)]
    out = {"speed_m_s": speed, "model_beats": model, "kicks": []}
    for ph in PHASES:
        snap = settled(speed, ph * period)  # one settled flight, kicked and not
        kicked, n, dt = _after_kick(speed, snap, 1.0, row)
        calm, _, _ = _after_kick(speed, snap, 0.0, row)
        d = kicked - calm
        beats = [d[k * n:(k + 1) * n].mean(axis=0).tolist() for k in range(BEATS)]
        first = np.arange(1, n + 1) * dt
        model_p = [float((sl.expm(A * t) @ x0)[3]) for t in first]
        out["kicks"].append({"phase": ph, "beats": beats, "first_beat_roll_rate_extreme": float(d[:n, 0][np.argmax(
            np.abs(d[:n, 0]))]), "model_first_beat_roll_rate_extreme": model_p[int(np.argmax(np.abs(model_p)))]})
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE / "results" / "lateral_kick.json"))
    args = ap.parse_args(argv)
    from lifelike_mj.butterfly.flight3d import designed as D

    spec = D.design(D.check_model(json.loads(MODEL.read_text()), str(MODEL)))
    rows = [measure(v, spec) for v in (1.0, 1.5)]
    write_json(args.out, {"provenance": provenance(benchmark="lateral_kick", model=str(MODEL), phases=list(PHASES),
                                                   beats=BEATS, kick_rad_s=1.0),
                          "machine": machine_info(), "speeds": rows})
    for r in rows:
        print(f"{r['speed_m_s']} m/s: model yaw rate in beat {BEATS}: {r['model_beats'][-1][2]:+.2f} rad/s; simulator by "
              "phase: " + ", ".join(f"{k['phase']}: {k['beats'][-1][2]:+.2f}" for k in r["kicks"])
              + "; first-beat roll rate, simulator " + ", ".join(f"{k['first_beat_roll_rate_extreme']:+.2f}"
                                                                 for k in r["kicks"])
              + f", model {r['kicks'][0]['model_first_beat_roll_rate_extreme']:+.2f}")


if __name__ == "__main__":
    main()
