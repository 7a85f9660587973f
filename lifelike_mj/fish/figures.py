"""Figures of the fish swims, after Satoi, Nakadai, Hoshino 2015 ("Satoi 2015"; life-like tropical fish).

* :func:`tracks_figure`: horizontal and vertical position of one fish against time over 30 s, with
  its *accelerate* motion units marked, and its path in the side view (Satoi 2015 Fig. 7 and 8);
* :func:`accel_histogram_figure`: the histogram of the tangential acceleration seen from the side
  at 24 frames/s, in body lengths/s^2 (Satoi 2015 Fig. 2 for real fish, Fig. 7 and 8 simulated);
* :func:`patterns_figure`: the four motion patterns NB-ND, NB-D, B-ND, B-D on the objective measures
  (burstiness, kurtosis of the acceleration, turning entropy) that stand in for the paper's
  questionnaire (Satoi 2015 Fig. 10-12);

The figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas, without pyplot (the
process's matplotlib backend is never changed); every PNG is written atomically (a temporary file
beside it, then renamed).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.figure import Figure

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.render.plot import finish, png_path
from lifelike_mj.render.plot import new_figure as _new_figure

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.fish.sim import SwimResult

#: The paper's four motion patterns (Satoi 2015 section 5.1.1), in the order of its figures.
PATTERN_ORDER = ("NB-ND", "NB-D", "B-ND", "B-D")
_PATTERN_COLOURS = {"NB-ND": "tab:gray", "NB-D": "tab:green", "B-ND": "tab:orange", "B-D": "tab:blue"}
#: The measures of :func:`patterns_figure`: key, axis label, what the paper's ratings imply.
PATTERN_MEASURES = (
    ("burstiness", "burstiness of acceleration events\n(Kim & Jo A_n; -1 periodic, 0 Poisson, 1 bursty)",
     "expected: B-* above NB-*"),
    ("accel_kurtosis", "excess kurtosis of the side-view\nacceleration (24 fps)", "expected: B-* above NB-*"),
    ("turn_entropy", "entropy of turning angles\nover 0.25 s (bits)", "expected: *-D above *-ND"),
)


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``(start, end)`` index pairs (end exclusive) of the runs of True in a 1-D boolean array."""
    m = np.concatenate(([False], np.asarray(mask, dtype=bool), [False]))
    edges = np.flatnonzero(m[1:] != m[:-1])
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _shade(ax, t: np.ndarray, mask: np.ndarray, dt: float, colour: str, label: str, y0: float = 0.0,
           y1: float = 1.0, alpha: float = 0.35) -> None:
    """Shade the time spans where ``mask`` holds (a sample ``t[i]`` covers ``[t[i] - dt, t[i]]``: the
    control step that led to it) from ``y0`` to ``y1`` in axes coordinates."""
    trans = ax.get_xaxis_transform()
    for n, (a, b) in enumerate(_runs(mask)):
        ax.axvspan(t[a] - dt, t[b - 1], ymin=y0, ymax=y1, color=colour, alpha=alpha, lw=0,
                   label=label if n == 0 else None, transform=trans)


