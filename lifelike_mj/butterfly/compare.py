"""Comparison run: one controller and set of conditions flown on both backends (issue: E-compare).

The paper-equivalent MuJoCo configuration (light wings, planar joints, tip-speed force) must
reproduce the paper backend; the rich configuration (free body, realistic wing mass, strip
integration) shows what the paper's simplifications cost.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lifelike_mj.butterfly import batch
from lifelike_mj.butterfly.backends import DEFAULT_FORCE_MODE, paper
from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import Condition, Trajectory
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError


@dataclass(frozen=True)
class CompareResult:
    """Largest differences (m) between the two backends over the whole flight."""

    config: str
    force_mode: str
    duration_s: float
    dt_s: float
    max_altitude_diff_m: float
    max_forward_diff_m: float
    max_altitude_excursion_m: float  # of the paper backend: max |y - y0|
    paper: dict
    mujoco: dict
    trajectories: tuple[Trajectory, Trajectory] | None = None

    @property
    def altitude_diff_fraction(self) -> float:
        return self.max_altitude_diff_m / self.max_altitude_excursion_m if self.max_altitude_excursion_m else 0.0

    def to_dict(self) -> dict:
        return {
            "config": self.config,
            "force_mode": self.force_mode,
            "duration_s": self.duration_s,
            "dt_s": self.dt_s,
            "max_altitude_diff_m": self.max_altitude_diff_m,
            "max_forward_diff_m": self.max_forward_diff_m,
            "max_altitude_excursion_m": self.max_altitude_excursion_m,
            "altitude_diff_fraction_of_excursion": self.altitude_diff_fraction,
            "paper": self.paper,
            "mujoco": self.mujoco,
        }


def compare(controller: ButterflyController, config: str = "paper", params: ButterflyParams | None = None,
            condition: Condition | None = None, duration_s: float = 20.0, dt_s: float = 1.0 / 1200.0,
            force_mode: str | None = None) -> CompareResult:
    """Fly ``controller`` on both backends and report the largest differences over the flight."""
    if config not in DEFAULT_FORCE_MODE:
        raise UserError(f"unknown configuration {config!r}; choose paper or rich.")
    mode = force_mode or DEFAULT_FORCE_MODE[config]
    p = params or ButterflyParams()
    cond = condition or Condition()
    ref = paper.simulate(controller, p, cond, duration_s, dt_s)[0]
    mj = batch.simulate_mujoco(controller, p, cond, duration_s, dt_s, config=config, force_mode=mode)[0]
    dy, dz = ref.max_difference(mj)
    excursion = float(np.nanmax(np.abs(ref.y - ref.y0)))
    return CompareResult(config, mode, duration_s, dt_s, dy, dz, excursion, ref.summary(), mj.summary(), (ref, mj))
