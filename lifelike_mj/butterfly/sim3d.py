"""The 3D butterfly in free flight, in the stepper shape every creature shares.

:class:`Flight3D` flies ``models/butterfly/butterfly3d.xml``: a free body that only the air, gravity and
its own joints move (:mod:`lifelike_mj.butterfly.backends.mj3d`). It is steered by its kinematics alone
(:class:`~lifelike_mj.butterfly.kinematics3d.KinematicsCommand`: flap frequency, each wing's stroke
amplitude and offset, feathering, the abdomen), which change smoothly whenever a new command is set::

    from lifelike_mj.butterfly.sim3d import Flight3D
    from lifelike_mj.butterfly.kinematics3d import KinematicsCommand

    flight = Flight3D(KinematicsCommand(frequency_hz=10.0))
    flight.step(1200)                       # one second
    print(flight.state()["position_m"])     # x forward, y to the left, z up (m)

A controller is any callable ``controller(flight) -> KinematicsCommand | None``, called before every
``control_every``-th step (``None``: keep the command).

World frame: x forward at the start, y to the left, z up; the body's pitch is nose-up positive, its roll
right-wing-down positive, its yaw to the left positive.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.backends import mj3d
from lifelike_mj.butterfly.kinematics3d import JOINTS, Kinematics, KinematicsCommand
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.stability import describe, was_reset, watching
from lifelike_mj.stepper import StepCounter

#: Names of :meth:`Flight3D.state` and their units.
STATE_UNITS = {
    "position_m": "m: the thorax's origin, x forward at the start, y left, z up",
    "velocity_m_s": "m/s: the thorax's origin, world frame",
    "attitude_rad": "rad: roll (right wing down > 0), pitch (nose up > 0), yaw (left > 0)",
    "angular_velocity_rad_s": "rad/s: the thorax's, in its own axes (x forward, y left, z up)",
    "joints_rad": "rad: " + ", ".join(JOINTS),
    "joint_rates_rad_s": "rad/s: the same joints' rates",
}

#: The fewest time steps per wing beat a 3D flight accepts.
MIN_STEPS_PER_BEAT = 8
#: A speed above this (m/s) is a runaway: the flight has diverged.
RUNAWAY_M_S = 1e3


def euler_from_quat(q: np.ndarray) -> np.ndarray:
    """Roll, pitch (nose up > 0) and yaw (rad) of the unit quaternion ``q`` (w, x, y, z), composed
    yaw, then pitch, then roll (Tait-Bryan z-y-x, the aircraft convention with y pointing left, so that
    the pitch is nose-up positive)."""
    w, x, y, z = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = -math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return np.array([roll, pitch, yaw])


def quat_from_pitch(pitch_rad: float) -> np.ndarray:
    """The attitude (w, x, y, z) of a level body pitched nose up by ``pitch_rad`` (heading +x)."""
    return np.array([math.cos(0.5 * pitch_rad), 0.0, -math.sin(0.5 * pitch_rad), 0.0])


class Flight3D(StepCounter):
    """One 3D butterfly in free flight (module docstring).

    ``command``: the kinematics at the start (default: the paper's 10 Hz flap over [-60, 75] deg, no
    feathering); ``params``: the physical constants (mass, wing size, air; Oe 2010 Table 1);
    ``controller`` and ``control_every``: see the module docstring; ``wind_m_s``: the air's velocity
    (world frame, m/s); ``start_m``: the thorax's start position. Model options: ``force_law``
    (``strip``: eq. 1 on wing panels; ``tip``: the paper's tip-speed formula; ``none``), ``drag_frame``
    (``body`` or ``world``), ``body_areas_m2`` (the body's drag areas along x, y, z; default the paper's
    ``A_b`` on every axis), ``masses`` (``animal`` or ``paper``), ``n_strips`` and ``n_chord`` (panels per
    wing), ``drive_hz`` (the joints' tracking bandwidth), ``omega_c`` (rad/s, how fast the kinematics
    follow a command; default one wing beat). ``assist="hold"`` holds the attitude at
    ``pitch_law(flight)`` (rad, nose up), set once per step, roll and yaw 0: the reduction check to the
    planar model, not free flight.
    """

    def __init__(self, command: KinematicsCommand | None = None, params: ButterflyParams | None = None, *,
                 controller: Callable | None = None, control_every: int = 1, wind_m_s=(0.0, 0.0, 0.0),
                 start_m=(0.0, 0.0, 0.0), force_law: str = "strip", drag_frame: str = "body",
                 body_areas_m2=None, masses: str = "animal", dt_s: float = 1.0 / 1200.0, n_strips: int = 16,
                 n_chord: int = 3, drive_hz: float = 50.0, omega_c: float | None = None, assist: str = "none",
                 pitch_law: Callable | None = None, _model: mujoco.MjModel | None = None) -> None:
        self.command = command or KinematicsCommand()
        if not isinstance(self.command, KinematicsCommand):
            raise UserError(f"a kinematics command is a KinematicsCommand, got {self.command!r}.")
        self.params = params or ButterflyParams()
        self.dt = checks.positive("time step dt_s", dt_s, "s")
        period = 1.0 / self.command.frequency_hz
        if self.dt > period / MIN_STEPS_PER_BEAT:
            raise UserError(f"time step {self.dt:g} s does not resolve the {period:g} s wing beat: it must be at most "
                            f"1/{MIN_STEPS_PER_BEAT} of it ({period / MIN_STEPS_PER_BEAT:g} s).")
        if controller is not None and not callable(controller):
            raise UserError(f"a controller is a function of the flight returning a command, got {controller!r}.")
        if assist == "hold" and not callable(pitch_law):
            raise UserError("the attitude hold needs pitch_law, a function of the flight returning the pitch (rad).")
        self.controller, self.control_every = controller, checks.whole("control_every", control_every, 1)
        self.wind_m_s = np.array(checks.vector("wind_m_s", wind_m_s, 3), dtype=float)
        self.start_m = np.array(checks.vector("start_m", start_m, 3), dtype=float)
        self.options = {"force_law": force_law, "drag_frame": drag_frame, "body_areas_m2": body_areas_m2,
                        "assist": assist, "drive_hz": checks.positive("drive_hz", drive_hz, "Hz"),
                        "n_strips": n_strips, "n_chord": n_chord}
        self.masses, self.omega_c, self.pitch_law = masses, omega_c, pitch_law
        self._model = _model if _model is not None else mj3d.build_model(self.params, masses)
        self._model.opt.timestep = self.dt
        self._model.opt.gravity[:] = (0.0, 0.0, -self.params.gravity)
        self._root_q = int(self._model.jnt_qposadr[self._model.joint("root").id])
        self._root_d = int(self._model.jnt_dofadr[self._model.joint("root").id])
        self._q, self._driven, _ = mj3d.driven_dofs(self._model)
        self.reset()

    # ---- the stepper shape ---------------------------------------------------------------------

    @property
    def model(self) -> mujoco.MjModel:
        return self._model

    @property
    def data(self) -> mujoco.MjData:
        return self._data

    def sync(self) -> None:
        """``data`` already shows the current state; this computes what drawing needs."""
        mujoco.mj_kinematics(self._model, self._data)

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: at rest at ``start_m``, level, heading +x, the kinematics at the start command.
        The flight has no randomness yet; ``seed`` is accepted for the common shape."""
        self._k = 0
        self.kinematics = Kinematics(self.command, self.omega_c)
        self._data = mj3d.setup_data(self._model, self.kinematics, self.params, air_m_s=self.wind_m_s,
                                     **self.options)
        self._data.qpos[self._root_q : self._root_q + 3] = self.start_m
        self._diverged = ""

    def set_command(self, command: KinematicsCommand) -> None:
        """The kinematics head for ``command`` from now on (smoothly)."""
        self.kinematics.set_command(command)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps (the controller, if any, before every ``control_every``-th). An unstable
        flight raises :class:`~lifelike_mj.errors.Diverged` naming the step and the cause."""
        n = checks.whole("the number of steps", n, 0)
        self._check_alive()
        m, d, kin = self._model, self._data, self.kinematics
        hold = self.options["assist"] == "hold"
        with passive_callback(mj3d.COMPILED_PASSIVE), watching():
            for _ in range(n):
                if self.controller is not None and self._k % self.control_every == 0:
                    command = self.controller(self)
                    if command is not None:
                        kin.set_command(command)
                if hold:
                    pitch = float(self.pitch_law(self))
                    d.qpos[self._root_q + 3 : self._root_q + 7] = quat_from_pitch(pitch)
                    d.qvel[self._root_d + 3 : self._root_d + 6] = 0.0
                mj3d.load_kinematics(d, kin)
                t0 = d.time
                mujoco.mj_step(m, d)
                kin.advance(self.dt)
                self._k += 1
                if was_reset(d, t0, 1, self.dt):
                    self._diverged = describe(d, "the 3D flight")
                elif not np.abs(d.qvel[self._root_d : self._root_d + 3]).max() < RUNAWAY_M_S:
                    self._diverged = f"the 3D flight diverged: its speed ran away above {RUNAWAY_M_S:g} m/s;"
                if self._diverged:
                    self._diverged += f" (step {self._k}, t = {self.time:.4f} s)"
                    break
        self._check_alive()

    def _check_alive(self) -> None:
        if self._diverged:
            raise Diverged(f"{self._diverged} the likely cause is the time step ({self.dt:g} s), the constants or "
                           "the controller's commands.")

    def state(self) -> dict[str, np.ndarray]:
        """Named arrays with units (:data:`STATE_UNITS`)."""
        d, rq, rd = self._data, self._root_q, self._root_d
        return {"position_m": d.qpos[rq : rq + 3].copy(), "velocity_m_s": d.qvel[rd : rd + 3].copy(),
                "attitude_rad": euler_from_quat(d.qpos[rq + 3 : rq + 7]),
                "angular_velocity_rad_s": d.qvel[rd + 3 : rd + 6].copy(),
                "joints_rad": d.qpos[self._q].copy(), "joint_rates_rad_s": d.qvel[self._driven].copy()}

    def forces(self) -> dict[str, np.ndarray]:
        """The air's forces and the joints' torques at the current state (:func:`mj3d.forces`; N, N m, world
        frame), computed afresh (one ``mj_forward``; the simulation is not advanced)."""
        mj3d.load_kinematics(self._data, self.kinematics)
        with passive_callback(mj3d.COMPILED_PASSIVE):
            mujoco.mj_forward(self._model, self._data)
        return mj3d.forces(self._data)
