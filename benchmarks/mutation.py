"""Mutation testing, by hand, of the physics and optimiser modules: does a wrong model fail the tests?

Each mutant changes one constant, sign, index or reading in the source (the kinds of bugs a formula
test does not see), runs the tests that cover that module, and counts as *killed* when a test fails.
The source is restored after each mutant. The numba cache is keyed on the source
(``lifelike_mj/_numba_cache.py``), so every mutant is compiled afresh.

    python benchmarks/mutation.py                      # every mutant, this checkout
    python benchmarks/mutation.py --root DIR           # another checkout (e.g. an older commit)
    python benchmarks/mutation.py --only rcga_alpha    # some mutants

Writes ``benchmarks/results/mutation.json`` (or ``--out``) and prints a table: mutant, module,
killed or survived, by which test, seconds.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

PAPER = "tests/butterfly/test_paper_backend.py tests/butterfly/test_experiments.py"
# (id, file, old, new, tests): one occurrence of ``old`` is replaced by ``new``.
MUTANTS = [
    # --- physics: the fluid force (Oe 2010 eq. 1, 10), the butterfly's equations (eq. 7-11), RK4
    ("fluid_half", "lifelike_mj/physics/fluid.py", "return -0.5 * area_m2 * rho * cd * v_normal * abs(v_normal)",
     "return -0.25 * area_m2 * rho * cd * v_normal * abs(v_normal)", "tests/physics tests/butterfly/test_aero.py"),
    ("fluid_sign", "lifelike_mj/physics/fluid.py", "return -0.5 * np.asarray(area_m2, dtype=float) * rho * cd * v * np.abs(v)",
     "return 0.5 * np.asarray(area_m2, dtype=float) * rho * cd * v * np.abs(v)", "tests/physics tests/butterfly/test_aero.py"),
    ("paper_eq7_sign", "lifelike_mj/butterfly/backends/paper.py", "vp = c[_L] * omega - vzr * sphi  # eq. 7",
     "vp = c[_L] * omega + vzr * sphi  # eq. 7", PAPER),
    ("paper_gravity", "lifelike_mj/butterfly/backends/paper.py", "/ c[_MASS] - c[_G]  # eq. 11 (+ gravity)",
     "/ c[_MASS] - 0.9 * c[_G]  # eq. 11 (+ gravity)", PAPER),
    ("paper_lift_cos", "lifelike_mj/butterfly/backends/paper.py", "ay = (-f * cphi * ctheta + fby)",
     "ay = (-f * cphi + fby)", PAPER),
    ("paper_rk4_weight", "lifelike_mj/butterfly/backends/paper.py",
     "vy += dt / 6.0 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y)", "vy += dt / 6.0 * (a1y + 2.0 * a2y + 3.0 * a3y + a4y)",
     PAPER),
    ("params_rho", "lifelike_mj/physics/fluid.py", "RHO_AIR: float = 1.28", "RHO_AIR: float = 1.2",
     "tests/test_paper_constants.py tests/butterfly/test_experiments.py"),
    ("fitness_speed", "lifelike_mj/butterfly/flight.py", "return vz / 3.0 * 0.1 / (abs(y_rel) + 0.1)",
     "return vz / 3.0 * 0.1 / (abs(y_rel) + 0.2)", "tests/butterfly/test_paper_backend.py tests/butterfly/test_ann.py"),
    ("ann_inputs_swapped", "lifelike_mj/butterfly/ann.py", "    if cp[A_RELATIVE] > 0.5:\n        vy = vy - air_y",
     "    if cp[A_RELATIVE] < 0.5:\n        vy = vy - air_y", "tests/test_paper_constants.py tests/butterfly/test_ann.py"),
    ("mj_wing_sign", "lifelike_mj/butterfly/backends/mj.py",
     "                vp = ud[U_L] * qvel[int(ud[U_FLAP_D + i])] - vbx * sphi\n                fn = -ud[U_KHALF]",
     "                vp = ud[U_L] * qvel[int(ud[U_FLAP_D + i])] - vbx * sphi\n                fn = ud[U_KHALF]",
     "tests/butterfly/test_mj_backend.py"),
    ("fish_drag_half", "lifelike_mj/fish/sim.py", "fb = np.zeros(3) if mu == CRUISE else -0.5 * rho * cd * sv * vb * np.abs(vb)",
     "fb = np.zeros(3) if mu == CRUISE else -0.25 * rho * cd * sv * vb * np.abs(vb)", "tests/fish/test_fish.py"),
    ("fish_phi_range", "lifelike_mj/fish/sim.py", "phi = 90.0 + c[C_PHR] * (2.0 * u[i, 3] - 1.0)",
     "phi = 90.0 + 0.5 * c[C_PHR] * (2.0 * u[i, 3] - 1.0)", "tests/fish/test_fish.py tests/fish/test_tank_behaviours.py"),
    ("fish_no_orderings", "lifelike_mj/fish/experiments.py", "    for k in DIVERSITY_MEASURES:\n        pairs +=",
     "    for k in ():\n        pairs +=", "tests/fish/test_fish.py"),
    ("boids_w_s", "lifelike_mj/boids/engine.py", "W_S = 0.05", "W_S = 0.1",
     "tests/test_paper_constants.py tests/boids/test_boids_engine.py"),
    ("boids_align_mean", "lifelike_mj/boids/engine.py", "                f += g / na", "                f += g / (na + 1)",
     "tests/boids/test_boids_engine.py"),
    # --- optimisers: the paper's GA (Oe 2010 section 6.2), CMA-ES, the driver
    ("rcga_alpha", "lifelike_mj/evolve/rcga.py", "ALPHA = 0.45", "ALPHA = 0.3",
     "tests/test_paper_constants.py tests/evolve"),
    ("rcga_mut_scale", "lifelike_mj/evolve/rcga.py", "MUTATION_SCALE = 2.0", "MUTATION_SCALE = 1.5",
     "tests/test_paper_constants.py tests/evolve"),
    ("rcga_mut_rate", "lifelike_mj/evolve/rcga.py", "MUTATION_RATE = 0.01", "MUTATION_RATE = 0.02",
     "tests/test_paper_constants.py tests/evolve"),
    ("rcga_tournament", "lifelike_mj/evolve/rcga.py", "wins_b = f[b] > f[a] if maximize else f[b] < f[a]",
     "wins_b = f[b] < f[a] if maximize else f[b] > f[a]", "tests/evolve"),
    ("rcga_thirds", "lifelike_mj/evolve/rcga.py", "        kind = j % 3", "        kind = (j + 1) % 3", "tests/evolve"),
    ("rcga_elite", "lifelike_mj/evolve/rcga.py", "    return int(np.argmax(f) if maximize else np.argmin(f))",
     "    return int(np.argmin(f) if maximize else np.argmax(f))", "tests/evolve"),
    ("cmaes_sigma0", "lifelike_mj/evolve/cmaes.py", "sigma0 = 0.25 * float(np.mean(width))",
     "sigma0 = 0.3 * float(np.mean(width))", "tests/evolve"),
    ("driver_nan_worst", "lifelike_mj/evolve/driver.py", "f[bad] = worst_value(self.maximize)",
     "f[bad] = worst_value(not self.maximize)", "tests/evolve"),
    ("driver_tie_keeps_older", "lifelike_mj/evolve/driver.py", "return a > b if self.maximize else a < b",
     "return a >= b if self.maximize else a <= b", "tests/evolve"),
    # --- a second set, written after the tests of issue 13 were (so not aimed at by them)
    ("fresh_rk4_half_step", "lifelike_mj/butterfly/backends/paper.py", "    h = 0.5 * dt\n", "    h = 0.45 * dt\n", PAPER),
    ("fresh_ann_transfer", "lifelike_mj/butterfly/ann.py", "math.exp(-12.0 * (u + 0.5))", "math.exp(-10.0 * (u + 0.5))",
     "tests/butterfly/test_ann.py tests/butterfly/test_shipped_networks.py"),
    ("fresh_ann_dphi_sign", "lifelike_mj/butterfly/ann.py", "phi = phi_prev + cp[A_DMAX] * transfer(out)",
     "phi = phi_prev - cp[A_DMAX] * transfer(out)", "tests/butterfly/test_ann.py tests/butterfly/test_shipped_networks.py"),
    ("fresh_fish_brake_area", "lifelike_mj/fish/sim.py", "fb[a] = normal_drag_scalar(ud[U_SV + a] + brake * ud[U_DSV + a]",
     "fb[a] = normal_drag_scalar(ud[U_SV + a] + 0.5 * brake * ud[U_DSV + a]", "tests/fish"),
    ("fresh_fish_balance_sign", "lifelike_mj/fish/sim.py", "sg = 1.0 if pitch > 0 else (-1.0 if pitch < 0 else 0.0)",
     "sg = -1.0 if pitch > 0 else (1.0 if pitch < 0 else 0.0)", "tests/fish"),
    ("fresh_fish_buoyancy", "lifelike_mj/fish/sim.py", "* float(np.linalg.norm(m.opt.gravity)) * params.buoyancy_offset_m",
     "* float(np.linalg.norm(m.opt.gravity)) * 2.0 * params.buoyancy_offset_m", "tests/fish"),
    ("fresh_boids_wall_weight", "lifelike_mj/boids/engine.py", "                    f += w_s\n",
     "                    f += 2.0 * w_s\n", "tests/boids/test_boids_engine.py tests/boids/test_flock.py"),
    ("fresh_boids_cohesion_mean", "lifelike_mj/boids/engine.py", "                f += g / nc\n",
     "                f += g / (nc + 1)\n", "tests/boids/test_boids_engine.py tests/boids/test_flock.py"),
    ("fresh_rcga_odd_partner", "lifelike_mj/evolve/rcga.py", "j = r if r < i else r + 1", "j = r", "tests/evolve"),
    ("fresh_nlopt_block", "lifelike_mj/evolve/nloptalgs.py", 'if status["calls"] % block == 0 or',
     'if status["calls"] % (block + 1) == 0 or', "tests/evolve"),
    ("fresh_cmaes_ipop", "lifelike_mj/evolve/cmaes.py", "run.population * 2**restart", "run.population * 3**restart",
     "tests/evolve"),
    ("fresh_budget_off_by_one", "lifelike_mj/evolve/driver.py", "return self.generations >= self.budget.value",
     "return self.generations > self.budget.value", "tests/evolve"),
]


def _env(root: Path, cache: str) -> dict:
    """The tests' environment: the mutated checkout first on the path (for subprocesses too) and an
    empty numba cache of its own (so that no compiled code of the unmutated source is served, also on
    checkouts older than the source-keyed cache)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(root))
    return env


