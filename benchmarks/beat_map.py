"""The butterfly's beat-to-beat map against its averaged model (issue 42): one wing beat of the simulator, linearised
about level flight, beside the averaged linear model over the same beat.

Run: ``python benchmarks/beat_map.py`` (about 7 s). Writes ``benchmarks/results/beat_map.json``.

At 1, 1.5 and 2 m/s the butterfly is settled in level flight by the shipped designed controller (4 s), flown on to
the start of a wing beat (phase 0), its kinematics set to the trim's, and from there flown open loop for one beat.
The map from the body's state at phase 0 (velocity and rates in body axes, a small rotation about body axes: the
averaged model's states) to the state one beat later is taken by central differences (steps 0.02 m/s, 0.2 rad/s,
0.01 rad). A turn about the world's vertical changes nothing, so that direction is kept as the map's own
(multiplier 1). Its multipliers are the Floquet multipliers of the flapping body, whatever the phase it is sampled
at; beside them, the averaged model's over the same beat (``expm(A T)``), both as rates (``ln|mu| / T``, per second).

The controls are compared by their beat means, not at phase 0 (a step of the feathering difference at phase 0 leaves
a yaw rate at the next phase 0 of about 50 rad/s per rad at 1.5 m/s, mostly the new within-beat swing it makes, not
its mean): each lateral control stepped by +-0.02 rad at four phases of the beat (a quarter apart) and flown three
beats, the body rates averaged over each beat, against the averaged model's beat means after the same step through
the same one-beat filter.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import scipy.linalg as sl

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _beat import beat_means, open_loop, schedule_row, settled  # noqa: E402  (shared with lateral_kick, beat_regulator)

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
MODEL = HERE / "results" / "monarch_model.json"
STATE_STEPS = np.array([0.02] * 3 + [0.2] * 3 + [0.01] * 3)
LATERAL = {"offset_difference": 3, "amplitude_difference": 4, "feather_mean_difference": 6}
PHASES = (0.0, 0.25, 0.5, 0.75)


def beat_map(speed: float, row: dict) -> dict:
    """The simulator's one-beat map and the averaged model's over the same beat (module docstring)."""
    import mujoco

    from lifelike_mj.butterfly.flight3d import controls as ct
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.designed import _log, quat2mat
    from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

    trim = np.array(row["command"], float)
    s0 = settled(speed, phase_zero=True, trim=trim)
    r_ref = quat2mat(np.ascontiguousarray(s0["qpos"][3:7]))
    period = 1.0 / trim[0]

    def state(d) -> np.ndarray:
        r = quat2mat(np.ascontiguousarray(d.qpos[3:7]))
        return np.concatenate([r.T @ d.qvel[0:3], d.qvel[3:6], _log(r_ref.T @ r)])

    def one_beat(dx: np.ndarray, du: np.ndarray) -> tuple[np.ndarray, float]:
        cmd = ct.command_from_controls(trim, du)
        g = open_loop(speed, cmd, s0)
        g.data.userdata[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = cmd
        r = r_ref @ ct.exp_rotation(dx[6:9])
        q = np.zeros(4)
        mujoco.mju_mat2Quat(q, r.reshape(-1))
        g.data.qpos[3:7] = q
        g.data.qvel[0:3] = r @ (r_ref.T @ s0["qvel"][0:3] + dx[0:3])
        g.data.qvel[3:6] = s0["qvel"][3:6] + dx[3:6]
        n = int(round(period / g.dt))
        g.step(n)
        return state(g.data), n * g.dt

    _, t_beat = one_beat(np.zeros(9), np.zeros(9))
    phi = np.zeros((9, 9))
    for i in range(9):
        e = np.zeros(9)
        e[i] = STATE_STEPS[i]
        phi[:, i] = (one_beat(e, np.zeros(9))[0] - one_beat(-e, np.zeros(9))[0]) / (2 * STATE_STEPS[i])
    h = np.zeros(9)
    h[6:9] = r_ref.T @ np.array([0.0, 0.0, 1.0])
    phi = phi + np.outer(h - phi @ h, h) / (h @ h)  # a turn about the vertical: neutral
    ad = sl.expm(np.array(row["A"]) * t_beat)

    def rates(m: np.ndarray) -> list[float]:
        return sorted((float(v) for v in np.log(np.abs(np.linalg.eigvals(m))) / t_beat), reverse=True)

    return {"speed_m_s": speed, "beat_s": t_beat, "map_rates_per_s": rates(phi), "averaged_rates_per_s": rates(ad),
            "map": phi.tolist()}


def mean_control_effects(speed: float, row: dict, step: float = 0.02, beats: int = 3) -> dict:
    """Each lateral control's beat-mean effect on the body rates (p, q, r; rad/s per rad), stepped at four phases of
    the beat from settled flight, against the averaged model's (module docstring)."""
    from lifelike_mj.butterfly.flight3d import controls as ct
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

    trim = np.array(row["command"], float)
    period = 1.0 / trim[0]
    snaps = {ph: settled(speed, ph * period) for ph in PHASES}  # one settled flight per phase, for every step

    def flown(j: int, delta: float, ph: float) -> np.ndarray:
        u = np.zeros(9)
        u[j] = delta
        cmd = ct.command_from_controls(trim, u)
        g = open_loop(speed, cmd, snaps[ph])
        g.data.userdata[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS] = trim
        g.data.userdata[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS] = 0.0
        g.data.userdata[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = cmd
        return beat_means(g, int(round(period / g.dt)), beats)[1]

    a, b = np.array(row["A"]), np.array(row["B"])
    wc = 2.0 * math.pi * trim[0]
    z = np.zeros((36, 36))
    z[0:9, 0:9], z[0:9, 9:18], z[9:18, 18:27] = a, b, np.eye(9)
    z[18:27, 9:18], z[18:27, 18:27], z[18:27, 27:36] = -wc * wc * np.eye(9), -2.0 * wc * np.eye(9), wc * wc * np.eye(9)
    ts = np.linspace(0.0, beats * period, 60 * beats + 1)
    out = {}
    for name, j in LATERAL.items():
        xs = np.array([sl.expm(z * t)[3:6, 27 + j] for t in ts])
        model = [xs[(ts >= k * period) & (ts < (k + 1) * period)].mean(axis=0).tolist() for k in range(beats)]
        sim = {str(ph): ((flown(j, step, ph) - flown(j, -step, ph)) / (2.0 * step)).tolist()
               for ph in PHASES}
        out[name] = {"averaged_beats_p_q_r": model, "simulator_beats_p_q_r_by_phase": sim}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE / "results" / "beat_map.json"))
    args = ap.parse_args(argv)
    from lifelike_mj.butterfly.flight3d import designed as D

    spec = D.design(D.check_model(json.loads(MODEL.read_text()), str(MODEL)))
    rows = []
    for v in (1.0, 1.5, 2.0):
        row = schedule_row(spec, v)
        rows.append({**beat_map(v, row), "lateral_controls_beat_means": mean_control_effects(v, row)})
    write_json(args.out, {"provenance": provenance(benchmark="beat_map", model=str(MODEL),
                                                   state_steps=STATE_STEPS.tolist(), phases=list(PHASES)),
                          "machine": machine_info(), "speeds": rows})
    for r in rows:
        fm = r["lateral_controls_beat_means"]["feather_mean_difference"]
        sim = np.array(list(fm["simulator_beats_p_q_r_by_phase"].values()))  # phase, beat, (p, q, r)
        mod = np.array(fm["averaged_beats_p_q_r"])
        print(f"{r['speed_m_s']} m/s: fastest growth, Floquet {r['map_rates_per_s'][0]:+.2f}/s, averaged "
              f"{r['averaged_rates_per_s'][0]:+.2f}/s; a feathering difference, third beat's mean roll rate "
              f"{sim[:, 2, 0].min():+.1f} to {sim[:, 2, 0].max():+.1f} by phase (averaged {mod[2, 0]:+.1f}), yaw rate "
              f"{sim[:, 2, 2].min():+.1f} to {sim[:, 2, 2].max():+.1f} ({mod[2, 2]:+.1f}) rad/s per rad")


if __name__ == "__main__":
    main()
