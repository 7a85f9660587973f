"""The 3D butterfly in free flight, in the stepper shape every creature shares.

:class:`Flight3D` flies ``models/butterfly/butterfly3d.xml``: a free body that only the air, gravity and
its own joints move (:mod:`lifelike_mj.butterfly.flight3d.model`). It is steered by its kinematics alone
(:class:`~lifelike_mj.butterfly.flight3d.kinematics.KinematicsCommand`: flap frequency, each wing's stroke
amplitude and offset, feathering, the abdomen), which change smoothly whenever a new command is set::

    from lifelike_mj.butterfly.flight3d import Flight3D, KinematicsCommand

    flight = Flight3D(KinematicsCommand(frequency_hz=10.0))
    flight.step(800)                        # one second (the time step is 1/800 s)
    print(flight.state()["position_m"])     # x forward, y to the left, z up (m)

A controller is a 3D controller file (:mod:`~lifelike_mj.butterfly.flight3d.controllers`: a network from the body's
attitude and motion to changes of the kinematics, flown in the compiled loop towards a task's references),
or any callable ``controller(flight) -> KinematicsCommand | None``, called from Python before every
``control_every``-th step (``None``: keep the command)::

    from lifelike_mj.butterfly.flight3d import turn
    Flight3D(controller="monarch", task=turn(90.0)).step(6000)

World frame: x forward at the start, y to the left, z up; the body's pitch is nose-up positive, its roll
right-wing-down positive, its yaw to the left positive.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.controllers import Controller3D
from lifelike_mj.butterfly.flight3d.designed_kernel import load_compiled
from lifelike_mj.butterfly.flight3d.kinematics import JOINTS, N_PARAMS, Kinematics, KinematicsCommand, joint_refs
from lifelike_mj.butterfly.flight3d.loop import TUMBLE_RAD, Batch
from lifelike_mj.butterfly.flight3d.parts import BUTTERFLY_KEYWORDS, WORLD_KEYWORDS, Butterfly, World
from lifelike_mj.butterfly.flight3d.tasks import (
    R_DIVERGED,
    R_PASSED,
    R_TUMBLED,
    R_WP,
    T_KIND,
    T_ROW0,
    T_WIND,
    Task3D,
    level,
    new_record,
)
from lifelike_mj.butterfly.flight3d.timing import DT_FINE_S, DT_S  # noqa: F401  (DT_FINE_S: here too)
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.stability import describe
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


def check_time_step(dt_s: object, frequency_hz: float, what: str = "time step") -> float:
    """``dt_s`` (s) as a float, or a :class:`~lifelike_mj.errors.UserError` unless it is positive and resolves a wing
    beat of ``frequency_hz`` in at least :data:`MIN_STEPS_PER_BEAT` steps: the rule :class:`Flight3D` applies, and a
    command or an evolution applies before any flight begins. ``what`` names the time step (``"--dt"``)."""
    dt = checks.positive(f"{what} dt_s" if what == "time step" else what, dt_s, "s")
    period = 1.0 / float(frequency_hz)
    if dt > period / MIN_STEPS_PER_BEAT:
        raise UserError(f"{what} {dt:g} s does not resolve the {period:g} s wing beat: it must be at most "
                        f"1/{MIN_STEPS_PER_BEAT} of it ({period / MIN_STEPS_PER_BEAT:g} s).")
    return dt


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


def _parts(butterfly, world, flat: dict) -> tuple[Butterfly, World]:
    """The flight's butterfly and world: as given, or made from ``Flight3D``'s flat keywords of before (``flat``, name
    to value, ``None`` where not given), each taken with a note once per name (a ``DeprecationWarning``); the same
    part given both ways is a :class:`~lifelike_mj.errors.UserError`."""
    given = {k: v for k, v in flat.items() if v is not None}
    for part, cls, names in (("butterfly", Butterfly, BUTTERFLY_KEYWORDS), ("world", World, WORLD_KEYWORDS)):
        mine = {k: v for k, v in given.items() if k in names}
        value = butterfly if part == "butterfly" else world
        if value is not None and not isinstance(value, cls):
            raise UserError(f"{part} is a flight3d.{cls.__name__}, got {value!r}.")
        if mine and value is not None:
            raise UserError(f"give the {part} once: {part}={cls.__name__}(...) or the keywords "
                            f"{', '.join(sorted(mine))}, not both.")
        for k in mine:
            if k != "wind_m_s":  # the older spelling of the wind has its own note (checks.one_wind)
                checks.renamed(f"Flight3D({k}=...)", f"Flight3D({part}={cls.__name__}({k}=...))",
                               "the butterfly, the world and the flight are given apart", stacklevel=5)
        if part == "butterfly":
            butterfly = value if value is not None else Butterfly(**mine)
        else:
            if "wind_m_s" in mine:
                wind = checks.one_wind("Flight3D", mine.pop("wind_to_m_s", None), mine.pop("wind_from_m_s", None),
                                       mine.pop("wind_m_s"), "to")
                mine["wind_to_m_s"] = wind
            world = value if value is not None else World(**mine)
    return butterfly, world


class Flight3D(StepCounter):
    """One 3D butterfly in free flight (module docstring).

    A flight is made of three parts, given apart (:mod:`~lifelike_mj.butterfly.flight3d.parts`):

    * ``butterfly``: what flies, a :class:`~lifelike_mj.butterfly.flight3d.parts.Butterfly` (the animal, its physical
      constants, masses and wing force law, the panels and the joints' drive); its ``None`` fields are the
      controller's (a network's or a designed controller's animal, force law and kinematics filter), else the paper's
      swallowtail, the ``exact`` law and one wing beat;
    * ``world``: where it flies, a :class:`~lifelike_mj.butterfly.flight3d.parts.World` (the mean wind, replacing the
      task's, whose gusts and flutter go on; legs that touch the ground, flowers, the ground's height);
    * the flight: ``command``, the kinematics at the start (default: the controller's base command or trim, else the
      paper's 10 Hz flap over [-60, 75] deg, no feathering); ``controller``, a 3D controller
      (:class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D`, a designed controller, or the name or path
      of a controller file of either kind: ``"designed"``, ``"monarch"``;
      :func:`~lifelike_mj.butterfly.flight3d.designed_kernel.load_compiled`),
      flown in the compiled loop towards ``task``'s references (:class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`;
      default level flight at 1.5 m/s), or any callable ``controller(flight) -> KinematicsCommand | None`` run from
      Python before every ``control_every``-th step; ``start_m``, the thorax's start position; ``dt_s``, the time step.

    The flat keywords of before (``params`` and ``animal``, ``force_law``, ``masses``, ``drag_frame``,
    ``body_areas_m2``, ``n_strips``, ``n_chord``, ``drive_hz``, ``omega_c`` for the butterfly; ``wind_to_m_s``,
    ``wind_from_m_s``, ``wind_m_s``, ``contact``, ``flowers``, ``ground_m`` for the world) are taken for one more
    release, with a note once per name.
    ``end_on_tumble``: a roll or pitch beyond :data:`~lifelike_mj.butterfly.flight3d.loop.TUMBLE_RAD` ends the
    flight there (as in an evolution; :attr:`tumbled`), else it flies on.
    ``assist="hold"`` holds the attitude at ``pitch_law(flight)`` (rad, nose up), set once per step, roll
    and yaw 0: the reduction check to the planar model, not free flight.
    """

    @checks.known_keywords
    def __init__(self, command: KinematicsCommand | None = None, params: ButterflyParams | None = None, *,
                 butterfly: Butterfly | None = None, world: World | None = None, controller=None, task=None,
                 control_every: int = 1, start_m=(0.0, 0.0, 0.0), dt_s: float = DT_S, assist: str = "none",
                 pitch_law: Callable | None = None, end_on_tumble: bool = False,
                 animal: str | None = None, force_law: str | None = None, masses: str | None = None,
                 drag_frame: str | None = None, body_areas_m2=None, n_strips: int | None = None,
                 n_chord: int | None = None, drive_hz: float | None = None, omega_c: float | None = None,
                 wind_to_m_s=None, wind_from_m_s=None, wind_m_s=None, contact: bool | None = None, flowers=None,
                 ground_m: float | None = None, _model: mujoco.MjModel | None = None) -> None:
        butterfly, world = _parts(butterfly, world, {
            "animal": animal, "force_law": force_law, "params": params, "masses": masses, "drag_frame": drag_frame,
            "body_areas_m2": body_areas_m2, "n_strips": n_strips, "n_chord": n_chord, "drive_hz": drive_hz,
            "omega_c": omega_c, "wind_to_m_s": wind_to_m_s, "wind_from_m_s": wind_from_m_s, "wind_m_s": wind_m_s,
            "contact": contact, "flowers": flowers, "ground_m": ground_m})
        #: The butterfly flown and the world it flies in, as given (:mod:`~lifelike_mj.butterfly.flight3d.parts`;
        #: ``None`` fields filled from the controller where it has them).
        self.butterfly, self.world = butterfly, world
        animal, force_law, params, omega_c = butterfly.animal, butterfly.force_law, butterfly.params, butterfly.omega_c
        masses, drag_frame, body_areas_m2 = butterfly.masses, butterfly.drag_frame, butterfly.body_areas_m2
        n_strips, n_chord, drive_hz = butterfly.n_strips, butterfly.n_chord, butterfly.drive_hz
        contact, flowers, ground_m = world.contact, world.flowers, world.ground_m
        self.network = None
        #: A designed controller flown in the compiled loop (``designed_kernel.CompiledDesigned``), or ``None``.
        self.designed = None
        if isinstance(controller, (str, Path)):  # a name or a file of either kind, a designed one ready to fly compiled
            controller = load_compiled(controller)
        designed = getattr(controller, "start_command", None) is not None and not isinstance(controller, Controller3D)
        if designed:  # a designed controller: its animal and force law, its trim at the task's speed to start from
            animal = animal if animal is not None else controller.animal
            force_law = force_law if force_law is not None else controller.force_law
            start = task.start_speed_m_s if isinstance(task, Task3D) else 1.5
            command = command or controller.start_command(start)
            if getattr(controller, "compiled", False):
                self.designed, controller = controller, None
        if isinstance(controller, Controller3D):
            self.network, controller = controller, None
            omega_c = self.network.omega_c_rad_s if omega_c is None else omega_c
            command = command or self.network.base
        elif controller is not None and not callable(controller):
            raise UserError(f"a controller is a 3D controller or a function of the flight returning a command, "
                            f"got {controller!r}.")
        from lifelike_mj.butterfly.flight3d.animals import animal as _animal

        #: The butterfly flown (:data:`~lifelike_mj.butterfly.flight3d.animals.ANIMALS`): given, else the 3D
        #: controller's, else the paper's swallowtail.
        self.animal = _animal(animal if animal is not None else
                              (self.network.animal if self.network is not None else "swallowtail")).name
        self.command = command or KinematicsCommand()
        if not isinstance(self.command, KinematicsCommand):
            raise UserError(f"a kinematics command is a KinematicsCommand, got {self.command!r}.")
        self.task = task if task is not None else level(1.5)
        if not isinstance(self.task, Task3D):
            raise UserError(f"a task is a Task3D (flight3d.level, turn, course), got {self.task!r}.")
        self.params = params if params is not None else ButterflyParams()
        if not isinstance(self.params, ButterflyParams):
            raise UserError(f"params must be ButterflyParams, got {self.params!r}.")
        self.dt = check_time_step(dt_s, self.command.frequency_hz)
        if assist == "hold" and not callable(pitch_law):
            raise UserError("the attitude hold needs pitch_law, a function of the flight returning the pitch (rad).")
        self.controller, self.control_every = controller, checks.whole("control_every", control_every, 1)
        wind = checks.one_wind("Flight3D", world.wind_to_m_s, world.wind_from_m_s, None, "to")
        if wind is not None:
            from dataclasses import replace

            self.task = replace(self.task, wind_to_m_s=wind)
        self.wind_to_m_s = np.array(self.task.wind_to_m_s)
        self.start_m = np.array(checks.vector("start_m", start_m, 3), dtype=float)
        if force_law is None:
            force_law = self.network.force_law if self.network is not None else "exact"
        self.options = {"force_law": force_law, "drag_frame": drag_frame, "body_areas_m2": body_areas_m2,
                        "assist": assist, "drive_hz": checks.positive("drive_hz", drive_hz, "Hz"),
                        "n_strips": n_strips, "n_chord": n_chord, "animal": self.animal}
        self.masses, self.omega_c, self.pitch_law = masses, omega_c, pitch_law
        self.end_on_tumble = checks.flag("end_on_tumble", end_on_tumble)
        #: The blossoms' centres (``(n, 3)``, m), or ``None``.
        self.flowers = None if flowers is None else np.array(checks.points("flowers", flowers, "m"))
        if ground_m is not None:
            ground_m = checks.number("ground_m", ground_m, -1000.0, 1000.0, unit="m")
        self.contact = checks.flag("contact", contact) or self.flowers is not None
        self._model = _model if _model is not None else mj3d.build_model(self.params, masses, self.animal,
                                                                          contact=self.contact, flowers=self.flowers,
                                                                          ground_m=ground_m)
        self._model.opt.timestep = self.dt
        self._model.opt.gravity[:] = (0.0, 0.0, -self.params.gravity)
        self._root_q = int(self._model.jnt_qposadr[self._model.joint("root").id])
        self._root_d = int(self._model.jnt_dofadr[self._model.joint("root").id])
        self._q, self._driven, _ = mj3d.driven_dofs(self._model)
        n_rows = len(self.task.rows)
        self._task = self.task.as_array(n_rows)
        self._n_rows = n_rows
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
        mujoco.mj_comPos(self._model, self._data)
        mujoco.mj_camlight(self._model, self._data)  # the cameras and lights follow the bodies

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: at rest at ``start_m``, level, heading +x, the kinematics at the start command.
        The flight has no randomness yet; ``seed`` is accepted for the common shape."""
        self._k = 0
        kin = Kinematics(self.command, self.omega_c)
        self._data = mj3d.setup_data(self._model, kin, self.params, air_m_s=self.wind_to_m_s, **self.options)
        self._data.qpos[self._root_q : self._root_q + 3] = self.start_m
        net = self.network
        # the task afresh: a landing turns its array's kind into a perch
        self._batch = Batch(self._model, [self._data], self.task.as_array(self._n_rows), net, dt_s=self.dt,
                            records=new_record(1, self._n_rows), base=None if net else self.command.as_array(),
                            tumble_rad=TUMBLE_RAD if self.end_on_tumble else math.inf, designed=self.designed)
        self._task = self._batch.tasks[0]
        self._rec = self._batch.records[0]
        self._diverged = ""

    @property
    def kinematics(self) -> Kinematics:
        """The kinematics now (a copy: parameters, rates, phase and command; change them with :meth:`set_command`)."""
        ud = self._data.userdata
        k = Kinematics(self.command, ud[mj3d.U_OMEGA_C])
        k.p = ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS].copy()
        k.dp = ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS].copy()
        k.psi = float(ud[mj3d.U_PSI0])
        k.target = ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS].copy()
        return k

    def set_command(self, command: KinematicsCommand) -> None:
        """The kinematics head for ``command`` from now on (smoothly). A 3D controller's next command replaces it."""
        if not isinstance(command, KinematicsCommand):
            raise UserError(f"a kinematics command is a KinematicsCommand, got {command!r}.")
        self.command = command
        self._data.userdata[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = command.as_array()

    @property
    def wind_m_s(self) -> np.ndarray:
        """The older name of :attr:`wind_to_m_s` (with a note)."""
        checks.renamed("Flight3D.wind_m_s", "Flight3D.wind_to_m_s", "where the wind blows to")
        return self.wind_to_m_s

    def set_wind(self, wind_to_m_s=None, *, wind_from_m_s=None, wind_m_s=None) -> None:
        """The mean wind from now on (world frame, m/s: where it blows to, or ``wind_from_m_s``, where it comes from;
        ``wind_m_s``: the older spelling of ``wind_to_m_s``); the task's gusts and flutter go on. For interactive
        scenes (the viewers' wind keys)."""
        from dataclasses import replace

        w = checks.one_wind("set_wind", wind_to_m_s, wind_from_m_s, wind_m_s, "to")
        if w is None:
            raise UserError("set_wind: give the wind, as wind_to_m_s or wind_from_m_s.")
        self.task = replace(self.task, wind_to_m_s=w)
        self.wind_to_m_s = np.array(w)
        self._task[T_WIND : T_WIND + 3] = w
        self._data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3] = w  # the gusts are added at the next step

    def set_reference(self, heading_rad: float | None = None, altitude_m: float | None = None,
                      speed_m_s: float | None = None) -> None:
        """Fly level at ``heading_rad`` (from +x, left > 0), ``altitude_m`` and ``speed_m_s`` from now on: the task
        becomes a one-row schedule (:func:`~lifelike_mj.butterfly.flight3d.tasks.level`), its weather kept. What is
        not given stays: the schedule's current value, else the heading and altitude the butterfly has now and
        the task's speed. For interactive scenes (the viewers' course and altitude keys)."""
        from dataclasses import replace

        now = self.reference
        h = float(now[0] if heading_rad is None else checks.number("heading_rad", heading_rad, unit="rad"))
        a = float(now[1] if altitude_m is None else checks.number("altitude_m", altitude_m, -1000, 1000, unit="m"))
        v = float(now[2] if speed_m_s is None else checks.number("speed_m_s", speed_m_s, 0.0, 10.0, unit="m/s"))
        self.task = replace(self.task, kind="schedule", rows=((0.0, h, a, v),), name="interactive")
        fresh = self.task.as_array(self._n_rows)
        self._task[:T_ROW0] = fresh[:T_ROW0]
        self._task[T_ROW0:] = fresh[T_ROW0:]

    @property
    def reference(self) -> tuple[float, float, float]:
        """``(heading_rad, altitude_m, speed_m_s)`` the butterfly is asked to fly now: a schedule's current row,
        else its own heading and altitude now at the task's speed."""
        if self.task.kind == "schedule":
            row = [r for r in self.task.rows if r[0] <= self.time][-1]
            return float(row[1]), float(row[2]), float(row[3])
        d, rq = self._data, self._root_q
        return float(euler_from_quat(d.qpos[rq + 3 : rq + 7])[2]), float(d.qpos[rq + 2]), float(self.task.speed_m_s)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps (a Python controller, if any, before every ``control_every``-th). An unstable
        flight raises :class:`~lifelike_mj.errors.Diverged` naming the step and the cause."""
        n = checks.whole("the number of steps", n, 0)
        self._check_alive()
        d = self._data
        hold = self.options["assist"] == "hold"
        if self.controller is None and not hold:
            self._batch.advance(n)
        else:
            for _ in range(n):
                if self.controller is not None and self._k % self.control_every == 0:
                    command = self.controller(self)
                    if command is not None:
                        self.set_command(command)
                if hold:
                    d.qpos[self._root_q + 3 : self._root_q + 7] = quat_from_pitch(float(self.pitch_law(self)))
                    d.qvel[self._root_d + 3 : self._root_d + 6] = 0.0
                self._batch.advance(1)
                self._k = int(self._rec[1])
                if self._rec[R_DIVERGED] >= 0:
                    break
        self._settle()

    def _settle(self) -> None:
        """After the compiled loop: the step count from the run record, and a divergence named and raised."""
        self._k = int(self._rec[1])
        if self._rec[R_DIVERGED] >= 0:
            if self._data.time < 0.5 * self._k * self.dt:  # MuJoCo reset the simulation (its clock went back)
                self._diverged = describe(self._data, "the 3D flight")
            else:
                self._diverged = f"the 3D flight diverged: its speed ran away above {RUNAWAY_M_S:g} m/s;"
            self._diverged += f" (step {self._k}, t = {self.time:.4f} s)"
        self._check_alive()

    def decide(self, action=None, *, max_steps: int | None = None) -> np.ndarray:
        """Fly on to the controller's next decision with ``action`` taken now: the nine actions
        (:data:`~lifelike_mj.butterfly.flight3d.controllers.ACTION_NAMES`, each in ``[-1, 1]``) of a policy of your
        own in place of the network's (the task's flutter is added to them as to the network's). The flight then
        goes on, as the compiled loop flies it, to the next step at which the network would run (every
        ``every`` steps of the controller), or until it ends (a tumble: :attr:`tumbled`) or has flown
        ``max_steps`` steps. ``action=None``: take no action, only observe (at the start). Returns the
        observation there (:data:`~lifelike_mj.butterfly.flight3d.controllers.OBS_NAMES`, SI units). A runaway
        raises :class:`~lifelike_mj.errors.Diverged`. This is the step of the Gymnasium environment
        ``lifelike_mj/ButterflyFlight3D-v0``; :attr:`reward` sums the same rewards as the evolution's.

        With a designed controller (compiled) the nine actions are a **residual** policy's, one per control of
        :data:`~lifelike_mj.butterfly.flight3d.averaged.CONTROLS`, times
        :data:`~lifelike_mj.butterfly.flight3d.designed.RESIDUAL_SCALE`, added to the controller's own command at each
        of its control steps (within its limits; no flutter): zeros fly the designed controller as :meth:`step` does,
        bit for bit. Its command at the decision reached is :attr:`baseline_command`."""
        if self.network is None and self.designed is None:
            raise UserError("decide needs a 3D controller (a network's base command, scales and rate, or a designed "
                            "controller under a residual policy); give one to Flight3D.")
        self._check_alive()
        if action is not None:
            from lifelike_mj.butterfly.flight3d.controllers import N_ACT

            a = np.asarray(action)
            if a.dtype.kind not in "fiu" or a.size != N_ACT or not np.isfinite(a).all():
                raise UserError(f"an action is {N_ACT} finite numbers in [-1, 1], got {action!r}.")
            action = np.clip(a.astype(np.float64).reshape(1, N_ACT), -1.0, 1.0)
        limit = np.iinfo(np.int64).max if max_steps is None else checks.whole("max_steps", max_steps, 0)
        self._batch.decide(action, limit)
        self._settle()
        return self._batch.observations[0].copy()

    @property
    def baseline_command(self) -> np.ndarray | None:
        """The designed controller's own command (kinematics parameters, :class:`KinematicsCommand`'s order) at the
        last decision (:meth:`decide`), before a residual policy's actions; ``None`` without a designed controller."""
        return None if self.designed is None else self._batch.baselines[0].copy()

    # ---- landing, perching and take-off -----------------------------------------------------------

    def land_on(self, flower: int, radius_m: float = 0.035, speed_m_s: float = 1.0):
        """The landing task (:func:`~lifelike_mj.butterfly.flight3d.tasks.land`) on this flight's flower ``flower``
        (an index into :attr:`flowers`): its blossom's top, at this butterfly's standing height."""
        from lifelike_mj.butterfly.flight3d.flowers import landing_surface
        from lifelike_mj.butterfly.flight3d.tasks import land

        if self.flowers is None:
            raise UserError("this flight has no flowers to land on; give Flight3D flowers=[(x, y, z), ...].")
        k = checks.whole("flower", flower, 0, len(self.flowers) - 1)
        return land(landing_surface(self.flowers[k]), mj3d.standing_height_m(self.animal), radius_m, speed_m_s,
                    name=f"land on flower {k}")

    @property
    def perched(self) -> bool:
        """Whether the butterfly has touched down on a landing task's flower and sits there (until :meth:`take_off`)."""
        from lifelike_mj.butterfly.flight3d.tasks import TASK_PERCH

        return int(self._task[T_KIND]) == TASK_PERCH

    @property
    def behaviour(self) -> str:
        """Which of the 3D controller's networks flies now: ``"flight"``, or a behaviour network's name (``"land"``,
        ``"take_off"``: :data:`~lifelike_mj.butterfly.flight3d.controllers.MODES`) within its reach; ``"perched"``
        while perched, ``"none"`` without a 3D controller."""
        from lifelike_mj.butterfly.flight3d.controllers import NETWORKS
        from lifelike_mj.butterfly.flight3d.loop import behaviour

        if self.network is None:
            return "none"
        if self.perched:
            return "perched"
        return NETWORKS[behaviour(self._task, self._data.qpos[self._root_q : self._root_q + 3], self.time, self._rec,
                                  self._batch.reach)]

    @property
    def touchdown(self) -> dict | None:
        """The last touchdown of this landing: ``time_s`` and ``speed_m_s`` (over the ground), or ``None``."""
        from lifelike_mj.butterfly.flight3d.tasks import R_LANDED_AT, R_TOUCH_SPEED

        if self._rec[R_LANDED_AT] < 0:
            return None
        return {"time_s": float(self._rec[R_LANDED_AT]), "speed_m_s": float(self._rec[R_TOUCH_SPEED])}

    def take_off(self, task: Task3D, clap_s: float | None = None) -> None:
        """Take off from the perch and fly ``task`` (a course, a schedule, or the landing on the next flower,
        :meth:`land_on`): the wings open to the top of the stroke (:func:`~lifelike_mj.butterfly.flight3d.loop.
        take_off_kinematics`) and the network flies again, its first ``clap_s`` s (default
        :data:`~lifelike_mj.butterfly.flight3d.tasks.CLAP_S`) with larger strokes whose tops meet: a clap."""
        from lifelike_mj.butterfly.flight3d import tasks as t3
        from lifelike_mj.butterfly.flight3d.loop import take_off_kinematics

        if not self.perched:
            raise UserError("take_off: the butterfly is not perched (it perches when a landing task touches down).")
        if not isinstance(task, Task3D):
            raise UserError(f"a task is a Task3D (flight3d.level, course, land), got {task!r}.")
        clap = t3.CLAP_S if clap_s is None else checks.number("clap_s", clap_s, 0.0, 10.0, unit="s")
        rec = new_record(1, len(task.rows))
        keep = [i for i in range(t3.R_WP) if i not in (t3.R_PASSED, t3.R_LANDED_AT, t3.R_TOUCH_SPEED)]
        rec[0, keep] = self._rec[keep]
        t3.start_take_off(rec[0], self.time, clap)
        self._fly_task(task, rec)
        take_off_kinematics(self._data.userdata, self._batch.base)

    def _fly_task(self, task: Task3D, records: np.ndarray) -> None:
        """Fly ``task`` from now on, with the run record ``records`` (``(1, ...)``): a fresh batch of one on the same
        model and data."""
        self.task, self._n_rows = task, len(task.rows)
        self._batch = Batch(self._model, [self._data], task.as_array(self._n_rows), self.network, dt_s=self.dt,
                            records=records, base=None if self.network else self.command.as_array(),
                            tumble_rad=self._batch.tumble_rad, designed=self.designed)
        self._task = self._batch.tasks[0]
        self._rec = self._batch.records[0]

    def perch_on(self, flower: int) -> None:
        """Put the butterfly at rest on flower ``flower`` (an index into :attr:`flowers`), standing, facing its
        heading now, its wings closed: perched, as after a landing's touchdown (ready for :meth:`take_off`)."""
        from lifelike_mj.butterfly.flight3d import tasks as t3
        from lifelike_mj.butterfly.flight3d.loop import perch_command

        task = self.land_on(flower)
        row = task.rows[0]
        yaw = float(euler_from_quat(self._data.qpos[self._root_q + 3 : self._root_q + 7])[2])
        self._fly_task(task, new_record(1, len(task.rows)))
        self._task[T_KIND] = t3.TASK_PERCH
        self._rec[t3.R_LANDED_AT], self._rec[t3.R_AIM] = self.time, yaw
        d, rq = self._data, self._root_q
        d.qpos[rq : rq + 3] = (row[0], row[1], row[2] + row[3])
        d.qpos[rq + 3 : rq + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        d.qvel[:] = 0.0
        ud = d.userdata
        perch_command(self._batch.base, ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS])
        ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS] = ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS]
        ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS] = 0.0
        refs = np.zeros((len(JOINTS), 3))
        joint_refs(ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS], np.zeros(N_PARAMS), np.zeros(N_PARAMS), float(ud[mj3d.U_PSI0]),
                   refs)
        d.qpos[self._q] = refs[:, 0]
        d.qvel[self._driven] = 0.0

    @property
    def tumbled(self) -> bool:
        """Whether the flight ended in a tumble (a roll or pitch beyond
        :data:`~lifelike_mj.butterfly.flight3d.loop.TUMBLE_RAD`, in flights that stop there)."""
        return bool(self._rec[R_TUMBLED] >= 0)

    def _check_alive(self) -> None:
        if self._diverged:
            raise Diverged(f"{self._diverged} the likely cause is the time step ({self.dt:g} s), the constants or "
                           "the controller's commands.", self._k)

    @property
    def reward(self) -> float:
        """The task's reward summed over the steps flown (s; :func:`~lifelike_mj.butterfly.flight3d.loop.reward` per
        second): divided by the time flown, the mean in ``[0, 1]`` the evolution maximises."""
        return float(self._rec[0])

    @property
    def waypoints_passed(self) -> int:
        """How many of the task's waypoints have been passed (within its radius), in order."""
        return int(self._rec[R_PASSED]) if self.task.kind == "waypoints" else 0

    @property
    def closest_approach_m(self) -> np.ndarray:
        """The closest approach (m) so far to each of the task's waypoints (inf: not yet aimed at)."""
        return self._rec[R_WP : R_WP + self._n_rows].copy()

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
        self._data.userdata[mj3d.U_T0] = self._data.time
        with passive_callback(mj3d.COMPILED_PASSIVE):
            mujoco.mj_forward(self._model, self._data)
        return mj3d.forces(self._data)

    def record(self, n_steps: int | None = None, *, duration_s: float | None = None, every: int | None = None) -> dict:
        """Fly on ``n_steps`` steps (or ``duration_s`` seconds) and return the path sampled every ``every``
        steps (default: every 10 ms), the current state first: ``t_s``, and :meth:`state`'s arrays stacked (one row
        per sample)."""
        if (n_steps is None) == (duration_s is None):
            raise UserError("give either n_steps or duration_s.")
        every = max(1, round(0.01 / self.dt)) if every is None else checks.whole("every", every, 1)
        n = (checks.whole("the number of steps", n_steps, 1) if n_steps is not None
             else checks.steps_of(checks.positive("duration", duration_s, "s"), self.dt))
        checks.work(f"a 3D flight of {n:,} steps", n, checks.MAX_BODY_STEPS, "time steps",
                    "a shorter flight or a larger time step")
        checks.work(f"recording {n:,} steps every {every}", n / every, checks.MAX_RECORD_ROWS, "rows",
                    "recording less often")
        rows, times = [self.state()], [self.time]
        for _ in range(n // every):
            self.step(every)
            rows.append(self.state())
            times.append(self.time)
        out = {k: np.array([r[k] for r in rows]) for k in rows[0]}
        out["t_s"] = np.array(times)
        return out
