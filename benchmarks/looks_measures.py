"""The exported creatures' secondary motion measured against the published relations it follows (issue 25):
writes benchmarks/results/looks.json and prints the rows for docs/results.md.

Run: ``python benchmarks/looks_measures.py``. Seeds 3-8 (seeds 1 and 2 were looked at while building):

* fish (6 tanks of 6 fish, 20 s each): the tail-beat frequency read from the caudal bone of the written file in
  every burst above 5 beats/s (at least two beats), against Bainbridge's (4 U / L + 4) / 3 at the fish's speed;
  how much of the time the body wave runs; how far the spine bends;
* birds (pattern 5b, 300 agents, 1,500 steps): the flight bone's roll against atan(v * yaw rate / g), and the
  wing beat's frequency and the share of time gliding;
* every creature: the largest miss of any bone, as written and played, from its pose at every sample.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from lifelike_mj.export import write_poses
from lifelike_mj.export.poses import record_poses
from lifelike_mj.export.rig import check_bone_keys, qconj, qmul, qrot
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance


def tail_beats(rig, t):
    """(measured Hz, Bainbridge Hz, speed BL/s) for every burst of a fish's rig (its caudal joint's beat)."""
    bones = {b.name: b for b in rig.bones}
    q = qmul(qconj(bones[f"{rig.name}/spine4"].quat_wxyz), bones[f"{rig.name}/caudal"].quat_wxyz)
    yaw = 2.0 * np.arctan2(q[:, 3], q[:, 0])
    L = rig.extras["length_m"]
    s = rig.secondary
    on = (s["wave"] >= 0.3) & (s["speed_m_s"] > 2.75 * L)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
    out = []
    for a, b in zip(edges[::2], edges[1::2]):
        if b - a < 12:
            continue  # too short for a beat
        y = yaw[a:b] - np.convolve(yaw[a:b], np.ones(9) / 9, mode="same")
        h = 0.2 * np.percentile(np.abs(y), 90)
        tt, tc, armed = t[a:b], [], False
        for i in range(1, len(y)):
            armed = armed or y[i - 1] < -h
            if armed and y[i - 1] < 0 <= y[i]:
                tc.append(tt[i - 1] - y[i - 1] * (tt[i] - tt[i - 1]) / (y[i] - y[i - 1]))
                armed = False
        if len(tc) < 3:
            continue
        inside = (tt >= tc[0]) & (tt <= tc[-1])
        u = s["speed_m_s"][a:b][inside] / L
        out.append(((len(tc) - 1) / (tc[-1] - tc[0]), float(np.mean((4.0 * u + 4.0) / 3.0)), float(np.mean(u))))
    return out


def main() -> None:
    from lifelike_mj.boids import Flock
    from lifelike_mj.boids.look import agent_length
    from lifelike_mj.boids.look import rigs as bird_rigs
    from lifelike_mj.boids.presets import load_preset
    from lifelike_mj.butterfly import flight3d
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.look import rigs as butterfly_rigs
    from lifelike_mj.fish import Tank
    from lifelike_mj.fish.look import rigs as fish_rigs

    result: dict = {}
    beats, wave_share, bend = [], [], []
    for seed in range(3, 9):
        poses = record_poses(Tank(n_fish=6, seed=seed), 20.0)
        for r in fish_rigs(poses):
            beats += tail_beats(r, poses.t_s)
            wave_share.append(float(np.mean(r.secondary["wave"] > 0.5)))
            spine = [b for b in r.bones if b.name.rsplit("/", 1)[-1] in ("spine1", "caudal")]
            d = np.abs(np.sum(spine[0].quat_wxyz * spine[1].quat_wxyz, axis=1))
            bend.append(float(np.degrees(np.max(2 * np.arccos(np.clip(d, 0, 1))))))
    ratio = np.array([m / b for m, b, _ in beats])
    result["fish"] = {"bursts": len(beats), "speed_bl_s": [float(min(u for *_, u in beats)),
                                                           float(max(u for *_, u in beats))],
                      "tail_beat_over_bainbridge": {"median": float(np.median(ratio)), "min": float(ratio.min()),
                                                    "max": float(ratio.max())},
                      "measured_hz": [float(min(m for m, *_ in beats)), float(max(m for m, *_ in beats))],
                      "wave_share": {"median": float(np.median(wave_share))},
                      "largest_bend_deg": {"median": float(np.median(bend)), "max": float(max(bend))}}
    poses = record_poses(Flock(load_preset("5b"), n=300, seed=3), 1500, fps=0.2, time_scale=1 / 150)
    birds = bird_rigs(poses)
    err, banks = [], []
    for r in birds:
        b = r.bones[0]  # the drawn bird
        fwd = qrot(b.quat_wxyz, np.array([1.0, 0.0, 0.0]))
        right = qrot(b.quat_wxyz, np.array([0.0, -1.0, 0.0]))
        level = np.cross(fwd, [0.0, 0.0, 1.0])
        level /= np.linalg.norm(level, axis=1, keepdims=True)
        roll = np.arctan2(np.sum(np.cross(right, level) * fwd, axis=1), np.sum(level * right, axis=1))
        s = r.secondary
        want = np.arctan(s["lateral_m_s2"] / 9.81)
        err.append(float(np.degrees(np.max(np.abs(roll - want)))))
        banks.append(np.degrees(np.abs(roll)))
    length = agent_length(poses)
    off = np.array([r.secondary["off_path"] for r in birds]) / length
    result["birds"] = {"pattern": "5b", "bank_error_deg_max": float(max(err)),
                       "bank_deg": {"median": float(np.median(np.concatenate(banks))),
                                    "p90": float(np.percentile(np.concatenate(banks), 90))},
                       "flap_hz": birds[0].cycle.period_s ** -1, "phase_groups": len({r.group for r in birds}),
                       "off_path_body_lengths": {"rms": float(np.sqrt(np.mean(off ** 2))), "max": float(off.max())}}
    flight = Flight3D(controller=flight3d.withdrawn_file("steer"), task=flight3d.course(103))
    bp = record_poses(flight, 3.0)
    misses = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, p, rigs in (("butterfly3d", bp, butterfly_rigs(bp)), ("fish", poses_f := record_poses(
                Tank(n_fish=6, seed=5), 5.0), fish_rigs(poses_f)), ("birds", poses, birds[:30])):
            write_poses(p, Path(tmp) / f"{name}.glb", rigs=rigs)
            worst = [check_bone_keys(p.t_s, r, r.keys(p.t_s)) for r in rigs]
            misses[name] = {"m": max(w[0] for w in worst), "deg": math.degrees(max(w[1] for w in worst))}
    result["largest_miss"] = misses
    out = Path(__file__).parent / "results" / "looks.json"
    write_json(out, {**result, "machine": machine_info(), "provenance": provenance()})
    print(result)


if __name__ == "__main__":
    main()
