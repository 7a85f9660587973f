"""Which patterns the boids viewer's keys show (issue 24): the live flock switched to each pattern's weights.

``lifelike-mj view boids`` starts a mixed flock of 300 agents with 5a's weights; Right and Left give it another
pattern's ``W_a``, ``W_c``, the agents where they are. This flies what a viewer does, for every pattern and seed:
5a for ``--before`` steps (the time before a key is pressed: 1,500 steps are 10 s at the viewer's 150 steps/s),
then the pattern's weights for 10,000 steps (the classifier's run, 67 s of viewing), and classifies the last 2,000
steps with the objective classifier (its thresholds were tuned on seeds 10-14 of fresh starts; these seeds are
20-39). Beside it: the same, the flock scattered afresh as the key switches (the viewer's Enter key), and fresh
starts with the pattern's weights from step 0 (the paper's runs).

Run: ``python benchmarks/viewer_patterns.py [--seeds 20-39] [--before 1500] [--patterns 4a,4b]``. Writes (adds the
patterns run to) ``benchmarks/results/viewer_patterns.json``; about 5 minutes per pattern on 2 cores.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from lifelike_mj.boids import Flock
from lifelike_mj.boids.metrics import RECORD_EVERY, RUN_STEPS, WINDOW_STEPS, classify, measures
from lifelike_mj.boids.presets import PATTERNS, load_preset
from lifelike_mj.errors import Diverged
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance


def switched(pattern: str, seed: int, before: int, n: int = 300, start: str = "5a", scatter: bool = False) -> str:
    """The label of a flock of ``start``'s weights switched to ``pattern``'s after ``before`` steps, and, with
    ``scatter``, then scattered afresh as the viewer's Enter key does (``diverged``: an agent ran away, which 5b's
    anti-alignment does now and then)."""
    flock = Flock(load_preset(start), n, seed)
    try:
        if before:
            flock.step(before)
        p = load_preset(pattern)
        flock.set_weights(wa=p.wa, wc=p.wc)
        if scatter:
            flock.scatter(seed + 1)
        run = flock.record(RUN_STEPS, every=RECORD_EVERY, record_from=RUN_STEPS - WINDOW_STEPS + 1)
    except Diverged:
        return "diverged"
    return classify(measures(run, window=WINDOW_STEPS))[0]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="20-39")
    ap.add_argument("--before", type=int, default=1500)
    ap.add_argument("--patterns", default=",".join(PATTERNS), help="which patterns (the others are kept from --out)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "viewer_patterns.json"))
    args = ap.parse_args()
    a, b = (int(x) for x in args.seeds.split("-"))
    seeds = list(range(a, b + 1))
    t0 = time.perf_counter()
    out = Path(args.out)
    old = json.loads(out.read_text()) if out.exists() else {}
    same = old.get("seeds") == seeds and old.get("before_steps") == args.before
    rows = dict(old.get("patterns", {})) if same else {}
    for pattern in args.patterns.split(","):
        labels = {"viewer": [switched(pattern, s, args.before) for s in seeds],
                  "enter": [switched(pattern, s, args.before, scatter=True) for s in seeds],
                  "fresh": [switched(pattern, s, 0, start=pattern) for s in seeds]}
        rows[pattern] = {**{f"{k}_labels": v for k, v in labels.items()},
                         **{f"{k}_shows": sum(x == pattern for x in v) for k, v in labels.items()}}
        print(f"{pattern}: " + ", ".join(f"{k} {rows[pattern][k + '_shows']}/{len(seeds)}" for k in labels), flush=True)
        write_json(out, {"seeds": seeds, "before_steps": args.before, "run_steps": RUN_STEPS,
                         "window_steps": WINDOW_STEPS, "agents": 300,
                         "patterns": {k: rows[k] for k in PATTERNS if k in rows},
                         "wall_s": time.perf_counter() - t0, "machine": machine_info(),
                         "provenance": provenance(seeds=args.seeds, before=args.before, patterns=args.patterns)})


if __name__ == "__main__":
    main()
