"""Boids experiments: one classified run, trajectories on disk, and parameter sweeps on the project's
evaluator (serial, process pool or Ray: ``lifelike_mj.evolve.make_evaluator``).

A sweep is a :class:`Sweep`: a picklable problem whose rows are ``(value_1, ..., value_m, seed)``
and whose ``evaluate`` runs each row and returns :data:`OUTPUTS` (the pattern label's code and the
measures that decide it), so the same seed gives the same table on every executor.
"""

from __future__ import annotations

import csv
import hashlib
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.boids.engine import N_AGENTS, BoidParams, BoidRun
from lifelike_mj.boids.metrics import HOMOGENEOUS_LABELS
from lifelike_mj.boids.presets import PATTERNS
from lifelike_mj.boids.sim import simulate
from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path, write_npz

#: Labels a run can get: the eight patterns, ``other``, and ``diverged``.
#: Labels of two-type runs (the eight patterns), then of one-type runs (Fig. 2's regimes).
TWO_TYPE_LABELS = (*PATTERNS, "other", "diverged")
LABELS = (*TWO_TYPE_LABELS, *HOMOGENEOUS_LABELS)
#: What a sweep row returns, in this order.
OUTPUTS = ("label", "paper_picture", "segregation_index", "centroid_distance", "radius_ratio",
           "radial_sorting_error", "plane_split", "n_groups", "polarisation", "speed")


def run_settings() -> dict:
    """Run length, measuring window and recording interval of a classified run (boids/metrics.py)."""
    from lifelike_mj.boids import metrics

    return {"n_steps": metrics.RUN_STEPS, "window": metrics.WINDOW_STEPS, "record_every": metrics.RECORD_EVERY}


def classified_run(params: BoidParams, n: int = N_AGENTS, seed: int = 0, n_steps: int | None = None,
                   trail_steps: int = 5, progress: bool = False,
                   record_every: int | None = None) -> tuple[BoidRun, dict, str, object]:
    """Run, measure over the late window and classify. The run records every ``record_every`` steps of
    the classifier (:func:`run_settings`) over the window and every step over the last ``trail_steps``
    (for the paper-style figure). Returns ``(run, measures, label, reasons)``.

    ``record_every=K`` keeps the whole run instead: every ``K``-th step from step 0, as well as the
    classifier's frames, which alone are measured (so the measures and the label do not depend on ``K``).
    """
    from lifelike_mj.boids import metrics

    s = run_settings()
    steps = int(n_steps or s["n_steps"])
    window = min(s["window"], steps)
    trail = range(steps - trail_steps, steps + 1)
    if record_every is None:
        run = simulate(params, n, steps, seed, record_every=s["record_every"], record_from=steps - window,
                       progress=progress, extra_steps=trail)
        measured = run
    else:
        classifier = sorted(set(range(steps - window, steps + 1, s["record_every"])) | set(trail))
        run = simulate(params, n, steps, seed, record_every=checks.whole("record_every", record_every, 1),
                       record_from=0, progress=progress, extra_steps=classifier)
        keep = np.isin(run.steps, classifier)
        measured = replace(run, steps=run.steps[keep], positions=run.positions[keep], velocities=run.velocities[keep])
    m = metrics.measures(measured, window=window)
    label, reasons = metrics.classify(m) if params.n_types > 1 else metrics.classify_homogeneous(m)
    return run, m, label, reasons


