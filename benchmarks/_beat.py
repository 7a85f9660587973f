"""What the beat-map benchmarks (``lateral_kick.py``, ``beat_map.py``, ``beat_regulator.py``) share: the schedule's
row at a speed, level flight settled by the shipped designed controller and its state taken, and open-loop flights of
the calibrated monarch started from such a state."""

from __future__ import annotations

import math

import numpy as np

#: The parts of an ``MjData`` a snapshot holds (and its clock, ``time``).
PARTS = ("qpos", "qvel", "act", "userdata")


def schedule_row(spec: dict, speed: float) -> dict:
    """The designed schedule's entry at ``speed`` (m/s; one of its speeds)."""
    return next(p for p in spec["schedule"] if abs(p["speed_m_s"] - speed) < 1e-9)


def settled(speed: float, extra_s: float = 0.0, phase_zero: bool = False, trim=None) -> dict:
    """The state of level flight at ``speed`` settled by the shipped designed controller for 4 s plus ``extra_s``;
    with ``phase_zero`` flown on to the first step of a new wing beat; with ``trim`` (kinematics parameters) the
    kinematics set to it, at rest in its filter."""
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

    f = Flight3D(controller="designed", task=tasks.level(speed))
    f.step(int(round((4.0 + extra_s) / f.dt)))
    if phase_zero:
        prev = float(f.data.userdata[mj3d.U_PSI0]) % (2 * math.pi)
        while True:
            f.step(1)
            now = float(f.data.userdata[mj3d.U_PSI0]) % (2 * math.pi)
            if now < prev:
                break
            prev = now
    snap = {n: getattr(f.data, n).copy() for n in PARTS}
    snap["time"] = f.data.time
    if trim is not None:
        snap["userdata"][mj3d.U_P0 : mj3d.U_P0 + N_PARAMS] = trim
        snap["userdata"][mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS] = 0.0
    return snap


def open_loop(speed: float, command, snapshot: dict | None = None, *, clock: bool = True, task=None,
              controller=None):
    """A flight of the calibrated monarch at ``speed``'s level task (or ``task``) on the kinematics ``command``
    (parameters), held open loop unless a Python ``controller`` is given; started from ``snapshot`` (with its clock
    unless ``clock`` is false) if given."""
    from lifelike_mj.butterfly.flight3d import tasks
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.butterfly.flight3d.parts import Butterfly

    g = Flight3D(KinematicsCommand(*command), butterfly=Butterfly("monarch", force_law="calibrated"),
                 task=task or tasks.level(speed), controller=controller)
    if snapshot is not None:
        for n in PARTS:
            getattr(g.data, n)[:] = snapshot[n]
        if clock:
            g.data.time = snapshot["time"]
    return g


def beat_means(g, per_beat: int, beats: int) -> np.ndarray:
    """Fly ``g`` ``beats`` beats of ``per_beat`` steps; its body rates (p, q, r; rad/s) at every step, then averaged
    over each beat: ``(rates, means)``."""
    rates = []
    for _ in range(beats * per_beat):
        g.step(1)
        rates.append(g.data.qvel[3:6].copy())
    rates = np.array(rates)
    return rates, np.array([rates[k * per_beat : (k + 1) * per_beat].mean(axis=0) for k in range(beats)])
