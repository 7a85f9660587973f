"""Behaviour that must not change when the code is reorganised: command lines and what they compute.

Each case is a command line of ``lifelike-mj`` (with ``--json``) and the files it writes. Its
*record* is the JSON it prints, less the keys that measure the machine (wall times, real-time
factors, dates), plus a SHA-256 of every array in every ``.npz`` it writes and of the weights of
every controller file it writes. ``tests/data/golden_cli.json`` holds the records made by
``python tests/golden_cases.py record`` on version 0.1.0 before the library reorganisation (issue
12), and the 3D butterfly's cases (``fly3d_*``, ``evolve3d_*``, ``assess3d_*``) on commit 0e7f3e6, before the 3D
flight became a slice of its own (issue 26); they pin ``--dt 1/1200``, the default then.
``tests/cli/test_unchanged.py`` recomputes them and compares. The 3D cases of the controllers `steer` and `wind`, since
withdrawn, fly their kept files (``{withdrawn}``: :func:`~lifelike_mj.butterfly.flight3d.controllers.withdrawn_file`).

Run as a script::

    python tests/golden_cases.py record [FILE]   # write the records of the installed code
    python tests/golden_cases.py record FILE CASE ...   # (re)record these cases into FILE, keeping the others
    python tests/golden_cases.py check [FILE]    # recompute and compare bit for bit
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

GOLDEN = Path(__file__).resolve().parent / "data" / "golden_cli.json"

#: Keys whose values measure the machine or the clock, not the model.
VOLATILE = ("wall_time_s", "wall_s", "realtime_factor", "created", "seconds_per_evaluation", "render_s", "sim_s",
            "encode_s", "render_fps", "out", "files", "path", "workers", "machine", "command", "version",
            "lifelike_mj_version", "package_version", "elapsed_s", "plot")

#: name -> (argv with ``{out}`` for a fresh folder, files under ``{out}`` to fingerprint)
CASES: dict[str, tuple[list[str], list[str]]] = {
    "fly_paper": (["butterfly", "fly", "--controller", "simple_rule", "--duration", "5", "--out", "{out}"],
                  ["trajectory.npz"]),
    "fly_paper_phi14_ab": (["butterfly", "fly", "--controller", "simple_rule", "--phi-up-deg", "14", "--duration", "3",
                            "--body-area-cm2", "1.53", "--dt", "0.0004"], []),
    "fly_mujoco": (["butterfly", "fly", "--controller", "simple_rule", "--backend", "mujoco", "--duration", "5",
                    "--out", "{out}"], ["trajectory.npz"]),
    "fly_mujoco_rich": (["butterfly", "fly", "--controller", "simple_rule", "--backend", "mujoco", "--config", "rich",
                         "--duration", "2", "--y0", "5", "--wind", "2,0", "--out", "{out}"], ["trajectory.npz"]),
    "fly_ann_wind": (["butterfly", "fly", "--controller", "ann_paper", "--y0", "10", "--wind", "1,0.5", "--duration",
                      "5", "--out", "{out}"], ["trajectory.npz"]),
    "fly_ann_ground_mujoco": (["butterfly", "fly", "--controller", "ann_robust", "--inputs", "ground", "--backend",
                               "mujoco", "--wind=-1,0", "--duration", "3", "--out", "{out}"], ["trajectory.npz"]),
    "compare_paper": (["butterfly", "compare", "--controller", "simple_rule", "--duration", "3"], []),
    "compare_rich": (["butterfly", "compare", "--controller", "ann_paper", "--config", "rich", "--duration", "2"], []),
    "speed_limit": (["butterfly", "speed-limit", "--body-area-cm2", "1.53"], []),
    "forces": (["butterfly", "forces"], []),
    "timestep": (["butterfly", "timestep"], []),
    "trim_mujoco": (["butterfly", "trim", "--backend", "mujoco", "--dt", "0.000833333"], []),
    "windmap": (["butterfly", "windmap", "--controller", "ann_paper", "--step", "1", "--max", "2"], []),
    "evolve_rcga": (["butterfly", "evolve", "--optimizer", "rcga", "--population", "8", "--generations", "3",
                     "--executor", "serial", "--quiet", "--out", "{out}/rcga.json"], ["rcga.json"]),
    "evolve_cmaes_robust": (["butterfly", "evolve", "--optimizer", "cmaes", "--evaluations", "24", "--task", "robust",
                             "--executor", "serial", "--quiet", "--out", "{out}/cmaes.json"], ["cmaes.json"]),
    "evolve_mujoco": (["butterfly", "evolve", "--optimizer", "rcga", "--backend", "mujoco", "--population", "4",
                       "--generations", "2", "--executor", "serial", "--quiet", "--out", "{out}/mj.json"], ["mj.json"]),
    "fly3d_steer_turn": (["butterfly", "fly3d", "--controller", "{withdrawn}/steer.json", "--task", "turn", "--angle", "-90",
                          "--duration", "4", "--dt", "1/1200", "--out", "{out}"], ["path.npz"]),
    "fly3d_wind_course": (["butterfly", "fly3d", "--controller", "{withdrawn}/wind.json", "--task", "course", "--seed", "3",
                           "--wind-to", "1,0.5,0", "--gusts", "0.5", "--flutter", "0.1", "--duration", "4", "--dt",
                           "1/1200", "--out", "{out}"], ["path.npz"]),
    "evolve3d_cmaes": (["butterfly", "evolve3d", "--population", "4", "--generations", "2", "--duration", "0.5",
                        "--dt", "1/1200", "--quiet", "--out", "{out}/c3.json"], ["c3.json"]),
    "assess3d_wind": (["butterfly", "assess3d", "--controller", "{withdrawn}/wind.json", "--duration", "6", "--courses", "100",
                       "--gusts", "0.3", "--dt", "1/1200"], []),
    "fish_swim": (["fish", "swim", "--fish", "5", "--duration", "4", "--out", "{out}"], ["tracks.npz"]),
    "fish_swim_nbnd": (["fish", "swim", "--preset", "NB-ND", "--fish", "3", "--duration", "3", "--seed", "2",
                        "--tank-scale", "0.5"], []),
    "fish_drag_check": (["fish", "drag-check"], []),
    "boids_run": (["boids", "run", "--preset", "4c", "--n", "100", "--steps", "60", "--out", "{out}"],
                  ["trajectories.npz"]),
    "boids_run_2d": (["boids", "run", "--wa", "0.5,-0.15;-0.15,0.5", "--wc", "0.01,0.01;0.01,0.01", "--dims", "2",
                      "--n", "60", "--steps", "40"], []),
    "boids_sweep": (["boids", "sweep", "--preset", "5a", "--x", "wa_cross=-0.2:0.2:2", "--seeds", "0", "--steps", "30",
                     "--n", "40", "--executor", "serial"], []),
}


def _strip(obj):
    """``obj`` without the volatile keys, recursively."""
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items() if k not in VOLATILE}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    if isinstance(obj, float) and obj != obj:
        return None  # strict JSON
    return obj


def _digest(path: Path) -> dict:
    if path.suffix == ".npz":
        with np.load(path, allow_pickle=False) as z:
            return {k: hashlib.sha256(np.ascontiguousarray(z[k]).tobytes()).hexdigest() for k in sorted(z.files)}
    data = json.loads(path.read_text())
    w = data.get("parameters", {}).get("weights", data.get("weights"))
    prov = data.get("provenance", {})
    return {"weights": hashlib.sha256(np.asarray(w, dtype=float).tobytes()).hexdigest(),
            "best_fitness": prov.get("best_fitness"), "evaluations": prov.get("evaluations")}


def run_case(name: str) -> dict:
    """Run one case in this process; its record."""
    from lifelike_mj.butterfly.flight3d.controllers import withdrawn_file
    from lifelike_mj.cli import main

    argv, files = CASES[name]
    withdrawn = str(withdrawn_file("steer").parent)  # the 3D controllers since withdrawn, kept for these cases
    with tempfile.TemporaryDirectory() as tmp:
        args = [a.replace("{out}", tmp).replace("{withdrawn}", withdrawn) for a in argv] + ["--json"]
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = main(args)
        if code != 0:
            raise RuntimeError(f"case {name} exited with {code}")
        text = buf.getvalue()
        record = {"stdout": _strip(json.loads(text[text.index("{"):]))}
        for f in files:
            record[f] = _digest(Path(tmp) / f)
    return record


#: The boids' measures (nearest-neighbour distance, anisotropy, polarisation ...) go through BLAS and LAPACK
#: (a matrix product for the distances, an eigen-solver), whose kernels are chosen for the processor: on an
#: AVX-512 machine they differ from the records' machine in the last 1-4 bits (seen: 0.037379307495051875
#: against 0.03737930749505196) while the trajectories stay identical bit for bit. Those numbers are compared
#: to this relative tolerance; everything else, the trajectories' files included, exactly.
BLAS_REL = 1e-12
BLAS_PREFIXES = ("boids_run/stdout/", "boids_run_2d/stdout/", "boids_sweep/stdout/")


def differences(expected, actual, where: str = "") -> list[str]:
    """Where ``actual`` differs from ``expected`` (keys that ``actual`` adds are allowed): exactly, except the
    numbers under :data:`BLAS_PREFIXES` (to :data:`BLAS_REL`)."""
    if isinstance(expected, dict):
        if not isinstance(actual, dict):
            return [f"{where}: expected an object, got {actual!r:.80}"]
        out = []
        for k, v in expected.items():
            if k not in actual:
                out.append(f"{where}/{k}: missing")
            else:
                out += differences(v, actual[k], f"{where}/{k}")
        return out
    if isinstance(expected, list):
        if not isinstance(actual, list) or len(actual) != len(expected):
            return [f"{where}: expected a list of {len(expected)}, got {actual!r:.80}"]
        return [d for i, (e, a) in enumerate(zip(expected, actual)) for d in differences(e, a, f"{where}[{i}]")]
    if isinstance(expected, float) and isinstance(actual, float) and where.startswith(BLAS_PREFIXES):
        same = (math.isnan(expected) and math.isnan(actual)) or math.isclose(expected, actual, rel_tol=BLAS_REL)
        return [] if same else [f"{where}: expected {expected!r}, got {actual!r}"]
    if expected != actual:
        return [f"{where}: expected {expected!r}, got {actual!r}"]
    return []


def main(argv: list[str]) -> int:
    mode = argv[0] if argv else "check"
    path = Path(argv[1]) if len(argv) > 1 else GOLDEN
    if mode == "record":
        names = argv[2:] or list(CASES)
        records = json.loads(path.read_text()) if argv[2:] and path.exists() else {}
        records.update({name: run_case(name) for name in names})
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(records, indent=1, sort_keys=True) + "\n")
        print(f"wrote {len(records)} records to {path}")
        return 0
    golden = json.loads(path.read_text())
    bad = 0
    for name in CASES:
        diff = differences(golden[name], run_case(name), name)
        bad += bool(diff)
        print(f"{name}: {'same' if not diff else 'DIFFERENT'}")
        for d in diff[:10]:
            print("   ", d)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
