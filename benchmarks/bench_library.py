"""Library benchmarks (issue 12): start-up of the commands, and the cost of pitch laws of your own.

* **Start-up**: wall time of whole commands, each run in a fresh process with a numba cache folder of
  its own (``NUMBA_CACHE_DIR``): *first run* with an empty cache (everything compiles), *second run*
  with the cache the first run left. Goal: a second run starts computing within 1.5 s.
* **Pitch laws**: one butterfly, 24,000 steps (20 s at 1/1200 s), recorded every step, through
  :class:`lifelike_mj.butterfly.Flight` with the built-in ``simple_rule``, the same rule as a numba
  function (compiled into the loop) and as a Python function (called once per step); per step, and
  the numba/built-in ratio measured in each repeat (goal: within 10 %).

Run: ``python benchmarks/bench_library.py [--repeats 5]``; writes ``benchmarks/results/library.json``
and prints the Markdown tables of docs/performance.md.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

COMMANDS = {
    "butterfly fly (paper backend, 20 s)": ["butterfly", "fly", "--controller", "simple_rule", "--json"],
    "butterfly fly --backend mujoco --duration 1": ["butterfly", "fly", "--controller", "simple_rule", "--backend",
                                                    "mujoco", "--duration", "1", "--json"],
    "fish swim --duration 1": ["fish", "swim", "--duration", "1", "--json"],
    "boids run --steps 10": ["boids", "run", "--steps", "10", "--json"],
}


def _run(argv: list[str], cache: str) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "lifelike_mj.cli", *argv], env=env, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0:
        raise RuntimeError(f"{argv} failed: {r.stderr[-500:]}")
    return dt


def startup(repeats: int) -> dict:
    out = {}
    for name, argv in COMMANDS.items():
        first, second = [], []
        for _ in range(repeats):
            with tempfile.TemporaryDirectory() as cache:
                first.append(_run(argv, cache))
                second.append(_run(argv, cache))
        out[name] = {"first_s": first, "second_s": second, "first_median_s": statistics.median(first),
                     "second_median_s": statistics.median(second)}
        print(f"  {name}: first {out[name]['first_median_s']:.2f} s, second {out[name]['second_median_s']:.2f} s",
              file=sys.stderr)
    return out


def laws(repeats: int, n_steps: int = 24000) -> dict:
    import numpy as np
    from numba import njit

    from lifelike_mj import butterfly

    rule = butterfly.load_controller("simple_rule")
    up, down = np.radians([rule.parameters["phi_up_deg"], rule.parameters["phi_down_deg"]])

    def py_rule(obs):
        return up if obs.omega_rad_s > 1e-9 else down

    nb_rule = njit(py_rule)
    result = {}
    for backend in ("paper", "mujoco"):
        kinds = {"built-in": None, "numba": nb_rule, "python": py_rule}
        for law in kinds.values():  # warm-up: compile
            butterfly.Flight(rule, backend=backend, pitch_law=law).record(n_steps=100)
        samples = {k: [] for k in kinds}
        ratios = []
        for _ in range(repeats):
            for k, law in kinds.items():
                f = butterfly.Flight(rule, backend=backend, pitch_law=law)
                t0 = time.perf_counter()
                f.record(n_steps=n_steps)
                samples[k].append((time.perf_counter() - t0) / n_steps * 1e9)
            ratios.append(samples["numba"][-1] / samples["built-in"][-1])
        result[backend] = {
            "ns_per_step": {k: statistics.median(v) for k, v in samples.items()},
            "samples_ns_per_step": samples,
            "numba_over_builtin": statistics.median(ratios),
            "numba_over_builtin_samples": ratios,
            "python_law_extra_us_per_step": (statistics.median(samples["python"])
                                             - statistics.median(samples["built-in"])) / 1e3,
        }
        print(f"  {backend}: " + ", ".join(f"{k} {v:.0f} ns/step" for k, v in result[backend]["ns_per_step"].items())
              + f"; numba/built-in {result[backend]['numba_over_builtin']:.3f}", file=sys.stderr)
    return result


def main() -> None:
    from lifelike_mj.io import write_json
    from lifelike_mj.machine import machine_info

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "library.json"))
    args = ap.parse_args()
    print("start-up ...", file=sys.stderr)
    s = startup(args.repeats)
    print("pitch laws ...", file=sys.stderr)
    lw = laws(args.repeats)
    r = {"machine": machine_info(), "repeats": args.repeats, "command": " ".join(sys.argv),
         "date": time.strftime("%Y-%m-%d"), "startup": s, "pitch_laws": lw}
    write_json(args.out, r)
    print("| command | first run (cold numba cache) | second run | goal |\n|---|---|---|---|")
    for name, v in s.items():
        ok = "met" if v["second_median_s"] <= 1.5 else "**not met**"
        print(f"| `lifelike-mj {name}` | {v['first_median_s']:.2f} s | {v['second_median_s']:.2f} s | <= 1.5 s: {ok} |")
    print("\n| backend | built-in simple_rule | numba law | Python law | numba / built-in (goal <= 1.10) |")
    print("|---|---|---|---|---|")
    for b, v in lw.items():
        ns = v["ns_per_step"]
        unit = (lambda x: f"{x:.0f} ns/step") if b == "paper" else (lambda x: f"{x / 1e3:.2f} us/step")
        print(f"| {b} | {unit(ns['built-in'])} | {unit(ns['numba'])} | {unit(ns['python'])} | "
              f"{v['numba_over_builtin']:.3f} |")
    assert all(math.isfinite(v["numba_over_builtin"]) for v in lw.values())


if __name__ == "__main__":
    main()
