"""The butterfly paper's figures (Oe 2010 Fig. 3, 4, 5 and the speed limit of section 4.3).

Each ``fig_*`` function draws one result of :mod:`lifelike_mj.butterfly.experiments` with the
same axes, quantities and units as the paper's figure, names the figure in its title and
annotates the paper's numbers where the paper states them, and returns the figure; given a path
it also writes the PNG atomically (a temporary file in the same folder, then ``os.replace``). The figures are built on
:class:`matplotlib.figure.Figure` with the Agg canvas, without pyplot, so drawing them never
changes the process's matplotlib backend.
"""

from __future__ import annotations

import os

import numpy as np
from matplotlib.figure import Figure

from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.render.plot import finish
from lifelike_mj.render.plot import new_figure as _new_figure

_DT_COLOURS = {"1/12000": "black", "1/1200": "tab:blue", "1/360": "tab:orange", "1/120": "tab:red"}
_SPEED_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple")


def fig3_forces(curves, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 3: ``F_y`` and ``F_z`` (mN, both wings, eq. 8-9 at ``theta = 0``) against the
    pitch ``phi`` (deg) for ``v_z`` = 0, 2, 4 m/s, upstroke (solid) and downstroke (dashed).

    ``curves`` is an :class:`~lifelike_mj.butterfly.aero.Fig3Curves`. The body weight ``m g``
    of the default swallowtail (3.1 mN) is drawn on the ``F_y`` panel for scale.
    """
    fig = _new_figure(11.0, 5.0)
    ax_y, ax_z = fig.subplots(1, 2, sharex=True)
    speeds = sorted({v for v, _ in curves.curves})
    for i, v in enumerate(speeds):
        colour = _SPEED_COLOURS[i % len(_SPEED_COLOURS)]
        for stroke, style in (("up", "-"), ("down", "--")):
            if (v, stroke) not in curves.curves:
                continue
            fy, fz = curves.curves[(v, stroke)]
            label = f"v_z = {v:g} m/s ({stroke})"
            ax_y.plot(curves.phi_deg, 1e3 * np.asarray(fy), style, color=colour, label=label)
            ax_z.plot(curves.phi_deg, 1e3 * np.asarray(fz), style, color=colour, label=label)
    default = ButterflyParams()
    weight_mn = default.mass_kg * default.gravity * 1e3
    ax_y.axhline(weight_mn, color="grey", lw=0.8, ls=":")
    ax_y.annotate(f"weight m g = {weight_mn:.2f} mN", (-88, weight_mn), xytext=(0, 3),
                  textcoords="offset points", fontsize=8, color="grey")
    for ax, name in ((ax_y, "F_y (up)"), (ax_z, "F_z (forward)")):
        ax.axhline(0.0, color="k", lw=0.6)
        ax.axvline(0.0, color="k", lw=0.6)
        ax.set_xlabel("pitch φ [deg]")
        ax.set_ylabel(f"{name} [mN]")
        ax.set_xlim(-90, 90)
        ax.set_xticks(np.arange(-90, 91, 30))
        ax.grid(alpha=0.3)
    fig.legend(*ax_z.get_legend_handles_labels(), loc="outside lower center", ncol=6, fontsize=8)
    ax_z.text(0.02, 0.02, "paper: as v_z grows both ranges widen,\nwhile the maximum of F_z decreases",
              transform=ax_z.transAxes, fontsize=8, va="bottom")
    fig.suptitle("Oe 2010 Fig. 3 — forces for the forward velocity (eq. 8–9, θ = 0, ω = ±62.8 rad/s)")
    return finish(fig, path)


def fig_speed_limit(sweep, path: str | os.PathLike | None = None) -> Figure:
    """Speed limit of Oe 2010 section 4.3 (cm/s, 1 cm/s steps) against the body area ``A_b``
    (cm^2) of eq. 10, with the paper's 380 cm/s and the points at 1.0 and 1.53 cm^2 marked.

    ``sweep`` is an :class:`~lifelike_mj.butterfly.experiments.SpeedLimitSweep`.
    """
    fig = _new_figure(7.5, 4.8)
    ax = fig.subplots()
    ax.plot(sweep.areas_cm2, sweep.limits_cm_s, color="tab:blue", label="ours: max_φ F_z(v_z) > |F_bz(v_z)|")
    ax.axhline(380, color="tab:red", ls="--", lw=1.0, label="paper: 380 cm/s")
    ax.plot([1.0], [sweep.limit_at_1cm2_cm_s], "o", color="k")
    ax.annotate(f"A_b = 1.0 cm² (default): {sweep.limit_at_1cm2_cm_s} cm/s", (1.0, sweep.limit_at_1cm2_cm_s),
                xytext=(10, 10), textcoords="offset points", fontsize=9)
    ax.plot([1.53], [sweep.limit_at_1_53cm2_cm_s], "s", color="tab:red")
    note = f"A_b = 1.53 cm²: {sweep.limit_at_1_53cm2_cm_s} cm/s\n(380 cm/s up to A_b = {sweep.area_at_380_cm2:.4f})"
    ax.annotate(note, (1.53, sweep.limit_at_1_53cm2_cm_s), xytext=(10, 12), textcoords="offset points", fontsize=9)
    ax.axvline(sweep.area_at_380_cm2, color="tab:red", lw=0.6, ls=":")
    ax.set_xlabel("body area A_b [cm²]")
    ax.set_ylabel("forward-speed limit v_z [cm/s]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9)
    ax.set_title("Oe 2010 section 4.3 — forward-speed limit against the body area (ω = 62.8 rad/s)", fontsize=10)
    return finish(fig, path)


def fig4_trim(trim, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 4: flight by the simple rule. Left: altitude ``y`` (m) against forward
    distance ``z`` (m) over the whole flight at the level angle and at level -/+ 0.5 deg.
    Right: a few flap cycles of the settled level flight, ``y`` in cm against ``z`` in m,
    showing the ripple (paper: about 5.3 cm).

    ``trim`` is a :class:`~lifelike_mj.butterfly.experiments.TrimResult` with its trajectories.
    """
    if trim.level is None:
        raise ValueError("the trim result carries no trajectories to draw")
    fig = _new_figure(12.0, 4.8)
    ax, axz = fig.subplots(1, 2, width_ratios=[1.6, 1.0])
    def trend(numbers: dict) -> str:
        return "climbs" if numbers.get("settled_climb_rate_cm_s", 0.0) > 0 else "descends"

    lines = [
        (trim.above_trajectory, trim.above.get("phi_up_deg"), "tab:red", "--", f"level + 0.5°: {trend(trim.above)}"),
        (trim.level, trim.phi_up_level_deg, "k", "-", "level"),
        (trim.below_trajectory, trim.below.get("phi_up_deg"), "tab:blue", "--", f"level − 0.5°: {trend(trim.below)}"),
    ]
    for tr, angle, colour, style, what in lines:
        if tr is None:
            continue
        ax.plot(tr.z, tr.y - tr.y0, style, color=colour, lw=0.8, label=f"φ_up = {angle:.3f}° ({what})")
    lv = trim.level
    ax.set_xlabel("forward distance z [m]")
    ax.set_ylabel("altitude y [m]")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower left", fontsize=9)
    ax.set_title(f"{trim.duration_s:g} s, RK4, dt = 1/{round(1 / trim.dt_s)} s, A_b = {trim.body_area_cm2:g} cm²",
                 fontsize=10)
    paper = (
        "paper: level at φ_up = 12.77°, 340 cm/s,\ninitial drop ≈ 3 m\n"
        f"ours: level at φ_up = {trim.phi_up_level_deg:.3f}°, {trim.mean_forward_speed_cm_s:.1f} cm/s,\n"
        f"initial drop {trim.initial_drop_m:.2f} m"
    )
    ax.text(0.02, 0.97, paper, transform=ax.transAxes, ha="left", va="top", fontsize=9,
            bbox={"boxstyle": "round", "fc": "white", "alpha": 0.85})
    # zoom: the last five flap cycles of the settled level flight
    mask = lv.t >= lv.t[-1] - 5.0 * lv.flap_period_s - 1e-12
    axz.plot(lv.z[mask], 100.0 * (lv.y[mask] - lv.y0), "k-", lw=1.0)
    axz.set_xlabel("forward distance z [m]")
    axz.set_ylabel("altitude y [cm]")
    axz.grid(alpha=0.3)
    axz.set_title("settled level flight, last 5 flap cycles", fontsize=10)
    note = f"ripple: paper ≈ 5.3 cm, ours {trim.ripple_cm:.2f} cm\n(mean peak-to-peak per cycle, last 10 s)"
    axz.text(0.02, 0.97, note, transform=axz.transAxes, va="top", fontsize=9,
             bbox={"boxstyle": "round", "fc": "white", "alpha": 0.85})
    ylo, yhi = axz.get_ylim()
    axz.set_ylim(ylo, yhi + 0.45 * (yhi - ylo))
    fig.suptitle("Oe 2010 Fig. 4 — flight by a simple rule (φ = φ_up on the upstroke, 0 on the downstroke)")
    return finish(fig, path)


def fig5_timestep(ts, path: str | os.PathLike | None = None) -> Figure:
    """Oe 2010 Fig. 5: variation of flights by the time step (``phi_up`` = 14 deg).
    (a) altitude ``y`` (m) against forward distance ``z`` (m), one point every 1 s, for
    dt = 1/12000, 1/1200, 1/360, 1/120 s; (b) altitude difference from the 1/12000 s run,
    ``y_ref - y_dt`` (m), every 1 s, on a log scale, with the paper's errors at 20 s (about 1 %
    at 1/1200 s and 10 % at 1/360 s of 15-16 m) marked.

    ``ts`` is a :class:`~lifelike_mj.butterfly.experiments.TimestepResult`.
    """
    fig = _new_figure(12.0, 4.8)
    ax_a, ax_b = fig.subplots(1, 2)
    for label in ts.altitude_every_1s_m:
        colour = _DT_COLOURS.get(label, None)
        ax_a.plot(ts.forward_every_1s_m[label], ts.altitude_every_1s_m[label], "o-", ms=3.5, lw=0.8,
                  color=colour, label=f"dt = {label} s: y(20 s) = {ts.altitude_20s_m[label]:.3f} m")
    ax_a.axhspan(15.0, 16.0, color="tab:green", alpha=0.15, label="paper: y(20 s) ≈ 15–16 m")
    ax_a.set_xlabel("forward distance z [m]")
    ax_a.set_ylabel("altitude y [m]")
    ax_a.grid(alpha=0.3)
    ax_a.legend(fontsize=8, loc="upper left")
    ax_a.set_title("(a) flight for twenty seconds (points every 1 s)", fontsize=10)
    t = np.asarray(ts.times_s)
    for label, diff in ts.altitude_diff_every_1s_m.items():
        d = np.abs(np.asarray(diff))
        keep = (t > 0) & (d > 0)
        if not keep.any():
            continue
        sign = "" if np.all(np.asarray(diff)[keep] > 0) else " (|y_ref − y|)"
        ax_b.semilogy(t[keep], d[keep], "o-", ms=3.5, lw=0.8, color=_DT_COLOURS.get(label),
                      label=f"dt = {label} s: {100 * ts.rel_error[label]:.3g} % at 20 s{sign}")
    ref20 = 15.5
    for label, frac in (("1/1200", 0.01), ("1/360", 0.10)):
        ax_b.plot([20.0], [frac * ref20], marker="*", ms=12, ls="none", color=_DT_COLOURS[label], mec="k",
                  label=f"paper, dt = {label} s: ≈{100 * frac:g} % of ≈15.5 m")
    ax_b.set_xlabel("time t [s]")
    ax_b.set_ylabel("altitude difference y_ref − y_dt [m]")
    ax_b.set_xlim(0, 21)
    ax_b.set_xticks(np.arange(0, 21, 2))
    ax_b.grid(alpha=0.3, which="both")
    ax_b.legend(fontsize=8, loc="lower right")
    ax_b.set_title(f"(b) difference from dt = 1/12000 s; error ×{ts.error_ratio_per_3x_dt:.3g} for dt ×3 "
                   "(paper ≈ ×10)", fontsize=10)
    fig.suptitle(f"Oe 2010 Fig. 5 — variation of flights by the time step (φ_up = {ts.phi_up_deg:g}°, RK4)")
    return finish(fig, path)


def fig_flight(traj, path: str | os.PathLike | None = None, title: str = "") -> Figure:
    """One flight: altitude y (m) against forward distance z (m), and the pitch phi and flap theta
    (deg) over the first 0.5 s."""
    fig = _new_figure(11.0, 4.0)
    a, b = fig.subplots(1, 2, width_ratios=[2, 1])
    a.plot(traj.z, traj.y, lw=0.8)
    a.set_xlabel("forward distance z [m]")
    a.set_ylabel("altitude y [m] (target 0 m)")
    a.grid(alpha=0.3)
    a.set_title(title or f"flight ({traj.backend} backend)")
    mask = traj.t <= min(traj.t[-1], 0.5)
    b.plot(traj.t[mask], np.degrees(traj.theta[mask]), label="flap theta")
    b.plot(traj.t[mask], np.degrees(traj.phi[mask]), label="pitch phi")
    b.set_xlabel("time [s]")
    b.set_ylabel("angle [deg]")
    b.legend(loc="upper right", fontsize=8)
    b.grid(alpha=0.3)
    return finish(fig, path)


def fig_compare(results, path: str | os.PathLike | None = None) -> Figure:
    """Altitude (m) against time (s) on both backends, one panel per MuJoCo configuration
    (:class:`~lifelike_mj.butterfly.compare.CompareResult` with its trajectories)."""
    fig = _new_figure(6.0 * len(results), 4.0)
    axes = fig.subplots(1, len(results), squeeze=False)
    for ax, r in zip(axes[0], results):
        ref, mj = r.trajectories
        ax.plot(ref.t, ref.y - ref.y0, lw=1.2, label="paper backend (eq. 7-11)")
        ax.plot(mj.t, mj.y - mj.y0, lw=0.8, ls="--", label=f"MuJoCo, {r.config} config, {r.force_mode} force")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("altitude y [m]")
        ax.set_title(f"{r.config}: max |dy| = {100 * r.max_altitude_diff_m:.2f} cm, "
                     f"max |dz| = {100 * r.max_forward_diff_m:.1f} cm", fontsize=9)
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    return finish(fig, path)
