"""A flock as a crowd (issue 43): 300 birds for 60 s of playback, its file and Blender's import of it.

Run: ``python benchmarks/bench_crowd.py [--seed 0] [--repeats 3]``; writes benchmarks/results/crowd.json and prints
the rows for docs/performance.md. The flock (the default pattern 5a, 9,000 steps at 5 a frame and 30 frames/s) is
recorded and rigged once (``lifelike_mj.boids.look.rigs``: each bird drawn along its smoothed path, its wings on
the shared wing beat), then written as glb twice: as exported, and the same document with its animations taken out
(the same 300 rigs, meshes and skins, nothing moving). Reported:

* the drawn path's distance from the simulated positions, rms and largest, in body lengths (issue 43: at most 0.15
  rms; there are no wraps to leave out, the box's walls reflect);
* the largest miss of the keys against the drawn motion, channel by channel, over every sample (issue 43: 0.5 mm
  and 0.5 deg);
* the files' sizes (issue 43: at most 25 MB) and what the animation takes of it;
* Blender's glTF import of each, timed inside Blender (``bpy.ops.import_scene.gltf``, a fresh Blender per import,
  the two files alternating, ``--repeats`` each, the median; issue 43: the animated file at most twice the other),
  in Debian's Blender (``blender``) and in Blender 5 as a Python module (``.ci/bpy``) where they are installed.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

ROOT = Path(__file__).resolve().parents[1]
BPY = ROOT / ".ci" / "bpy" / "bin" / "python"
IMPORT = ("import sys, time, bpy, numpy\n"
          "numpy.bool = getattr(numpy, 'bool', bool)  # Debian's Blender 3.4 glTF importer asks numpy for np.bool\n"
          "t = time.perf_counter()\n"
          "bpy.ops.import_scene.gltf(filepath=sys.argv[-1])\n"
          "print('IMPORT_S', time.perf_counter() - t, flush=True)\n")


def blender_import_s(path: Path, which: str) -> float:
    """Seconds Blender's glTF importer takes on ``path`` (timed inside a fresh Blender)."""
    if which == "debian":
        cmd = [shutil.which("blender"), "-b", "--factory-startup", "--python-expr", IMPORT, "--", str(path)]
    else:
        cmd = [str(BPY), "-c", IMPORT, str(path)]
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=1800, check=True).stdout
    return float(next(line.split()[1] for line in out.splitlines() if line.startswith("IMPORT_S")))


def main() -> None:
    from lifelike_mj.boids import Flock
    from lifelike_mj.boids.look import agent_length
    from lifelike_mj.boids.look import rigs as bird_rigs
    from lifelike_mj.export.gltf import build_gltf, save
    from lifelike_mj.export.poses import record_poses
    from lifelike_mj.export.rig import check_bone_keys

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--n", type=int, default=300)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "crowd.json"))
    args = ap.parse_args()
    steps = int(round(args.seconds * 150))
    t0 = time.perf_counter()
    poses = record_poses(Flock(n=args.n, seed=args.seed), steps, fps=0.2, time_scale=1.0 / 150.0)
    t1 = time.perf_counter()
    rigs = bird_rigs(poses)
    t2 = time.perf_counter()
    length = agent_length(poses)
    off = np.array([r.secondary["off_path"] for r in rigs]) / length
    misses = [check_bone_keys(poses.t_s, r, r.keys(poses.t_s)) for r in rigs]
    row = {"birds": args.n, "steps": steps, "playback_s": float(poses.t_s[-1] - poses.t_s[0]), "seed": args.seed,
           "simulate_s": t1 - t0, "build_rigs_s": t2 - t1, "body_length": length,
           "off_path_body_lengths": {"rms": float(np.sqrt(np.mean(off ** 2))), "max": float(off.max())},
           "largest_key_miss": {"m": max(m for m, _ in misses), "deg": math.degrees(max(a for _, a in misses))},
           "phase_groups": len({r.group for r in rigs})}
    with tempfile.TemporaryDirectory() as tmp:
        t = time.perf_counter()
        gl = build_gltf(poses, "flock", {"seed": args.seed, "n": args.n, "steps": steps}, rigs=rigs)
        animated = save(gl, Path(tmp) / "flock.glb")
        row["write_s"] = time.perf_counter() - t
        gl.animations = []
        still = save(gl, Path(tmp) / "flock_still.glb")  # the same rigs, nothing moving (its buffer as it was)
        row["bytes"] = animated.stat().st_size
        print(json.dumps(row), flush=True)
        row["blender"] = {}
        for which in ("debian", "bpy5"):
            if (which == "debian" and shutil.which("blender") is None) or (which == "bpy5" and not BPY.exists()):
                continue
            got: dict[str, list[float]] = {"animated": [], "still": []}
            for _ in range(args.repeats):
                for name, path in (("animated", animated), ("still", still)):
                    got[name].append(blender_import_s(path, which))
                    print(which, name, got[name][-1], flush=True)
            a, s = statistics.median(got["animated"]), statistics.median(got["still"])
            row["blender"][which] = {"animated_s": got["animated"], "still_s": got["still"], "median_animated_s": a,
                                     "median_still_s": s, "ratio": a / s}
    write_json(args.out, {"crowd": row, "machine": machine_info(), "provenance": provenance(**vars(args))})
    print(f"| 300 birds, {row['playback_s']:.0f} s | {row['bytes'] / 1e6:.1f} MB | drawn path "
          f"{row['off_path_body_lengths']['rms']:.3f} BL rms, {row['off_path_body_lengths']['max']:.2f} max |")
    for which, b in row["blender"].items():
        print(f"| Blender ({which}) import | animated {b['median_animated_s']:.1f} s | still {b['median_still_s']:.1f} s "
              f"| ratio {b['ratio']:.2f} |")


if __name__ == "__main__":
    main()
