"""The evolved controller's experiments E6-E11 (Oe 2010 sections 6.4 and 7).

* E6 :func:`e6_level`: the evolved network in still air from 0 m (Fig. 7-10).
* E7 :func:`e7_from_above`: start at +10 m (Fig. 11).
* E8 :func:`e8_glide`: the gliding descent (phi = 0, wings fixed at 75 deg) against the
  controller's descent from +10 m: maximum sink speeds (Fig. 12; the paper finds about 2x).
* E9 :func:`e9_from_below`: start at -10, -2, -1 m (Fig. 13; the paper's controller fails).
* E10 :func:`e10_winds`: uniform 2 m/s winds from the front, above, behind and below, with the
  network fed air-relative or ground velocities (Fig. 14, 15).
* E11 :func:`e11_windmap`: the pass/fail map over winds on a grid (Fig. 15 "boundary").

Altitudes are in metres measured from the target altitude 0 m; the settled window is the last
10 s of a 20 s flight; speeds in m/s unless a name says cm/s. Every function flies on the paper
backend by default (``backend="mujoco"`` flies the MuJoCo model instead).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lifelike_mj.butterfly import batch, controllers
from lifelike_mj.butterfly.backends.paper import compile_controllers, constants_row, run_batch
from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import Condition, Trajectory
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

DT_S = 1.0 / 1200.0  # section 6.3
DURATION_S = 20.0
SETTLE_S = 10.0
#: Pass band of the wind map (section 7.2): settled altitude within [-1, 1] m, forward speed >= 0.
MAP_BAND_M = 1.0
#: Acceptance band of level flight (issue 3): settled altitude within +-0.25 m.
LEVEL_BAND_M = 0.25
#: The winds of Fig. 14-15: label (where it comes from) -> (a, b) in m/s.
PAPER_WINDS: dict[str, tuple[float, float]] = {
    "front (2,0)": (2.0, 0.0),
    "above (0,2)": (0.0, 2.0),
    "behind (-2,0)": (-2.0, 0.0),
    "below (0,-2)": (0.0, -2.0),
}
PAPER_E6 = {"initial_drop_m": 0.5, "time_to_z20_s": 6.9, "phi_max_per_cycle_deg": 30.0}
PAPER_E8_SINK_RATIO = 2.0


def _fly(ctrl: ButterflyController, conds, backend: str, params, record_every: int = 1) -> list[Trajectory]:
    return batch.simulate(backend, ctrl, params, conds, DURATION_S, DT_S, record_every)


def flight_numbers(tr: Trajectory, band_m: float = LEVEL_BAND_M) -> dict:
    """Summary of one flight plus: whether the settled altitude stays within ``band_m`` of 0 m, and
    when the butterfly first comes within 0.5 m of 0 m (s, ``None`` if never)."""
    s = tr.summary(SETTLE_S)
    near = np.flatnonzero(np.abs(tr.y) <= 0.5)
    lo, hi = abs(s["settled_altitude_min_m"]), abs(s["settled_altitude_max_m"])
    s["holds_level"] = bool(tr.finite and lo <= band_m and hi <= band_m)
    s["time_to_within_0_5m_s"] = float(tr.t[near[0]]) if len(near) else None
    s["reaches_target"] = bool(len(near) and tr.finite and lo <= 0.5 and hi <= 0.5)
    return s


@dataclass(frozen=True)
class LevelResult:
    """E6: the evolved network from 0 m in still air."""

    numbers: dict
    time_to_z20_s: float | None
    phi_max_per_cycle_deg: list[float]
    phi_min_per_cycle_deg: list[float]
    altitude_per_cycle_m: list[float]
    corr_phi_min_altitude: float
    fitness_history: list = field(default_factory=list)
    trajectory: Trajectory | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        return {
            **self.numbers,
            "time_to_z20_s": self.time_to_z20_s,
            "phi_max_per_cycle_deg_first_30": self.phi_max_per_cycle_deg[:30],
            "phi_min_per_cycle_deg_first_30": self.phi_min_per_cycle_deg[:30],
            "cycles_with_phi_max_30deg": int(np.sum(np.isclose(self.phi_max_per_cycle_deg, 30.0, atol=1e-6))),
            "cycles": len(self.phi_max_per_cycle_deg),
            "corr_phi_min_altitude": self.corr_phi_min_altitude,
            "paper": dict(PAPER_E6),
        }


def e6_level(ctrl: ButterflyController, backend: str = "paper", params: ButterflyParams | None = None) -> LevelResult:
    """E6 (Fig. 8, 9): drop, hold, speed, time to reach z = 20 m, and phi per flap cycle."""
    tr = _fly(ctrl, Condition(0.0), backend, params)[0]
    z20 = np.flatnonzero(tr.z >= 20.0)
    period = 1.0 / ctrl.flap.frequency_hz
    cyc = np.floor(tr.t / period + 1e-9).astype(int)
    n_full = int(cyc[-1])
    pmax, pmin, alt = [], [], []
    for c in range(n_full):
        m = cyc == c
        pmax.append(float(np.degrees(tr.phi[m].max())))
        pmin.append(float(np.degrees(tr.phi[m].min())))
        alt.append(float(tr.y[m].mean()))
    k = min(30, n_full)  # the first 3 s, as Fig. 9
    corr = float(np.corrcoef(pmin[:k], alt[:k])[0, 1]) if k > 2 and np.std(pmin[:k]) > 0 else float("nan")
    hist = list(ctrl.provenance.get("fitness_history", []))
    return LevelResult(flight_numbers(tr), float(tr.t[z20[0]]) if len(z20) else None, pmax, pmin, alt, corr, hist, tr)


@dataclass(frozen=True)
class StartsResult:
    """E7 / E9: flights from other start altitudes (m)."""

    flights: dict  # start altitude label -> flight_numbers
    trajectories: dict = field(default_factory=dict, repr=False, compare=False)

    def to_dict(self) -> dict:
        return {"flights": {k: dict(v) for k, v in self.flights.items()}}


def _starts(ctrl, starts, backend, params) -> StartsResult:
    trs = _fly(ctrl, [Condition(float(y)) for y in starts], backend, params)
    return StartsResult({f"{y:+g} m": flight_numbers(t) for y, t in zip(starts, trs)},
                        {f"{y:+g} m": t for y, t in zip(starts, trs)})


def e7_from_above(ctrl: ButterflyController, backend: str = "paper", params: ButterflyParams | None = None) -> StartsResult:
    """E7 (Fig. 11): start at +10 m; the paper's controller descends to about 0 m and holds it."""
    return _starts(ctrl, (10.0,), backend, params)


