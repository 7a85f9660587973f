"""The paper's experiments E1-E5 (Oe 2010 sections 4-5).

Each experiment is a function returning a small frozen dataclass with ``to_dict()`` (plain JSON
data). Arrays needed only for figures (trajectories) are kept as attributes and left out of
``to_dict``.

* E1 :func:`e1_closed_forms`: closed forms of Oe 2010 eq. 4 and 6 against strip integration.
* E2 :func:`e2_fig3`: Fig. 3, wing forces of eq. 8-9 against the pitch ``phi``.
* E3 :func:`e3_speed_limit`, :func:`e3_speed_limit_vs_area`: the forward-speed limit of
  section 4.3 (380 cm/s in the paper), and how it depends on the body area ``A_b`` of eq. 10.
* E4 :func:`e4_trim`: the simple rule of section 5.1 (Fig. 4): the upstroke pitch for level
  flight (12.77 deg in the paper).
* E5 :func:`e5_timestep`: the time-step study of section 5.2 (Fig. 5).

Units: SI inside; the names say where a number is in cm, cm/s, cm^2 or degrees.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly import aero, backends, controllers
from lifelike_mj.butterfly.batch import simulate as simulate_batch
from lifelike_mj.butterfly.flight import Trajectory
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

#: The paper's numbers for the simple rule (Oe 2010 section 5.1, Fig. 4).
PAPER_E4: dict = {
    "phi_up_level_deg": 12.77,
    "mean_forward_speed_cm_s": 340.0,
    "ripple_cm": 5.3,
    "initial_drop_m": 3.0,
}
#: The paper's speed limit, cm/s (Oe 2010 section 4.3).
PAPER_SPEED_LIMIT_CM_S: int = 380
#: The paper's time-step study (Oe 2010 section 5.2, Fig. 5).
PAPER_E5: dict = {
    "altitude_20s_m": "about 15-16 m for every dt except 1/120 s",
    "rel_error": {"1/1200": 0.01, "1/360": 0.10},
    "error_ratio_per_3x_dt": 10.0,
}
#: Time steps of Oe 2010 section 5.2: label -> steps per second.
E5_STEPS_PER_S: dict[str, int] = {"1/12000": 12000, "1/1200": 1200, "1/360": 360, "1/120": 120}

_SETTLE_WINDOW_S = 10.0


# --------------------------------------------------------------------------- E1, E2


def e1_closed_forms(params: ButterflyParams | None = None) -> aero.ClosedFormCheck:
    """E1: the closed forms of Oe 2010 eq. 4 (force, N) and eq. 6 (torque, N m) of the three
    planforms of eq. 3 against strip integration, plus the two efficiencies of section 4.1."""
    return aero.check_closed_forms(params)


def e2_fig3(params: ButterflyParams | None = None) -> aero.Fig3Curves:
    """E2 (Oe 2010 Fig. 3): ``F_y``, ``F_z`` (N) of eq. 8-9 against ``phi`` for ``v_z`` = 0, 2,
    4 m/s, upstroke and downstroke at the mean flap rate +-62.8 rad/s (section 4.3)."""
    return aero.fig3_curves(params)


# --------------------------------------------------------------------------- E3


def e3_speed_limit(params: ButterflyParams | None = None) -> aero.SpeedLimit:
    """E3: the quasi-static forward-speed limit of Oe 2010 section 4.3 (cm/s, 1 cm/s steps):
    the largest ``v_z`` at which ``max_phi F_z`` (eq. 9) still exceeds the body drag ``F_bz``
    (eq. 10). The paper reports 380 cm/s."""
    return aero.speed_limit(params)


@dataclass(frozen=True)
class SpeedLimitSweep:
    """E3 swept over the body area ``A_b`` (Oe 2010 eq. 10; not stated in the paper).

    ``areas_cm2`` (cm^2) and ``limits_cm_s`` (cm/s, on the paper's 1 cm/s grid) are the sweep;
    ``area_at_380_cm2`` is the area whose drag at 380 cm/s equals ``max_phi F_z`` there (the
    limit is 380 cm/s just below it); ``grid_areas_380_cm2`` is the range of swept areas whose
    limit is exactly 380 cm/s; ``limit_at_1cm2_cm_s`` and ``limit_at_1_53cm2_cm_s`` are the
    limits at ``A_b`` = 1.0 cm^2 (the default) and 1.53 cm^2.
    """

    areas_cm2: np.ndarray
    limits_cm_s: np.ndarray
    area_at_380_cm2: float
    grid_areas_380_cm2: tuple[float, float] | None
    limit_at_1cm2_cm_s: int
    limit_at_1_53cm2_cm_s: int
    omega_rad_s: float

    def to_dict(self) -> dict:
        return {
            "areas_cm2": [round(float(a), 10) for a in self.areas_cm2],
            "limits_cm_s": [int(v) for v in self.limits_cm_s],
            "area_at_380_cm2": self.area_at_380_cm2,
            "grid_areas_380_cm2": list(self.grid_areas_380_cm2) if self.grid_areas_380_cm2 else None,
            "limit_at_1cm2_cm_s": self.limit_at_1cm2_cm_s,
            "limit_at_1_53cm2_cm_s": self.limit_at_1_53cm2_cm_s,
            "omega_rad_s": self.omega_rad_s,
            "paper_speed_limit_cm_s": PAPER_SPEED_LIMIT_CM_S,
        }


def e3_speed_limit_vs_area(
    areas_cm2: Sequence[float] | np.ndarray = np.arange(0.5, 2.51, 0.01),  # noqa: B008 (read-only default)
    params: ButterflyParams | None = None,
) -> SpeedLimitSweep:
    """E3 against ``A_b`` (cm^2): the speed limit of Oe 2010 section 4.3 for each body area.

    The limit ``v*`` solves ``max_phi F_z(v) = 1/2 rho C_d A_b v^2`` (eq. 9-10); since the drag
    is linear in ``A_b``, the area giving a limit of 380 cm/s is
    ``A_b = max_phi F_z(3.80) / (1/2 rho C_d 3.80^2)`` exactly.
    """
    p = params or ButterflyParams()
    omega = 20.0 * math.pi  # the mean flap rate of section 4.3, rad/s
    areas = np.asarray(areas_cm2, dtype=float)
    if areas.ndim != 1 or areas.size == 0 or not np.all(np.isfinite(areas)) or np.any(areas <= 0):
        raise UserError("body areas must be a non-empty list of positive numbers (cm^2).")
    limits = np.array([aero.speed_limit(replace(p, body_area_m2=a * 1e-4), omega).speed_limit_cm_s for a in areas])
    v380 = PAPER_SPEED_LIMIT_CM_S / 100.0
    a380_m2 = float(aero.max_forward_force(p, omega, v380)) / (0.5 * p.rho * p.cd * v380**2)
    hit = areas[limits == PAPER_SPEED_LIMIT_CM_S]
    grid = (round(float(hit.min()), 10), round(float(hit.max()), 10)) if hit.size else None
    return SpeedLimitSweep(
        areas_cm2=areas,
        limits_cm_s=limits,
        area_at_380_cm2=a380_m2 * 1e4,
        grid_areas_380_cm2=grid,
        limit_at_1cm2_cm_s=aero.speed_limit(replace(p, body_area_m2=1.0e-4), omega).speed_limit_cm_s,
        limit_at_1_53cm2_cm_s=aero.speed_limit(replace(p, body_area_m2=1.53e-4), omega).speed_limit_cm_s,
        omega_rad_s=omega,
    )


# --------------------------------------------------------------------------- E4


@dataclass(frozen=True)
class TrimResult:
    """E4: the simple rule of Oe 2010 section 5.1 trimmed for level flight (Fig. 4).

    ``phi_up_level_deg`` is the upstroke pitch (deg) whose settled climb rate (least-squares
    slope of altitude over the last 10 s) is zero; the other numbers are measured on that flight:
    forward speed (cm/s, mean ``v_z`` over the last 10 s), ripple (cm, mean per-flap-cycle
    altitude peak-to-peak over the last 10 s), initial drop (m, ``-min y``), final altitude (m).
    ``below`` / ``above`` hold the same flight at ``level -/+ 0.5 deg``.
    """

    phi_up_level_deg: float
    mean_forward_speed_cm_s: float
    ripple_cm: float
    initial_drop_m: float
    final_altitude_m: float
    settled_climb_rate_cm_s: float
    backend: str
    dt_s: float
    duration_s: float
    body_area_cm2: float
    below: dict
    above: dict
    bracket_deg: tuple[float, float]
    n_flights: int
    search: list = field(default_factory=list)  # (phi_up_deg, settled climb rate cm/s) flown
    level: Trajectory | None = field(default=None, repr=False, compare=False)
    below_trajectory: Trajectory | None = field(default=None, repr=False, compare=False)
    above_trajectory: Trajectory | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        return {
            "phi_up_level_deg": self.phi_up_level_deg,
            "mean_forward_speed_cm_s": self.mean_forward_speed_cm_s,
            "ripple_cm": self.ripple_cm,
            "initial_drop_m": self.initial_drop_m,
            "final_altitude_m": self.final_altitude_m,
            "settled_climb_rate_cm_s": self.settled_climb_rate_cm_s,
            "backend": self.backend,
            "dt_s": self.dt_s,
            "duration_s": self.duration_s,
            "body_area_cm2": self.body_area_cm2,
            "below": dict(self.below),
            "above": dict(self.above),
            "bracket_deg": [float(self.bracket_deg[0]), float(self.bracket_deg[1])],
            "n_flights": self.n_flights,
            "search": [{"phi_up_deg": a, "settled_climb_rate_cm_s": r} for a, r in self.search],
            "paper": dict(PAPER_E4),
        }


def _check_trim_window(duration_s: float) -> None:
    if not (math.isfinite(duration_s) and duration_s > _SETTLE_WINDOW_S):
        raise UserError(
            f"trim needs a flight longer than the {_SETTLE_WINDOW_S:g} s settling window, got {duration_s} s."
        )


def _climb_rate(tr: Trajectory) -> float:
    """Settled climb rate (m/s) of one flight; NaN when the flight diverged."""
    if tr.diverged_step >= 0 or not tr.finite:
        return math.nan
    return tr.climb_rate_m_s(_SETTLE_WINDOW_S)


def _first_bracket(angles: list[float], rates: list[float]) -> tuple[int, int] | None:
    """Indices ``(i, j)`` of the first neighbouring pair (in angle order) whose climb rates change sign."""
    order = sorted(range(len(angles)), key=lambda k: angles[k])
    for a, b in zip(order, order[1:], strict=False):
        ra, rb = rates[a], rates[b]
        if math.isfinite(ra) and math.isfinite(rb) and (ra <= 0.0 <= rb or rb <= 0.0 <= ra):
            return a, b
    return None


def _find_level_angle(
    climb_rates: Callable[[list[float]], list[float]], lo: float, hi: float, tol: float, batch: int
) -> tuple[float, tuple[float, float], list[tuple[float, float]]]:
    """Root (deg) of the settled climb rate between ``lo`` and ``hi``.

    With ``batch > 2`` each round flies ``batch`` angles spread over the current bracket in one
    call and keeps the neighbouring pair that changes sign (a grid search, shrinking the bracket
    by ``batch + 1`` per round). With ``batch <= 2`` (a backend that flies a batch one flight
    after another) a grid of 5 finds the bracket and the Illinois variant of regula falsi, one
    flight per step, shrinks it. Stops when the bracket is narrower than ``tol``; the result is
    the linear interpolation of the climb rate inside the final bracket.
    """
    flown: list[tuple[float, float]] = []

    def fly(angles: list[float]) -> list[float]:
        rates = climb_rates(angles)
        flown.extend(zip(angles, rates, strict=True))
        return rates

    first = [float(a) for a in np.linspace(lo, hi, batch if batch > 2 else 5)]
    rates = fly(first)
    pair = _first_bracket(first, rates)
    if pair is None:
        shown = ", ".join(f"{a:.3f} deg: {100 * r:+.2f} cm/s" for a, r in zip(first, rates, strict=True))
        raise UserError(f"no level-flight angle between {lo} and {hi} deg (settled climb rates {shown}).")
    (a0, r0), (a1, r1) = sorted([(first[pair[0]], rates[pair[0]]), (first[pair[1]], rates[pair[1]])])
    f0, f1 = r0, r1  # Illinois: end values, halved when the same end is kept twice in a row
    last = 0  # which end the previous step replaced (-1 low, +1 high)
    while a1 - a0 >= tol and r0 != 0.0 and r1 != 0.0:
        if batch > 2:
            grid = [float(a) for a in np.linspace(a0, a1, batch + 2)[1:-1]]
            rs = fly(grid)
            angles, rates = [a0, *grid, a1], [r0, *rs, r1]
            pair = _first_bracket(angles, rates)
            if pair is None:  # a flight inside the bracket diverged: cannot shrink further
                break
            (a0, r0), (a1, r1) = sorted([(angles[pair[0]], rates[pair[0]]), (angles[pair[1]], rates[pair[1]])])
            continue
        x = a0 - f0 * (a1 - a0) / (f1 - f0)
        x = min(max(x, a0 + 0.05 * tol), a1 - 0.05 * tol)
        (rx,) = fly([x])
        if not math.isfinite(rx):
            break
        if (rx < 0.0) == (r0 < 0.0):
            a0, r0, f0 = x, rx, rx
            if last == -1:
                f1 *= 0.5
            last = -1
        else:
            a1, r1, f1 = x, rx, rx
            if last == +1:
                f0 *= 0.5
            last = +1
    if r0 == 0.0:
        level = a0
    elif r1 == 0.0:
        level = a1
    else:
        level = a0 - r0 * (a1 - a0) / (r1 - r0)
    return float(level), (float(a0), float(a1)), flown


def _flight_numbers(tr: Trajectory, phi_up_deg: float) -> dict:
    s = tr.summary(_SETTLE_WINDOW_S)
    return {
        "phi_up_deg": float(phi_up_deg),
        "final_altitude_m": s["final_altitude_m"],
        "settled_climb_rate_cm_s": s["settled_climb_rate_cm_s"],
        "settled_forward_speed_cm_s": s["settled_forward_speed_cm_s"],
        "initial_drop_m": s["initial_drop_m"],
        "diverged_step": s["diverged_step"],
    }


def check_trim_work(backend: str = "paper", dt_s: float = 1.0 / 12000.0, duration_s: float = 20.0, lo_deg: float = 10.0,
                    hi_deg: float = 16.0, tol_deg: float = 1e-3) -> None:
    """Before E4's search: its flights (a bound on their number: the paper backend's rounds of 16, the MuJoCo
    backend's regula falsi, then 3 recorded flights) times their steps, refused above
    :data:`~lifelike_mj.checks.MAX_BODY_STEPS`."""
    rounds = math.ceil(math.log(max((hi_deg - lo_deg) / tol_deg, 2.0), 17 if backend == "paper" else 2)) + 1
    flights = (16 * rounds if backend == "paper" else 5 + 2 * rounds) + 3
    checks.work(f"E4's search ({flights} flights of {duration_s:g} s at {dt_s:g} s)",
                flights * checks.steps_of(duration_s, dt_s), checks.MAX_BODY_STEPS, "time steps", "a larger time step")


def e4_trim(
    params: ButterflyParams | None = None,
    backend: str = "paper",
    dt_s: float = 1.0 / 12000.0,
    duration_s: float = 20.0,
    lo_deg: float = 10.0,
    hi_deg: float = 16.0,
    tol_deg: float = 1e-3,
    **backend_options,
) -> TrimResult:
    """E4 (Oe 2010 section 5.1, Fig. 4): upstroke pitch ``phi_up`` (deg) for level flight.

    The simple rule (``phi = phi_up`` on the upstroke, 0 on the downstroke; flap [-90, 90] deg
    at 10 Hz) flies eq. 11 with RK4 from rest at ``y = 0`` for ``duration_s`` (s) at step
    ``dt_s`` (s). The level angle is the root of the settled climb rate (m/s, least-squares
    slope of altitude over the last 10 s), searched in ``[lo_deg, hi_deg]`` to ``tol_deg``.
    On the batched paper backend each round flies 16 angles in one call; on the MuJoCo backend
    (flights one after another) a grid of 5 then regula falsi. The level angle and
    ``level -/+ 0.5 deg`` are then flown once more, recorded at every step. Paper: 12.77 deg,
    340 cm/s, ripple 5.3 cm, initial drop about 3 m; below the level angle it descends, above it
    climbs.
    """
    backends.check_backend(backend)
    p = params or ButterflyParams()
    _check_trim_window(duration_s)
    if not (math.isfinite(lo_deg) and math.isfinite(hi_deg) and lo_deg < hi_deg):
        raise UserError(f"trim range must satisfy lo < hi, got [{lo_deg}, {hi_deg}] deg.")
    if not (math.isfinite(tol_deg) and tol_deg > 0):
        raise UserError(f"trim tolerance must be positive, got {tol_deg} deg.")
    check_trim_work(backend, dt_s, duration_s, lo_deg, hi_deg, tol_deg)
    base = controllers.load("simple_rule").with_parameters(phi_down_deg=0.0)
    # the search needs the climb-rate slope only: sample about every millisecond
    search_every = max(1, int(round(1e-3 / dt_s)))

    def climb_rates(angles: list[float]) -> list[float]:
        trs = simulate_batch(
            backend, [base.with_parameters(phi_up_deg=a) for a in angles], p, None, duration_s, dt_s, search_every,
            **backend_options,
        )
        return [_climb_rate(tr) for tr in trs]

    batch = 16 if backend == "paper" else 1
    level, bracket, flown = _find_level_angle(climb_rates, float(lo_deg), float(hi_deg), float(tol_deg), batch)
    angles = [level, level - 0.5, level + 0.5]
    lv, lo_tr, hi_tr = simulate_batch(
        backend, [base.with_parameters(phi_up_deg=a) for a in angles], p, None, duration_s, dt_s, 1, **backend_options
    )
    s = lv.summary(_SETTLE_WINDOW_S)
    below, above = _flight_numbers(lo_tr, angles[1]), _flight_numbers(hi_tr, angles[2])
    return TrimResult(
        phi_up_level_deg=level,
        mean_forward_speed_cm_s=s["settled_forward_speed_cm_s"],
        ripple_cm=s["ripple_cm"],
        initial_drop_m=s["initial_drop_m"],
        final_altitude_m=s["final_altitude_m"],
        settled_climb_rate_cm_s=s["settled_climb_rate_cm_s"],
        backend=backend,
        dt_s=float(dt_s),
        duration_s=float(duration_s),
        body_area_cm2=p.body_area_m2 * 1e4,
        below=below,
        above=above,
        bracket_deg=bracket,
        n_flights=len(flown) + 3,
        search=[(float(a), float(100.0 * r)) for a, r in flown],
        level=lv,
        below_trajectory=lo_tr,
        above_trajectory=hi_tr,
    )


# --------------------------------------------------------------------------- E5


@dataclass(frozen=True)
class TimestepResult:
    """E5 (Oe 2010 section 5.2, Fig. 5): the simple rule at ``phi_up`` = 14 deg flown for 20 s
    at four time steps (s); altitudes (m) at 20 s and sampled every 1 s, errors against the
    1/12000 s run.

    ``rel_error[k] = |y_k(20) - y_ref(20)| / |y_ref(20)|``; ``altitude_diff_every_1s_m[k]`` is
    ``y_ref - y_k`` (m) at t = 0, 1, ..., 20 s (the paper's Fig. 5(b) plots the reference's
    altitude minus each run's); ``error_ratio_per_3x_dt`` is ``rel_error["1/360"] /
    rel_error["1/1200"]`` (the paper: about 10 when dt grows 3x).
    """

    phi_up_deg: float
    backend: str
    duration_s: float
    dts_s: dict
    altitude_20s_m: dict
    rel_error: dict
    error_ratio_per_3x_dt: float
    times_s: list
    altitude_every_1s_m: dict
    forward_every_1s_m: dict
    altitude_diff_every_1s_m: dict
    diverged_step: dict
    trajectories: dict = field(default_factory=dict, repr=False, compare=False)  # label -> Trajectory

    def to_dict(self) -> dict:
        return {
            "phi_up_deg": self.phi_up_deg,
            "backend": self.backend,
            "duration_s": self.duration_s,
            "dts_s": dict(self.dts_s),
            "altitude_20s_m": dict(self.altitude_20s_m),
            "rel_error": dict(self.rel_error),
            "error_ratio_per_3x_dt": self.error_ratio_per_3x_dt,
            "times_s": list(self.times_s),
            "altitude_every_1s_m": {k: list(v) for k, v in self.altitude_every_1s_m.items()},
            "forward_every_1s_m": {k: list(v) for k, v in self.forward_every_1s_m.items()},
            "altitude_diff_every_1s_m": {k: list(v) for k, v in self.altitude_diff_every_1s_m.items()},
            "diverged_step": dict(self.diverged_step),
            "paper": {k: (dict(v) if isinstance(v, dict) else v) for k, v in PAPER_E5.items()},
        }


def e5_timestep(
    params: ButterflyParams | None = None, phi_up_deg: float = 14.0, backend: str = "paper", **backend_options
) -> TimestepResult:
    """E5 (Oe 2010 section 5.2, Fig. 5): fly the simple rule (``phi_up`` deg, flap [-90, 90] deg
    at 10 Hz, RK4 on eq. 11) for 20 s at dt = 1/12000, 1/1200, 1/360 and 1/120 s.

    Every run is recorded every 1/120 s (``record_every`` = steps per second / 120), so whole
    seconds fall exactly on samples. Paper: altitude at 20 s about 15-16 m except at 1/120 s;
    error about 1 % at 1/1200 s and 10 % at 1/360 s.
    """
    backends.check_backend(backend)
    p = params or ButterflyParams()
    duration = 20.0
    ctrl = controllers.load("simple_rule").with_parameters(phi_up_deg=phi_up_deg, phi_down_deg=0.0)
    trs: dict[str, Trajectory] = {}
    for label, per_s in E5_STEPS_PER_S.items():
        (tr,) = simulate_batch(backend, [ctrl], p, None, duration, 1.0 / per_s, per_s // 120, **backend_options)
        trs[label] = tr
    per_second = 120  # samples per simulated second
    seconds = list(range(int(duration) + 1))
    idx = [s * per_second for s in seconds]
    y1 = {k: [float(v) for v in tr.y[idx] - tr.y0] for k, tr in trs.items()}
    z1 = {k: [float(v) for v in tr.z[idx]] for k, tr in trs.items()}
    ref = "1/12000"
    y_ref = np.array(y1[ref])
    diff = {k: [float(v) for v in y_ref - np.array(y)] for k, y in y1.items()}
    alt20 = {k: y[-1] for k, y in y1.items()}
    rel = {k: abs(alt20[k] - alt20[ref]) / abs(alt20[ref]) for k in alt20}
    ratio = rel["1/360"] / rel["1/1200"] if rel["1/1200"] > 0 else math.inf
    return TimestepResult(
        phi_up_deg=float(phi_up_deg),
        backend=backend,
        duration_s=duration,
        dts_s={k: 1.0 / v for k, v in E5_STEPS_PER_S.items()},
        altitude_20s_m=alt20,
        rel_error=rel,
        error_ratio_per_3x_dt=float(ratio),
        times_s=[float(s) for s in seconds],
        altitude_every_1s_m=y1,
        forward_every_1s_m=z1,
        altitude_diff_every_1s_m=diff,
        diverged_step={k: int(tr.diverged_step) for k, tr in trs.items()},
        trajectories=trs,
    )


# ---- one flight, as `butterfly fly` flies it ------------------------------------------------------


@dataclass(frozen=True)
class FlyResult:
    """One flight (:func:`fly`): its trajectory and the summary numbers ``butterfly fly`` prints."""

    trajectory: Trajectory
    summary: dict
    #: What made the flight (:func:`lifelike_mj.provenance.provenance`): controller, constants, conditions.
    provenance: dict = field(default_factory=dict)

    def write(self, out_dir: str, title: str = "") -> list[str]:
        """``trajectory.npz``, ``trajectory.csv``, ``flight.png`` and ``summary.json`` into ``out_dir``
        (atomically); returns the paths written."""
        from pathlib import Path

        from lifelike_mj.butterfly.figures import fig_flight
        from lifelike_mj.io import write_json, write_npz, write_text

        out = Path(out_dir)
        files = [write_npz(out / "trajectory.npz", **self.trajectory.to_npz_dict()),
                 write_text(out / "trajectory.csv", self.trajectory.to_csv())]
        fig_flight(self.trajectory, out / "flight.png", title)
        files += [out / "flight.png", write_json(out / "summary.json", {**self.summary, "provenance": self.provenance})]
        return [str(f) for f in files]


def fly(controller: controllers.ButterflyController, params: ButterflyParams | None = None, condition=None,
        duration_s: float = 20.0, dt_s: float = 1.0 / 1200.0, backend: str = "paper", config: str = "paper",
        force_mode: str | None = None, name: str = "") -> FlyResult:
    """Fly ``controller`` for ``duration_s`` seconds at time step ``dt_s`` (s) on ``backend`` (the MuJoCo
    backend in ``config`` with ``force_mode``); every step recorded. A runaway is a
    :class:`~lifelike_mj.errors.Diverged` error naming the step."""
    from lifelike_mj.butterfly.flight import Condition, check_timing
    from lifelike_mj.errors import Diverged

    backends.check_backend(backend)
    opts = backends.mujoco_options(config, force_mode) if backend == "mujoco" else {}
    check_timing(duration_s, dt_s)
    traj = simulate_batch(backend, controller, params or ButterflyParams(), condition or Condition(), duration_s,
                             dt_s, 1, **opts)[0]
    summary = {"controller": controller.name or name, **traj.summary(), **({"config": opts} if opts else {})}
    if traj.diverged_step >= 0:
        from lifelike_mj.butterfly.sim import runaway_message

        raise Diverged(traj.diverged_cause or runaway_message(traj.diverged_step, dt_s, params or ButterflyParams()),
                       traj.diverged_step)
    from dataclasses import asdict

    from lifelike_mj.provenance import provenance

    cond = condition or Condition()
    prov = provenance(controller=controller.to_dict(), params=asdict(params or ButterflyParams()), y0_m=cond.y0_m,
                      wind_from_m_s=list(cond.wind_from_m_s), duration_s=duration_s, dt_s=dt_s, backend=backend, **opts)
    return FlyResult(traj, summary, prov)