def tracks_figure(result: SwimResult, out_path: str | os.PathLike | None = None, fish: int = 0,
                  duration_s: float = 30.0) -> Figure:
    """Satoi 2015 Fig. 7/8 style: the tracks of fish ``fish`` over the first ``duration_s`` s (or
    the whole swim if shorter), written as a PNG.

    Three panels: the horizontal position x (m, along the tank) and the vertical position z (m,
    above the floor) against time (s), with the control steps whose motion unit was *accelerate*
    shaded and those spent avoiding a wall marked by a bar along the bottom; and the path in the
    side view (x against z, true aspect, the tank's walls dashed), from a circle (start) to a
    square (end). ``result``: a :class:`~lifelike_mj.fish.sim.SwimResult`. Returns the path written.
    """
    out = None if out_path is None else png_path(out_path, "tracks figure")
    n = result.n_fish
    if not checks.is_whole(fish) or not 0 <= fish < n:
        raise UserError(f"fish must be a whole number from 0 to {n - 1}, got {fish!r}.")
    if not checks.is_number(duration_s) or not duration_s > 0:
        raise UserError(f"duration must be a positive number of seconds, got {duration_s!r}.")
    t_all = np.asarray(result.times_s, dtype=float)
    keep = t_all <= t_all[0] + duration_s + 1e-9
    t = t_all[keep]
    pos = np.asarray(result.positions)[keep, fish, :]
    mu = np.asarray(result.mu)[keep, fish]
    accel = (mu % 4) == 0
    avoid = mu >= 4
    accel[0] = avoid[0] = False  # row 0 is the initial state, no control step led to it
    dt = float(np.median(np.diff(t_all))) if t_all.size > 1 else 0.0
    L, _D, H = result.tank_m
    name = result.params.name or "custom"
    span = float(t[-1] - t[0])

    fig = _new_figure(11.0, 8.0)
    grid = fig.add_gridspec(3, 1, height_ratios=(1.0, 1.0, 1.25))
    ax_x = fig.add_subplot(grid[0])
    ax_z = fig.add_subplot(grid[1], sharex=ax_x)
    ax_p = fig.add_subplot(grid[2])
    for ax, col, label, lo, hi in ((ax_x, 0, "horizontal position x (m)", -L / 2, L / 2),
                                   (ax_z, 2, "vertical position z (m)", 0.0, H)):
        _shade(ax, t, accel, dt, "tab:red", "accelerate MU", alpha=0.3)
        _shade(ax, t, avoid, dt, "k", "avoiding a wall", y0=0.0, y1=0.04, alpha=0.6)
        ax.plot(t, pos[:, col], color="tab:blue", lw=1.2, label=f"fish {fish}")
        for wall in (lo, hi):
            ax.axhline(wall, color="0.4", ls="--", lw=0.8)
        pad = 0.03 * (hi - lo)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    ax_x.legend(loc="upper right", fontsize=8, ncols=3)
    ax_z.set_xlabel("time (s)")
    ax_x.set_xlim(t[0], t[-1])
    ax_x.set_title(f"Horizontal and vertical track of fish {fish} over {span:.0f} s, preset {name} "
                   f"(cf. Satoi 2015 Fig. 7 and 8); shaded: accelerate MU "
                   f"({100.0 * accel[1:].mean():.0f} % of control steps)", fontsize=10)

    ax_p.plot([-L / 2, L / 2, L / 2, -L / 2, -L / 2], [0.0, 0.0, H, H, 0.0], color="0.4", ls="--", lw=0.8)
    ax_p.plot(pos[:, 0], pos[:, 2], color="tab:blue", lw=0.9)
    ax_p.plot(pos[accel, 0], pos[accel, 2], ".", color="tab:red", ms=2.5, label="accelerate MU")
    ax_p.plot(pos[0, 0], pos[0, 2], "o", color="k", ms=6, mfc="none", label=f"start (t = {t[0]:.0f} s)")
    ax_p.plot(pos[-1, 0], pos[-1, 2], "s", color="k", ms=6, mfc="none", label=f"end (t = {t[-1]:.0f} s)")
    ax_p.set_aspect("equal")
    ax_p.set_xlim(-L / 2 - 0.02 * L, L / 2 + 0.02 * L)
    ax_p.set_ylim(-0.05 * H, 1.05 * H)
    ax_p.set_xlabel("x (m, along the tank)")
    ax_p.set_ylabel("z (m)")
    ax_p.set_title(f"Path in the side view (tank {L:g} m x {H:g} m, dashed)", fontsize=10)
    ax_p.legend(loc="upper left", fontsize=8, ncols=3)
    return finish(fig, out)


