"""Figures of the evolved controller's experiments E6-E11 (Oe 2010 Fig. 7-9 and 11-15).

Each ``fig*`` function draws one result of :mod:`lifelike_mj.butterfly.ann_experiments` (or an
optimiser's fitness history) with the quantities and units of the paper's figure, names that
figure in its title ("cf. Oe 2010 Fig. 8") and returns the figure; given a path it also writes a
PNG through :func:`lifelike_mj.render.plot.save` (atomically: a temporary file in the same folder,
then ``os.replace``). Figures are built with :func:`lifelike_mj.render.plot.new_figure` on the Agg
canvas, without pyplot, so drawing them never changes the process's matplotlib backend.

Units: altitude ``y`` and forward distance ``z`` in m (``y`` measured from the target altitude
0 m), velocities in m/s, angles in degrees, time in s, winds ``(a, b)`` in m/s named by where the
wind comes from (``a`` > 0 from the front, ``b`` > 0 from above). Fitness is ``H`` of eq. 13
(dimensionless).

Flights that run far from the interesting range (a crash falling 100 m, a runaway climb) would
squash every other curve; the altitude axes of the flight figures are therefore limited to the
start altitudes, the target and the bands drawn, plus a margin, and a curve that leaves that
window is annotated at its exit with its altitude at the end of the flight.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from lifelike_mj.butterfly.ann_experiments import (
    LEVEL_BAND_M,
    MAP_BAND_M,
    PAPER_E6,
    PAPER_E8_SINK_RATIO,
    PAPER_WINDS,
    GlideResult,
    LevelResult,
    StartsResult,
    WindMap,
    WindsResult,
)
from lifelike_mj.butterfly.flight import Trajectory
from lifelike_mj.render.plot import finish
from lifelike_mj.render.plot import new_figure as _new_figure

__all__ = [
    "fig7_fitness",
    "fig8_flight",
    "fig9_phi",
    "fig11_from_above",
    "fig12_sink",
    "fig13_from_below",
    "fig14_15_winds",
    "fig_compare_starts",
    "fig_optimizer_convergence",
    "fig_windmap",
]

_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive",
            "tab:cyan", "tab:grey")
_WIND_COLOURS = {"front (2,0)": "tab:blue", "above (0,2)": "tab:green", "behind (-2,0)": "tab:red",
                 "below (0,-2)": "tab:purple"}
_BOX = {"boxstyle": "round", "fc": "white", "alpha": 0.85}
#: Categories of a wind-map cell: (label, colour). Index 0 passes.
_MAP_CATEGORIES = (
    ("pass", "#009e73"),  # Okabe-Ito colours: told apart by colour-blind readers
    (f"fail: settled y below −{MAP_BAND_M:g} m", "#0072b2"),
    (f"fail: settled y above +{MAP_BAND_M:g} m", "#e69f00"),
    ("fail: flies backwards (v_z < 0)", "#cc79a7"),
    ("fail: diverged (non-finite)", "#252525"),
)


# ----------------------------------------------------------------------------------------------
# helpers


def _colour(i: int) -> str:
    return _COLOURS[i % len(_COLOURS)]


def _altitude_window(anchors: Sequence[float], curves: Sequence[np.ndarray], min_pad_m: float = 1.0) -> tuple[float, float]:
    """Altitude limits (m) showing every value in ``anchors`` (starts, target, bands) plus a margin
    of ``max(min_pad_m, 30 % of their span)``; within that window the limits shrink to the data."""
    lo_a, hi_a = float(min(anchors)), float(max(anchors))
    pad = max(min_pad_m, 0.3 * (hi_a - lo_a))
    lo_w, hi_w = lo_a - pad, hi_a + pad
    finite = [c[np.isfinite(c)] for c in curves]
    finite = [c for c in finite if c.size]
    d_lo = min([float(c.min()) for c in finite], default=lo_a)
    d_hi = max([float(c.max()) for c in finite], default=hi_a)
    lo = max(lo_w, min(d_lo, lo_a))
    hi = min(hi_w, max(d_hi, hi_a))
    margin = 0.06 * max(hi - lo, 1e-3)
    return lo - margin, hi + margin


def _mark_exits(ax: Axes, x: np.ndarray, y: np.ndarray, colour: str, ylim: tuple[float, float], t_end_s: float,
                slot: int = 0) -> None:
    """Annotate where a curve first leaves the altitude window ``ylim`` (m), with its final altitude;
    ``slot`` staggers the notes of several curves so that none hides another."""
    lo, hi = ylim
    out = np.flatnonzero(~np.isfinite(y) | (y < lo) | (y > hi))
    if not len(out):
        return
    i = int(out[0])
    below = not (np.isfinite(y[i]) and y[i] > hi)
    edge = lo if below else hi
    final = y[np.isfinite(y)][-1] if np.isfinite(y).any() else float("nan")
    ax.annotate(f"{'↓' if below else '↑'} leaves the plot; y({t_end_s:g} s) = {final:+.1f} m", (x[i], edge),
                xytext=(6, (10 + 16 * slot) if below else -(14 + 16 * slot)), textcoords="offset points", fontsize=8,
                color=colour,
                bbox={"boxstyle": "round", "fc": "white", "ec": colour, "alpha": 0.9})


def _target_line(ax: Axes) -> None:
    ax.axhline(0.0, color="k", lw=0.7, ls=":", label="target altitude 0 m")


# ----------------------------------------------------------------------------------------------
# E6: Fig. 7, 8, 9


def fig7_fitness(history: Sequence[Mapping], path: str | os.PathLike | None = None, label: str = "") -> Figure:
    """Oe 2010 Fig. 7: the best (best so far) and the mean fitness ``H`` (eq. 13, dimensionless)
    of each generation against the generation.

    ``history`` is a list of dicts with keys ``generation``, ``best``, ``mean`` and
    ``evaluations`` (cumulative), as in a controller file's provenance ``fitness_history``;
    ``label`` (e.g. the controller's name) goes into the title. Non-finite means are left out.
    """
    if not history:
        raise ValueError("the fitness history is empty; nothing to draw")
    gen = np.array([float(h.get("generation", i + 1)) for i, h in enumerate(history)])
    best = np.array([float(h.get("best", np.nan)) for h in history])
    mean = np.array([float(h.get("mean", np.nan)) for h in history])
    fig = _new_figure(8.0, 4.8)
    ax = fig.subplots()
    ok = np.isfinite(best)
    ax.plot(gen[ok], best[ok], "-", color="tab:red", lw=1.6, label="best so far")
    ok = np.isfinite(mean)
    if ok.any():
        ax.plot(gen[ok], mean[ok], "-", color="tab:blue", lw=1.0, alpha=0.8, label="mean of the generation")
    ax.set_xlabel("generation")
    ax.set_ylabel("fitness H (eq. 13) [–]")
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=9)
    evals = history[-1].get("evaluations")
    finite_best = best[np.isfinite(best)]
    note = f"final best H = {finite_best[-1]:.6g}" if finite_best.size else "no finite fitness"
    if evals is not None:
        note += f"\n{len(history)} generations, {int(evals)} evaluations"
    ax.text(0.02, 0.97, note, transform=ax.transAxes, va="top", fontsize=9, bbox=_BOX)
    ylo, yhi = ax.get_ylim()
    ax.set_ylim(ylo, yhi + 0.15 * (yhi - ylo))
    what = f" — {label}" if label else ""
    ax.set_title(f"cf. Oe 2010 Fig. 7 — fitness per generation{what}", fontsize=11)
    return finish(fig, path)


def _require(tr: Trajectory | None, what: str) -> Trajectory:
    if tr is None:
        raise ValueError(f"the {what} carries no trajectory to draw")
    return tr


def fig8_flight(level: LevelResult, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 8: the evolved controller's flight from 0 m in still air, altitude ``y`` (m)
    against forward distance ``z`` (m) over the whole flight (20 s), with the level band
    (±``LEVEL_BAND_M`` m), the point where ``z`` = 20 m is reached and the paper's numbers
    (initial drop ≈ 0.5 m, ``z`` = 20 m at ≈ 6.9 s)."""
    tr = _require(level.trajectory, "level result")
    n = level.numbers
    fig = _new_figure(10.0, 4.6)
    ax = fig.subplots()
    ax.axhspan(-LEVEL_BAND_M, LEVEL_BAND_M, color="tab:green", alpha=0.12, label=f"level band ±{LEVEL_BAND_M:g} m")
    ax.axhline(-PAPER_E6["initial_drop_m"], color="tab:red", lw=0.8, ls="--",
               label=f"paper: initial drop ≈ {PAPER_E6['initial_drop_m']:g} m")
    _target_line(ax)
    ax.plot(tr.z, tr.y, "k-", lw=0.9, label="evolved controller")
    if level.time_to_z20_s is not None:
        ax.axvline(20.0, color="tab:blue", lw=0.8, ls="--",
                   label=f"z = 20 m at t = {level.time_to_z20_s:.2f} s (paper ≈ {PAPER_E6['time_to_z20_s']:g} s)")
    ylim = _altitude_window([-0.6, 0.4], [tr.y], min_pad_m=0.2)
    ax.set_ylim(*ylim)
    _mark_exits(ax, tr.z, tr.y, "k", ylim, float(tr.t[-1]))
    ax.set_xlabel("forward distance z [m]")
    ax.set_ylabel("altitude y [m]")
    ax.set_xlim(left=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    note = (f"ours: initial drop {n['initial_drop_m']:.2f} m, settled y in [{n['settled_altitude_min_m']:+.3f}, "
            f"{n['settled_altitude_max_m']:+.3f}] m,\nmean forward speed {n['mean_forward_speed_cm_s']:.0f} cm/s, "
            f"ripple {n['ripple_cm']:.1f} cm; holds level: {'yes' if n.get('holds_level') else 'no'}")
    ax.text(0.01, 0.97, note, transform=ax.transAxes, va="top", fontsize=8, bbox=_BOX)
    ax.set_title(f"cf. Oe 2010 Fig. 8 — optimized flight from 0 m in still air ({tr.t[-1] - tr.t[0]:g} s)", fontsize=11)
    return finish(fig, path)


def fig9_phi(level: LevelResult, path: str | os.PathLike | None = None, window_s: float = 3.0) -> Figure:
    """Oe 2010 Fig. 9: the pitch ``phi`` (deg) chosen by the network over the first ``window_s``
    seconds (3 s as in the paper), with the flap angle ``theta`` (deg) for reference and the
    ±30° pitch limits marked. A lower panel shows the altitude ``y`` (cm) and each flap cycle's
    minimum of ``phi`` (deg): the paper finds the maximum at 30° every cycle and the minimum
    tracking the altitude."""
    tr = _require(level.trajectory, "level result")
    m = tr.t <= tr.t[0] + window_s + 1e-9
    t = tr.t[m]
    fig = _new_figure(10.0, 6.4)
    ax, axy = fig.subplots(2, 1, sharex=True, height_ratios=[1.6, 1.0])
    ax.plot(t, np.degrees(tr.theta[m]), "-", color="tab:grey", lw=0.8, alpha=0.8, label="flap angle θ")
    ax.plot(t, np.degrees(tr.phi[m]), "-", color="tab:red", lw=1.3, label="pitch φ (network)")
    for s in (1, -1):
        ax.axhline(30.0 * s, color="k", lw=0.8, ls="--", label="φ limits ±30°" if s > 0 else None)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_ylabel("angle [deg]")
    ax.set_ylim(-75, 100)
    ax.set_yticks(np.arange(-60, 91, 30))
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", ncol=3, fontsize=8)
    n30 = int(np.sum(np.isclose(level.phi_max_per_cycle_deg, 30.0, atol=1e-6)))
    ncyc = len(level.phi_max_per_cycle_deg)
    ax.set_title(f"φ max = 30° in {n30} of {ncyc} flap cycles (paper: every cycle)", fontsize=9)

    axy.plot(t, 100.0 * tr.y[m], "k-", lw=1.0, label="altitude y")
    axy.axhline(0.0, color="k", lw=0.5, ls=":")
    axy.set_ylabel("altitude y [cm]")
    axy.set_xlabel("time t [s]")
    axy.grid(alpha=0.3)
    axp = axy.twinx()
    period = tr.flap_period_s
    k = min(len(level.phi_min_per_cycle_deg), int(math.floor(window_s / period + 1e-9)))
    centres = tr.t[0] + (np.arange(k) + 0.5) * period
    axp.plot(centres, level.phi_min_per_cycle_deg[:k], "o-", color="tab:red", ms=3.5, lw=0.8,
             label="φ min of each flap cycle")
    axp.set_ylabel("φ min per cycle [deg]", color="tab:red")
    axp.tick_params(axis="y", colors="tab:red")
    h1, l1 = axy.get_legend_handles_labels()
    h2, l2 = axp.get_legend_handles_labels()
    axy.legend(h1 + h2, l1 + l2, loc="lower right", fontsize=8, ncol=2)
    corr = level.corr_phi_min_altitude
    corr_txt = "n/a" if not np.isfinite(corr) else f"{corr:+.2f}"
    n_corr = min(30, len(level.phi_min_per_cycle_deg))  # as computed by e6_level
    axy.set_title(f"correlation of φ min per cycle with the cycle's mean altitude (first {n_corr} cycles): {corr_txt}",
                  fontsize=9)
    ax.set_xlim(tr.t[0], tr.t[0] + window_s)
    fig.suptitle(f"cf. Oe 2010 Fig. 9 — pitch φ of the evolved controller, first {window_s:g} s", fontsize=11)
    return finish(fig, path)


# ----------------------------------------------------------------------------------------------
# E7, E9: Fig. 11, 13


def _starts_figure(starts: StartsResult, path: str | os.PathLike | None, title: str, band_m: float, paper: str) -> Figure:
    """Every start of ``starts``: (a) altitude ``y`` (m) against forward distance ``z`` (m), the
    paper's axes; (b) altitude against time ``t`` (s), where a flight that drops without moving
    forward (a vertical line in (a)) can be seen."""
    if not starts.trajectories:
        raise ValueError("the starts result carries no trajectories to draw")
    fig = _new_figure(12.0, 5.4)
    ax, axt = fig.subplots(1, 2, sharey=True, width_ratios=[1.6, 1.0])
    trs = list(starts.trajectories.items())
    anchors = [0.0, band_m, -band_m] + [float(tr.y0) for _, tr in trs]
    ylim = _altitude_window(anchors, [tr.y for _, tr in trs])
    for a in (ax, axt):
        a.axhspan(-band_m, band_m, color="tab:green", alpha=0.12, label=f"within ±{band_m:g} m of the target")
        _target_line(a)
    for i, (label, tr) in enumerate(trs):
        num = starts.flights.get(label, {})
        t_near = num.get("time_to_within_0_5m_s")
        reach = "never within 0.5 m" if t_near is None else f"within 0.5 m at {t_near:.2f} s"
        ok = "holds 0 m" if num.get("reaches_target") else "does not hold 0 m"
        ax.plot(tr.z, tr.y, "-", color=_colour(i), lw=1.2,
                label=f"start {label}: y({tr.t[-1]:g} s) = {tr.y[-1]:+.2f} m, z({tr.t[-1]:g} s) = {tr.z[-1]:.1f} m; "
                      f"{reach}; {ok}")
        axt.plot(tr.t, tr.y, "-", color=_colour(i), lw=1.2)
        _mark_exits(ax, tr.z, tr.y, _colour(i), ylim, float(tr.t[-1]))
        _mark_exits(axt, tr.t, tr.y, _colour(i), ylim, float(tr.t[-1]))
    ax.set_ylim(*ylim)
    z_hi = max(float(np.nanmax(tr.z)) for _, tr in trs)
    ax.set_xlim(-0.02 * z_hi, 1.02 * z_hi)  # a flight dropping at z = 0 stays off the spine
    t0, t1 = min(float(tr.t[0]) for _, tr in trs), max(float(tr.t[-1]) for _, tr in trs)
    axt.set_xlim(t0 - 0.02 * (t1 - t0), t1)
    ax.set_xlabel("forward distance z [m]")
    ax.set_ylabel("altitude y [m]")
    axt.set_xlabel("time t [s]")
    ax.set_title("(a) altitude against forward distance (the paper's axes)", fontsize=10)
    axt.set_title("(b) altitude against time", fontsize=10)
    for a in (ax, axt):
        a.grid(alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=8)
    axt.text(0.98, 0.97, paper, transform=axt.transAxes, ha="right", va="top", fontsize=8, bbox=_BOX)
    fig.suptitle(title, fontsize=11)
    return finish(fig, path)


def fig11_from_above(starts: StartsResult, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 11: the flight from +10 m, altitude ``y`` (m) against forward distance
    ``z`` (m); the paper's controller descends to about 0 m and holds it."""
    return _starts_figure(starts, path, "cf. Oe 2010 Fig. 11 — flight from above the target (+10 m)", 0.5,
                          "paper: descends to ≈ 0 m and holds it")


def fig13_from_below(starts: StartsResult, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 13: flights from -10, -2 and -1 m, altitude ``y`` (m) against forward
    distance ``z`` (m); the paper's controller never climbs back to 0 m."""
    return _starts_figure(starts, path, "cf. Oe 2010 Fig. 13 — flights from below the target", 0.5,
                          "paper: fails to climb back to 0 m from every start")


# ----------------------------------------------------------------------------------------------
# E8: Fig. 12


def fig12_sink(glide: GlideResult, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 12: climb rate ``v_y`` (m/s) against time ``t`` (s) of the controller's
    flapping descent from +10 m ("Flapping") and of the glide from the same height (phi = 0,
    wings fixed at 75°, "Gliding"). The window over which the maximum sink speeds are compared
    (until the flapping flight first comes within 0.5 m of 0 m) is shaded, and both maxima are
    marked; the paper finds the glide sinking about twice as fast."""
    flap = _require(glide.flapping, "glide result's flapping flight")
    gl = _require(glide.gliding, "glide result's gliding flight")
    near = np.flatnonzero(flap.y <= 0.5)
    end = float(flap.t[near[0]] if len(near) else flap.t[-1])
    t_show = float(min(flap.t[-1], max(4.0, 2.0 * end + 1.0)))
    fig = _new_figure(10.0, 5.0)
    ax = fig.subplots()
    ax.axvspan(flap.t[0], end, color="tab:grey", alpha=0.12, label=f"compared: 0–{end:.2f} s (flapping reaches 0.5 m)")
    for tr, name, colour, vmax in ((flap, "Flapping (controller)", "tab:blue", glide.max_sink_flapping_m_s),
                                   (gl, "Gliding (φ = 0, θ = 75°)", "tab:red", glide.max_sink_gliding_m_s)):
        m = tr.t <= t_show + 1e-9
        ax.plot(tr.t[m], tr.vy[m], "-", color=colour, lw=0.9, label=f"{name}: max sink {vmax:.2f} m/s")
        ax.axhline(-vmax, color=colour, lw=0.8, ls="--")
    period = flap.flap_period_s
    cyc = np.floor((flap.t - flap.t[0]) / period + 1e-9).astype(int)
    n_cyc = int(math.floor((t_show - flap.t[0]) / period + 1e-9))
    if n_cyc >= 2:
        centres = flap.t[0] + (np.arange(n_cyc) + 0.5) * period
        means = [float(np.mean(flap.vy[cyc == c])) for c in range(n_cyc)]
        ax.plot(centres, means, "-", color="navy", lw=2.0, alpha=0.8, label="Flapping, mean over each flap cycle")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlim(0, t_show)
    ylo, yhi = ax.get_ylim()
    ax.set_ylim(ylo, yhi + 0.2 * (yhi - ylo))
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("climb rate v_y [m/s]")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    note = (f"max sink gliding / flapping: ours {glide.ratio:.2f}, paper ≈ {PAPER_E8_SINK_RATIO:g}\n"
            "(dashed lines: −max sink speed in the shaded window)")
    ax.text(0.99, 0.97, note, transform=ax.transAxes, ha="right", va="top", fontsize=8, bbox=_BOX)
    ax.set_title("cf. Oe 2010 Fig. 12 — climb rate of the flapping descent and of the glide from +10 m", fontsize=11)
    return finish(fig, path)


# ----------------------------------------------------------------------------------------------
# E10: Fig. 14, 15


#: Flights in wind that end within this altitude (m) are drawn whole in :func:`fig14_15_winds`.
LEVEL_SHOWN_M = 10.0


def _wind_passes(num: Mapping) -> bool:
    """The wind map's pass test on one flight's numbers: settled y within ±MAP_BAND_M, v_z >= 0."""
    return bool(abs(num.get("settled_altitude_min_m", np.inf)) <= MAP_BAND_M
                and abs(num.get("settled_altitude_max_m", np.inf)) <= MAP_BAND_M
                and num.get("settled_forward_speed_cm_s", -np.inf) >= 0.0)


def fig14_15_winds(winds: WindsResult, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 14 and 15: flights from 0 m in the four uniform 2 m/s winds, altitude ``y``
    (m) against forward distance ``z`` (m), one panel per input kind (network fed air-relative
    velocities, Fig. 14; ground velocities, Fig. 15), with the pass band ±1 m shaded. Each
    legend entry gives the altitude at the end and the wind map's pass/fail verdict."""
    if not winds.trajectories:
        raise ValueError("the winds result carries no trajectories to draw")
    kinds = list(winds.trajectories)
    fig = _new_figure(6.0 * len(kinds), 5.6)
    axes = np.atleast_1d(fig.subplots(1, len(kinds), sharey=True))
    all_y = [tr.y for k in kinds for tr in winds.trajectories[k].values()]
    # every flight that levels off (within +-LEVEL_SHOWN_M) is drawn whole; only falls and climbs leave the plot
    finals = [float(y[np.isfinite(y)][-1]) for y in all_y if np.isfinite(y).any()]
    ylim = _altitude_window([-MAP_BAND_M, MAP_BAND_M, *[f for f in finals if abs(f) <= LEVEL_SHOWN_M]], all_y,
                            min_pad_m=1.0)
    names = {"relative": "air-relative velocity inputs (cf. Fig. 14)", "ground": "ground velocity inputs (cf. Fig. 15)"}
    for j, (ax, kind) in enumerate(zip(axes, kinds)):
        ax.axhspan(-MAP_BAND_M, MAP_BAND_M, color="tab:green", alpha=0.12, label=f"pass band ±{MAP_BAND_M:g} m")
        _target_line(ax)
        exits = 0
        for i, (label, tr) in enumerate(winds.trajectories[kind].items()):
            colour = _WIND_COLOURS.get(label, _colour(i))
            num = winds.flights.get(kind, {}).get(label, {})
            verdict = "pass" if _wind_passes(num) else "fail"
            ax.plot(tr.z, tr.y, "-", color=colour, lw=1.0,
                    label=f"wind {label}: y({tr.t[-1]:g} s) = {tr.y[-1]:+.2f} m, {verdict}")
            _mark_exits(ax, tr.z, tr.y, colour, ylim, float(tr.t[-1]), slot=exits)
            exits += int(bool(np.any(~np.isfinite(tr.y) | (tr.y < ylim[0]) | (tr.y > ylim[1]))))
        ax.set_ylim(*ylim)
        ax.set_xlim(left=min(0.0, ax.get_xlim()[0]))
        ax.set_xlabel("forward distance z [m]")
        if j == 0:
            ax.set_ylabel("altitude y [m]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), fontsize=8)
        ax.set_title(f"({chr(ord('a') + j)}) {names.get(kind, kind + ' inputs')}", fontsize=10)
    fig.suptitle("cf. Oe 2010 Fig. 14, 15 — flights in uniform 2 m/s winds (a, b) [m/s], named by where the wind "
                 "comes from", fontsize=11)
    return finish(fig, path)


# ----------------------------------------------------------------------------------------------
# E11: Fig. 15 "boundary"


def _map_codes(m: WindMap) -> np.ndarray:
    """Category index (see ``_MAP_CATEGORIES``) of every cell of ``m``, shape ``(len(b), len(a))``."""
    smin = np.asarray(m.settled_min_m, dtype=float)
    smax = np.asarray(m.settled_max_m, dtype=float)
    v = np.asarray(m.forward_speed_m_s, dtype=float)
    codes = np.full(smin.shape, 3, dtype=int)
    codes[v < 0] = 3
    codes[smax > MAP_BAND_M] = 2
    codes[smin < -MAP_BAND_M] = 1
    codes[~(np.isfinite(smin) & np.isfinite(smax) & np.isfinite(v))] = 4
    codes[np.asarray(m.passed, dtype=bool)] = 0
    return codes


def fig_windmap(maps: Sequence[WindMap] | WindMap, path: str | os.PathLike | None = None,
                titles: Sequence[str] | None = None) -> Figure:
    """Oe 2010 Fig. 15 "boundary": pass/fail of the settled flight over a grid of uniform winds,
    one panel per map (e.g. relative and ground inputs side by side, or two controllers).

    x axis: horizontal wind ``a`` (m/s, > 0 from the front); y axis: vertical wind ``b`` (m/s,
    > 0 from above). A cell passes when the altitude over the last 10 s stays within ±1 m and the
    mean forward speed there is >= 0; failing cells are coloured by the first reason that applies
    (diverged, below the band, above the band, backwards). The paper's four 2 m/s winds are marked
    and each panel's title gives ``pass_cells/total_cells``. ``titles`` defaults to the maps'
    input kinds.
    """
    maps = [maps] if isinstance(maps, WindMap) else list(maps)
    if not maps:
        raise ValueError("no wind map to draw")
    if titles is not None and len(titles) != len(maps):
        raise ValueError(f"{len(titles)} titles for {len(maps)} maps")
    n = len(maps)
    fig = _new_figure(min(max(6.8, 5.4 * n), 18.0), 5.9 if n > 1 else 6.6)
    axes = np.atleast_1d(fig.subplots(1, n, sharey=True, squeeze=False)[0])
    cmap = ListedColormap([c for _, c in _MAP_CATEGORIES])
    used: set[int] = set()
    for j, (ax, m) in enumerate(zip(axes, maps)):
        a = np.asarray(m.winds_a, dtype=float)
        b = np.asarray(m.winds_b, dtype=float)
        da = float(a[1] - a[0]) if len(a) > 1 else 1.0
        db = float(b[1] - b[0]) if len(b) > 1 else 1.0
        codes = _map_codes(m)
        used.update(int(c) for c in np.unique(codes))
        ax.imshow(codes, origin="lower", cmap=cmap, vmin=-0.5, vmax=len(_MAP_CATEGORIES) - 0.5, interpolation="nearest",
                  extent=(a[0] - da / 2, a[-1] + da / 2, b[0] - db / 2, b[-1] + db / 2), aspect="equal")
        if len(a) <= 31 and len(b) <= 31:  # coarse grids: show the cell edges
            for x in np.append(a - da / 2, a[-1] + da / 2):
                ax.axvline(x, color="white", lw=0.4)
            for y in np.append(b - db / 2, b[-1] + db / 2):
                ax.axhline(y, color="white", lw=0.4)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.axvline(0.0, color="k", lw=0.6)
        for label, (wa, wb) in PAPER_WINDS.items():
            ax.plot([wa], [wb], marker="*", ms=13, color="white", mec="k", mew=1.0, ls="none")
            ax.annotate(label, (wa, wb), xytext=(0, 9), textcoords="offset points", ha="center", fontsize=7.5,
                        bbox={"boxstyle": "round,pad=0.15", "fc": "white", "alpha": 0.8, "lw": 0})
        ax.set_xlabel("a: horizontal wind [m/s] (+ from the front)")
        if j == 0:
            ax.set_ylabel("b: vertical wind [m/s] (+ from above)")
        name = titles[j] if titles is not None else f"{m.inputs} velocity inputs"
        pct = 100.0 * m.pass_cells / m.total_cells if m.total_cells else 0.0
        ax.set_title(f"{name}\n{m.pass_cells}/{m.total_cells} cells pass ({pct:.0f} %)", fontsize=10)
    handles = [Patch(fc=_MAP_CATEGORIES[k][1], ec="k", lw=0.5, label=_MAP_CATEGORIES[k][0]) for k in sorted(used)]
    handles.append(Patch(fc="white", ec="white", label="★ the paper's 2 m/s winds"))
    fig.legend(handles=handles, loc="outside lower center", ncol=1 if n == 1 else min(3, len(handles)),
               fontsize=8.5)
    a0 = np.asarray(maps[0].winds_a, dtype=float)
    step = float(a0[1] - a0[0]) if len(a0) > 1 else 0.0
    fig.suptitle(f'cf. Oe 2010 Fig. 15 "boundary" — wind map, grid step {step:g} m/s\n'
                 f"(pass: settled y within ±{MAP_BAND_M:g} m over the last 10 s and forward speed ≥ 0)", fontsize=11)
    return finish(fig, path)


# ----------------------------------------------------------------------------------------------
# comparisons beyond the paper


def fig_compare_starts(trajs: Mapping[str, Trajectory], path: str | os.PathLike | None, title: str) -> Figure:
    """Several labelled flights side by side: altitude ``y`` (m) against time ``t`` (s), e.g. two
    controllers started from -10 m. ``title`` should name the paper figure compared with (for
    example ``"cf. Oe 2010 Fig. 13 — ann_paper vs ann_robust from -10 m"``)."""
    if not trajs:
        raise ValueError("no trajectories to draw")
    fig = _new_figure(10.0, 5.0)
    ax = fig.subplots()
    items = list(trajs.items())
    ylim = _altitude_window([0.0, 0.5, -0.5] + [float(tr.y0) for _, tr in items], [tr.y for _, tr in items])
    ax.axhspan(-0.5, 0.5, color="tab:green", alpha=0.12, label="within ±0.5 m of the target")
    _target_line(ax)
    for i, (label, tr) in enumerate(items):
        near = np.flatnonzero(np.abs(tr.y) <= 0.5)
        reach = f"within 0.5 m at {tr.t[near[0]]:.2f} s" if len(near) else "never within 0.5 m"
        ax.plot(tr.t, tr.y, "-", color=_colour(i), lw=1.0,
                label=f"{label}: start {tr.y0:+g} m, y({tr.t[-1]:g} s) = {tr.y[-1]:+.2f} m, {reach}")
        _mark_exits(ax, tr.t, tr.y, _colour(i), ylim, float(tr.t[-1]))
    ax.set_ylim(*ylim)
    ax.set_xlim(min(float(tr.t[0]) for _, tr in items), max(float(tr.t[-1]) for _, tr in items))
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("altitude y [m]")
    ax.grid(alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", fontsize=8)
    ax.set_title(title, fontsize=11)
    return finish(fig, path)


def _best_on_grid(run: Sequence[Mapping], grid: np.ndarray) -> np.ndarray:
    """A run's best-so-far fitness as a step function of the evaluations, sampled on ``grid``;
    NaN before its first record and after its last."""
    ev = np.array([float(h["evaluations"]) for h in run])
    best = np.array([float(h["best"]) for h in run])
    ok = np.isfinite(ev) & np.isfinite(best)
    ev, best = ev[ok], best[ok]
    out = np.full(grid.shape, np.nan)
    if not ev.size:
        return out
    idx = np.searchsorted(ev, grid, side="right") - 1
    inside = (idx >= 0) & (grid <= ev[-1])
    out[inside] = best[idx[inside]]
    return out


def fig_optimizer_convergence(runs: Mapping[str, Sequence[Sequence[Mapping]]], path: str | os.PathLike | None = None,
                              log_x: bool | None = None) -> Figure:
    """Best fitness so far (``H`` of eq. 13, dimensionless) against the number of fitness
    evaluations for several optimisers, cf. Oe 2010 Fig. 7.

    ``runs`` maps an optimiser's name to its runs (one per seed), each a history list of dicts
    with keys ``evaluations`` (cumulative) and ``best`` (best so far). Each seed is drawn thin;
    the median over the seeds (taken where every seed has a record) is drawn thick. ``log_x``
    (default: when the evaluations span more than a factor 50) puts the evaluations on a log axis.
    """
    runs = {k: [r for r in v if r] for k, v in runs.items()}
    runs = {k: v for k, v in runs.items() if v}
    if not runs:
        raise ValueError("no optimiser history to draw")
    all_ev = np.array([float(h["evaluations"]) for v in runs.values() for r in v for h in r])
    all_ev = all_ev[np.isfinite(all_ev) & (all_ev > 0)]
    if log_x is None:
        log_x = bool(all_ev.size and all_ev.max() / all_ev.min() > 50)
    fig = _new_figure(9.0, 5.2)
    ax = fig.subplots()
    for i, (name, seeds) in enumerate(runs.items()):
        colour = _colour(i)
        grid = np.unique(np.concatenate([[float(h["evaluations"]) for h in r] for r in seeds]))
        vals = np.array([_best_on_grid(r, grid) for r in seeds])
        for v in vals:
            ax.step(grid, v, where="post", color=colour, lw=0.7, alpha=0.45)
        full = np.all(np.isfinite(vals), axis=0)
        if full.any():
            med = np.median(vals[:, full], axis=0)
            finals = [float(v[np.isfinite(v)][-1]) for v in vals if np.isfinite(v).any()]
            ax.step(grid[full], med, where="post", color=colour, lw=2.4,
                    label=f"{name}: median of {len(seeds)} seed(s), final median {np.median(finals):.5g}")
        else:
            ax.plot([], [], color=colour, lw=2.4, label=f"{name}: {len(seeds)} seed(s), no common range")
    if log_x:
        ax.set_xscale("log")
    ax.set_xlabel("fitness evaluations (cumulative)" + (" — log scale" if log_x else ""))
    ax.set_ylabel("best fitness so far H (eq. 13) [–]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(loc="best", fontsize=8.5, title="thick: median over seeds; thin: each seed", title_fontsize=8)
    ax.set_title("cf. Oe 2010 Fig. 7 — convergence of the optimisers (best so far per evaluation)", fontsize=11)
    return finish(fig, path)