def e9_from_below(ctrl: ButterflyController, backend: str = "paper", params: ButterflyParams | None = None,
                  starts=(-10.0, -2.0, -1.0)) -> StartsResult:
    """E9 (Fig. 13): start below the target; the paper's controller never climbs back to 0 m."""
    return _starts(ctrl, starts, backend, params)


@dataclass(frozen=True)
class GlideResult:
    """E8 (Fig. 12): maximum sink speeds (m/s, positive down) of the flapping descent from +10 m
    and of the glide (phi = 0, wings fixed at 75 deg) from the same height, and their ratio."""

    max_sink_flapping_m_s: float
    max_sink_gliding_m_s: float
    ratio: float
    flapping: Trajectory | None = field(default=None, repr=False, compare=False)
    gliding: Trajectory | None = field(default=None, repr=False, compare=False)

    def to_dict(self) -> dict:
        return {"max_sink_flapping_m_s": self.max_sink_flapping_m_s, "max_sink_gliding_m_s": self.max_sink_gliding_m_s,
                "ratio_gliding_over_flapping": self.ratio, "paper_ratio": PAPER_E8_SINK_RATIO}


def e8_glide(ctrl: ButterflyController, backend: str = "paper", params: ButterflyParams | None = None,
             y0_m: float = 10.0) -> GlideResult:
    """E8: how much faster the glide sinks than the controller's flapping descent. The glide is
    compared over the time the controller takes to descend (until it first comes within 0.5 m of
    0 m, or the whole flight)."""
    flap = _fly(ctrl, Condition(y0_m), backend, params)[0]
    glide = _fly(controllers.load("glide"), Condition(y0_m), backend, params)[0]
    near = np.flatnonzero(flap.y <= 0.5)
    end = flap.t[near[0]] if len(near) else flap.t[-1]
    fs = float(-np.nanmin(flap.vy[flap.t <= end]))
    gs = float(-np.nanmin(glide.vy[glide.t <= end]))
    return GlideResult(fs, gs, gs / fs if fs > 0 else float("inf"), flap, glide)


