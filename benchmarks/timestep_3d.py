"""The time step the 3D butterfly needs: open-loop flights and the shipped controllers' task scores against the time
step (1/2400 to 1/200 s) and MuJoCo's integrator (RK4, implicitfast, Euler) (issue 26).

Run: ``python benchmarks/timestep_3d.py`` (about 10 minutes on 2 cores). Writes
``benchmarks/results/timestep_3d.json`` and ``docs/figures/timestep_3d.png``.

* **Open loop**: the paper's 10 Hz flap (the shipped controllers' base command, no controller), from rest, for
  ``OPEN_S`` seconds; the thorax's path compared with the same flight at 1/4800 s with RK4 (the reference), every
  1/100 s. Criterion: the largest distance from the reference path, divided by the flight's length in seconds,
  at most 1 mm per second.
* **Closed loop**: each shipped controller's fitness on its own task set (the evolution's score, mean reward per
  second in [0, 1]) at each step and integrator. The controllers run their network every time step, so a larger
  step also runs it less often. Criterion: every fitness within the spread that the butterfly's own flutter makes
  at 1/1200 s with RK4 (the standard deviation over ``FLUTTER_SEEDS`` flutter seeds of 0.1).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj.butterfly import flight3d
from lifelike_mj.errors import Diverged
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

STEPS = [Fraction(1, n) for n in (2400, 1200, 800, 600, 400, 300, 200)]
INTEGRATORS = {"RK4": mujoco.mjtIntegrator.mjINT_RK4, "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               "Euler": mujoco.mjtIntegrator.mjINT_EULER}
REFERENCE = (Fraction(1, 4800), "RK4")
OPEN_S = 1.0
SAMPLE_S = 0.01
CONTROLLERS = ("steer", "wind")
FLUTTER_SEEDS = range(5)
MM_PER_S = 1.0


def _model(integrator: str):
    m = flight3d.build_model()
    m.opt.integrator = INTEGRATORS[integrator]
    return m


def open_loop(dt: Fraction, integrator: str) -> np.ndarray:
    """The thorax's positions (m) every ``SAMPLE_S`` of an open-loop flight; NaN once it diverged."""
    base = flight3d.controllers.default_base()
    f = flight3d.Flight3D(base, dt_s=float(dt), _model=_model(integrator))
    every = int(round(SAMPLE_S / float(dt)))
    rows = [f.state()["position_m"]]
    try:
        for _ in range(int(round(OPEN_S / SAMPLE_S))):
            f.step(every)
            rows.append(f.state()["position_m"])
    except Exception:  # a diverged flight: the rest is NaN
        rows += [np.full(3, np.nan)] * (int(round(OPEN_S / SAMPLE_S)) + 1 - len(rows))
    return np.array(rows)


def fitness(name: str, dt: Fraction, integrator: str, flutter: float = 0.0, seed: int = 0) -> float:
    ctl = flight3d.load_controller(flight3d.withdrawn_file(name))  # the (since withdrawn) swallowtail controllers
    tasks = tuple(replace(t, flutter=flutter, seed=seed) if flutter else t for t in flight3d.TASK_SETS[name]())
    p = flight3d.FlightProblem3D(tasks, ctl, duration_s=4.0, dt_s=float(dt))
    p._model = _model(integrator)
    p._model.opt.timestep = float(dt)
    return float(p.evaluate(np.zeros((1, p.dim)))[0])


def cost(dt: Fraction, integrator: str, n: int = 20, seconds: float = 2.0) -> float | None:
    """Seconds of wall time per second of flight of a garden of ``n`` (median of 3), this machine."""
    g = flight3d.Garden(n, str(flight3d.withdrawn_file("steer")), seed=1, dt_s=float(dt))
    g._phys.opt.integrator = INTEGRATORS[integrator]
    steps = int(round(seconds / float(dt)))
    walls = []
    try:
        g.step(10)
        for _ in range(3):
            t = time.perf_counter()
            g.step(steps)
            walls.append(time.perf_counter() - t)
    except Diverged:
        return None
    return float(np.median(walls)) / seconds


