"""Plot of one flight (``butterfly fly --out``): altitude against distance, pitch and flap angles."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lifelike_mj.io import atomic_path  # noqa: E402


def fig_flight(traj, path: str | Path, title: str = "") -> Path:
    """Altitude y (m) vs forward distance z (m), and phi, theta (deg) over the first 0.5 s."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [2, 1]})
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
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)


def fig_compare(results, path: str | Path) -> Path:
    """Altitude (m) against time (s) on both backends, one panel per MuJoCo configuration."""
    fig, axes = plt.subplots(1, len(results), figsize=(6 * len(results), 4), squeeze=False)
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
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)
    return Path(path)
