"""A first regulator on the butterfly's beat-to-beat map (issue 42, the design the averaged model's misses point to):
a prototype at one speed, flown against the shipped designed controller.

Run: ``python benchmarks/beat_regulator.py`` (about 20 s). Writes ``benchmarks/results/beat_regulator.json``.

At 1.5 m/s: the butterfly is settled in level flight by the shipped designed controller and flown on to the start of a
wing beat (phase 0); its state there (body velocity and rates, attitude with the heading taken out, altitude) is the
reference. The one-beat map from the state at phase 0 to the next phase 0, with the controls stepped at phase 0 (and
the kinematics following through their one-beat filter), is taken by central differences, open loop on the trim's
kinematics (``benchmarks/beat_map.py`` does the same for the multipliers); a turn about the vertical is kept neutral.
Augmented with the integrals of the altitude and heading errors, it gets a discrete LQR (``solve_discrete_are``; the
weights are the designed controller's Bryson scales, altitude 0.05 m and its integral 0.1 m s). In flight the
regulator measures the body at each phase 0 (no averaging, no template: the map's state is the sample itself) and
holds its command for the beat, clipped to the natural envelope. Flown, from the reference state: level flight
(10 s), a 90 deg turn asked at 2 s (the heading asked turning at 2 rad/s at most), and 30 s of level flight in gusts
of 0.5 m/s on every axis with no mean wind (seeds 100-102), the shipped designed controller beside it on the same
gusts. Not a shipped controller: one speed, no schedule, no wind estimate, no guidance.
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
from _beat import PARTS, open_loop, schedule_row, settled  # noqa: E402  (shared with lateral_kick, beat_map)

from lifelike_mj.io import write_json
from lifelike_mj.machine import machine_info
from lifelike_mj.provenance import provenance

HERE = Path(__file__).parent
MODEL = HERE / "results" / "monarch_model.json"
SPEED = 1.5
STATE_SCALES = [0.9, 0.9, 0.9, 3.0, 3.0, 3.0, 0.45, 0.45, 0.3, 0.05, 0.1, 0.6]
CONTROL_SCALES = [0.5, 0.06, 0.06, 0.06, 0.06, 0.1, 0.06, 0.1, 0.15]


def _yaw(r: np.ndarray) -> float:
    return math.atan2(r[1, 0], r[0, 0])


def _rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class Plant:
    """The reference at phase 0, the identified map and the regulator (module docstring)."""

    def __init__(self, spec: dict) -> None:
        from lifelike_mj.butterfly.flight3d.designed import quat2mat

        self.trim = np.array(schedule_row(spec, SPEED)["command"], float)
        self.period = 1.0 / self.trim[0]
        self.s0 = settled(SPEED, phase_zero=True, trim=self.trim)
        r0 = quat2mat(np.ascontiguousarray(self.s0["qpos"][3:7]))
        self.r_att = _rz(-_yaw(r0)) @ r0
        self.v_ref, self.w_ref = r0.T @ self.s0["qvel"][0:3], self.s0["qvel"][3:6].copy()
        self.h = np.zeros(10)
        self.h[6:9] = self.r_att.T @ np.array([0.0, 0.0, 1.0])
        self.identify()
        self.design()

    def state(self, qpos, qvel, heading: float, z_ref: float) -> np.ndarray:
        from lifelike_mj.butterfly.flight3d.designed import _log, quat2mat

        r = quat2mat(np.ascontiguousarray(qpos[3:7]))
        return np.concatenate([r.T @ qvel[0:3] - self.v_ref, qvel[3:6] - self.w_ref,
                               _log((_rz(heading) @ self.r_att).T @ r), [qpos[2] - z_ref]])

    def start(self, g, dx=None) -> None:
        """``g`` (a Flight3D of the same butterfly) put in the reference state (plus ``dx``), heading 0, at the origin."""
        import mujoco

        from lifelike_mj.butterfly.flight3d import controls as ct

        dx = np.zeros(10) if dx is None else dx
        for n in PARTS:  # the reference's state, on the flight's own clock
            getattr(g.data, n)[:] = self.s0[n]
        r = self.r_att @ ct.exp_rotation(dx[6:9])
        q = np.zeros(4)
        mujoco.mju_mat2Quat(q, r.reshape(-1))
        g.data.qpos[3:7] = q
        g.data.qpos[0:3] = (0.0, 0.0, dx[9])
        g.data.qvel[0:3] = r @ (self.v_ref + dx[0:3])
        g.data.qvel[3:6] = self.w_ref + dx[3:6]

    def flight(self, command, task=None, controller=None):
        return open_loop(SPEED, command, task=task, controller=controller)

    def one_beat(self, dx: np.ndarray, du: np.ndarray) -> np.ndarray:
        from lifelike_mj.butterfly.flight3d import controls as ct
        from lifelike_mj.butterfly.flight3d import model as mj3d
        from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

        cmd = ct.command_from_controls(self.trim, du)
        g = self.flight(cmd)
        self.start(g, dx)
        g.data.userdata[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = cmd
        g.step(int(round(self.period / g.dt)))
        return self.state(g.data.qpos, g.data.qvel, 0.0, 0.0)

    def identify(self) -> None:
        steps = np.array([0.02] * 3 + [0.2] * 3 + [0.01] * 3 + [0.01])
        usteps = np.array([0.1] + [0.01] * 8)
        phi, gam = np.zeros((10, 10)), np.zeros((10, 9))
        for i in range(10):
            e = np.zeros(10)
            e[i] = steps[i]
            phi[:, i] = (self.one_beat(e, np.zeros(9)) - self.one_beat(-e, np.zeros(9))) / (2 * steps[i])
        for i in range(9):
            e = np.zeros(9)
            e[i] = usteps[i]
            gam[:, i] = (self.one_beat(np.zeros(10), e) - self.one_beat(np.zeros(10), -e)) / (2 * usteps[i])
        self.phi = phi + np.outer(self.h - phi @ self.h, self.h) / (self.h @ self.h)
        self.gam = gam

    def design(self) -> None:
        pa, ga = np.zeros((12, 12)), np.zeros((12, 9))
        pa[:10, :10], ga[:10] = self.phi, self.gam
        pa[10, 10], pa[10, 9] = 1.0, self.period
        pa[11, 11], pa[11, 6:9] = 1.0, self.period * self.h[6:9]
        q, r = np.diag(1.0 / np.square(STATE_SCALES)), np.diag(1.0 / np.square(CONTROL_SCALES))
        p = sl.solve_discrete_are(pa, ga, q, r)
        self.K = np.linalg.solve(r + ga.T @ p @ ga, ga.T @ p @ pa)
        self.multipliers = (float(np.abs(np.linalg.eigvals(pa)).max()),
                            float(np.abs(np.linalg.eigvals(pa - ga @ self.K)).max()))


class BeatRegulator:
    """The regulator as a Python controller for Flight3D: at each phase 0 a new command, held for the beat."""

    def __init__(self, plant: Plant, turn_at_s: float | None = None, turn_to_rad: float = 0.0) -> None:
        from lifelike_mj.butterfly.flight3d import controls as ct
        from lifelike_mj.butterfly.flight3d import designed as D

        self.p, self.heading, self.prev, self.integral = plant, 0.0, None, np.zeros(2)
        self.turn_at_s, self.turn_to_rad = turn_at_s, turn_to_rad
        self.lo, self.hi = D.limits()
        self.trim_u = ct.controls_of(plant.trim)

    def __call__(self, fl):
        from lifelike_mj.butterfly.flight3d import controls as ct
        from lifelike_mj.butterfly.flight3d import model as mj3d
        from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

        ph = float(fl.data.userdata[mj3d.U_PSI0]) % (2 * math.pi)
        new_beat = self.prev is not None and ph < self.prev
        self.prev = ph
        if not new_beat:
            return None
        p = self.p
        if self.turn_at_s is not None and fl.time >= self.turn_at_s:
            d = (self.turn_to_rad - self.heading + math.pi) % (2 * math.pi) - math.pi
            self.heading += float(np.clip(d, -2.0 * p.period, 2.0 * p.period))
        x = p.state(fl.data.qpos, fl.data.qvel, self.heading, 0.0)
        x[6:9] = np.clip(x[6:9], -0.5, 0.5)
        x[9] = float(np.clip(x[9], -0.25, 0.25))
        u = -p.K @ np.concatenate([x, self.integral])
        u = np.clip(self.trim_u + u, self.lo, self.hi) - self.trim_u
        self.integral = np.clip(self.integral + p.period * np.array([x[9], p.h[6:9] @ x[6:9]]), -0.3, 0.3)
        return KinematicsCommand(*ct.command_from_controls(p.trim, u))


def _yaws_and_heights(g, seconds: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from lifelike_mj.butterfly.flight3d.designed import quat2mat
    from lifelike_mj.butterfly.flight3d.flight import euler_from_quat

    yaw, z, roll = [], [], []
    for _ in range(int(round(seconds / 0.01))):
        g.step(int(round(0.01 / g.dt)))
        yaw.append(_yaw(quat2mat(np.ascontiguousarray(g.data.qpos[3:7]))))
        z.append(float(g.data.qpos[2]))
        roll.append(float(euler_from_quat(g.data.qpos[3:7])[0]))
    return np.degrees(np.unwrap(yaw)), np.array(z), np.degrees(np.array(roll))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE / "results" / "beat_regulator.json"))
    args = ap.parse_args(argv)
    from lifelike_mj.butterfly.flight3d import designed as D
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    spec = D.design(D.check_model(json.loads(MODEL.read_text()), str(MODEL)))
    plant = Plant(spec)
    out: dict = {"speed_m_s": SPEED, "open_loop_largest_multiplier": plant.multipliers[0],
                 "closed_loop_largest_multiplier": plant.multipliers[1]}
    g = plant.flight(plant.trim, controller=BeatRegulator(plant))
    plant.start(g)
    _, z, _ = _yaws_and_heights(g, 10.0)
    out["level"] = {"altitude_each_second_m": z[99::100].tolist(), "altitude_rms_after_6_s_m": float(
        np.sqrt(np.mean(z[600:] ** 2)))}
    turns = {}
    for name, ctl in (("beat_regulator", None), ("designed", "designed")):
        if ctl is None:
            g = plant.flight(plant.trim, controller=BeatRegulator(plant, turn_at_s=2.0, turn_to_rad=math.pi / 2))
            plant.start(g)
        else:
            g = Flight3D(controller="designed", task=tasks.turn(90.0, at_s=2.0, speed_m_s=SPEED))
        yaw, z, _ = _yaws_and_heights(g, 7.0)
        mean = np.convolve(yaw, np.ones(10) / 10, "valid")
        turns[name] = {"overshoot_deg": float(yaw[200:].max() - 90.0), "beat_mean_overshoot_deg": float(
            mean[200:].max() - 90.0), "last_second_error_max_deg": float(np.abs(yaw[-100:] - 90.0).max())}
    out["turn_90"] = turns
    gusts = []
    for seed in (100, 101, 102):
        task = tasks.level(SPEED).with_weather(gust_m_s=0.5, gust_vertical_m_s=0.5, seed=seed)
        row = {"seed": seed}
        for name in ("beat_regulator", "designed"):
            if name == "designed":
                g = Flight3D(controller="designed", task=task)
            else:
                g = plant.flight(plant.trim, task=task, controller=BeatRegulator(plant))
                plant.start(g)
            _, z, roll = _yaws_and_heights(g, 30.0)
            mean_roll = np.convolve(roll, np.ones(10) / 10, "valid")
            row[name] = {"roll_beat_mean_max_deg": float(np.abs(mean_roll).max()), "altitude_lowest_m": float(z.min()),
                         "altitude_rms_m": float(np.sqrt(np.mean(z ** 2)))}
        gusts.append(row)
    out["gusts_every_axis_no_mean_wind"] = gusts
    write_json(args.out, {"provenance": provenance(benchmark="beat_regulator", model=str(MODEL), speed_m_s=SPEED,
                                                   state_scales=STATE_SCALES, control_scales=CONTROL_SCALES),
                          "machine": machine_info(), **out})
    t = out["turn_90"]
    print(f"multipliers: open loop {plant.multipliers[0]:.3f}, closed {plant.multipliers[1]:.3f}; level: altitude "
          f"rms {100 * out['level']['altitude_rms_after_6_s_m']:.1f} cm after 6 s; 90 deg turn overshoot: beat "
          f"regulator {t['beat_regulator']['overshoot_deg']:.1f} deg, designed {t['designed']['overshoot_deg']:.1f} deg")
    for r in gusts:
        b, d = r["beat_regulator"], r["designed"]
        print(f"gusts seed {r['seed']}: lowest {b['altitude_lowest_m']:+.2f} m (designed {d['altitude_lowest_m']:+.2f}), "
              f"beat-mean roll at most {b['roll_beat_mean_max_deg']:.0f} deg ({d['roll_beat_mean_max_deg']:.0f})")


if __name__ == "__main__":
    main()
