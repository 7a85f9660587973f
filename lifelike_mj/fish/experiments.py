"""Fish experiments: one swim and its measures, the drag cross-check, the four-pattern table.

* :func:`swim_summary`: the measures of ``fish/metrics.py`` on a swim's tracks (what
  ``lifelike-mj fish swim --json`` prints), plus ``fish_outside_tank``;
* :func:`drag_check`: the custom drag of ``fish/sim.py`` (C_D = 1, the areas of the body's
  equivalent inertia box) against MuJoCo's own inertia-box fluid model (``option density``) on
  random states: ``max_rel_error``;
* :func:`pattern_table`: the four motion patterns of Satoi 2015 section 5.1.1 over several seeds,
  and whether they order on the objective measures as the paper's questionnaire ratings do
  (Fig. 11-12: B-D above NB-ND on burstiness and diversity, B above NB on burstiness, D above ND
  on diversity), seed by seed;
* :func:`write_tracks`: tracks as npz and a tidy CSV.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj.fish.metrics import MU_NAMES, track_measures
from lifelike_mj.fish.params import COAST, FishParams, load_preset
from lifelike_mj.fish.scene import BODY_LENGTH_M, box_areas
from lifelike_mj.fish.shoal import group_measures
from lifelike_mj.fish.sim import (
    COMPILED_PASSIVE,
    FISH_BLOCK,
    MAGIC,
    U_CD,
    U_CDROT,
    U_FISH,
    U_MAGIC,
    U_N,
    U_RHO,
    U_SV,
    U_SW,
    SwimResult,
    swim,
)
from lifelike_mj.io import atomic_path, write_npz
from lifelike_mj.paths import model_path
from lifelike_mj.physics.callbacks import passive_callback

PATTERNS = ("NB-ND", "NB-D", "B-ND", "B-D")
#: The measures that stand for the paper's two rated qualities.
BURSTINESS_MEASURES = ("burstiness", "accel_kurtosis")
DIVERSITY_MEASURES = ("turn_entropy",)


def swim_summary(result: SwimResult) -> dict:
    """Measures of a swim (``fish/metrics.track_measures`` on the tracks at 24 fps, side view; the
    MU entropy rate and dwell times from the MU log), plus ``fish_outside_tank`` (fish whose centre
    ever left the water volume), the run's settings and its speed (simulated s per wall s)."""
    p = result.params
    m = track_measures(result.times_s, result.positions, BODY_LENGTH_M, mu_log=result.mu % 4,
                       control_dt=p.control_dt_s)
    duration = float(result.times_s[-1] - result.times_s[0])
    m["group"] = group_measures(result.times_s, result.positions, BODY_LENGTH_M, result.tank_m)
    m.update({
        "fish_outside_tank": int(result.outside_tank().sum()),
        "avoiding_fraction": float((result.mu >= 4).mean()),
        "preset": p.name,
        "fish": int(result.n_fish),
        "duration_s": duration,
        "seed": int(result.seed),
        "tank_m": [float(v) for v in result.tank_m],
        "wall_time_s": float(result.wall_time_s),
        "realtime_factor": duration / result.wall_time_s if result.wall_time_s > 0 else float("nan"),
    })
    return m


