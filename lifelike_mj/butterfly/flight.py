"""The vocabulary both butterfly backends share (Oe 2010 sections 5-6): a flight's conditions, its
time step, the pitch laws run once per step, the fitness term of eq. 13, and the trajectory.

* :class:`Condition`: start altitude (m) and wind (m/s, named by where it comes from);
* :func:`check_timing`: duration and time step checked, the number of steps;
* :func:`pitch_command`: the compiled pitch laws (``constant``, ``simple_rule``, ``ann``);
* :class:`PitchObservation`: what a pitch law of your own sees (the six inputs of section 6,
  named, SI units, plus time and the air's velocity);
* :func:`fitness_term`: one step's term of eq. 13;
* :class:`Trajectory`: a sampled flight and its summary numbers.

Importing this module does not import MuJoCo.
"""

from __future__ import annotations

import csv
import functools
import io
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from lifelike_mj import checks
from lifelike_mj.butterfly.ann import ann_pitch, mlp_pitch
from lifelike_mj.butterfly.controllers import KIND_ANN, KIND_MLP, KIND_SIMPLE_RULE, OMEGA_EPS
from lifelike_mj.errors import UserError

#: Bounds of a flight's conditions: start altitudes within +-1 km, winds within +-50 m/s (a storm;
#: the paper's winds are within +-3 m/s).
MAX_ALTITUDE_M = 1000.0
MAX_WIND_M_S = 50.0


@dataclass(frozen=True, init=False)
class Condition:
    """Conditions of one flight: the start altitude ``y0_m`` (m) and the wind ``wind_from_m_s = (a, b)`` (m/s,
    where it comes from: ``a > 0`` from ahead, ``b > 0`` from above). ``wind_to_m_s`` gives the same wind as where
    it blows to (the air's velocity, forward and up; also readable); ``wind_m_s`` is the older spelling of
    ``wind_from_m_s`` (taken this release, with a note). Positionally: ``Condition(y0_m, wind_from_m_s)``."""

    y0_m: float = 0.0
    wind_from_m_s: tuple[float, float] = (0.0, 0.0)

    def __init__(self, y0_m: float = 0.0, wind_from_m_s: tuple[float, float] | None = None, *,
                 wind_to_m_s: tuple[float, float] | None = None, wind_m_s: tuple[float, float] | None = None) -> None:
        if wind_to_m_s is None and wind_m_s is None:
            w = (0.0, 0.0) if wind_from_m_s is None else wind_from_m_s
        else:
            w = tuple(0.0 - v for v in checks.one_wind("Condition", wind_to_m_s, wind_from_m_s, wind_m_s, "from", n=2))
        object.__setattr__(self, "y0_m", y0_m)
        object.__setattr__(self, "wind_from_m_s", w)
        self.__post_init__()

    def __post_init__(self) -> None:
        checks.number("the start altitude y0", self.y0_m, -MAX_ALTITUDE_M, MAX_ALTITUDE_M, unit="m")
        w = self.wind_from_m_s
        if not (isinstance(w, (tuple, list)) and len(w) == 2):
            raise UserError(f"the wind must be two numbers (a, b) in m/s, got {w!r}.")
        for name, v in zip(("a", "b"), w):
            checks.number(f"the wind component {name}", v, -MAX_WIND_M_S, MAX_WIND_M_S, unit="m/s")

    @property
    def wind_to_m_s(self) -> tuple[float, float]:
        """The wind as where it blows to (m/s, forward and up): the air's velocity."""
        return self.air_velocity()

    @property
    def wind_m_s(self) -> tuple[float, float]:
        """The older name of :attr:`wind_from_m_s` (with a note)."""
        checks.renamed("Condition.wind_m_s", "Condition.wind_from_m_s", "where the wind comes from")
        return self.wind_from_m_s

    def air_velocity(self) -> tuple[float, float]:
        """Air velocity (forward, up) in m/s: ``-(a, b)`` (docs/models/butterfly.md)."""
        return (-float(self.wind_from_m_s[0]), -float(self.wind_from_m_s[1]))


def check_timing(duration_s: float, dt_s: float, record_every: int = 1) -> int:
    """Validate duration and step; return the number of steps."""
    if not (math.isfinite(duration_s) and duration_s > 0):
        raise UserError(f"duration must be a positive number of seconds, got {duration_s}.")
    if not (math.isfinite(dt_s) and 0 < dt_s <= 0.1):
        raise UserError(f"time step must be in (0, 0.1] s, got {dt_s}.")
    if record_every < 1:
        raise UserError("record_every must be at least 1.")
    steps = checks.work(f"a flight of {duration_s:g} s at a time step of {dt_s:g} s", checks.steps_of(duration_s, dt_s),
                        checks.MAX_BODY_STEPS, "time steps", "a shorter flight or a larger time step")
    checks.work(f"recording a flight of {steps:,} steps every {record_every} steps", steps / record_every,
                checks.MAX_RECORD_ROWS, "rows", "a shorter flight, a larger time step or recording less often")
    return int(round(duration_s / dt_s))