def figure(out: dict, path: Path, chosen: str | None = None) -> None:
    from lifelike_mj.render.plot import new_figure, save

    fig = new_figure(10, 3.8)
    a, b = fig.subplots(1, 2)
    x = [1.0 / float(Fraction(s)) for s in out["steps"]]
    styles = {"RK4": ("o-", None), "implicitfast": ("s--", 9), "Euler": ("x:", None)}
    for name, rows in out["open_loop_mm_per_s"].items():
        a.semilogy(x, [v if v is not None else np.nan for v in rows], styles[name][0], ms=styles[name][1],
                   label=name + (" (= Euler here)" if name == "implicitfast" else ""))
    a.axhline(MM_PER_S, color="k", lw=0.8, ls="--")
    a.set_ylabel("path error (mm per s of flight)")
    a.set_title(f"open loop, {OPEN_S:g} s, against 1/4800 s RK4 (missing: diverged)", fontsize=10)
    a.legend(fontsize=8)
    colours = dict(zip(out["fitness"], ("C0", "C3", "C2")))
    i1200 = out["steps"].index("1/1200")
    for name, per in out["fitness"].items():
        ref, sd = per["RK4"][i1200], out["flutter_spread"][name][1]
        b.axhspan(ref - sd, ref + sd, color=colours[name], alpha=0.12)
        for integ, rows in per.items():
            b.plot(x, rows, styles[integ][0], color=colours[name], ms=styles[integ][1] or 5,
                   alpha=1.0 if integ == "RK4" else 0.5, label=f"{name} {integ}")
    b.set_ylabel("fitness on its own task set")
    b.set_title("closed loop (bands: 1/1200 s RK4 +- the flutter's spread)", fontsize=10)
    b.legend(fontsize=6, ncol=3, loc="lower right")
    for ax in (a, b):
        ax.set_xscale("log")
        ax.set_xticks(x, [str(round(v)) for v in x])
        ax.minorticks_off()
        ax.set_xlabel("steps per second (1/dt)")
        if chosen:
            ax.axvline(1.0 / float(Fraction(chosen)), color="k", lw=0.8, alpha=0.5)
    save(fig, path)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = Path(__file__).resolve().parents[1]
    ap.add_argument("--out", default=str(root / "benchmarks" / "results" / "timestep_3d.json"))
    ap.add_argument("--figure", default=str(root / "docs" / "figures" / "timestep_3d.png"))
    ap.add_argument("--no-cost", action="store_true", help="skip the garden's wall-time measurement (a busy machine)")
    args = ap.parse_args()
    ref = open_loop(*REFERENCE)
    out: dict = {"steps": [str(s) for s in STEPS], "reference": [str(REFERENCE[0]), REFERENCE[1]],
                 "open_loop_s": OPEN_S, "criterion_mm_per_s": MM_PER_S, "open_loop_mm_per_s": {}, "fitness": {},
                 "flutter_spread": {}, "garden_cost_s_per_s": {}}
    for integ in INTEGRATORS:
        row = []
        for dt in STEPS:
            path = open_loop(dt, integ)
            err = float(np.max(np.linalg.norm(path - ref, axis=1))) if np.isfinite(path).all() else None
            row.append(None if err is None else 1000.0 * err / OPEN_S)
        out["open_loop_mm_per_s"][integ] = row
        print(integ, "open loop mm/s:", ["-" if v is None else f"{v:.3g}" for v in row], flush=True)
    for name in CONTROLLERS:
        spread = [fitness(name, Fraction(1, 1200), "RK4", 0.1, s) for s in FLUTTER_SEEDS]
        out["flutter_spread"][name] = [float(np.mean(spread)), float(np.std(spread))]
        out["fitness"][name] = {integ: [fitness(name, dt, integ) for dt in STEPS] for integ in INTEGRATORS}
        print(name, "spread", out["flutter_spread"][name], "fitness", out["fitness"][name], flush=True)
    for integ in INTEGRATORS:
        out["garden_cost_s_per_s"][integ] = [None if args.no_cost else cost(dt, integ) for dt in STEPS]
    ok = []
    for j, dt in enumerate(STEPS):
        for integ in INTEGRATORS:
            e = out["open_loop_mm_per_s"][integ][j]
            closed = all(abs(out["fitness"][n][integ][j] - out["fitness"][n]["RK4"][1]) <= out["flutter_spread"][n][1]
                         for n in CONTROLLERS)
            if e is not None and e <= MM_PER_S and closed:
                ok.append((float(dt), integ, out["garden_cost_s_per_s"][integ][j]))
    out["meets_both"] = [[f"1/{round(1 / d)}", i, c] for d, i, c in ok]
    rk4 = [d for d, i, _ in ok if i == "RK4"]
    out["largest_rk4_step_meeting_both"] = f"1/{round(1 / max(rk4))}" if rk4 else None
    out["cheapest_meeting_both"] = min(out["meets_both"], key=lambda r: (r[2] or 0.0, -1.0 / float(Fraction(r[0]))))\
        if ok else None
    write_json(args.out, {"provenance": provenance(**vars(args)), "machine": machine_info(), **out})
    figure(out, Path(args.figure), out["largest_rk4_step_meeting_both"])
    print("meets both:", out["meets_both"])
    print("cheapest:", out["cheapest_meeting_both"])


if __name__ == "__main__":
    main()