def write_tracks(result: SwimResult, out_dir: str | Path) -> dict[str, Path]:
    """``tracks.npz`` (times_s, positions, quats, mu, avoiding) and ``tracks.csv`` (one row per
    control step and fish: time_s, fish, x_m, y_m, z_m, mu, avoiding), written atomically."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    npz, csv_path = out / "tracks.npz", out / "tracks.csv"
    write_npz(npz, times_s=result.times_s, positions=result.positions, quats=result.quats,
              mu=(result.mu % 4).astype(np.int8), avoiding=result.mu >= 4, tank_m=np.array(result.tank_m),
              seed=result.seed)
    T, F = result.mu.shape
    with atomic_path(csv_path) as tmp:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["time_s", "fish", "x_m", "y_m", "z_m", "mu", "avoiding"])
            for k in range(T):
                t = f"{result.times_s[k]:.6f}"
                for f in range(F):
                    x, y, z = result.positions[k, f]
                    mu = int(result.mu[k, f])
                    w.writerow([t, f, f"{x:.6f}", f"{y:.6f}", f"{z:.6f}", MU_NAMES[mu % 4], int(mu >= 4)])
    return {"npz": npz, "csv": csv_path}


# ---- drag cross-check ----------------------------------------------------------------------------


def drag_check(trials: int = 200, seed: int = 0) -> dict:
    """Compare the compiled drag callback (coast MU, ``C_D = 1``, areas of the equivalent inertia
    box, no push, no buoyancy moment) with MuJoCo's inertia-box fluid model (``density`` = water,
    ``viscosity`` 0) on ``trials`` random orientations and velocities of one fish. Returns the
    largest relative difference of the 6 generalized forces (``max |ours - mujoco| / max |mujoco|``
    per state) and the areas used."""
    rng = np.random.default_rng(seed)
    rho = FishParams().water_density_kg_m3
    spec = mujoco.MjSpec.from_file(str(model_path("fish", "fish.xml")))
    spec.nuserdata = U_FISH + FISH_BLOCK
    spec.body("fish").gravcomp = 0.0
    m = spec.compile()
    m.opt.gravity[:] = 0.0
    body = m.body("fish").id
    sv, sw = box_areas(float(m.body_mass[body]), m.body_inertia[body])
    m_fluid = spec.compile()
    m_fluid.opt.gravity[:] = 0.0
    m_fluid.opt.density = rho
    m_fluid.opt.viscosity = 0.0
    d_ours, d_mj = mujoco.MjData(m), mujoco.MjData(m_fluid)
    ud = d_ours.userdata
    ud[U_MAGIC], ud[U_N], ud[U_RHO], ud[U_CD], ud[U_CDROT] = MAGIC, 1, rho, 1.0, 1.0
    ud[U_SV : U_SV + 3] = sv
    ud[U_SW : U_SW + 3] = sw
    ud[U_FISH], ud[U_FISH + 1], ud[U_FISH + 2] = m.jnt_qposadr[0], m.jnt_dofadr[0], COAST
    worst = 0.0
    with passive_callback(COMPILED_PASSIVE):
        for _ in range(trials):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            v = rng.normal(scale=0.3, size=3)
            w = rng.normal(scale=3.0, size=3)
            for d in (d_ours, d_mj):
                d.qpos[:3] = rng.uniform(-1, 1, 3) if d is d_ours else d_ours.qpos[:3]
                d.qpos[3:7] = q
                d.qvel[:3], d.qvel[3:] = v, w
                mujoco.mj_forward(m if d is d_ours else m_fluid, d)
            ref = d_mj.qfrc_fluid
            worst = max(worst, float(np.max(np.abs(d_ours.qfrc_passive - ref)) / np.max(np.abs(ref))))
    return {"max_rel_error": worst, "trials": int(trials), "water_density_kg_m3": rho,
            "S_v_m2": [float(x) for x in sv], "S_w_m5": [float(x) for x in sw]}


# ---- the four patterns -----------------------------------------------------------------------------


@dataclass
class PatternTable:
    """Measures of the four patterns over seeds, and the orderings the paper's ratings imply."""

    rows: list[dict]
    seeds: list[int]
    duration_s: float
    n_fish: int
    checks: dict = field(default_factory=dict)

    def median(self, preset: str, key: str) -> float:
        vals = [r[key] for r in self.rows if r["preset"] == preset]
        return float(np.median(vals))

    def to_dict(self) -> dict:
        return {"seeds": self.seeds, "duration_s": self.duration_s, "fish": self.n_fish, "rows": self.rows,
                "checks": self.checks, "all_orderings_hold": all(c["holds"] for c in self.checks.values())}


def _orderings() -> list[tuple[str, str, str]]:
    """(higher, lower, measure) pairs implied by the paper's ratings (Satoi 2015 Fig. 11-12)."""
    pairs = []
    for k in BURSTINESS_MEASURES:
        pairs += [("B-D", "NB-ND", k), ("B-D", "NB-D", k), ("B-ND", "NB-ND", k)]
    for k in DIVERSITY_MEASURES:
        pairs += [("B-D", "NB-ND", k), ("B-D", "B-ND", k), ("NB-D", "NB-ND", k)]
    return pairs


def pattern_table(seeds=(0, 1, 2, 3, 4), duration_s: float = 60.0, n_fish: int = 10, progress: bool = False,
                  presets: dict[str, FishParams] | None = None) -> PatternTable:
    """Swim each pattern with each seed; check every ordering seed by seed (not on average)."""
    presets = presets or {name: load_preset(name) for name in PATTERNS}
    rows = []
    jobs = [(name, s) for s in seeds for name in PATTERNS]
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(jobs), desc="patterns", leave=False)
    for name, s in jobs:
        r = swim(presets[name], n_fish, duration_s, s)
        summary = swim_summary(r)
        summary["preset"] = name
        rows.append(summary)
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    table = PatternTable(rows, list(seeds), float(duration_s), int(n_fish))
    by = {(r["preset"], r["seed"]): r for r in rows}
    for hi, lo, k in _orderings():
        margins = [by[(hi, s)][k] - by[(lo, s)][k] for s in seeds]
        ok = all(math.isfinite(x) and x > 0 for x in margins)
        table.checks[f"{hi} > {lo} on {k}"] = {"holds": ok, "margins": [float(x) for x in margins]}
    return table


def write_swim(result: SwimResult, out_dir: str | Path, summary: dict | None = None) -> list[str]:
    """A swim's files, as ``fish swim --out`` writes them: the tracks (npz, CSV), the Fig. 7/8-style
    tracks and acceleration histogram (PNG) and the measures (``measures.json``: ``summary``, or
    :func:`swim_summary` of the swim). Atomic writes; returns the paths written."""
    from lifelike_mj.fish.figures import accel_histogram_figure, tracks_figure
    from lifelike_mj.io import write_json

    out = Path(out_dir)
    files = write_tracks(result, out)
    tracks_figure(result, out / "tracks.png")
    accel_histogram_figure(result, out / "accel_histogram.png")
    from lifelike_mj.provenance import provenance

    prov = provenance(preset=result.params.to_file_dict(), n_fish=result.n_fish, seed=int(result.seed),
                      tank_m=list(result.tank_m), duration_s=float(result.times_s[-1] - result.times_s[0]))
    write_json(out / "measures.json", {**(summary if summary is not None else swim_summary(result)), "provenance": prov})
    return [str(f) for f in (*files.values(), out / "tracks.png", out / "accel_histogram.png", out / "measures.json")]