def side_accelerations_bl(result: SwimResult, body_length_m: float = 0.07, fps: float | None = None) -> np.ndarray:
    """Side-view tangential accelerations of every fish in body lengths/s^2, shape (N - 2, F): the
    tracks resampled at ``fps`` frames/s (default the paper's 24), projected on the side view (x, z)
    and differentiated twice (:mod:`lifelike_mj.fish.metrics`), divided by ``body_length_m`` (m)."""
    from lifelike_mj.fish.metrics import VIDEO_FPS, resample, side_view, speed_and_accel

    rate = VIDEO_FPS if fps is None else fps
    _t, p = resample(result.times_s, result.positions, rate)
    _speed, accel = speed_and_accel(side_view(p), rate)
    return accel / body_length_m


def accel_histogram_figure(result: SwimResult, out_path: str | os.PathLike | None = None, body_length_m: float = 0.07) -> Figure:
    """Satoi 2015 Fig. 2/7/8 style: histogram of the tangential acceleration in the side view, pooled
    over the fish, in body lengths/s^2, written as a PNG.

    As the paper's video analysis: the tracks at 24 frames/s, side view (x, z), speed from frame to
    frame, acceleration from speed to speed (:func:`side_accelerations_bl`). 41 bins over +-the
    99th percentile of |a| (:func:`lifelike_mj.fish.metrics.accel_histogram`); the zero line and the
    histogram's mode are drawn, and the mode, the share of positive samples, the skewness and the
    excess kurtosis are printed. ``body_length_m``: m (the model fish: 0.07). Returns the path.
    """
    from lifelike_mj.fish.metrics import VIDEO_FPS, accel_histogram, histogram_summary, kurtosis

    out = None if out_path is None else png_path(out_path, "acceleration histogram")
    if not checks.is_number(body_length_m) or not body_length_m > 0:
        raise UserError(f"the body length must be a positive number of m, got {body_length_m!r}.")
    a = side_accelerations_bl(result, body_length_m)
    finite = a[np.isfinite(a)]
    if finite.size < 4:
        raise UserError("the swim is too short for an acceleration histogram (it needs at least 0.25 s).")
    counts, edges = accel_histogram(finite, bins=41)
    summary = histogram_summary(finite, bins=41)
    centres = 0.5 * (edges[:-1] + edges[1:])
    name = result.params.name or "custom"
    span = float(result.times_s[-1] - result.times_s[0])

    fig = _new_figure(8.0, 5.0)
    ax = fig.subplots()
    ax.bar(centres, counts, width=np.diff(edges), color="tab:blue", alpha=0.75, edgecolor="white", lw=0.5,
           label=f"{finite.size} frames, {result.n_fish} fish pooled")
    ax.axvline(0.0, color="k", lw=1.0, label="zero acceleration")
    ax.axvline(summary["mode"], color="tab:red", ls="--", lw=1.5,
               label=f"mode {summary['mode']:+.2f} body lengths/s$^2$")
    ax.set_xlabel("tangential acceleration in the side view (body lengths/s$^2$)")
    ax.set_ylabel(f"count of {VIDEO_FPS:g} fps frames")
    ax.set_xlim(edges[0], edges[-1])
    ax.grid(alpha=0.3, axis="y")
    ax.legend(loc="upper right", fontsize=8)
    ax.text(0.02, 0.97, f"positive: {100.0 * summary['fraction_positive']:.0f} %\n"
            f"skewness: {summary['skewness']:+.2f}\nexcess kurtosis: {kurtosis(finite):.1f}\n"
            f"(outside +-{edges[-1]:.1f}: {finite.size - int(counts.sum())} frames)",
            transform=ax.transAxes, va="top", ha="left", fontsize=8,
            bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": "0.7", "alpha": 0.9})
    ax.set_title(f"Side-view acceleration at {VIDEO_FPS:g} fps, preset {name}, {span:.0f} s "
                 "(cf. Satoi 2015 Fig. 2 real fish, Fig. 7/8 simulated)", fontsize=10)
    return finish(fig, out)


def patterns_figure(rows: list[dict], out_path: str | os.PathLike | None = None) -> Figure:
    """Satoi 2015 Fig. 10-12 stand-in: the four motion patterns NB-ND, NB-D, B-ND, B-D (not bursty /
    bursty, not diverse / diverse) compared on the objective measures that replace the paper's
    questionnaire ratings, written as a PNG.

    ``rows``: one dict per swim with ``"preset"`` (str), ``"seed"`` (int) and the measures
    ``"burstiness"`` (Kim & Jo A_n of the acceleration events, dimensionless), ``"accel_kurtosis"``
    (excess kurtosis of the side-view acceleration, dimensionless) and ``"turn_entropy"`` (bits),
    as :func:`lifelike_mj.fish.experiments.pattern_table` produces; other keys are ignored. One
    panel per measure: a point per seed (slightly spread sideways) and the median over seeds (bar
    and value); the paper's four patterns first, any other preset after them. Non-finite values
    are left out. Returns the path written.
    """
    out = None if out_path is None else png_path(out_path, "patterns figure")
    if not isinstance(rows, (list, tuple)) or not rows:
        raise UserError("the patterns figure needs at least one row of measures.")
    for i, r in enumerate(rows):
        if not isinstance(r, dict):
            raise UserError(f"row {i} of the patterns figure is not a dict of measures.")
        missing = [k for k in ("preset", *(m[0] for m in PATTERN_MEASURES)) if k not in r]
        if missing:
            raise UserError(f"row {i} of the patterns figure lacks {', '.join(missing)}.")
    present = {str(r["preset"]) for r in rows}
    presets = [p for p in PATTERN_ORDER if p in present] + sorted(present - set(PATTERN_ORDER))
    seeds = sorted({r.get("seed") for r in rows}, key=lambda s: (s is None, s))

    fig = _new_figure(4.0 * len(PATTERN_MEASURES) + 0.5, 4.8)
    axes = fig.subplots(1, len(PATTERN_MEASURES))
    for ax, (key, label, expected) in zip(np.atleast_1d(axes), PATTERN_MEASURES):
        for i, preset in enumerate(presets):
            vals = np.array([float(r[key]) for r in rows if str(r["preset"]) == preset
                             and r[key] is not None], dtype=float)
            vals = vals[np.isfinite(vals)]
            colour = _PATTERN_COLOURS.get(preset, "tab:purple")
            if vals.size:
                spread = np.linspace(-0.15, 0.15, vals.size) if vals.size > 1 else np.zeros(1)
                ax.plot(i + spread, vals, "o", color=colour, ms=5, alpha=0.7, mfc="none")
                med = float(np.median(vals))
                ax.plot([i - 0.3, i + 0.3], [med, med], color=colour, lw=2.5)
                ax.annotate(f"{med:.3g}", (i + 0.32, med), va="center", fontsize=8, color=colour)
        ax.set_xticks(range(len(presets)), presets)
        ax.set_xlim(-0.6, len(presets) - 0.4)
        ax.set_ylabel(label, fontsize=9)
        ax.set_title(expected, fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    seed_text = f"{len(seeds)} seed{'s' if len(seeds) != 1 else ''}"
    fig.suptitle(f"The four motion patterns (Satoi 2015 Fig. 10-12) on objective measures in place of the "
                 f"questionnaire: one point per seed ({seed_text}), bar = median", fontsize=10)
    return finish(fig, out)


__all__ = ["PATTERN_ORDER", "accel_histogram_figure", "patterns_figure", "side_accelerations_bl", "tracks_figure"]


def group_figure(result: SwimResult, out_path: str | os.PathLike | None = None, body_length_m: float = 0.07) -> Figure:
    """The measures of fish living together (:mod:`lifelike_mj.fish.shoal`), from the tracks alone, in eight panels:
    the nearest-neighbour distance, the polarisation and milling over time, the cohesion and the spread of depths over
    time, the intervals between kicks, the speed, the distance to the nearest side wall (histograms, body lengths and
    seconds), where the neighbours are in a fish's own frame (ahead, to its left; a 2-D histogram within 10 body
    lengths, the maps of Calovi et al. 2018) and how they head relative to it (a histogram of the heading
    difference)."""
    from lifelike_mj.fish import shoal

    if not checks.is_number(body_length_m) or not body_length_m > 0:
        raise UserError(f"the body length must be a positive number of m, got {body_length_m!r}.")
    t, p, bl = result.times_s, result.positions, float(body_length_m)
    if t.size < 3:
        raise UserError("the swim is too short for the group measures (it needs at least three samples).")
    m = shoal.group_measures(t, p, bl, result.tank_m)
    vel = shoal.velocities(t, p)
    head = shoal.headings(vel, shoal.MIN_SPEED_BL_S * bl)
    speed = np.linalg.norm(vel, axis=-1)
    iv = shoal.kick_intervals_s(t, speed, shoal.KICK_RISE_BL_S * bl)
    fig = _new_figure(17.0, 7.5)
    axs = fig.subplots(2, 4)
    name = result.params.name or "custom"
    fig.suptitle(f"{result.n_fish} {name} fish, {float(t[-1] - t[0]):g} s (seed {result.seed}): living together, "
                 "from the tracks alone")
    nn = shoal.nearest_neighbour_m(p) / bl
    ax = axs[0, 0]
    if np.isfinite(nn).any():
        ax.hist(nn[np.isfinite(nn)].ravel(), bins=40, color="tab:blue", alpha=0.8)
        ax.axvline(m["nn_distance_bl"]["median"], color="tab:red", ls="--",
                   label=f"median {m['nn_distance_bl']['median']:.1f} BL")
        ax.legend(fontsize=8)
    ax.set_xlabel("nearest-neighbour distance (body lengths)")
    ax.set_ylabel("fish x samples")
    ax = axs[0, 1]
    ax.plot(t, shoal.polarisation(head), lw=0.8, label=f"polarisation O_P (mean {m['polarisation']:.2f})")
    ax.plot(t, shoal.milling(p, head), lw=0.8, label=f"milling O_R (mean {m['milling']:.2f})")
    ax.axhline(0.65, color="k", lw=0.6, ls=":")
    ax.axhline(0.35, color="k", lw=0.6, ls=":")
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("order parameter")
    ax.legend(fontsize=8, loc="upper right")
    ax = axs[0, 2]
    ax.plot(t, shoal.cohesion_m(p) / bl, lw=0.8, color="tab:brown", label=f"cohesion (mean {m['cohesion_bl']:.1f} BL)")
    ax.plot(t, shoal.depth_spread_m(p) / bl, lw=0.8, color="tab:cyan",
            label=f"spread of depths (mean {m['depth_spread_bl']:.1f} BL)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("body lengths")
    ax.legend(fontsize=8, loc="upper right")
    ax = axs[0, 3]
    k = m["kick_interval_s"]
    if iv.size:
        ax.hist(iv, bins=np.arange(0.0, max(2.0, float(np.percentile(iv, 99))) + 0.05, 1.0 / 30.0), color="tab:green",
                alpha=0.8, label=f"mean {k['mean']:.2f} s, CV {k['cv']:.2f}\n5th percentile {k['p5']:.2f} s\n"
                f"(a kick: a speed rise of {shoal.KICK_RISE_BL_S:g} BL/s or more)")
        ax.legend(fontsize=8)
    ax.set_xlabel("interval between a fish's kicks (s)")
    ax.set_ylabel("intervals")
    ax = axs[1, 0]
    ax.hist((speed / bl).ravel(), bins=40, color="tab:orange", alpha=0.8,
            label=f"median {m['speed_bl_s']['median']:.2f} BL/s")
    ax.legend(fontsize=8)
    ax.set_xlabel("speed (body lengths/s)")
    ax.set_ylabel("fish x samples")
    ax = axs[1, 1]
    w = shoal.wall_distance_m(p, result.tank_m) / bl
    ax.hist(w.ravel(), bins=40, color="tab:purple", alpha=0.8,
            label=f"median {m['wall_distance_bl']['median']:.1f} BL")
    ax.legend(fontsize=8)
    ax.set_xlabel("distance to the nearest side wall (body lengths)")
    ax.set_ylabel("fish x samples")
    ax = axs[1, 2]
    rel, dphi = shoal.neighbour_frame(p, head)
    rel = rel / bl
    if rel.size:
        ax.hist2d(rel[:, 1], rel[:, 0], bins=40, range=[[-10, 10], [-10, 10]], cmap="viridis")
    ax.plot([0.0], [0.0], marker="^", color="w", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("neighbour to the fish's left (body lengths)")
    ax.set_ylabel("neighbour ahead (body lengths)")
    ax.invert_xaxis()
    ax = axs[1, 3]
    if dphi.size:
        ad = np.degrees(np.abs(dphi))
        ax.hist(ad, bins=np.linspace(0.0, 180.0, 37), color="tab:gray", alpha=0.8,
                label=f"median {np.median(ad):.0f} deg")
        ax.legend(fontsize=8)
    ax.set_xlabel("a neighbour's heading less the fish's, |dphi| (deg)")
    ax.set_ylabel("fish pairs x samples")
    return finish(fig, out_path, "group figure")


#: The published values the pair figure marks (Calovi et al. 2018, the tetras' kicks and glides; tagged in
#: docs/results.md): the mean kick duration (s), its floor (s) and the glide's decay time (s).
CALOVI_KICK_MEAN_S, CALOVI_KICK_FLOOR_S, CALOVI_GLIDE_TAU_S = 0.5, 0.2, 0.8


def pair_figure(one: dict, two: dict, out_path: str | os.PathLike | None = None, title: str = "") -> Figure:
    """One fish against two, as Calovi et al. (2018) compare their tetras: six density histograms of
    :func:`lifelike_mj.fish.shoal.pair_quantities`' arrays, ``one`` (a lone fish's, pooled over runs) beside ``two``
    (two fish's): the distance to the nearest wall and the angle to it, the distance between the two fish and their
    heading difference, the kicks' durations and lengths. Dashed lines mark Calovi et al.'s mean kick duration and
    its floor."""
    for name, q in (("one", one), ("two", two)):
        if not isinstance(q, dict) or "wall_distance_bl" not in q:
            raise UserError(f"the pair figure's {name!r} must be fish.shoal.pair_quantities' dict.")
    if "distance_bl" not in two:
        raise UserError("the pair figure's 'two' must come from two fish or more.")
    fig = _new_figure(13.0, 7.5)
    axs = fig.subplots(2, 3)
    fig.suptitle(title or "one fish and two fish, from the tracks alone (densities)")
    panels = (("wall_distance_bl", "distance to the nearest side wall (body lengths)", np.linspace(0, 8, 33)),
              ("wall_angle_deg", "angle to the nearest wall (deg; 90 = along it)", np.linspace(0, 180, 37)),
              ("distance_bl", "distance between the two fish (body lengths)", np.linspace(0, 12, 49)),
              ("heading_difference_deg", "heading difference |dphi| (deg)", np.linspace(0, 180, 37)),
              ("kick_duration_s", "kick duration (s)", np.linspace(0, 2, 41)),
              ("kick_length_bl", "kick length (body lengths)", np.linspace(0, 6, 41)))
    for ax, (key, label, bins) in zip(axs.ravel(), panels, strict=True):
        for q, colour, who in ((one, "tab:blue", "one fish"), (two, "tab:orange", "two fish")):
            x = np.asarray(q.get(key, ()), dtype=float)
            x = x[np.isfinite(x)]
            if x.size:
                ax.hist(x, bins=bins, density=True, histtype="step", lw=1.6, color=colour,
                        label=f"{who}: median {np.median(x):.2f}")
        if key == "kick_duration_s":
            ax.axvline(CALOVI_KICK_MEAN_S, color="k", ls="--", lw=0.8, label="tetras' mean (Calovi et al.)")
            ax.axvline(CALOVI_KICK_FLOOR_S, color="k", ls=":", lw=0.8, label="tetras' floor (Calovi et al.)")
        ax.set_xlabel(label)
        ax.set_ylabel("density")
        ax.legend(fontsize=8)
    return finish(fig, out_path, "pair figure")