@njit(cache=True, inline="always")
def pitch_command(kind, cparams, t, theta, omega, y, z, vy, vz, air_y, air_z, phi_prev):
    """Pitch ``phi`` (rad) chosen once per step by the compiled controller ``kind``: flap angle
    ``theta`` (rad) and rate ``omega`` (rad/s), altitude ``y`` (relative to the target altitude 0 m;
    the start altitude of a :class:`Condition` only sets the initial state) and forward
    position ``z`` (m), ground velocities ``vy``, ``vz`` and air velocity ``air_y``, ``air_z`` (m/s),
    previous pitch ``phi_prev`` (rad)."""
    if kind == KIND_SIMPLE_RULE:
        return cparams[0] if omega > OMEGA_EPS else cparams[1]
    if kind == KIND_ANN:
        return ann_pitch(cparams, theta, omega, y, vy, vz, air_y, air_z, phi_prev)
    if kind == KIND_MLP:
        return mlp_pitch(cparams, theta, omega, y, vy, vz, air_y, air_z, phi_prev)
    return cparams[0]  # KIND_CONSTANT


@njit(cache=True, inline="always", error_model="numpy")
def fitness_term(y_rel, vz):
    """One step's term of the fitness ``H`` of Oe 2010 eq. 13: ``(v_z/3) 0.1/(|y| + 0.1)``, with the
    ground forward speed ``v_z`` (m/s) and the altitude ``y`` (m) measured from the target altitude 0 m
    (the paper's start altitude; section 7.1 keeps the target at 0 m when the start changes)."""
    return vz / 3.0 * 0.1 / (abs(y_rel) + 0.1)


class PitchObservation(NamedTuple):
    """What a pitch law sees once per step (Oe 2010 section 6: the network's six inputs, named, in SI
    units; plus the time and the air's velocity). Velocities are ground velocities; the air-relative
    ones are ``climb_m_s - air_up_m_s`` and ``forward_m_s - air_forward_m_s`` (section 7.2).

    A pitch law of your own is a function ``law(obs) -> pitch`` (rad); a numba ``@njit`` function of
    the same signature runs inside the compiled stepping loops (``obs`` is then a numba named tuple).
    """

    t_s: float  #: time of the step's start, s
    phi_rad: float  #: the previous step's pitch, rad (0 at the first step)
    omega_rad_s: float  #: flap rate d theta/dt, rad/s (positive on the upstroke)
    theta_rad: float  #: flap angle, rad
    climb_m_s: float  #: vertical ground velocity v_y, m/s (up > 0)
    altitude_m: float  #: altitude y above the target 0 m, m
    forward_m_s: float  #: forward ground velocity v_z, m/s
    air_up_m_s: float  #: the air's vertical velocity, m/s (wind from above: < 0)
    air_forward_m_s: float  #: the air's forward velocity, m/s (head wind: < 0)

    # the environment's names of before 0.3, kept one release (a pitch law run in Python may still read them)
    @property
    def phi_prev_rad(self) -> float:
        return _renamed("phi_prev_rad", "phi_rad", self.phi_rad)

    @property
    def v_y_m_s(self) -> float:
        return _renamed("v_y_m_s", "climb_m_s", self.climb_m_s)

    @property
    def y_m(self) -> float:
        return _renamed("y_m", "altitude_m", self.altitude_m)

    @property
    def v_z_m_s(self) -> float:
        return _renamed("v_z_m_s", "forward_m_s", self.forward_m_s)


def _renamed(old: str, new: str, value: float) -> float:
    """``value``, with a one-line note (once per name and process) that ``old`` is now ``new``."""
    checks.renamed(f"PitchObservation.{old}", f"PitchObservation.{new}", "the name the environment also uses")
    return value


@njit(inline="always")
def builtin_law(kind, cp, obs):
    """The compiled pitch laws (:func:`pitch_command`) as a law of an
    observation: what every stepping loop calls once per step."""
    return pitch_command(kind, cp, obs.t_s, obs.theta_rad, obs.omega_rad_s, obs.altitude_m, 0.0, obs.climb_m_s,
                         obs.forward_m_s, obs.air_up_m_s, obs.air_forward_m_s, obs.phi_rad)


def kernel_law(law: Callable) -> Callable:
    """A user's compiled pitch law ``law(obs) -> phi`` (a numba ``@njit`` function of a
    :class:`PitchObservation`, rad) in the form the stepping loops call: ``(kind, cp, obs) -> phi``."""
    return _kernel_law(law)


@functools.lru_cache(maxsize=64)
def _kernel_law(law):
    @njit(inline="always")
    def call(kind, cp, obs):
        return law(obs)

    return call


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
    #: Why the flight diverged, when it did (a sentence); empty for a runaway speed or no divergence.
    diverged_cause: str = ""

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