@dataclass(frozen=True)
class WindsResult:
    """E10 (Fig. 14, 15): flights in the four 2 m/s winds, per input kind."""

    flights: dict  # inputs -> wind label -> flight_numbers
    trajectories: dict = field(default_factory=dict, repr=False, compare=False)

    def to_dict(self) -> dict:
        return {"flights": {k: {w: dict(v) for w, v in d.items()} for k, d in self.flights.items()}}


def e10_winds(ctrl: ButterflyController, backend: str = "paper", params: ButterflyParams | None = None) -> WindsResult:
    """E10: each wind of Fig. 14-15, with the network fed air-relative and ground velocities."""
    flights, trajs = {}, {}
    for inputs in ("relative", "ground"):
        c = ctrl.with_inputs(inputs)
        trs = _fly(c, [Condition(0.0, w) for w in PAPER_WINDS.values()], backend, params)
        flights[inputs] = {label: flight_numbers(t, MAP_BAND_M) for label, t in zip(PAPER_WINDS, trs)}
        trajs[inputs] = dict(zip(PAPER_WINDS, trs))
    return WindsResult(flights, trajs)


@dataclass(frozen=True)
class WindMap:
    """E11: pass/fail of the settled flight over a grid of winds ``(a, b)`` (m/s, where the wind
    comes from: ``a`` > 0 from the front, ``b`` > 0 from above). A cell passes when the altitude over
    the last 10 s stays within [-1, 1] m and the mean forward (ground) speed there is >= 0."""

    inputs: str
    winds_a: np.ndarray
    winds_b: np.ndarray
    passed: np.ndarray  # (len(b), len(a)) bool
    settled_min_m: np.ndarray
    settled_max_m: np.ndarray
    forward_speed_m_s: np.ndarray

    @property
    def pass_cells(self) -> int:
        return int(self.passed.sum())

    @property
    def total_cells(self) -> int:
        return int(self.passed.size)

    def to_dict(self) -> dict:
        return {
            "inputs": self.inputs,
            "pass_cells": self.pass_cells,
            "total_cells": self.total_cells,
            "pass_fraction": self.pass_cells / self.total_cells,
            "step_m_s": float(self.winds_a[1] - self.winds_a[0]) if len(self.winds_a) > 1 else 0.0,
            "max_m_s": float(self.winds_a[-1]),
            "quadrants_pass_fraction": self.quadrants(),
        }

    def quadrants(self) -> dict:
        """Pass fraction per quadrant (tail = a < 0, head = a > 0; down = b > 0 from above, up = b < 0)."""
        A, B = np.meshgrid(self.winds_a, self.winds_b)
        out = {}
        for name, m in (("tail+from_above", (A < 0) & (B > 0)), ("tail+from_below", (A < 0) & (B < 0)),
                        ("head+from_above", (A > 0) & (B > 0)), ("head+from_below", (A > 0) & (B < 0))):
            out[name] = float(self.passed[m].mean()) if m.any() else float("nan")
        return out


