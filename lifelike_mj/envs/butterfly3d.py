"""``lifelike_mj/ButterflyFlight3D-v0``: the free-flying 3D butterfly as a Gymnasium environment, and its vector
form on the compiled MuJoCo batch."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from lifelike_mj import checks
from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.controllers import ALTITUDE_CLIP_M, DEFAULT_SCALE
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.envs.butterfly import Drawn, check_num_envs, check_options, check_render_mode, check_seed, copy_rngs
from lifelike_mj.envs.pages import Entry, documented, names
from lifelike_mj.errors import Diverged, UserError

#: The tasks an episode can fly (``task=``), besides a :class:`~lifelike_mj.butterfly.flight3d.Task3D` of your own.
TASKS = ("level", "turn", "course", "wind")
#: The options ``reset`` takes.
RESET_OPTIONS = ("task",)
#: The wind task's weather: 1 m/s of wind from a side drawn per episode, with the gusts the (withdrawn) ``wind`` controller was
#: evolved in (0.5 m/s horizontally, half that vertically: the low-altitude Dryden ratio).
WIND_M_S = 1.0
GUSTS = {"gust_m_s": 0.5, "gust_vertical_m_s": 0.5 * 0.5}
#: A course's most waypoints in these episodes (the vector form's task arrays are this wide).
COURSE_WAYPOINTS = 10
#: The most copies of the vector form (one ``mjData`` each).
MAX_NUM_ENVS = 10_000


#: The observation's bounds beyond the angles: rates (rad/s) and speeds (m/s). A flight whose speed passes 10^3 m/s
#: has diverged; rates beyond these are shown as the bound.
MAX_RATE_RAD_S = 1.0e4
MAX_SPEED_M_S = 2.0e3
_PI = math.pi

#: The observation's eleven entries, in order (a 3D controller's network inputs,
#: :data:`~lifelike_mj.butterfly.flight3d.controllers.OBS_NAMES`), with their units, meanings and bounds (the
#: observation space's; angles within pi, rates and speeds within :data:`MAX_RATE_RAD_S` and :data:`MAX_SPEED_M_S`,
#: the altitude error within its clip, 1 m).
OBSERVATIONS = (
    Entry("roll_rad", "rad", "roll, right wing down > 0", _PI),
    Entry("pitch_rad", "rad", "pitch, nose up > 0", _PI),
    Entry("heading_error_rad", "rad", "the reference heading less the yaw, in (-pi, pi]", _PI),
    Entry("roll_rate_rad_s", "rad/s", "the thorax's roll rate", MAX_RATE_RAD_S),
    Entry("pitch_rate_rad_s", "rad/s", "its pitch rate, nose up > 0", MAX_RATE_RAD_S),
    Entry("yaw_rate_rad_s", "rad/s", "its yaw rate, left > 0", MAX_RATE_RAD_S),
    Entry("speed_error_m_s", "m/s", "forward speed less the reference speed", MAX_SPEED_M_S),
    Entry("sideways_m_s", "m/s", "speed to the left", MAX_SPEED_M_S),
    Entry("climb_m_s", "m/s", "climb rate (over the ground)", MAX_SPEED_M_S),
    Entry("altitude_error_m", "m", "altitude less the reference, clipped to +-1 m", ALTITUDE_CLIP_M),
    Entry("speed_ref_m_s", "m/s", "the forward speed asked (the reference's own speed)", MAX_SPEED_M_S),
)
#: The observation's names, in order (``info["observation_names"]``; the controllers' ``OBS_NAMES``, tested).
OBSERVATION_NAMES = names(OBSERVATIONS)
#: The action's nine entries, in order (:data:`~lifelike_mj.butterfly.flight3d.controllers.ACTION_NAMES`), each in
#: [-1, 1], multiplied by its scale (a new controller's, :data:`~lifelike_mj.butterfly.flight3d.controllers.DEFAULT_SCALE`;
#: rad, Hz for the frequency) and added to the base command.
ACTIONS = tuple(Entry(name, "1", meaning, 1.0, DEFAULT_SCALE[name], "Hz" if name == "frequency" else "rad")
                for name, meaning in (
    ("offset_sym", "both wings' stroke offset (the stroke's middle)"),
    ("offset_asym", "the left wing's offset up, the right's down"),
    ("amplitude_sym", "both wings' stroke amplitude"),
    ("amplitude_asym", "the left wing's amplitude up, the right's down"),
    ("feather_sym", "both wings' mean feathering (leading edge down > 0)"),
    ("feather_asym", "the left wing's feathering up, the right's down"),
    ("feather_amplitude", "both wings' feathering amplitude"),
    ("abdomen_mean", "the abdomen's mean angle"),
    ("frequency", "the flap frequency"),
))
#: The title of the actions' scale column in the tables.
ACTION_SCALE_TITLE = "scale (default)"


def _observation_space() -> spaces.Box:
    """Each entry of :data:`OBSERVATIONS` within its bound."""
    hi = np.array([e.bound for e in OBSERVATIONS])
    return spaces.Box(-hi, hi, (len(OBSERVATIONS),), dtype=np.float64)


def check_actions3d(actions: Any, n: int | None = None) -> np.ndarray:
    """A single environment's action (``n`` None: shape ``(9,)``) or a vector environment's ``n`` actions (shape
    ``(n, 9)``) as a float64 array: real numbers (no bools, strings or objects) of that shape, each finite; a
    :class:`~lifelike_mj.errors.UserError` saying which of these fails otherwise (the first entry that is not finite
    named by its index and action name)."""
    a = np.asarray(actions)
    shape = (flight3d.N_ACT,) if n is None else (n, flight3d.N_ACT)
    what = "an action" if n is None else "the actions"
    if a.dtype.kind not in "fiu":
        raise UserError(f"{what} must be real numbers in [-1, 1] of shape {shape}, got {actions!r} (dtype {a.dtype}).")
    if a.shape != shape:
        per = "" if n is None else " per copy"
        raise UserError(f"{what} must have shape {shape} (the {flight3d.N_ACT} actions offset_sym to frequency{per}), "
                        f"got shape {a.shape}.")
    a = a.astype(np.float64)
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        where = tuple(int(i) for i in bad[0])
        name = flight3d.ACTION_NAMES[where[-1]]
        if n is None:
            raise UserError(f"the action's entry {where[0]} ({name}) is {float(a[where])}, not a finite number.")
        raise UserError(f"the actions' entry [{where[0]}, {where[1]}] (copy {where[0]}'s {name}) is {float(a[where])}, "
                        "not a finite number.")
    return a


def _controller(controller):
    """``controller`` (a name, a path, an object or ``None``) as the environment flies it: a designed controller for
    the compiled loop (``designed_kernel.CompiledDesigned``), a network (:class:`~lifelike_mj.butterfly.flight3d.
    Controller3D`), or without one a still network (:func:`_still_controller`); a file is read once."""
    from pathlib import Path

    from lifelike_mj.butterfly.flight3d.designed import DesignedController, load_any
    from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned

    if controller is None:
        return _still_controller()
    if isinstance(controller, (str, Path)):
        controller = load_any(controller)
    if isinstance(controller, DesignedController):
        return CompiledDesigned.of(controller)
    if isinstance(controller, (CompiledDesigned, flight3d.Controller3D)):
        return controller
    return flight3d.load_controller(controller)  # says in one sentence what a controller is


def _still_controller() -> flight3d.Controller3D:
    """A linear controller of zeros on every observation: the base command as it is (the actions come from outside)."""
    return flight3d.Controller3D([flight3d.N_OBS, flight3d.N_ACT], np.zeros(flight3d.n_weights([flight3d.N_OBS,
                                                                                                flight3d.N_ACT])))


@documented(OBSERVATIONS, ACTIONS, ACTION_SCALE_TITLE)
class ButterflyFlight3DEnv(Drawn, gym.Env):
    """``lifelike_mj/ButterflyFlight3D-v0``: fly the free 3D butterfly through a task by changing its wing and
    abdomen kinematics, as a 3D controller's network does.

    The butterfly is a free body that only the air (the normal-pressure force integrated over each wing), gravity
    and its own joints move. The agent acts where a 3D controller's network acts: every ``every`` time steps
    (the controller's; 1/800 s each by default) it sets nine numbers that shift the kinematics around a base
    command, which the kinematics then follow smoothly. An episode's return is the fitness ``lifelike-mj butterfly evolve3d``
    gives the same flight (the mean reward per second), so RL and the evolutions are scored alike.

    ## Action space

    Nine numbers in [-1, 1], float64, named as a 3D controller's actions
    (:data:`~lifelike_mj.butterfly.flight3d.controllers.ACTION_NAMES`), each multiplied by its scale (rad; Hz for
    the frequency) and added to the base command:

    {actions}

    Actions outside ``[-1, 1]`` are clipped; one that is not finite, or of another shape, is refused in one
    sentence naming it. With ``flutter`` the task adds the butterfly's own irregularity to them (as to a
    network's). The scales, the base command (a 10 Hz flap over [-60, 75] deg, feathered 0.3 rad a quarter beat
    ahead) and the rate ``every`` are those of the ``controller`` argument (default: a new controller's). So are
    the butterfly and the wing-force law: ``controller="monarch"`` flies the monarch with its measured wings under
    the quasi-steady law, and ``animal="monarch"`` picks the butterfly for a new controller.

    ## Observation space

    Eleven numbers, float64, SI units, in the heading frame (forward, left, up), relative to the task's reference
    (a heading, an altitude and a speed), named as a 3D controller's inputs
    (:data:`~lifelike_mj.butterfly.flight3d.controllers.OBS_NAMES`); rates are bounded by 10^4 rad/s and speeds by
    2 x 10^3 m/s (a flight diverges before):

    {observations}

    The forward and sideways speeds (and the speed asked) are over the ground, or through the air with
    ``inputs="air"`` (the air around the butterfly, wind and gusts included). ``info["observation_names"]`` gives
    the names at reset. A controller's network reads the first ten (the shipped ``monarch``) or all eleven.

    ## Reward

    Each time step's reward in ``[0, 1]`` (0.1 for flying upright, and up to 0.3 more for each of the speed within
    about 0.3 m/s, the altitude within 0.2 m and the heading within 0.3 rad) times the step (s), divided by the
    episode's length (s): the return is the flight's mean reward per second, the evolution's fitness of this
    task (tested to 1e-9 for the evolved controllers). The naturalness that ``evolve3d --natural`` multiplies in
    per flight (as ``exp(-cost)`` of the style integrals) is not part of it.

    ## Starting state

    At rest at the origin, level, heading +x, the kinematics at the base command. The task's gusts, flutter and
    (for ``course`` and ``wind``) waypoints and wind are drawn from the episode's seed (``reset(seed=...)``, a
    whole number from 0 to 2^32 - 1); a ``Task3D`` of your own is flown as it is (its own seed draws its gusts
    and flutter).

    ## Episode end

    Terminated when the butterfly tumbles (a roll or pitch beyond 80 deg: it earns nothing after, as in the
    evolution) or its flight diverges (``info["diverged"]``); truncated after ``duration_s``.

    ## Arguments

    ``task``: ``"level"`` (straight and level at ``speed_m_s``), ``"turn"`` (level, then ``angle_deg`` to the
    left at 1.5 s), ``"course"`` (10 waypoints 1.5 m apart, drawn per episode), ``"wind"`` (such a course in
    1 m/s of wind from a side drawn per episode, with 0.5 m/s gusts, half that vertically), or a
    :class:`~lifelike_mj.butterfly.flight3d.Task3D` of your own, or a list of these, one drawn per episode (the
    evolution's task sets: ``task=flight3d.TASK_SETS["steer"]()``); ``reset(options={"task": ...})`` changes it
    for one episode. ``speed_m_s`` (1.5), ``angle_deg`` (90), ``flutter`` (0), ``duration_s`` (4, the evolution's
    training flights), ``dt_s`` (1/800 s; 1/1200 s is the step the shipped swallowtail controllers were evolved
    at). ``controller``: a 3D controller (name, path or object) whose base
    command, action scales, rate ``every``, kinematics bandwidth and ``inputs`` the environment takes (default:
    a new controller's: the paper's 10 Hz flap, ``every=1``, speeds over the ground); ``every`` and ``inputs``
    override it; ``animal`` the butterfly flown (``"swallowtail"`` or ``"monarch"``; default the controller's).
    Rendering: ``render_mode`` ``"rgb_array"`` (offscreen frames of ``width`` x ``height``, EGL or
    OSMesa, no display needed; a camera following the butterfly) or ``"human"`` (the MuJoCo viewer; only where a
    window can open).

    ## A residual policy on the designed controller

    With ``controller`` a designed controller (``lifelike-mj butterfly design3d``'s file, its name or object) the
    designed controller flies every episode as a baseline policy, deciding every ``every`` steps of its own (8, 100
    Hz), and the nine actions are a **residual**: one per control (the flap frequency, the stroke offset and
    amplitude, their left-right differences, the mean feathering and its difference, the feathering amplitude, the
    abdomen), times :data:`~lifelike_mj.butterfly.flight3d.designed.RESIDUAL_SCALE` (0.5 Hz, 0.06 rad, ...), added
    to its command and kept within its limits (the natural envelope). Zeros fly the designed controller alone, bit
    for bit. ``info["baseline_command"]`` is its own command at each decision (the 13 kinematics parameters of
    ``flight3d.KinematicsCommand``). ``every``, ``inputs`` and ``animal`` are a network's and are refused.

    ## From a policy to a controller file

    :class:`NetworkInputs3D` divides the observation as a controller's network does, and :class:`NetworkActions3D`
    passes the actions through ``tanh`` as its output layer does. A policy with tanh hidden layers, trained through
    both wrappers, is then a 3D controller: :func:`network_controller3d` writes its weights in the controller file's
    form, and ``lifelike-mj butterfly fly3d --controller FILE`` flies it. ``examples/gym_sb3_flight3d.py`` does this
    with stable-baselines3's PPO.

    ## Version history

    * v0: the first version (lifelike-mj 0.3).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    @checks.known_keywords
    def __init__(self, task: str | flight3d.Task3D = "level", speed_m_s: float = 1.5, angle_deg: float = 90.0,
                 flutter: float = 0.0, duration_s: float = 4.0, dt_s: float = flight3d.DT_S, controller=None,
                 every: int | None = None, inputs: str | None = None, render_mode: str | None = None,
                 width: int = 640, height: int = 480, animal: str | None = None) -> None:
        self.task = self._check_task(task)
        self.speed_m_s = checks.number("speed_m_s", speed_m_s, 0.0, 10.0, lo_open=True, unit="m/s")
        self.angle_deg = checks.number("angle_deg", angle_deg, -360.0, 360.0, unit="deg")
        self.flutter = checks.number("flutter", flutter, 0.0, 1.0)
        self.dt_s = checks.number("dt_s", dt_s, 0.0, 0.01, lo_open=True, unit="s")
        self.duration_s = checks.number("duration_s", duration_s, 0.0, 3600.0, lo_open=True, unit="s")
        self.n_steps = checks.work(f"an episode of {duration_s:g} s at {dt_s:g} s", checks.steps_of(duration_s, dt_s),
                                   checks.MAX_BODY_STEPS, "time steps")
        ctl = _controller(controller)
        #: The designed controller flown under a residual policy (``designed_kernel.CompiledDesigned``), or ``None``.
        self.designed = None if isinstance(ctl, flight3d.Controller3D) else ctl
        if self.designed is not None:
            if every is not None or inputs is not None or (animal is not None and animal != ctl.animal):
                raise UserError("a designed controller keeps its own rate, inputs and butterfly: every, inputs and "
                                "animal are a network's (leave them out).")
        elif every is not None or inputs is not None or animal is not None:
            ctl = ctl.replace(every=ctl.every if every is None else every, inputs=inputs or ctl.inputs,
                              animal=animal or ctl.animal)
        self.controller = ctl
        check_render_mode(self, render_mode)
        from lifelike_mj.render.video import check_size

        check_size(width, height, "frame")
        self.render_mode, self.width, self.height = render_mode, int(width), int(height)
        self.action_space = spaces.Box(-1.0, 1.0, (flight3d.N_ACT,), dtype=np.float64)
        self.observation_space = _observation_space()
        self.flight: flight3d.Flight3D | None = None
        self.episode_task: flight3d.Task3D | None = None
        self._model = None
        self._renderer = None
        self._viewer = None

    # ---- the Gymnasium API ----------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        check_options(options, RESET_OPTIONS)
        super().reset(seed=check_seed(seed))
        chosen = (options or {}).get("task")
        self.episode_task = self.draw_task(self.np_random, self.task if chosen is None else self._check_task(chosen))
        if self._model is None:
            self._model = flight3d.build_model(animal=self.controller.animal)
        self.flight = flight3d.Flight3D(controller=self.controller, task=self.episode_task, dt_s=self.dt_s,
                                        end_on_tumble=True, _model=self._model)
        obs = self.flight.decide(max_steps=self.n_steps)
        info = {"observation_names": OBSERVATION_NAMES, "task": self.episode_task.name}
        if self.designed is not None:
            info["baseline_command"] = self.flight.baseline_command
        return self._shown(obs), info

    def step(self, action):
        if self.flight is None:
            raise RuntimeError("call reset() before step()")
        a = check_actions3d(action)
        before = self.flight.reward
        info: dict[str, Any] = {}
        terminated = False
        try:
            obs = self.flight.decide(a, max_steps=self.n_steps)
        except Diverged as exc:
            obs, terminated, info["diverged"] = np.zeros(flight3d.N_OBS), True, str(exc)
        terminated = terminated or self.flight.tumbled
        truncated = not terminated and self.flight.steps >= self.n_steps
        info["waypoints_passed"] = self.flight.waypoints_passed
        if self.designed is not None:
            info["baseline_command"] = self.flight.baseline_command
        reward = (self.flight.reward - before) / self.duration_s
        return self._shown(obs), float(reward), terminated, truncated, info

    def render(self):
        """``rgb_array``: the current state drawn offscreen from a camera following the butterfly (EGL or OSMesa),
        an ``(height, width, 3)`` uint8 array; ``human``: the MuJoCo viewer (needs a display)."""
        if self.render_mode is None or self.flight is None:
            return None
        f = self.flight
        f.sync()
        if self.render_mode == "human":
            self._show_in_viewer(f.model, f.data, "butterfly3d")
            return None
        from lifelike_mj.render import camera
        from lifelike_mj.render.offscreen import Offscreen

        if self._renderer is None:
            self._renderer = Offscreen(f.model, self.width, self.height)
        self._renderer.update(f.model, f.data, camera.tracking(int(f.model.body("butterfly").id), 0.3, 150.0, -20.0))
        return self._renderer.draw()

    def _shown(self, obs: np.ndarray) -> np.ndarray:
        """The observation within the space's bounds (only a flight about to diverge reaches them)."""
        return np.clip(obs, self.observation_space.low, self.observation_space.high)

    # ---- tasks ----------------------------------------------------------------------------------

    @classmethod
    def _check_task(cls, task) -> str | flight3d.Task3D | tuple:
        if isinstance(task, (list, tuple)):
            if not 1 <= len(task) <= 1000:
                raise UserError(f"a list of tasks has 1 to 1,000 tasks, got {len(task)}.")
            return tuple(cls._check_task(t) for t in task)
        if isinstance(task, flight3d.Task3D):
            if task.kind == "waypoints" and len(task.rows) > COURSE_WAYPOINTS:
                raise UserError(f"a course here has at most {COURSE_WAYPOINTS} waypoints, got {len(task.rows)}.")
            if task.kind == "schedule" and len(task.rows) > COURSE_WAYPOINTS:
                raise UserError(f"a schedule here has at most {COURSE_WAYPOINTS} rows, got {len(task.rows)}.")
            return task
        if task not in TASKS:
            raise UserError(f"task must be one of {', '.join(TASKS)}, a Task3D or a list of them, got {task!r}.")
        return task

    def draw_task(self, rng: np.random.Generator, task: str | flight3d.Task3D) -> flight3d.Task3D:
        """The episode's task: a Task3D as given (its own seed draws its gusts and flutter), else the named task at
        this environment's speed, angle and flutter, its random parts (the seed of the gusts and flutter, the
        course, the wind's side) drawn from ``rng``."""
        if isinstance(task, tuple):
            task = task[int(rng.integers(len(task)))]
        if isinstance(task, flight3d.Task3D):
            return task
        seed = int(rng.integers(2**32))
        if task == "level":
            t = flight3d.level(self.speed_m_s)
        elif task == "turn":
            t = flight3d.turn(self.angle_deg, 1.5, self.speed_m_s)
        else:
            t = flight3d.course(seed, COURSE_WAYPOINTS, speed_m_s=self.speed_m_s)
        if task == "wind":
            side = float(rng.uniform(0.0, 2.0 * math.pi))
            return t.with_weather((WIND_M_S * math.cos(side), WIND_M_S * math.sin(side), 0.0), flutter=self.flutter,
                                  seed=seed, **GUSTS)
        return t.with_weather(flutter=self.flutter, seed=seed)


class ButterflyFlight3DVectorEnv(VectorEnv):
    """``num_envs`` copies of :class:`ButterflyFlight3DEnv` as one Gymnasium :class:`~gymnasium.vector.VectorEnv`,
    all flown by one native, multi-threaded call per step on one compiled MuJoCo model
    (:meth:`lifelike_mj.butterfly.flight3d.loop.Batch.decide`: one ``mjData`` per copy, ``mj_step`` from native
    code on every core).

    Spaces, reward and episode end are the single environment's, batched; the episodes are those of
    ``num_envs`` single environments seeded ``s + i``, bit for bit (tested). Autoreset is ``NEXT_STEP``: the step
    after an episode ends resets that copy, ignores its action and returns its first observation with reward 0.
    Keyword arguments are the single environment's (no rendering: render a single environment); ``num_envs`` is a
    whole number from 1 to 10,000. Made by ``gymnasium.make_vec("lifelike_mj/ButterflyFlight3D-v0", num_envs=N,
    vectorization_mode="vector_entry_point")``; its speed next to bare ``mj_step`` is in ``docs/performance.md``."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}

    def __init__(self, num_envs: int = 16, **kwargs: Any) -> None:
        if kwargs.get("render_mode") is not None:
            raise UserError("the vector environment does not render; render a single ButterflyFlight3D-v0.")
        num_envs = check_num_envs(num_envs, MAX_NUM_ENVS)
        self.single = ButterflyFlight3DEnv(**kwargs)
        self.num_envs = num_envs
        self.single_observation_space = self.single.observation_space
        self.single_action_space = self.single.action_space
        self.observation_space = batch_space(self.single_observation_space, num_envs)
        self.action_space = batch_space(self.single_action_space, num_envs)
        s = self.single
        self._model = flight3d.build_model(animal=s.controller.animal)
        self._model.opt.timestep = s.dt_s
        self._model.opt.gravity[:] = (0.0, 0.0, -ButterflyParams().gravity)
        self._rows = COURSE_WAYPOINTS
        self._rngs = [np.random.default_rng() for _ in range(num_envs)]
        self._tasks: list[flight3d.Task3D | None] = [None] * num_envs
        self._batch: flight3d.Batch | None = None
        self._ended = np.zeros(num_envs, dtype=bool)

    def reset(self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None):
        check_options(options, RESET_OPTIONS)
        if seed is not None:
            self._rngs = copy_rngs(seed, self.num_envs)
        chosen = (options or {}).get("task")
        task = self.single.task if chosen is None else self.single._check_task(chosen)
        s = self.single
        tasks = [s.draw_task(r, task) for r in self._rngs]
        datas = [self._new_data(t) for t in tasks]
        self._tasks = tasks
        if s.designed is None:
            self._batch = flight3d.Batch(self._model, datas, np.array([t.as_array(self._rows) for t in tasks]),
                                         s.controller, dt_s=s.dt_s, records=flight3d.new_record(self.num_envs,
                                                                                                 self._rows),
                                         tumble_rad=flight3d.TUMBLE_RAD)
        else:  # the designed controller decides; its start command is the first task's (only perches read it)
            self._batch = flight3d.Batch(self._model, datas, np.array([t.as_array(self._rows) for t in tasks]), None,
                                         dt_s=s.dt_s, records=flight3d.new_record(self.num_envs, self._rows),
                                         tumble_rad=flight3d.TUMBLE_RAD, base=self._start(tasks[0]).as_array(),
                                         designed=s.designed)
        self._batch.decide(None, s.n_steps)
        self._ended[:] = False
        return self.single._shown(self._batch.observations), self._info({"observation_names": OBSERVATION_NAMES})

    def step(self, actions):
        b, s, n = self._batch, self.single, self.num_envs
        if b is None:
            raise RuntimeError("call reset() before step()")
        a = check_actions3d(actions, n)
        live = ~self._ended
        for i in np.flatnonzero(self._ended):  # NEXT_STEP autoreset of the copies whose episode ended last step
            self._reset_one(i)
        before = b.records[:, flight3d.tasks.R_FIT].copy()
        b.decide(np.clip(a, -1.0, 1.0), s.n_steps, act=live)  # one native call; the copies just reset only observe
        rec = b.records
        rewards = np.where(live, (rec[:, flight3d.tasks.R_FIT] - before) / s.duration_s, 0.0)
        diverged = live & (rec[:, flight3d.tasks.R_DIVERGED] >= 0)
        terminated = live & ((rec[:, flight3d.tasks.R_TUMBLED] >= 0) | diverged)
        truncated = live & ~terminated & (rec[:, flight3d.tasks.R_STEPS] >= s.n_steps)
        self._ended = terminated | truncated
        obs = self.single._shown(b.observations)
        obs[diverged] = 0.0
        info: dict[str, Any] = {"waypoints_passed": rec[:, flight3d.tasks.R_PASSED].astype(int)}
        if diverged.any():
            info["diverged"] = diverged
        return obs, rewards, terminated, truncated, self._info(info)

    def _info(self, info: dict) -> dict:
        """``info`` with the designed controller's commands (``baseline_command``, one row per copy), if it flies."""
        if self.single.designed is not None:
            info["baseline_command"] = self._batch.baselines.copy()
        return info

    def _start(self, task: flight3d.Task3D) -> flight3d.KinematicsCommand:
        """The kinematics a copy starts from: a designed controller's trim at the task's speed (as ``Flight3D`` takes
        it), else the network's base command."""
        if self.single.designed is None:
            return self.single.controller.base
        return self.single.designed.start_command(task.start_speed_m_s)

    # ---- internals ------------------------------------------------------------------------------

    def _new_data(self, task: flight3d.Task3D | None = None):
        from lifelike_mj.butterfly.flight3d import model as mj3d

        c = self.single.controller
        omega_c = None if self.single.designed is not None else c.omega_c_rad_s
        return mj3d.setup_data(self._model, flight3d.Kinematics(self._start(task), omega_c), animal=c.animal,
                               force_law=c.force_law)

    def _reset_one(self, i: int) -> None:
        b, s = self._batch, self.single
        task = s.draw_task(self._rngs[i], s.task)
        self._tasks[i] = task
        b.datas[i] = self._new_data(task)
        b.ptrs[i] = b.datas[i]._address
        b.tasks[i] = task.as_array(self._rows)
        b.records[i] = flight3d.new_record(1, self._rows)[0]
        if s.designed is not None:  # the designed controller's state afresh
            for state in b.designed_states:
                state[i] = 0.0


class NetworkInputs3D(gym.ObservationWrapper):
    """The observation divided by :data:`~lifelike_mj.butterfly.flight3d.controllers.INPUT_SCALE`, as a 3D
    controller's network sees it (every input of order one in flight)."""

    def __init__(self, env: gym.Env) -> None:
        from lifelike_mj.butterfly.flight3d.controllers import INPUT_SCALE

        super().__init__(env)
        box = env.observation_space
        self._scale = INPUT_SCALE
        self.observation_space = spaces.Box(box.low / INPUT_SCALE, box.high / INPUT_SCALE, box.shape, dtype=np.float64)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        return observation / self._scale


class NetworkActions3D(gym.ActionWrapper):
    """Actions through ``tanh``, as a 3D controller's output layer: a policy whose mean action is the pre-activation
    ``z`` of a last linear layer acts as the network with that layer does (``|z|`` beyond 20 is 20: ``tanh`` is
    1 there in float64)."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.action_space = spaces.Box(-20.0, 20.0, env.action_space.shape, dtype=np.float64)

    def action(self, action: np.ndarray) -> np.ndarray:
        return np.tanh(np.clip(np.asarray(action, dtype=np.float64), -20.0, 20.0))


def network_controller3d(layers: list[tuple[np.ndarray, np.ndarray]], template: flight3d.Controller3D | None = None,
                         provenance: dict | None = None) -> flight3d.Controller3D:
    """A 3D controller from a trained network's layers ``[(W, b), ...]`` (``W`` of shape (outputs, inputs), as
    ``torch.nn.Linear`` keeps it; ``tanh`` hidden layers) that reads :class:`NetworkInputs3D`'s observation and acts
    through :class:`NetworkActions3D`: the same network in the controller file's form (per neuron: its input
    weights, then its bias), with ``template``'s base command, scales, rate, inputs, butterfly and wing-force law
    (``animal``, ``force_law``). ``fly3d`` flies it."""
    sizes = [int(np.asarray(layers[0][0]).shape[1])] + [int(np.asarray(w).shape[0]) for w, _ in layers]
    flat = []
    for w, b in layers:
        w, b = np.asarray(w, dtype=np.float64), np.asarray(b, dtype=np.float64).reshape(-1)
        for j in range(w.shape[0]):
            flat.extend(w[j].tolist())
            flat.append(float(b[j]))
    t = template or _still_controller()
    return flight3d.Controller3D(sizes, flat, t.base, dict(zip(flight3d.ACTION_NAMES, t.scale)), t.every,
                                 t.omega_c_rad_s, provenance, "", t.inputs, animal=t.animal, force_law=t.force_law)
