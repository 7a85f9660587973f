"""A flight's trajectory and its summary numbers, shared by both backends."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Trajectory:
    """Sampled flight: time ``t`` (s), altitude ``y`` (m, absolute), forward ``z`` (m),
    velocities ``vy``, ``vz`` (m/s, ground frame), pitch ``phi`` and flap ``theta`` (rad)."""

    t: np.ndarray
    y: np.ndarray
    z: np.ndarray
    vy: np.ndarray
    vz: np.ndarray
    phi: np.ndarray
    theta: np.ndarray
    y0: float = 0.0
    flap_period_s: float = 0.1
    backend: str = "paper"
    diverged_step: int = -1
    fitness: float = float("nan")  #: ``H`` of Oe 2010 eq. 13 over the flight (dimensionless)

    def settled(self, window_s: float = 10.0) -> np.ndarray:
        """Mask of samples in the last ``window_s`` seconds."""
        return self.t >= self.t[-1] - window_s - 1e-12

    def ripple_m(self, window_s: float = 10.0) -> float:
        """Mean peak-to-peak altitude within one flap period over the settled window, m."""
        mask = self.settled(window_s)
        t, y = self.t[mask], self.y[mask]
        cycle = np.floor((t - t[0]) / self.flap_period_s + 1e-9).astype(int)
        full = [c for c in np.unique(cycle) if np.count_nonzero(cycle == c) > 2 and (cycle == c + 1).any()]
        if not full:
            return float(np.ptp(y))
        return float(np.mean([np.ptp(y[cycle == c]) for c in full]))

    def climb_rate_m_s(self, window_s: float = 10.0) -> float:
        """Least-squares slope of altitude over the settled window, m/s."""
        mask = self.settled(window_s)
        return float(np.polyfit(self.t[mask], self.y[mask], 1)[0])

    def summary(self, window_s: float = 10.0) -> dict:
        """The numbers that ``butterfly fly --json`` reports. Altitudes are measured from the target
        altitude 0 m (which is the start altitude unless the flight starts elsewhere, section 7.1);
        the initial drop is measured from the start."""
        mask = self.settled(window_s)
        rel = self.y
        dur = self.t[-1] - self.t[0]
        return {
            "backend": self.backend,
            "duration_s": float(dur),
            "final_altitude_m": float(rel[-1]),
            "min_altitude_m": float(np.nanmin(rel)),
            "max_altitude_m": float(np.nanmax(rel)),
            "start_altitude_m": float(self.y0),
            "initial_drop_m": float(max(0.0, self.y0 - np.nanmin(rel))),
            "mean_forward_speed_cm_s": float(100.0 * (self.z[-1] - self.z[0]) / dur) if dur > 0 else 0.0,
            "settled_altitude_min_m": float(np.nanmin(rel[mask])),
            "settled_altitude_max_m": float(np.nanmax(rel[mask])),
            "settled_forward_speed_cm_s": float(100.0 * np.nanmean(self.vz[mask])),
            "settled_climb_rate_cm_s": float(100.0 * self.climb_rate_m_s(window_s)),
            "ripple_cm": float(100.0 * self.ripple_m(window_s)),
            "diverged_step": self.diverged_step,
            "fitness_H": self.fitness,
        }

    def to_npz_dict(self) -> dict:
        return {k: getattr(self, k) for k in ("t", "y", "z", "vy", "vz", "phi", "theta")}

    def to_csv(self) -> str:
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["t_s", "y_m", "z_m", "vy_m_s", "vz_m_s", "phi_deg", "theta_deg"])
        for row in zip(self.t, self.y, self.z, self.vy, self.vz, np.degrees(self.phi), np.degrees(self.theta)):
            w.writerow([f"{v:.9g}" for v in row])
        return buf.getvalue()

    def max_difference(self, other: Trajectory) -> tuple[float, float]:
        """Largest |altitude| and |forward position| differences (m) at common sample times."""
        if len(self.t) != len(other.t) or not np.allclose(self.t, other.t):
            raise ValueError("trajectories are sampled at different times")
        return float(np.max(np.abs(self.y - other.y))), float(np.max(np.abs(self.z - other.z)))

    @property
    def finite(self) -> bool:
        return bool(np.all(np.isfinite(self.y))) and not math.isnan(float(self.y[-1]))