def e11_windmap(ctrl: ButterflyController, inputs: str | None = None, step_m_s: float = 0.1, max_m_s: float = 3.0,
                params: ButterflyParams | None = None, chunk: int = 400, progress: bool = False) -> WindMap:
    """E11 on the paper backend: one 20 s flight from 0 m per grid cell, batched."""
    if not (0 < step_m_s <= max_m_s <= 20.0):
        raise UserError(f"the wind grid needs 0 < step <= max <= 20 m/s, got step {step_m_s} and max {max_m_s}.")
    n_half = int(round(max_m_s / step_m_s))
    if abs(n_half * step_m_s - max_m_s) > 1e-9 * max(1.0, max_m_s):
        raise UserError(f"the wind grid's max ({max_m_s} m/s) must be a multiple of its step ({step_m_s} m/s).")
    c = ctrl.with_inputs(inputs) if inputs else ctrl
    grid = np.arange(-n_half, n_half + 1) * step_m_s
    A, B = np.meshgrid(grid, grid)
    winds = np.column_stack([A.ravel(), B.ravel()])
    p = params or ButterflyParams()
    kinds, cp = compile_controllers([c])
    n_steps = int(round(DURATION_S / DT_S))
    rec = 12  # 100 Hz records
    n_cells = len(winds)
    smin = np.empty(n_cells)
    smax = np.empty(n_cells)
    vfwd = np.empty(n_cells)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_cells, desc="wind map", unit="flight", leave=False)
    for s in range(0, n_cells, chunk):
        w = winds[s : s + chunk]
        n = len(w)
        out, _, _ = run_batch(np.repeat(kinds, n), np.repeat(cp, n, axis=0), np.repeat(c.flap.as_array()[None], n, axis=0),
                              -w, np.zeros(n), np.repeat(constants_row(p)[None], n, axis=0), n_steps, DT_S, rec)
        t = np.arange(out.shape[1]) * rec * DT_S
        m = t >= t[-1] - SETTLE_S - 1e-12
        y = out[:, m, 0]
        bad = ~np.all(np.isfinite(y), axis=1)
        smin[s : s + n] = np.where(bad, -np.inf, np.nanmin(np.where(np.isfinite(y), y, np.inf), axis=1))
        smax[s : s + n] = np.where(bad, np.inf, np.nanmax(np.where(np.isfinite(y), y, -np.inf), axis=1))
        vfwd[s : s + n] = np.where(bad, -np.inf, np.nanmean(out[:, m, 3], axis=1))
        if bar is not None:
            bar.update(n)
    if bar is not None:
        bar.close()
    passed = (smin >= -MAP_BAND_M) & (smax <= MAP_BAND_M) & (vfwd >= 0.0)
    shape = (len(grid), len(grid))
    return WindMap(c.parameters["inputs"], grid, grid, passed.reshape(shape), smin.reshape(shape), smax.reshape(shape),
                   vfwd.reshape(shape))


def assess(ctrl: ButterflyController, params: ButterflyParams | None = None, windmap_step_m_s: float = 0.1) -> dict:
    """The issue-3 acceptance numbers of a network controller in one dict (paper backend): E6 from
    0 m, E7 from +10 m, E9 from below, the 2 m/s tail wind, and the wind-map pass counts for both
    input kinds."""
    e6 = e6_level(ctrl, params=params).numbers
    starts = _starts(ctrl, (10.0, -10.0, -2.0, -1.0), "paper", params).flights
    tail = _fly(ctrl, Condition(0.0, PAPER_WINDS["behind (-2,0)"]), "paper", params)[0]
    maps = {k: e11_windmap(ctrl, k, windmap_step_m_s, 3.0, params) for k in ("relative", "ground")}
    still_ok = (e6["initial_drop_m"] <= 1.0 and e6["holds_level"] and e6["settled_forward_speed_cm_s"] > 200.0)
    tail_n = flight_numbers(tail, 0.5)
    return {
        "still_air": {k: e6[k] for k in ("initial_drop_m", "settled_altitude_min_m", "settled_altitude_max_m",
                                         "settled_forward_speed_cm_s", "holds_level")},
        "still_air_ok": bool(still_ok),
        "from_+10m_holds": bool(starts["+10 m"]["holds_level"]),
        "from_+10m_settled": [starts["+10 m"]["settled_altitude_min_m"], starts["+10 m"]["settled_altitude_max_m"]],
        "from_below_reaches_target": {k: bool(starts[k]["reaches_target"]) for k in ("-10 m", "-2 m", "-1 m")},
        "from_-10m_time_to_within_0_5m_s": starts["-10 m"]["time_to_within_0_5m_s"],
        "tail_wind_2m_s": {"holds_0_5m": bool(tail_n["holds_level"]), "initial_drop_m": tail_n["initial_drop_m"],
                           "settled": [tail_n["settled_altitude_min_m"], tail_n["settled_altitude_max_m"]]},
        "windmap_pass_cells": {k: m.pass_cells for k, m in maps.items()},
        "windmap_total_cells": maps["relative"].total_cells,
    }
