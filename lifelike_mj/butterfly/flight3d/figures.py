"""Figures of 3D flights: paths from above and from the side, and the forces on the wings.

Each function builds a matplotlib ``Figure`` (no pyplot) and writes a PNG only when given a path.
"""

from __future__ import annotations

import os

import numpy as np
from matplotlib.figure import Figure

from lifelike_mj.render.plot import finish, new_figure


def fig_paths(paths: list[dict], labels: list[str] | None = None, waypoints=None,
              path: str | os.PathLike | None = None, title: str = "", waypoint_label: str = "waypoints") -> Figure:
    """Top view (x, y; m) and side view (distance flown over ground, altitude; m) of one or more recorded 3D
    flights (:meth:`~lifelike_mj.butterfly.flight3d.flight.Flight3D.record`), with the task's waypoints if given."""
    fig = new_figure(12.0, 4.8)
    top, side = fig.subplots(1, 2, width_ratios=[1.2, 1])
    for i, rec in enumerate(paths):
        pos = rec["position_m"]
        label = labels[i] if labels else None
        top.plot(pos[:, 0], pos[:, 1], lw=0.9, label=label)
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pos[:, :2], axis=0), axis=1))])
        side.plot(s, pos[:, 2], lw=0.9, label=label)
    if waypoints is not None and len(waypoints):
        wp = np.asarray(waypoints, dtype=float)
        top.scatter(wp[:, 0], wp[:, 1], marker="o", s=30, facecolors="none", edgecolors="k", label=waypoint_label)
        for k, (x, y) in enumerate(wp[:, :2] if waypoint_label == "waypoints" else []):
            top.annotate(str(k + 1), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x [m] (forward at the start)")
    top.set_ylabel("y [m] (left)")
    top.set_title(title or "from above")
    side.set_xlabel("distance flown over ground [m]")
    side.set_ylabel("altitude z [m] (start 0 m)")
    side.set_title("from the side")
    for ax in (top, side):
        ax.grid(alpha=0.3)
    if labels or waypoints is not None:
        top.legend(loc="best", fontsize=8)
    return finish(fig, path)


def write_flight(out_dir: str | os.PathLike, rec: dict, summary: dict, task) -> list[str]:
    """``path.npz``, ``path.csv``, ``paths.png`` and ``summary.json`` (with provenance) into ``out_dir``,
    each written atomically; returns the paths written."""
    from pathlib import Path

    from lifelike_mj.io import write_json, write_npz, write_text
    from lifelike_mj.provenance import provenance

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t, pos, att = rec["t_s"], rec["position_m"], rec["attitude_rad"]
    cols = np.column_stack([t, pos, np.degrees(att), rec["velocity_m_s"]])
    header = "t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg,vx_m_s,vy_m_s,vz_m_s"
    csv = header + "\n" + "\n".join(",".join(f"{v:.6g}" for v in row) for row in cols) + "\n"
    files = [write_npz(out / "path.npz", **rec), write_text(out / "path.csv", csv)]
    wp = [r[:3] for r in task.rows] if task.kind == "waypoints" else None
    fig_paths([rec], waypoints=wp, path=out / "paths.png", title=summary.get("task", ""))
    files += [out / "paths.png", write_json(out / "summary.json", {**summary, "provenance": provenance(**summary)})]
    return [str(f) for f in files]


def force_breakdown(controller, force_law: str = "strip", speed_m_s: float = 1.5, settle_s: float = 3.0,
                    beats: int = 2, **flight) -> dict:
    """The left wing's force in parts (N, world frame) over ``beats`` wing beats of level flight after
    ``settle_s``: ``t_s``, ``lift_N``, ``drag_N``, ``rotational_N``, ``total_N`` (rows per step, x forward at
    the start, z up) and ``flap_rad``. The default law is eq. 1 on panels, which splits the force panel by
    panel (the exact law splits it by the flow at the wing's centroid)."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.parts import with_force_law

    f = Flight3D(controller=controller, task=tasks.level(speed_m_s), **with_force_law(flight, force_law))
    f.step(int(round(settle_s / f.dt)))
    n = int(round(beats / f.kinematics.p[0] / f.dt))
    rows = {"t_s": [], "lift_N": [], "drag_N": [], "rotational_N": [], "total_N": [], "flap_rad": []}
    for _ in range(n):
        parts = f.forces()
        rows["t_s"].append(f.time)
        rows["lift_N"].append(parts["wing_lift_N"][0])
        rows["drag_N"].append(parts["wing_drag_N"][0])
        rows["rotational_N"].append(parts["wing_rotational_N"][0])
        rows["total_N"].append(parts["wing_force_N"][0])
        rows["flap_rad"].append(f.state()["joints_rad"][0])
        f.step(1)
    return {k: np.array(v) for k, v in rows.items()}


def fig_force_breakdown(breakdowns: dict, weight_N: float, path: str | os.PathLike | None = None) -> Figure:
    """One column per force law (``breakdowns``: law -> :func:`force_breakdown`): the left wing's vertical
    (top) and forward (bottom) force in its parts, over the flap angle's beats, against the weight's share of
    one wing."""
    fig = new_figure(5.5 * len(breakdowns), 6.0)
    axes = fig.subplots(2, len(breakdowns), squeeze=False, sharex="col")
    for col, (law, b) in enumerate(breakdowns.items()):
        t = b["t_s"] - b["t_s"][0]
        for row, (k, name) in enumerate(((2, "vertical"), (0, "forward"))):
            ax = axes[row, col]
            for part, style in (("total_N", "-"), ("lift_N", "--"), ("drag_N", ":"), ("rotational_N", "-.")):
                ax.plot(t, 1e3 * b[part][:, k], style, lw=1.0, label=part.removesuffix("_N"))
            if k == 2:
                ax.axhline(1e3 * weight_N / 2, color="0.5", lw=0.6, label="half the weight")
                ax.set_title(f"{law}: left wing")
            ax.set_ylabel(f"{name} force [mN]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper right")
        axes[1, col].set_xlabel("time [s]")
    return finish(fig, path)


def fig_averaged(model: dict, path: str | os.PathLike | None = None) -> Figure:
    """The averaged model over its envelope (:func:`~lifelike_mj.butterfly.flight3d.averaged.build`): the trims' body
    angle, flap frequency and power against the forward speed (one line per climb rate; a point with no balance inside
    the natural envelope is left out), and the eigenvalues of the
    longitudinal and lateral linear models in the complex plane (1/s), coloured by the forward speed."""
    from matplotlib import colormaps

    fig = new_figure(12.0, 8.0)
    (body, power), (lon, lat) = fig.subplots(2, 2)
    climbs = sorted({p["climb_m_s"] for p in model["points"]})
    for c in climbs:
        pts = sorted((p for p in model["points"] if p["climb_m_s"] == c), key=lambda p: p["speed_m_s"])
        pts = [p for p in pts if p["trimmed"]]  # no balance inside the envelope: not drawn
        v = [p["speed_m_s"] for p in pts]
        body.plot(v, [p["body_angle_deg"] for p in pts], "o-", ms=3, label=f"climb {c:+g} m/s")
        power.plot(v, [p["flown"]["power_net_W_kg"] for p in pts], "o-", ms=3, label=f"climb {c:+g} m/s")
    level = sorted((p for p in model["points"] if p["climb_m_s"] == 0.0 and p["trimmed"]),
                   key=lambda p: p["speed_m_s"])
    ax2 = body.twinx()
    ax2.plot([p["speed_m_s"] for p in level], [p["command"]["frequency_hz"] for p in level], "k--", lw=0.9,
             label="flap frequency, level")
    ax2.set_ylabel("flap frequency [Hz] (dashed)")
    power.axhspan(12.5, 20.2, color="0.85", label="Dudley 1991, 12.5-20.2 W/kg")
    body.set_xlabel("forward speed [m/s]")
    body.set_ylabel("body angle [deg]")
    body.set_title("trims: body angle and frequency")
    power.set_xlabel("forward speed [m/s]")
    power.set_ylabel("power, perfect elastic storage [W/kg]")
    power.set_title("trims flown in the simulator: power")
    cmap = colormaps["viridis"]
    speeds = [p["speed_m_s"] for p in level]
    lo, hi = min(speeds), max(speeds)
    for ax, key, title in ((lon, "longitudinal", "longitudinal modes (level)"), (lat, "lateral", "lateral modes (level)")):
        for p in level:
            col = cmap((p["speed_m_s"] - lo) / (hi - lo) if hi > lo else 0.5)
            ev = p["modes"][key]
            ax.scatter([m["real_per_s"] for m in ev], [m["imag_rad_s"] for m in ev], color=col, s=14)
        ax.axvline(0.0, color="k", lw=0.6)
        ax.set_xscale("symlog", linthresh=5.0)
        ax.set_xlabel("real part [1/s] (right of 0: unstable)")
        ax.set_ylabel("imaginary part [rad/s]")
        ax.set_title(title + f", {lo:g} (purple) to {hi:g} m/s (yellow)")
    for ax in (body, power):
        ax.legend(fontsize=7)
    return finish(fig, path)


def fig_wind_course(t_s, position_m, waypoints, passed_at_s, wind_true_m_s, wind_estimate_m_s,
                    path: str | os.PathLike | None = None, title: str = "") -> Figure:
    """A course flown in wind: the path from above against its waypoints, the altitude against the waypoints' over
    time (each waypoint's altitude until it is passed), and each horizontal component of the wind the butterfly
    estimated against the wind it met (m/s, world axes; the estimate is the controller's own, made from its motion)."""
    fig = new_figure(12.0, 7.5)
    grid = fig.add_gridspec(2, 2, width_ratios=[1.0, 1.3])
    top = fig.add_subplot(grid[:, 0])
    alt = fig.add_subplot(grid[0, 1])
    wind = fig.add_subplot(grid[1, 1], sharex=alt)
    pos, wp = np.asarray(position_m), np.asarray(waypoints, dtype=float)
    top.plot(pos[:, 0], pos[:, 1], lw=0.9, label="path")
    top.scatter(wp[:, 0], wp[:, 1], marker="o", s=40, facecolors="none", edgecolors="k", label="waypoints (0.3 m)")
    for k, (x, y) in enumerate(wp[:, :2]):
        top.annotate(str(k + 1), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    top.set_aspect("equal", adjustable="datalim")
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_title(title or "from above")
    top.legend(fontsize=7)
    t = np.asarray(t_s)
    alt.plot(t, pos[:, 2], lw=0.9, label="altitude")
    edges = [0.0, *passed_at_s]
    for k, (a, b) in enumerate(zip(edges, [*passed_at_s, t[-1]])):
        if k < len(wp):
            alt.hlines(wp[k, 2], a, b, colors="k", linestyles="--", lw=0.8, label="waypoint asked" if k == 0 else None)
    alt.set_ylabel("altitude [m]")
    alt.legend(fontsize=7)
    true, est = np.asarray(wind_true_m_s), np.asarray(wind_estimate_m_s)
    for i, (name, col) in enumerate((("x", "C0"), ("y", "C1"))):
        wind.plot(t, true[:, i], color=col, lw=0.6, alpha=0.6, label=f"wind met, {name}")
        wind.plot(t, est[:, i], color=col, lw=1.6, label=f"estimate, {name}")
    wind.set_xlabel("time [s]")
    wind.set_ylabel("wind [m/s]")
    wind.legend(fontsize=7, ncol=2)
    return finish(fig, path)
