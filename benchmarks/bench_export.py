"""Export sizes and speed (issues 16 and 25): writes benchmarks/results/export.json and prints the table for
docs/performance.md.

Run: ``python benchmarks/bench_export.py [--repeats 3]``. Two runs are recorded once each, every step sampled: a
flock of 300 boids for 10,000 steps (5 steps a frame: 2,001 frames, played at 30 frames/s) and a tank of 10 fish
for 60 s (60 steps/s, 30 frames/s). Each is then written ``--repeats`` times (the median time is reported; the
rigged flock once, as it takes long) as:

* ``frames, every frame a key``: the layout before keys were chosen (issue 16's default file): the frames
  only, each a key (keyed here within 0.01 mm and 0.01 deg, which keeps nearly every frame that moves);
* ``mjcf, keyed``: the MJCF's geoms on each body, every step sampled and keyed within 0.5 mm and 0.5 deg;
* ``rig``: the default, each creature a skinned, textured mesh on its skeleton with its secondary motion
  (the rigs' building timed apart);
* ``html (rig)`` and ``usdc (mjcf)``;
* for the flock, ``rig, 2cm and 10 deg``: the rig keyed within a looser tolerance, what a flock seen from afar
  can afford.

A third run is the shipped scene (``examples/scenes/garden.json``: 6 butterflies, 10 fish, 60 birds for 8 s),
recorded and rigged once (timed), then written as glb ``--repeats`` times.

Sizes are bytes on disk, with the gzip size (what a web server sends).
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


def runs():
    from lifelike_mj.boids import Flock
    from lifelike_mj.boids.look import rigs as bird_rigs
    from lifelike_mj.fish import Tank
    from lifelike_mj.fish.look import rigs as fish_rigs

    t0 = time.perf_counter()
    flock = record_poses(Flock(n=300, seed=0), 10_000, fps=1.0 / 5.0, time_scale=1.0 / (5 * 30))
    t1 = time.perf_counter()
    tank = record_poses(Tank(n_fish=10, seed=0), 60.0, fps=30.0)
    t2 = time.perf_counter()
    return [("300 boids, 10,000 steps", flock, t1 - t0, bird_rigs), ("10 fish, 60 s", tank, t2 - t1, fish_rigs)]


def scene_row(tmp: Path, repeats: int) -> dict:
    """The shipped scene: its parts recorded and rigged once (timed), then written as glb ``repeats`` times."""
    from lifelike_mj.cli.scene import load_scene, scene_parts
    from lifelike_mj.export.scene import write_scene

    data = load_scene(Path(__file__).parents[1] / "examples" / "scenes" / "garden.json")
    t = time.perf_counter()
    parts = scene_parts(data, quiet=True)
    run_s = time.perf_counter() - t
    times = []
    path = tmp / "scene.glb"
    for _ in range(repeats):
        path.unlink(missing_ok=True)
        t = time.perf_counter()
        write_scene(parts, path, ground_half_m=data["ground_half_m"])
        times.append(time.perf_counter() - t)
    raw = path.read_bytes()
    print("scene", len(raw), statistics.median(times), flush=True)
    return {"run": "the garden scene, 8 s", "frames": int(data["duration_s"] * data["fps"]) + 1,
            "samples": sum(p.poses.n_samples for p in parts), "bodies": sum(len(p.poses.body_ids) for p in parts),
            "simulate_s": run_s, "build_rigs_s": None,  # scene_parts records and rigs each part: timed together
            "formats": {"scene (glb, rig)": {"bytes": len(raw), "write_s": statistics.median(times),
                                             "writes": len(times), "gzip_bytes": len(gzip.compress(raw, 6))}}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "export.json"))
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for label, poses, sim_s, make_rigs in runs():
            t = time.perf_counter()
            rigs = make_rigs(poses)
            rig_s = time.perf_counter() - t
            row = {"run": label, "frames": poses.n_frames, "samples": poses.n_samples, "bodies": len(poses.body_ids),
                   "simulate_s": sim_s, "build_rigs_s": rig_s, "formats": {}}
            variants = [("frames, every frame a key", ".glb", poses.frames(), (1e-5, 0.01), None),
                        ("mjcf, keyed", ".glb", poses, (0.0005, 0.5), None),
                        ("rig (default)", ".glb", poses, (0.0005, 0.5), rigs),
                        ("html (rig)", ".html", poses, (0.0005, 0.5), rigs),
                        ("usdc (mjcf)", ".usdc", poses, (0.0005, 0.5), None)]
            if label.startswith("300 boids"):
                variants.append(("rig, 2cm and 10 deg", ".glb", poses, (0.02, 10.0), rigs))
            for name, suffix, data, tol, rg in variants:
                path = Path(tmp) / f"run{suffix}"
                times = []
                for _ in range(1 if (rg is not None and len(rg) > 100) else args.repeats):
                    path.unlink(missing_ok=True)
                    t = time.perf_counter()
                    write_poses(data, path, tolerance=tol, rigs=rg)
                    times.append(time.perf_counter() - t)
                raw = path.read_bytes()
                row["formats"][name] = {"bytes": len(raw), "write_s": statistics.median(times), "writes": len(times),
                                        "gzip_bytes": len(gzip.compress(raw, 6))}
                print(label, name, len(raw), statistics.median(times), flush=True)
            rows.append(row)
        rows.append(scene_row(Path(tmp), args.repeats))
    write_json(args.out, {"runs": rows, "repeats": args.repeats, "machine": machine_info(),
                          "provenance": provenance(repeats=args.repeats)})
    print("| run | file | size | gzip | vs frames | write (median) |")
    print("|---|---|---|---|---|---|")
    for row in rows:
        base = row["formats"].get("frames, every frame a key", next(iter(row["formats"].values())))["bytes"]
        how = (f"recorded and rigged in {row['simulate_s']:.1f} s" if row["build_rigs_s"] is None else
               f"simulated in {row['simulate_s']:.1f} s, rigs built in {row['build_rigs_s']:.1f} s")
        print(f"| {row['run']} ({row['frames']:,} frames, {row['samples']:,} samples x {row['bodies']} bodies; "
              f"{how}) | | | | | |")
        for name, f in row["formats"].items():
            print(f"| | {name} | {f['bytes'] / 1e6:.2f} MB | {f['gzip_bytes'] / 1e6:.2f} MB | "
                  f"{f['bytes'] / base:.2f} | {f['write_s']:.2f} s |")


if __name__ == "__main__":
    main()
