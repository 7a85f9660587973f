"""The fish at their limits (issue 41): the largest tank the command line allows, and the group measures of many fish.

Run: ``python benchmarks/fish_limits.py`` (about five minutes on two cores; ``--quick`` for a smoke run of a minute).
Writes ``benchmarks/results/fish_limits.json`` and prints the tables of ``docs/performance.md``.

* **The largest tank** (``MAX_FISH`` = 5,000 fish): ``fish swim`` (the paper's ``B-D`` in the filmed tank, with
  ``--out``: tracks, figures, measures), ``fish swim --preset school`` (fish that touch, in the filmed tank),
  ``fish swim --preset shoal --tank 3,3,1`` and ``export fish`` (the rigged glTF), each for ``DURATION_S`` simulated
  seconds, each in a process of its own: its wall time and its peak resident memory (``ru_maxrss``), and what the
  command reports (the simulated seconds per wall second). MuJoCo's arena is sized from the scene
  (``fish.scene.arena_bytes``); before, the first step of such a tank ended in ``mj_stackAlloc: out of memory``.
* **The group measures** (``fish.shoal.group_measures``, what ``fish swim`` reports under ``group``) of ``school``
  fish in the open 3 x 3 x 1 m tank for 2 s (121 samples), ``N_FISH`` fish: the code before issue 41 (every pair of
  fish at every sample at once: ``shoal.py`` as of ``BEFORE_COMMIT``, read with ``git show``) and now (a k-d tree,
  frame by frame), each in a process of its own on the same tracks: wall time, peak resident memory, and whether the
  two give the same numbers. The code before is not run where it would need more than half the memory available
  (its need estimated as ``8 x 8 x T x N^2`` bytes: the pairwise differences, their squares and norms; 7.5 GB
  measured for 1,000 fish).
* **Issue 41's commands**: ``fish swim --preset school --n 1000 --tank 3,3,1 --duration D`` for D = 2, 5 and 10 s
  (the issue measured 7.9 GB, 19 GB, and the machine's 24 GB exhausted), as the largest tank is run.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lifelike_mj.fish.params import MAX_FISH

# This process stays small (no MuJoCo, no tracks): every measured run is a child of its own, and Linux carries a
# parent's peak resident memory into a child's ru_maxrss at its start.

ROOT = Path(__file__).resolve().parent.parent
#: The last commit with the all-pairs group measures.
BEFORE_COMMIT = "98c1328a6634c371392aed5e945637114f6faf06"
DURATION_S = 1.0
N_FISH = (100, 1000, 5000)
OPEN_TANK = "3,3,1"
MEASURES_DURATION_S = 2.0

#: name -> the command line (after ``lifelike-mj``) of a run of the largest tank; {out} is a fresh folder.
LARGEST = {
    "fish swim, B-D, filmed tank, --out": ["fish", "swim", "--n", str(MAX_FISH), "--duration", "{d}", "--out", "{out}/swim"],
    "fish swim, school (touching), filmed tank": ["fish", "swim", "--preset", "school", "--n", str(MAX_FISH),
                                                  "--duration", "{d}"],
    "fish swim, shoal, 3 x 3 x 1 m": ["fish", "swim", "--preset", "shoal", "--tank", OPEN_TANK, "--n", str(MAX_FISH),
                                      "--duration", "{d}"],
    "export fish, B-D, rigged glTF": ["export", "fish", "--n", str(MAX_FISH), "--duration", "{d}", "--fps", "30",
                                      "--out", "{out}/fish.glb"],
}

#: name -> the command line of issue 41's runs of a thousand fish.
ISSUE = {f"fish swim, school, 1,000 fish, 3 x 3 x 1 m, {d:g} s": ["fish", "swim", "--preset", "school", "--n", "1000",
                                                                   "--tank", OPEN_TANK, "--duration", f"{d:g}"]
         for d in (2.0, 5.0, 10.0)}

# The child processes: each prints one JSON line with its peak memory and time.
_CLI_CHILD = """
import json, resource, sys, time
t0 = time.perf_counter()
from lifelike_mj.cli import main
code = main(sys.argv[1:] + ["--json"])
print(json.dumps({"code": code, "wall_s": time.perf_counter() - t0,
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

_TRACKS_CHILD = """
import sys
import numpy as np
from lifelike_mj import fish
n, tank, duration, path = int(sys.argv[1]), tuple(float(v) for v in sys.argv[2].split(",")), float(sys.argv[3]), sys.argv[4]
r = fish.Tank(fish.load_preset("school"), n_fish=n, seed=1, size=tank).record(duration_s=duration)
np.savez(path, times_s=r.times_s, positions=r.positions, tank_m=np.array(r.tank_m))
print("{}")
"""

_MEASURES_CHILD = """
import importlib.util, json, resource, sys, time
import numpy as np
import scipy.sparse.csgraph, scipy.spatial  # loaded before the clock starts, for both (the code now loads them once)
module, tracks, out = sys.argv[1:4]
spec = importlib.util.spec_from_file_location("shoal_under_test", module)
shoal = importlib.util.module_from_spec(spec)
spec.loader.exec_module(shoal)
z = np.load(tracks)
t, p, tank = z["times_s"], z["positions"], tuple(z["tank_m"])
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
t0 = time.perf_counter()
m = shoal.group_measures(t, p, 0.070, tank)
wall = time.perf_counter() - t0
json.dump(m, open(out, "w"))
print(json.dumps({"wall_s": wall, "baseline_rss_mb": base,
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def _child(code: str, args: list[str], cwd: str) -> dict:
    """Run ``code`` in a fresh Python with ``args``: its last line of output, parsed, with ``report``: what it printed
    before that, parsed as JSON where it is (a command's ``--json`` summary); or the error."""
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, capture_output=True, text=True)
    lines = r.stdout.strip().splitlines()
    if r.returncode != 0 or not lines:
        return {"error": (r.stderr.strip().splitlines() or ["no output"])[-1], "returncode": r.returncode,
                "process_wall_s": time.perf_counter() - t0}
    out = json.loads(lines[-1])
    out["process_wall_s"] = time.perf_counter() - t0
    try:
        out["report"] = json.loads("\n".join(lines[:-1]))
    except json.JSONDecodeError:
        pass
    return out


def _available_mb() -> float:
    """MemAvailable of /proc/meminfo (MB), or infinity where there is none."""
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return float("inf")


def largest(duration_s: float, commands: dict[str, list[str]] = LARGEST) -> dict:
    """Each command of ``commands`` (:data:`LARGEST`) in a process of its own."""
    out = {}
    for name, argv in commands.items():
        with tempfile.TemporaryDirectory() as tmp:
            r = _child(_CLI_CHILD, [a.format(d=f"{duration_s:g}", out=tmp) for a in argv], tmp)
        rep = r.pop("report", {})
        keep = ("realtime_factor", "wall_time_s", "fish_outside_tank", "duration_s", "frames", "bytes", "size_bytes")
        r["reported"] = {k: rep[k] for k in keep if k in rep}
        out[name] = {"argv": ["lifelike-mj", *[a.format(d=f"{duration_s:g}", out=".") for a in argv]], **r}
        print(f"{name}: {out[name]}", flush=True)
    return out


def _tracks(n: int, folder: Path) -> Path:
    """``school`` tracks of ``n`` fish in the open tank for :data:`MEASURES_DURATION_S` (seed 1), as an npz (made in a
    child process)."""
    path = folder / f"tracks_{n}.npz"
    r = _child(_TRACKS_CHILD, [str(n), OPEN_TANK, f"{MEASURES_DURATION_S:g}", str(path)], str(folder))
    if "error" in r:
        raise RuntimeError(f"the tracks of {n} fish: {r['error']}")
    return path


def measures(n_fish: tuple[int, ...]) -> dict:
    """The group measures before and after, per number of fish (module docstring)."""
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        before = folder / "shoal_before.py"
        before.write_text(subprocess.run(["git", "show", f"{BEFORE_COMMIT}:lifelike_mj/fish/shoal.py"], cwd=ROOT,
                                         capture_output=True, text=True, check=True).stdout)
        after = ROOT / "lifelike_mj" / "fish" / "shoal.py"
        for n in n_fish:
            tracks = _tracks(n, folder)
            T = int(MEASURES_DURATION_S * 60) + 1
            need_mb = 8 * 8 * T * n * n / 2**20
            row: dict = {"fish": n, "samples": T, "before_estimated_mb": need_mb}
            for name, module in (("after", after), ("before", before)):
                if name == "before" and need_mb > 0.5 * _available_mb():
                    row[name] = {"not_run": f"needs about {need_mb / 1024:.0f} GB, more than half the "
                                            f"{_available_mb() / 1024:.0f} GB available"}
                    continue
                row[name] = _child(_MEASURES_CHILD, [str(module), str(tracks), str(folder / f"{name}_{n}.json")], tmp)
            if "wall_s" in row.get("before", {}) and "wall_s" in row["after"]:
                a = json.loads((folder / f"after_{n}.json").read_text())
                b = json.loads((folder / f"before_{n}.json").read_text())
                row["same_numbers"] = a == b
            print(f"{n} fish: {row}", flush=True)
            out[str(n)] = row
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "fish_limits.json"))
    ap.add_argument("--quick", action="store_true", help="0.1 s of the largest tank, group measures of 100 fish")
    args = ap.parse_args(argv)
    import resource

    start = time.perf_counter()
    duration = 0.1 if args.quick else DURATION_S
    n_fish = (100,) if args.quick else N_FISH
    parent_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    runs = {"largest": largest(duration), "group_measures": measures(n_fish),
            "issue_41": largest(duration, {} if args.quick else ISSUE)}
    from lifelike_mj.io import write_json
    from lifelike_mj.machine import machine_info
    from lifelike_mj.provenance import provenance

    result = {"provenance": provenance(benchmark="fish_limits", max_fish=MAX_FISH, duration_s=duration,
                                       n_fish=list(n_fish), before_commit=BEFORE_COMMIT, open_tank=OPEN_TANK,
                                       measures_duration_s=MEASURES_DURATION_S, quick=args.quick),
              "machine": {**machine_info(), "memory_available_mb_at_end": _available_mb(),
                          "cpu_count": os.cpu_count()},
              "parent_peak_rss_mb_before_the_runs": parent_mb, **runs}
    result["wall_time_s"] = time.perf_counter() - start
    write_json(args.out, result)
    print("\n| largest tank (5,000 fish, "
          f"{duration:g} s simulated) | wall time | peak memory | simulated s per wall s |\n|---|---|---|---|")
    for name, r in result["largest"].items():
        if "error" in r:
            print(f"| {name} | failed: {r['error']} | | |")
        else:
            rt = r["reported"].get("realtime_factor")
            print(f"| {name} | {r['process_wall_s']:.1f} s | {r['peak_rss_mb']:,.0f} MB | "
                  f"{'-' if rt is None else f'x{rt:.2f}'} |")
    print("\n| issue 41's command | wall time | peak memory |\n|---|---|---|")
    for name, r in result["issue_41"].items():
        print(f"| {name} | {r.get('process_wall_s', float('nan')):.1f} s | "
              f"{r.get('peak_rss_mb', float('nan')):,.0f} MB |" if "error" not in r else f"| {name} | {r['error']} | |")
    print("\n| group measures, fish | before: time | before: peak memory | now: time | now: peak memory | same |\n"
          "|---|---|---|---|---|---|")
    print("(peak memory of the process; its baseline, the tracks and the libraries loaded: "
          + ", ".join(f"{int(n):,} fish {row['after'].get('baseline_rss_mb', float('nan')):,.0f} MB"
                      for n, row in result["group_measures"].items()) + ")")
    for n, row in result["group_measures"].items():
        b, a = row["before"], row["after"]
        bt = f"{b['wall_s']:.2f} s" if "wall_s" in b else b.get("not_run", b.get("error", ""))
        bm = f"{b['peak_rss_mb']:,.0f} MB" if "wall_s" in b else f"(about {row['before_estimated_mb'] / 1024:.0f} GB)"
        print(f"| {int(n):,} | {bt} | {bm} | {a['wall_s']:.2f} s | {a['peak_rss_mb']:,.0f} MB | "
              f"{row.get('same_numbers', '-')} |")


if __name__ == "__main__":
    main()
