"""The 3D butterfly's speed (issue 15): writes benchmarks/results/butterfly3d.json and prints the table for
docs/performance.md.

Run: ``python benchmarks/bench_3d.py [--repeats 5] [--copies 64]``. Everything is measured in one run,
interleaved (each repeat measures every case once), on ``--copies`` butterflies (one ``mjData`` each) stepped
on every core by one compiled ``prange`` loop:

* **floor**: bare ``mj_step`` of the 3D model, no callback (every stage the model does not use is off in the
  model: contacts; it has no actuator, constraint, sensor or tendon);
* the same with the callback, each part alone: gravity and the joints' drive only (``none``), eq. 1 exactly
  (``exact``, the default: **the model's own step**, its physics included), eq. 1 on 48 and 144 panels per
  wing (``strip``), the quasi-steady law on 48 (``quasi_steady``);
* **evaluation**: what an evolution runs, :func:`~lifelike_mj.butterfly.flight3d.loop.fly_batch` with the shipped
  controller on a level-flight task (the default law, the network every step), paired with both floors;
* the pipeline's own profile (``mjData.timer``) of one butterfly;
* the garden: 20 butterflies flying their courses, simulated seconds per wall-clock second.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import mujoco
import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.kinematics import Kinematics
from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.stability import watching
from lifelike_mj.provenance import provenance

_step = mjabi.mj_step
_vp = mjabi.voidptr_from_int
DT = 1.0 / 1200.0


@njit(parallel=True)
def _bare(mptr, dptrs, n_steps):
    for b in prange(len(dptrs)):
        for _ in range(n_steps):
            _step(_vp(mptr), _vp(dptrs[b]))


def _datas(m, n, **kw):
    return [mj3d.setup_data(m, Kinematics(), **kw) for _ in range(n)]


def stepped(m, n_copies: int, n_steps: int, callback: bool, **kw) -> float:
    """Butterfly-steps per second of bare ``mj_step`` on ``n_copies`` datas (with or without the callback)."""
    ds = _datas(m, n_copies, **kw)
    ptrs = np.array([d._address for d in ds], dtype=np.int64)
    with passive_callback(mj3d.COMPILED_PASSIVE if callback else None), watching():
        _bare(m._address, ptrs, 2)
        t = time.perf_counter()
        _bare(m._address, ptrs, n_steps)
        return n_copies * n_steps / (time.perf_counter() - t)


def evaluation(m, ctl, n_copies: int, n_steps: int) -> float:
    """Butterfly-steps per second of the evolution's batch (the controller every step, level flight)."""
    prob = flight3d.FlightProblem3D((flight3d.level(1.5),), ctl, duration_s=n_steps * DT)
    prob._model = m
    w = np.tile(ctl.weights, (n_copies, 1))
    prob.fly(w[:2])  # compile
    t = time.perf_counter()
    recs = prob.fly(w)
    el = time.perf_counter() - t
    assert np.all(recs[:, 0, flight3d.tasks.R_STEPS] == n_steps), "a benchmark flight tumbled or diverged"
    return n_copies * n_steps / el


def profile(m) -> dict:
    """Mean microseconds per call of each pipeline stage of one butterfly, callback on (mjData.timer)."""
    d = mj3d.setup_data(m, Kinematics(), n_strips=8, n_chord=2)
    with passive_callback(mj3d.COMPILED_PASSIVE):
        mujoco.mj_step(m, d, 3000)
    out = {}
    for i in range(len(d.timer)):
        t = d.timer[i]
        if t.number:
            out[mujoco.mjtTimer(i).name.removeprefix("mjTIMER_").lower()] = t.duration / t.number * 1e6
    return out


def garden_speed(ctl, n: int, seconds: float) -> float:
    from lifelike_mj.butterfly.flight3d.garden import Garden

    g = Garden(n, ctl, seed=0)
    g.step(12)
    t = time.perf_counter()
    g.step(int(round(seconds / g.dt)))
    return seconds / (time.perf_counter() - t)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--copies", type=int, default=64)
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--controller", default=None, help="default: the (withdrawn) wind controller the table was measured with")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "butterfly3d.json"))
    args = ap.parse_args()
    m = mj3d.build_model()
    m.opt.timestep = DT
    ctl = flight3d.load_controller(args.controller or flight3d.withdrawn_file("wind"))
    cases = {
        "floor: bare mj_step": lambda: stepped(m, args.copies, args.steps, False),
        "callback, no air (drive only)": lambda: stepped(m, args.copies, args.steps, True, force_law="none"),
        "callback, eq. 1 exactly (the model's step)": lambda: stepped(m, args.copies, args.steps, True),
        "callback, eq. 1 on 48 panels": lambda: stepped(m, args.copies, args.steps, True, force_law="strip",
                                                        n_strips=8, n_chord=2),
        "callback, eq. 1 on 144 panels": lambda: stepped(m, args.copies, args.steps, True, force_law="strip",
                                                         n_strips=24, n_chord=2),
        "callback, quasi-steady on 48 panels": lambda: stepped(m, args.copies, args.steps, True,
                                                                force_law="quasi_steady", n_strips=8, n_chord=2),
        "evaluation (fly_batch, network every step)": lambda: evaluation(m, ctl, args.copies, args.steps),
        "garden, 20 butterflies (simulated s per s)": lambda: garden_speed(ctl, 20, 1.0),
    }
    runs: dict[str, list[float]] = {k: [] for k in cases}
    ratios: list[float] = []
    ratios_model: list[float] = []
    ev = "evaluation (fly_batch, network every step)"
    for _ in range(args.repeats):
        for k, f in cases.items():
            runs[k].append(f())
        ratios.append(runs["floor: bare mj_step"][-1] / runs[ev][-1])
        ratios_model.append(runs["callback, eq. 1 exactly (the model's step)"][-1] / runs[ev][-1])
    med = {k: float(np.median(v)) for k, v in runs.items()}
    result = {"provenance": provenance(**vars(args)), "machine": machine_info(), "copies": args.copies,
              "steps": args.steps, "dt_s": DT, "runs": runs, "median": med,
              "evaluation_over_floor_median": float(np.median(ratios)), "evaluation_over_floor_runs": ratios,
              "evaluation_over_model_step_median": float(np.median(ratios_model)),
              "evaluation_over_model_step_runs": ratios_model,
              "profile_us": profile(m),
              "evolution_wall_time_s": {ctl.name: ctl.provenance.get("evolution_wall_time_s")}}
    write_json(args.out, result)
    print(f"| case ({args.copies} butterflies, every core) | butterfly-steps/s (median of {args.repeats}) |")
    print("|---|---|")
    for k, v in med.items():
        unit = "" if "garden" not in k else " (x real time)"
        print(f"| {k} | {v:.3g}{unit} |")
    print(f"\nevaluation / the model's own step (paired, median): x{np.median(ratios_model):.2f}")
    print(f"evaluation / floor without the callback (paired, median): x{np.median(ratios):.2f}; "
          f"real time is {1 / DT:.0f} steps/s per butterfly")
    print("profile (us per call):", {k: round(v, 2) for k, v in result["profile_us"].items()})


if __name__ == "__main__":
    main()