def write_trajectories(run: BoidRun, out_dir: str | Path) -> dict[str, Path]:
    """``trajectories.npz`` (steps, positions, velocities, types) and a tidy ``trajectories.csv``
    (step, agent, type, x, y, z, vx, vy, vz; z and vz are 0 in 2D), written atomically."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    npz, path = out / "trajectories.npz", out / "trajectories.csv"
    write_npz(npz, steps=run.steps, positions=run.positions, velocities=run.velocities, types=run.types,
              seed=run.seed, box=run.params.box)
    T, n, D = run.positions.shape
    with atomic_path(path) as tmp:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["step", "agent", "type", "x", "y", "z", "vx", "vy", "vz"])
            for k in range(T):
                for i in range(n):
                    p = list(run.positions[k, i]) + [0.0] * (3 - D)
                    v = list(run.velocities[k, i]) + [0.0] * (3 - D)
                    w.writerow([int(run.steps[k]), i, int(run.types[i])] + [f"{a:.6f}" for a in p + v])
    return {"npz": npz, "csv": path}


# ---- sweeps ------------------------------------------------------------------------------------------

_AXES_HELP = ("wa_cross / wc_cross (both off-diagonal entries, symmetric), wa_IJ / wc_IJ (one entry, e.g. wa_01), "
              "wa / wc (every entry: a homogeneous weight)")


def apply_axis(params: BoidParams, axis: str, value: float) -> BoidParams:
    """``params`` with one swept quantity set (see :data:`_AXES_HELP`)."""
    if axis not in ("wa", "wc", "wa_cross", "wc_cross") and not (
            len(axis) == 5 and axis[:3] in ("wa_", "wc_") and axis[3:].isdigit()):
        raise UserError(f"unknown sweep axis {axis!r}; use {_AXES_HELP}.")
    key = axis[:2]
    m = np.array(getattr(params, key), dtype=float)
    k = m.shape[0]
    if axis in ("wa", "wc"):
        m[:] = value
    elif axis.endswith("cross"):
        if k != 2:
            raise UserError(f"{axis} needs two types, the matrix has {k}.")
        m[0, 1] = m[1, 0] = value
    else:
        i, j = int(axis[3]), int(axis[4])
        if i >= k or j >= k:
            raise UserError(f"{axis} is outside the {k}x{k} matrix.")
        m[i, j] = value
    return replace(params, **{key: tuple(map(tuple, m.tolist()))})


@dataclass(frozen=True)
class Sweep:
    """A grid of runs as an ``evolve`` problem with several outputs per row (rows: axis values, then
    the seed). ``evaluate`` is pure and deterministic, so serial, process and Ray runs agree."""

    base: BoidParams
    axes: tuple[str, ...]
    n: int = N_AGENTS
    n_steps: int | None = None

    @property
    def dim(self) -> int:
        return len(self.axes) + 1

    @property
    def lower(self) -> np.ndarray:
        return np.full(self.dim, -np.inf)

    @property
    def upper(self) -> np.ndarray:
        return np.full(self.dim, np.inf)

    maximize = True
    n_outputs = len(OUTPUTS)

    def fingerprint(self) -> str:
        text = json.dumps({"base": repr(self.base), "axes": self.axes, "n": self.n, "steps": self.n_steps})
        return "boids-sweep:" + hashlib.sha256(text.encode()).hexdigest()[:16]

    def check_cells(self, values: list[list[float]]) -> None:
        """Build every cell's parameters once, so that a bad axis or weight is a :class:`UserError` before
        any run starts."""
        import itertools

        for cell in itertools.product(*values):
            self.params_of([*cell, 0])

    def params_of(self, row) -> BoidParams:
        p = self.base
        for axis, value in zip(self.axes, row[:-1]):
            p = apply_axis(p, axis, float(value))
        return p

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        out = np.full((len(X), len(OUTPUTS)), np.nan)
        for r, row in enumerate(np.atleast_2d(X)):
            try:
                _, m, label, reasons = classified_run(self.params_of(row), self.n, int(row[-1]), self.n_steps)
            except UserError as exc:
                if "diverged" not in str(exc):
                    raise
                out[r, 0] = LABELS.index("diverged")
                continue
            out[r, 0] = LABELS.index(label)
            out[r, 1] = 1.0 if reasons.get("paper_picture") else 0.0
            for c, key in enumerate(OUTPUTS[2:], start=2):
                val = m.get(key, np.nan)
                out[r, c] = float(val) if isinstance(val, (int, float)) else np.nan
        return out


def run_sweep(sweep: Sweep, values: list[list[float]], seeds, executor: str = "process", workers: int | None = None,
              ray_address: str | None = None, bar=None) -> dict:
    """Evaluate every combination of ``values`` (one list per axis) and ``seeds``; returns the rows
    (one per combination and seed) and, per grid cell, the most frequent label. ``bar`` (a
    :func:`~lifelike_mj.progress.bar`): counts the runs done, the rows being handed to the executor in about ten
    batches (each row's run depends on the row alone, so the batches change no result)."""
    import itertools

    from lifelike_mj.evolve import make_evaluator

    grid = list(itertools.product(*values))
    rows = np.array([[*g, s] for g in grid for s in seeds], dtype=float)
    sweep.check_cells(values)
    with make_evaluator(sweep, executor=executor, workers=workers, ray_address=ray_address) as ev:
        if bar is None:
            res = ev(rows)
        else:
            chunk = max(1, -(-len(rows) // 10))
            res = []
            for k in range(0, len(rows), chunk):
                res.extend(ev(rows[k : k + chunk]))
                bar.update(len(rows[k : k + chunk]))
    table = []
    for row, r in zip(rows, res):
        d = {a: float(v) for a, v in zip(sweep.axes, row[:-1])}
        d["seed"] = int(row[-1])
        d["label"] = LABELS[int(r[0])]
        d["paper_picture"] = bool(r[1] == 1.0)
        d.update({k: (None if np.isnan(x) else float(x)) for k, x in zip(OUTPUTS[2:], r[2:])})
        table.append(d)
    cells = {}
    for g in grid:
        labs = [t["label"] for t in table if tuple(t[a] for a in sweep.axes) == tuple(float(x) for x in g)]
        cells[g] = max(set(labs), key=lambda lab: (labs.count(lab), -LABELS.index(lab)))
    return {"axes": list(sweep.axes), "values": [list(map(float, v)) for v in values], "seeds": list(seeds),
            "rows": table, "majority": {",".join(f"{x:g}" for x in g): lab for g, lab in cells.items()}}


def write_sweep(result: dict, sweep: Sweep, values: list[list[float]], out_dir: str | Path) -> list[str]:
    """A sweep's files, as ``boids sweep --out`` writes them: ``sweep.json`` (the result of
    :func:`run_sweep`) and, for two axes, ``phase_diagram.png`` (majority label per cell). Atomic."""
    from lifelike_mj.io import write_json

    out = Path(out_dir)

    from lifelike_mj.provenance import provenance

    prov = provenance(base=_settings(sweep.base), axes=list(sweep.axes), values=[list(map(float, v)) for v in values], n=sweep.n,
                      steps=sweep.n_steps)
    files = [write_json(out / "sweep.json", {**result, "provenance": prov})]
    if len(values) == 2:
        from lifelike_mj.boids.figures import phase_diagram_figure

        labels = np.array([[result["majority"][f"{a:g},{b:g}"] for a in values[0]] for b in values[1]])
        seeds = sorted({int(r["seed"]) for r in result["rows"]})
        base = "one type" if sweep.base.n_types == 1 else f"base {sweep.base.name}"
        title = (f"Classified patterns over {sweep.axes[0]} x {sweep.axes[1]}: {base}, n = {sweep.n}, "
                 f"{sweep.n_steps or run_settings()['n_steps']} steps; majority over seeds {', '.join(map(str, seeds))}")
        phase_diagram_figure(labels, values[0], values[1], sweep.axes[0], sweep.axes[1], out / "phase_diagram.png",
                             title=title)
        files.append(out / "phase_diagram.png")
    return [str(f) for f in files]


def measured_run(params: BoidParams, n: int = N_AGENTS, seed: int = 0, n_steps: int | None = None,
                 progress: bool = False, record_every: int | None = None) -> tuple[BoidRun, dict]:
    """:func:`classified_run` as ``boids run`` reports it: ``(run, result)`` with ``result`` holding the
    label, the classifier's reasons, every measure, and the run's settings and wall time."""
    run, m, label, reasons = classified_run(params, n, seed, n_steps, progress=progress, record_every=record_every)
    result = {"label": label, "reasons": reasons, **m, "preset": params.name, "n": n, "seed": seed,
              "steps": int(run.steps[-1]), "dims": params.dims, "wall_time_s": run.wall_time_s}
    return run, result


def _settings(params: BoidParams) -> dict:
    """Every setting of ``params``, the matrices under the paper's names W_a and W_c."""
    from dataclasses import asdict

    return {{"wa": "W_a", "wc": "W_c"}.get(k, k): v for k, v in asdict(params).items()}


def run_provenance(run: BoidRun) -> dict:
    """Everything that made ``run``: the matrices (Nakamura 2013 eq. 1-3), zones, weights, box, agents,
    seed and steps recorded, with the package version and the command."""

    from lifelike_mj.provenance import provenance

    return provenance(**_settings(run.params),
                      n=int(run.positions.shape[1]), seed=int(run.seed), steps=int(run.steps[-1]),
                      recorded_steps=int(len(run.steps)))


def write_run(run: BoidRun, result: dict, out_dir: str | Path) -> list[str]:
    """A run's files, as ``boids run --out`` writes them: the trajectories (npz, CSV) and
    ``measures.json`` (``result`` of :func:`measured_run`). Atomic; returns the trajectory files."""
    from lifelike_mj.io import write_json

    files = write_trajectories(run, out_dir)
    write_json(Path(out_dir) / "measures.json", {**result, "provenance": run_provenance(run)})
    return [str(f) for f in files.values()]