def run_mutant(root: Path, mid: str, file: str, old: str, new: str, tests: str, timeout_s: float) -> dict:
    path = root / file
    src = path.read_text()
    if src.count(old) != 1:
        return {"id": mid, "file": file, "status": "not applicable", "why": f"{src.count(old)} matches"}
    selected = [t for t in tests.split() if (root / t.split("::")[0]).exists()]
    path.write_text(src.replace(old, new))
    t0 = time.perf_counter()
    cache = tempfile.mkdtemp(prefix="mutant-numba-")
    try:
        proc = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *selected],
                              cwd=root, capture_output=True, text=True, timeout=timeout_s,
                              env=_env(root, cache))
        failed = proc.returncode != 0
        line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("FAILED")), "")
        status = "killed" if failed else "survived"
    except subprocess.TimeoutExpired:
        status, line = "killed", "timeout"
    finally:
        path.write_text(src)
        shutil.rmtree(cache, ignore_errors=True)
    return {"id": mid, "file": file, "tests": selected, "status": status, "by": line[7:160],
            "seconds": round(time.perf_counter() - t0, 1)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, default=ROOT, help="checkout to mutate (default: this one)")
    ap.add_argument("--only", nargs="*", default=None, help="mutant ids to run")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "mutation.json")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per mutant")
    args = ap.parse_args()
    rows = []
    for mid, file, old, new, tests in MUTANTS:
        if args.only and mid not in args.only:
            continue
        r = run_mutant(args.root.resolve(), mid, file, old, new, tests, args.timeout)
        rows.append(r)
        print(f"{mid:24s} {r['status']:15s} {r.get('seconds', 0):7.1f} s  {r.get('by', r.get('why', ''))}", flush=True)
    applicable = [r for r in rows if r["status"] != "not applicable"]
    killed = sum(r["status"] == "killed" for r in applicable)
    score = killed / len(applicable) if applicable else 0.0
    print(f"mutation score: {killed}/{len(applicable)} killed ({100 * score:.0f} %)")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=args.root, capture_output=True,
                            text=True).stdout.strip()
    args.out.write_text(json.dumps({"root_commit": commit, "killed": killed, "applicable": len(applicable),
                                    "score": score, "mutants": rows}, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
