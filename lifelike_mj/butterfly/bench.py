"""``lifelike-mj bench butterfly``: speed of both backends, measured in one run.

* ``paper_ns_per_step``: the compiled paper backend, a batch of 40 butterflies x 24,000 steps
  (the paper's population and episode), wall time / (40 x 24,000);
* ``naive_ns_per_step``: the same model as a plain Python per-step loop;
* ``mujoco_bare_us_per_step``: ``mj_step`` (RK4) of models/butterfly.xml from a native loop,
  no callback installed;
* ``mujoco_us_per_step``: the same native loop with the compiled wing-force callback (tip-speed
  mode) and the simple-rule controller once per step; ``mujoco_strip_us_per_step`` the same with
  strip integration.

Each figure is the median of ``repeats`` runs; the variants are interleaved within each repeat so
that their ratios compare like with like on a noisy shared machine.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from numba import njit

from lifelike_mj.butterfly import controllers
from lifelike_mj.butterfly.backends import mj as mjbackend
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.flight import Condition
from lifelike_mj.machine import machine_info
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.callbacks import passive_callback

_mj_step = mjabi.mj_step
_vp = mjabi.voidptr_from_int


@njit(cache=True)
def _bare_loop(mptr, dptr, n):
    for _ in range(n):
        _mj_step(_vp(mptr), _vp(dptr))


def _time_mujoco(m, ctrl, mode: str | None, n: int) -> float:
    d = mjbackend.setup_data(m, ctrl, None, Condition(), mode or "tip")
    if mode is None:
        t0 = time.perf_counter()
        _bare_loop(m._address, d._address, n)
        return (time.perf_counter() - t0) / n
    kind, cp = ctrl.compiled()
    out = np.empty((n + 1, 6))
    div = np.full(1, -1, dtype=np.int64)
    lay = mjbackend.layout(m).as_array()
    with passive_callback(mjbackend.COMPILED_PASSIVE):
        t0 = time.perf_counter()
        mjbackend.record_steps(m._address, d._address, d.qpos, d.qvel, d.userdata, 0, n, 1, kind, cp,
                               ctrl.flap.as_array(), 0.0, lay, float(m.opt.timestep), 0.0, out, 1, div, np.zeros(1))
        return (time.perf_counter() - t0) / n


def run(repeats: int = 5, batch: int = 40, steps: int = 24000, naive_steps: int = 2400,
        mujoco_steps: int = 24000) -> dict:
    """Measure everything (see module docstring); returns a JSON-ready dict."""
    ctrl = controllers.load("simple_rule")
    dt = 1.0 / 1200.0
    m = mjbackend.build_model(None, "paper")
    m.opt.timestep = dt
    # warm up (compilation)
    paper.simulate([ctrl] * 2, duration_s=0.01, dt_s=dt)
    _time_mujoco(m, ctrl, None, 10)
    _time_mujoco(m, ctrl, "tip", 10)
    samples: dict[str, list[float]] = {k: [] for k in ("paper", "naive", "bare", "tip", "strip")}
    for _ in range(repeats):
        t0 = time.perf_counter()
        paper.simulate([ctrl] * batch, duration_s=steps * dt, dt_s=dt, record_every=steps)
        samples["paper"].append((time.perf_counter() - t0) / (batch * steps))
        t0 = time.perf_counter()
        paper.simulate_naive(ctrl, n_steps=naive_steps, dt_s=dt)
        samples["naive"].append((time.perf_counter() - t0) / naive_steps)
        samples["bare"].append(_time_mujoco(m, ctrl, None, mujoco_steps))
        samples["tip"].append(_time_mujoco(m, ctrl, "tip", mujoco_steps))
        samples["strip"].append(_time_mujoco(m, ctrl, "strip", mujoco_steps))
    med = {k: statistics.median(v) for k, v in samples.items()}
    tip_over = [t / b - 1.0 for t, b in zip(samples["tip"], samples["bare"])]
    strip_over = [t / b - 1.0 for t, b in zip(samples["strip"], samples["bare"])]
    return {
        "paper_ns_per_step": med["paper"] * 1e9,
        "naive_ns_per_step": med["naive"] * 1e9,
        "paper_speedup_vs_naive": med["naive"] / med["paper"],
        "mujoco_bare_us_per_step": med["bare"] * 1e6,
        "mujoco_us_per_step": med["tip"] * 1e6,
        "mujoco_strip_us_per_step": med["strip"] * 1e6,
        "mujoco_callback_overhead": statistics.median(tip_over),
        "mujoco_strip_callback_overhead": statistics.median(strip_over),
        "repeats": repeats,
        "batch": batch,
        "steps": steps,
        "integrator": "RK4",
        "dt_s": dt,
        "machine": machine_info(),
        "samples": {k: [x * 1e9 for x in v] for k, v in samples.items()},
    }
