"""The largest garden and flock the help texts allow (issue 41), each in a process of its own: wall time and peak
resident memory (``ru_maxrss``). The largest tank is ``benchmarks/fish_limits.py``'s.

Run: ``python benchmarks/limits.py`` (about two minutes on two cores). Writes ``benchmarks/results/limits.json``.

* **Garden**: ``Garden(500)`` (``--garden`` and ``garden --n`` take at most 500 butterflies), built and flown 0.1 s.
* **Flock**: a million agents (``boids run --n`` takes at most 1,000,000) with the paper's 5a weights in a box 300
  units wide (the paper's 300 agents' density), 10 steps, then one frame's group measures (a k-d tree). In the
  paper's own 20-unit box each agent would see about 48,000 neighbours: such a run is refused before any work
  (``boids.engine.check_cost``).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from fish_limits import _child  # noqa: E402  (one child runner for both benchmarks)

ROOT = Path(__file__).resolve().parent.parent

_GARDEN = """
import json, resource, time
t0 = time.perf_counter()
from lifelike_mj.butterfly.flight3d.garden import Garden
g = Garden(500, seed=1)
built = time.perf_counter() - t0
g.step(int(round(0.1 / g.dt)))
g.sync()
print(json.dumps({"butterflies": 500, "flown_s": 0.1, "build_s": built, "wall_s": time.perf_counter() - t0,
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""

_FLOCK = """
import json, resource, time
from dataclasses import replace
t0 = time.perf_counter()
from lifelike_mj import boids
from lifelike_mj.boids import metrics
from lifelike_mj.cli.boids import MAX_AGENTS
f = boids.Flock(replace(boids.load_preset("5a"), box=300.0), n=MAX_AGENTS, seed=0)
f.step(1)  # compiled
t1 = time.perf_counter()
f.step(10)
t_steps = time.perf_counter() - t1
s = f.state()
t2 = time.perf_counter()
m = metrics.frame_measures(s["position_box"], s["velocity_box_per_step"], s["type"], box=300.0)
print(json.dumps({"agents": MAX_AGENTS, "box": 300.0, "steps_s_per_step": t_steps / 10,
                  "measures_s": time.perf_counter() - t2, "wall_s": time.perf_counter() - t0,
                  "neighbours_each": boids.engine.neighbours_each(f.params, MAX_AGENTS),
                  "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
"""


def main() -> None:
    argparse.ArgumentParser(description=__doc__.split("\n\n")[0]).parse_args()
    from lifelike_mj.provenance import provenance

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, code in (("garden of 500 butterflies", _GARDEN), ("flock of 1,000,000 agents", _FLOCK)):
            out[name] = _child(code, [], tmp)
            print(f"{name}: {out[name]}", flush=True)
    path = ROOT / "benchmarks" / "results" / "limits.json"
    from lifelike_mj.io import write_json

    write_json(path, {"runs": out, "provenance": provenance(benchmark="limits")})
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
