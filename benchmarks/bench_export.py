"""Export sizes and speed (issue 16): writes benchmarks/results/export.json and prints the table for
docs/performance.md.

Run: ``python benchmarks/bench_export.py [--repeats 3]``. Two runs are recorded once each: a flock of 300
boids for 10,000 steps (a keyframe every 5 steps: 2,001 frames, played at 30 frames/s) and a tank of 10 fish
for 60 s at 30 frames/s (1,801 frames). Each is then written in every format, ``--repeats`` times (the
median time is reported):

* ``glb (32-bit keys)``: the uncompressed baseline, every keyframe value a 32-bit float;
* ``glb``, ``gltf``, ``html``: the defaults (rotation keys as normalized 16-bit integers);
* ``usdc``, ``usda``: USD, binary and text.

Sizes are bytes on disk, with the gzip size of the defaults (what a web server sends). ``raw keys`` is the
least any file holding every keyframe as 32-bit floats can weigh: frames x bodies x 7 x 4 bytes.
"""

from __future__ import annotations

import argparse
import gzip
import statistics
import tempfile
import time
from pathlib import Path

from lifelike_mj.export import write_poses
from lifelike_mj.export.poses import record_poses
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

#: (label, file ending, rotations).
VARIANTS = [("glb (32-bit keys)", ".glb", "float"), ("glb", ".glb", "short"), ("gltf", ".gltf", "short"),
            ("html", ".html", "short"), ("usdc", ".usdc", "short"), ("usda", ".usda", "short")]


def runs():
    from lifelike_mj.boids import Flock
    from lifelike_mj.fish import Tank

    t0 = time.perf_counter()
    flock = record_poses(Flock(n=300, seed=0), 10_000, fps=1.0 / 5.0, time_scale=1.0 / (5 * 30))
    t1 = time.perf_counter()
    tank = record_poses(Tank(n_fish=10, seed=0), 60.0, fps=30.0)
    t2 = time.perf_counter()
    return [("300 boids, 10,000 steps", flock, t1 - t0), ("10 fish, 60 s", tank, t2 - t1)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "export.json"))
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, poses, sim_s in runs():
            raw = poses.n_frames * len(poses.body_ids) * 7 * 4
            row = {"run": label, "frames": poses.n_frames, "bodies": len(poses.body_ids), "simulate_s": sim_s,
                   "raw_keys_bytes": raw, "formats": {}}
            for name, suffix, rotations in VARIANTS:
                path = Path(tmp) / f"run{suffix}"
                times = []
                for _ in range(args.repeats):
                    path.unlink(missing_ok=True)
                    t = time.perf_counter()
                    write_poses(poses, path, rotations=rotations)
                    times.append(time.perf_counter() - t)
                data = path.read_bytes()
                row["formats"][name] = {"bytes": len(data), "write_s": statistics.median(times),
                                        "gzip_bytes": len(gzip.compress(data, 6))}
            rows.append(row)
    write_json(args.out, {"runs": rows, "repeats": args.repeats, "machine": machine_info(),
                          "provenance": provenance(repeats=args.repeats)})
    print("| run | format | size | gzip | vs 32-bit glb | write (median) |")
    print("|---|---|---|---|---|---|")
    for row in rows:
        base = row["formats"]["glb (32-bit keys)"]["bytes"]
        print(f"| {row['run']} ({row['frames']:,} frames x {row['bodies']} bodies; simulated in "
              f"{row['simulate_s']:.1f} s) | raw keys | {row['raw_keys_bytes'] / 1e6:.2f} MB | | | |")
        for name, f in row["formats"].items():
            print(f"| | {name} | {f['bytes'] / 1e6:.2f} MB | {f['gzip_bytes'] / 1e6:.2f} MB | "
                  f"{f['bytes'] / base:.2f} | {f['write_s']:.2f} s |")


if __name__ == "__main__":
    main()
