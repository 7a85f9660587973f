"""Check that ``lifelike-mj reproduce`` computes exactly what version 0.1.0 computed.

``tests/data/reproduce_v0.1.0/*.json.gz`` are the ``results.json`` files that ``lifelike-mj
reproduce all`` wrote on version 0.1.0 (commit fd0b398), before the library reorganisation of
issue 12. This script runs the reproduction again (or reads a folder of reports you already have)
and compares every number bit for bit, leaving out only the keys that measure the machine (wall
times, real-time factors).

    python benchmarks/reproduce_unchanged.py                 # runs reproduce all (about 8 minutes)
    python benchmarks/reproduce_unchanged.py --reports DIR   # DIR/butterfly/results.json, ...

Exit status 0 when every number is the same, 1 otherwise (the differences are printed).
"""

from __future__ import annotations

import argparse
import gzip
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from golden_cases import _strip, differences  # noqa: E402

BASELINE = ROOT / "tests" / "data" / "reproduce_v0.1.0"
CREATURES = ("butterfly", "fish", "boids")


def compare(reports: Path) -> int:
    bad = 0
    for name in CREATURES:
        expected = _strip(json.loads(gzip.decompress((BASELINE / f"{name}.json.gz").read_bytes())))
        actual = _strip(json.loads((reports / name / "results.json").read_text()))
        diff = differences(expected, actual, name)
        print(f"{name}: {'every number the same' if not diff else f'{len(diff)} differences'}")
        for d in diff[:20]:
            print("   ", d)
        bad += bool(diff)
    return 1 if bad else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reports", type=Path, help="folder with butterfly/, fish/, boids/ reports already made")
    args = ap.parse_args()
    if args.reports:
        return compare(args.reports)
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-m", "lifelike_mj.cli", "reproduce", "all", "--out", tmp], check=True)
        return compare(Path(tmp))


if __name__ == "__main__":
    sys.exit(main())
