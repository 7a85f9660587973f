"""Batches of planar flights on either backend: above the stepper (:class:`~lifelike_mj.butterfly.sim.Flight`),
which a compiled MuJoCo flight is.

``simulate(backend, controllers, params, conditions, duration_s, dt_s, record_every)`` returns a list of
:class:`~lifelike_mj.butterfly.flight.Trajectory`, sampled every ``record_every`` steps from ``t = 0``, whatever
the backend (:mod:`~lifelike_mj.butterfly.backends.paper`: the paper's equations, batched;
:mod:`~lifelike_mj.butterfly.backends.mj`: the MuJoCo model).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lifelike_mj.butterfly.backends import check_backend
from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import Condition, Trajectory, check_timing
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

if TYPE_CHECKING:
    import mujoco


def simulate(backend: str, controllers, params=None, conditions=None, duration_s: float = 20.0,
             dt_s: float = 1.0 / 1200.0, record_every: int = 1, **options):
    """Fly on the named backend. ``options`` go to the MuJoCo backend (``config``, ``force_mode``)."""
    check_backend(backend)
    if backend == "paper":
        from lifelike_mj.butterfly.backends import paper

        return paper.simulate(controllers, params, conditions, duration_s, dt_s, record_every)
    return simulate_mujoco(controllers, params, conditions, duration_s, dt_s, record_every, **options)


def fly_one(m: mujoco.MjModel, controller: ButterflyController, params: ButterflyParams | None = None,
            condition: Condition | None = None, duration_s: float = 20.0, record_every: int = 1,
            force_mode: str = "tip", n_strips: int = 16, callback: str = "compiled") -> Trajectory:
    """Fly one butterfly on model ``m`` (its timestep is the step). ``callback``: ``compiled`` (a
    :class:`~lifelike_mj.butterfly.sim.Flight` on this model) or ``python`` (the Python reference)."""
    from lifelike_mj.butterfly.backends.mj import _run_python, setup_data
    from lifelike_mj.butterfly.model import layout
    from lifelike_mj.butterfly.sim import Flight

    cond = condition or Condition()
    dt = float(m.opt.timestep)
    check_timing(duration_s, dt, record_every)
    if callback == "compiled":
        config = "rich" if layout(m).rich else "paper"
        flight = Flight(controller, params, cond, backend="mujoco", config=config, force_mode=force_mode, dt_s=dt,
                        n_strips=n_strips, _model=m)
        return flight.record(duration_s=duration_s, every=record_every)
    if callback != "python":
        raise UserError(f"unknown callback kind {callback!r}; choose compiled or python.")
    n_steps = check_timing(duration_s, dt, record_every)
    d = setup_data(m, controller, params, cond, force_mode, n_strips)
    lay = layout(m)
    n_rec = n_steps // record_every + 1
    out = np.empty((n_rec, 6))
    out[0] = (d.qpos[lay.q_height], d.qpos[lay.q_forward], 0.0, 0.0, 0.0, d.qpos[lay.q_flap_left])
    diverged = np.full(1, -1, dtype=np.int64)
    fit = np.zeros(1)
    _run_python(m, d, n_steps, record_every, controller, cond, lay, dt, out, diverged, fit)
    t = np.arange(n_rec) * (record_every * dt)
    return Trajectory(t=t, y=out[:, 0], z=out[:, 1], vy=out[:, 2], vz=out[:, 3], phi=out[:, 4], theta=out[:, 5],
                      y0=cond.y0_m, flap_period_s=1.0 / controller.flap.frequency_hz, backend="mujoco",
                      diverged_step=int(diverged[0]), fitness=float(fit[0]))


def simulate_mujoco(controllers, params=None, conditions=None, duration_s: float = 20.0, dt_s: float = 1.0 / 1200.0,
             record_every: int = 1, config: str = "paper", force_mode: str = "tip", n_strips: int = 16,
             callback: str = "compiled") -> list[Trajectory]:
    """Fly a batch (one after another) on the MuJoCo backend; same interface as ``paper.simulate``."""
    from lifelike_mj.butterfly.model import build_model, check_config

    check_config(config, force_mode)
    ctrls = [controllers] if isinstance(controllers, ButterflyController) else list(controllers)
    ps = [params] if params is None or isinstance(params, ButterflyParams) else list(params)
    cs = [conditions] if conditions is None or isinstance(conditions, Condition) else list(conditions)
    n = max(len(ctrls), len(ps), len(cs))
    if any(len(x) not in (1, n) for x in (ctrls, ps, cs)):
        raise UserError("batch sizes disagree between controllers, parameters and conditions.")
    ctrls, ps, cs = (x * n if len(x) == 1 else x for x in (ctrls, ps, cs))
    check_timing(duration_s, dt_s, record_every)
    models: dict = {}
    out = []
    for c, p, cond in zip(ctrls, ps, cs):
        key = p or ButterflyParams()
        if key not in models:
            models[key] = build_model(key, config)
            models[key].opt.timestep = dt_s
        out.append(fly_one(models[key], c, key, cond, duration_s, record_every, force_mode, n_strips, callback))
    return out
