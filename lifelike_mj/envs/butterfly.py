"""The butterfly's pitch task of Oe 2010 section 6 as a Gymnasium environment."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from lifelike_mj import checks
from lifelike_mj.butterfly import PAPER_FLAP, ButterflyController, ButterflyParams, Condition, Flight
from lifelike_mj.envs.pages import Entry, documented, names
from lifelike_mj.errors import Diverged, UserError

#: The observation's six entries (the network's inputs, Oe 2010 section 6.1), in order, named as a pitch law's
#: observation (:class:`~lifelike_mj.butterfly.flight.PitchObservation`) names them, with their units and meanings.
OBSERVATIONS = (
    Entry("phi_rad", "rad", "the pitch of the previous step"),
    Entry("omega_rad_s", "rad/s", "flap rate (positive on the upstroke)"),
    Entry("theta_rad", "rad", "flap angle"),
    Entry("climb_m_s", "m/s", "vertical velocity, relative to the air or the ground (`inputs`)"),
    Entry("altitude_m", "m", "altitude above the target altitude 0 m"),
    Entry("forward_m_s", "m/s", "forward velocity, relative to the air or the ground (`inputs`)"),
)
#: The observation's names, in order (``info["observation_names"]``).
OBSERVATION_NAMES = names(OBSERVATIONS)
#: The action's one entry in each ``action_mode``.
ACTIONS = {"dphi": (Entry("dphi_rad", "rad", "the pitch's change this step, at most `max_dphi_deg` (3 deg)"),),
           "phi": (Entry("phi_rad", "rad", "the pitch itself"),)}
#: Their names before 0.3 (kept one release: :func:`observation_index` takes them, with a one-line note).
OLD_OBSERVATION_NAMES = {"phi_prev_rad": "phi_rad", "v_y_m_s": "climb_m_s", "y_m": "altitude_m",
                         "v_z_m_s": "forward_m_s"}


def observation_index(name: str) -> int:
    """The index of the input ``name`` in an observation (:data:`OBSERVATION_NAMES`; a name of before 0.3 works
    for one more release, with a one-line note)."""
    if name in OLD_OBSERVATION_NAMES:
        checks.renamed(f"the observation {name!r}", repr(OLD_OBSERVATION_NAMES[name]), "the pitch law's name")
        name = OLD_OBSERVATION_NAMES[name]
    if name not in OBSERVATION_NAMES:
        raise UserError(f"the observation has no input {name!r}; its inputs are {', '.join(OBSERVATION_NAMES)}.")
    return OBSERVATION_NAMES.index(name)


ACTION_MODES = ("dphi", "phi")
#: Speeds beyond this end the flight as a runaway (m/s); altitudes are bounded for the space's sake (m).
RUNAWAY_M_S = 1.0e4
MAX_ALTITUDE_M = 1.0e5


def as_condition(value: Any) -> Condition:
    """A flight condition from ``(y0_m, (a, b))`` (start altitude, m; where the wind comes from: front,
    above; m/s) or a :class:`~lifelike_mj.butterfly.Condition`; :class:`UserError` otherwise."""
    if isinstance(value, Condition):
        return value
    try:
        y0, w = value
        a, b = w
    except (TypeError, ValueError):
        raise UserError(f"a flight condition is a (y0_m, (a, b)) pair in m and m/s, got {value!r}.") from None
    return Condition(y0, (a, b))  # which checks each number and says what is out of range


#: The options ``reset`` takes.
RESET_OPTIONS = ("condition",)


def check_options(options: Any, known) -> None:
    """``reset``'s ``options``: ``None`` or a mapping of known names (:class:`~lifelike_mj.errors.UnknownName`
    naming the closest otherwise)."""
    from lifelike_mj.errors import check_names

    if options is None:
        return
    if not isinstance(options, dict):
        raise UserError(f"reset's options must be a dict (known: {', '.join(known)}), got {options!r}.")
    check_names(options, known, "unknown reset option")


#: The largest seed a reset takes: seeds are 0 to 2^32 - 1, as everywhere in the package (``--seed``, a course's).
MAX_SEED = 2**32 - 1


def check_seed(seed: Any) -> int | None:
    """``reset``'s ``seed``: ``None``, or a whole number from 0 to 2^32 - 1 (a NumPy integer too; not a bool), as an
    ``int``; a :class:`~lifelike_mj.errors.UserError` naming the seed and that range otherwise."""
    if seed is None:
        return None
    return checks.whole("seed", seed, 0, MAX_SEED)


def check_num_envs(num_envs: Any, most: int) -> int:
    """A vector environment's ``num_envs``: a whole number from 1 to ``most`` (a NumPy integer too; not a bool, a
    float, a string or an array); a :class:`~lifelike_mj.errors.UserError` naming ``num_envs`` and that range."""
    return checks.whole("num_envs", num_envs, 1, most)


def copy_rngs(seed: Any, n: int) -> list[np.random.Generator]:
    """The random generators of a vector environment's ``n`` copies from ``reset(seed=...)``: copy ``i`` seeded
    ``seed + i`` (as a single environment reset with that seed), or one seed per copy from a list (or a 1-d array);
    every seed given is checked by :func:`check_seed`."""
    if isinstance(seed, (list, tuple)) or (isinstance(seed, np.ndarray) and seed.ndim == 1):
        seeds = [check_seed(sd) for sd in seed]
        if len(seeds) != n:
            raise UserError(f"give one seed or {n} seeds, got {len(seeds)}.")
    else:
        first = check_seed(seed)
        seeds = [first + i for i in range(n)]
    return [gym.utils.seeding.np_random(sd)[0] for sd in seeds]


def render_modes() -> list[str]:
    """The render modes this machine offers: ``rgb_array`` (offscreen, EGL or OSMesa) always, ``human`` (the MuJoCo
    viewer's window) only where a window can open (:func:`~lifelike_mj.render.viewer.has_display`). An environment's
    class ``metadata`` lists both (what it implements); an instance's lists these, so that Gymnasium's ``check_env``
    checks what works here."""
    from lifelike_mj.render.viewer import has_display

    return ["rgb_array", "human"] if has_display() else ["rgb_array"]


def check_render_mode(env: gym.Env, render_mode: Any) -> None:
    """``render_mode``: ``None``, ``"rgb_array"``, or ``"human"`` where a window can open; a
    :class:`~lifelike_mj.errors.UserError` otherwise. Sets the instance's ``metadata`` (:func:`render_modes`)."""
    implemented = type(env).metadata["render_modes"]
    if render_mode is not None and render_mode not in implemented:
        raise UserError(f"render_mode must be one of {implemented} or None, got {render_mode!r}.")
    env.metadata = {**type(env).metadata, "render_modes": render_modes()}
    if render_mode is not None and render_mode not in env.metadata["render_modes"]:
        raise UserError("render_mode='human' opens the MuJoCo viewer's window, which needs a display (DISPLAY and "
                        "WAYLAND_DISPLAY are unset); render_mode='rgb_array' draws offscreen without one.")


def check_actions(actions: Any, n: int) -> np.ndarray:
    """``n`` actions as a float64 array of shape ``(n,)``: accepted as shape ``(n,)`` or ``(n, 1)`` (one per copy),
    or, for ``n = 1``, a scalar; real numbers only (no bools, strings or objects), finite. Anything else is a
    :class:`~lifelike_mj.errors.UserError` (a ``ValueError``) giving the expected shape."""
    a = np.asarray(actions)
    want = "(1,)" if n == 1 else f"({n},) or ({n}, 1), one per copy"
    if a.dtype.kind not in "fiu":
        raise UserError(f"an action is a real number (the pitch, rad), got {actions!r} (dtype {a.dtype}); expected "
                        f"shape {want}.")
    if a.shape not in ((n,), (n, 1)) and not (n == 1 and a.shape == ()):
        raise UserError(f"expected an action array of shape {want}, got shape {a.shape}.")
    a = np.ascontiguousarray(a, dtype=np.float64).reshape(n)
    if not np.isfinite(a).all():
        raise UserError(f"every action must be a finite number, got {actions!r}.")
    return a


class Drawn:
    """What an environment that renders keeps: an offscreen renderer (``rgb_array``) and a viewer window
    (``human``), closed together by :meth:`close`."""

    _renderer = None
    _viewer = None

    def _show_in_viewer(self, model, data, creature: str) -> None:
        """``human``: the MuJoCo viewer on ``model`` and ``data`` (opened at the first call; needs a display)."""
        from lifelike_mj.render.viewer import launch_viewer, require_display

        if self._viewer is None:
            require_display(creature)
            self._viewer = launch_viewer(model, data)
        self._viewer.sync()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        if self._viewer is not None:
            self._viewer.close()
            self._viewer = None


@documented(OBSERVATIONS, ACTIONS["dphi"])
class ButterflyPitchEnv(Drawn, gym.Env):
    """``lifelike_mj/ButterflyPitch-v0``: choose the butterfly's pitch once per step so that it flies
    level and fast (Oe 2010 section 6).

    The butterfly flaps its wings at 10 Hz over [-60, 75] deg (the paper's section 6 pattern) and
    flies in a vertical plane (eq. 7-11). Each step the agent sets the body's pitch; the fitness of
    eq. 13 rewards flying near the target altitude 0 m at a forward speed near 3 m/s.

    ## Action space

    One number, float64, in rad: with ``action_mode="dphi"`` (default), ``Box(-max_dphi, max_dphi, (1,))``, the
    change of the pitch this step (the paper's network changes it by at most 3 deg per step); with
    ``action_mode="phi"``, ``Box(-phi_limit, phi_limit, (1,))``, the pitch itself. The pitch is always clipped to
    ``[-phi_limit, phi_limit]`` (30 deg). An action that is not a finite real number is refused in one sentence.

    {actions}

    ## Observation space

    Six numbers, float64, SI units (the network's six inputs, section 6.1), bounded by the pitch limit, the flap's
    range and peak rate, the runaway speed (10^4 m/s, where a flight diverges) and 10^5 m:

    {observations}

    The names are also in ``info["observation_names"]`` at reset. They are the fields of a pitch law's
    observation (:class:`~lifelike_mj.butterfly.flight.PitchObservation`), so a law written from this table runs
    as a pitch law (with ``inputs="ground"``, the values too are the same). Before 0.3 they were
    ``phi_prev_rad``, ``v_y_m_s``, ``y_m`` and ``v_z_m_s``: :func:`observation_index` still takes those, and a
    pitch law may still read them for one release, each with a one-line note.

    ## Reward

    Each step's term of Oe 2010 eq. 13, ``(v_z / 3) 0.1 / (|y| + 0.1)`` (ground forward speed, m/s;
    altitude, m), summed over the ``frame_skip`` simulation steps the action is held. Summed over an
    episode it is the fitness ``H`` that ``lifelike-mj butterfly evolve`` maximises.

    ## Starting state

    At rest at ``y0_m`` (default 0 m), wings at the top of the stroke, pitch 0. Nothing is random: the
    episode depends only on the actions (``reset(seed=...)``, a whole number from 0 to 2^32 - 1, is accepted for
    the common shape).
    ``reset(options={"condition": (y0_m, (a, b))})`` flies one episode from another start altitude and
    wind (the next plain ``reset()`` goes back to the environment's own).

    ## Episode end

    Truncated after ``duration_s`` (20 s, the paper's flights). Terminated when the flight diverges
    (a runaway speed, or MuJoCo finding its state unstable; ``info["diverged"]`` says why; the reward
    of a step in which MuJoCo reset the simulation is 0, since nothing after the reset is valid) or, if
    ``ground_m`` is given, when the butterfly sinks below ``-ground_m``. The paper's flights have no
    ground, so ``ground_m`` is ``None`` by default.

    ## Arguments

    ``backend`` (``"paper"``: eq. 7-11 with RK4, compiled; ``"mujoco"``), ``inputs`` (``"air"``:
    velocities through the air, the paper's section 6; ``"ground"``: over the ground, section 7.2; the older
    word ``"relative"`` for ``"air"`` is taken this release with a note), ``action_mode``, the wind:
    ``wind_from_m_s`` ``(a, b)`` (where it comes from: front, above; m/s) or ``wind_to_m_s`` (where it blows to:
    forward, up; ``wind_m_s`` is the older spelling of ``wind_from_m_s``), ``y0_m``, ``duration_s``,
    ``dt_s`` (1/1200 s), ``frame_skip``, ``max_dphi_deg`` (3), ``phi_limit_deg`` (30), ``params`` (a
    :class:`~lifelike_mj.butterfly.ButterflyParams`, or a dict of overrides in the command line's units
    such as ``{"body_area_cm2": 1.53}``), ``config`` and ``force_mode`` (MuJoCo backend), ``ground_m``;
    rendering: ``render_mode`` (``"rgb_array"``: offscreen frames of ``width`` x ``height`` pixels, EGL or
    OSMesa, no display needed; ``"human"``: the MuJoCo viewer, only where a window can open), ``camera``
    (``follow``, ``side``, ``chase``).

    ## Version history

    * v0: the first version (lifelike-mj 0.3).
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 30}

    @checks.known_keywords
    def __init__(self, backend: str = "paper", inputs: str = "air", action_mode: str = "dphi",
                 wind_from_m_s: tuple[float, float] | None = None, y0_m: float = 0.0, duration_s: float = 20.0,
                 dt_s: float = 1.0 / 1200.0, frame_skip: int = 1, max_dphi_deg: float = 3.0,
                 phi_limit_deg: float = 30.0, params: ButterflyParams | dict | None = None, config: str = "paper",
                 force_mode: str | None = None, ground_m: float | None = None, render_mode: str | None = None,
                 width: int = 640, height: int = 480, camera: str = "follow", wind_to_m_s=None,
                 wind_m_s=None) -> None:
        from lifelike_mj.butterfly.backends import check_backend, mujoco_options

        check_backend(backend)
        if backend == "mujoco":
            mujoco_options(config, force_mode)  # an unknown configuration is refused here, not at reset
        if inputs == "relative":
            checks.renamed("inputs='relative'", "inputs='air'", "the speeds through the air")
            inputs = "air"
        if inputs not in ("air", "ground"):
            raise UserError(f"inputs must be air or ground, got {inputs!r}.")
        if action_mode not in ACTION_MODES:
            raise UserError(f"action_mode must be dphi or phi, got {action_mode!r}.")
        check_render_mode(self, render_mode)
        if isinstance(params, dict):
            params = ButterflyParams().with_overrides(**params)
        self.params = params or ButterflyParams()
        self.backend, self.inputs, self.action_mode = backend, inputs, action_mode
        wind = Condition(wind_from_m_s=wind_from_m_s, wind_to_m_s=wind_to_m_s, wind_m_s=wind_m_s).wind_from_m_s
        self.condition = self._own_condition = as_condition((y0_m, wind))
        self.dt_s = checks.positive("dt_s", dt_s, "s")
        self.frame_skip = checks.whole("frame_skip", frame_skip, 1, 10_000)
        self.n_steps = int(round(checks.positive("duration_s", duration_s, "s") / self.dt_s))
        self.max_dphi = math.radians(checks.number("max_dphi_deg", max_dphi_deg, 0.0, 90.0, lo_open=True, unit="deg"))
        self.phi_limit = math.radians(checks.number("phi_limit_deg", phi_limit_deg, 0.0, 90.0, lo_open=True,
                                                    unit="deg"))
        self.ground_m = None if ground_m is None else checks.positive("ground_m", ground_m, "m")
        self.render_mode = render_mode
        from lifelike_mj.butterfly.render import CAMERAS
        from lifelike_mj.render.video import check_size

        check_size(width, height, "frame")
        if camera not in CAMERAS:
            raise UserError(f"camera must be one of {', '.join(CAMERAS)}, got {camera!r}.")
        self.width, self.height, self.camera = int(width), int(height), camera
        self._renderer = None
        self._renderer_model = None
        self._viewer = None
        self._controller = ButterflyController("constant", PAPER_FLAP, {"phi_deg": 0.0})
        self._flight_options = {"backend": backend, "config": config, "force_mode": force_mode}
        bound = self.max_dphi if action_mode == "dphi" else self.phi_limit
        self.action_space = spaces.Box(-bound, bound, (1,), dtype=np.float64)
        f = PAPER_FLAP
        w = f.theta_a * 2.0 * math.pi * f.frequency_hz * (1.0 + 1e-9)
        lo = np.array([-self.phi_limit, -w, f.theta_c - f.theta_a - 1e-9, -RUNAWAY_M_S, -MAX_ALTITUDE_M, -RUNAWAY_M_S])
        self.observation_space = spaces.Box(lo, -lo + np.array([0, 0, 2 * f.theta_c, 0, 0, 0]), (6,), dtype=np.float64)
        self._phi = 0.0
        self.flight: Flight | None = None

    # ---- the Gymnasium API ----------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        check_options(options, RESET_OPTIONS)
        super().reset(seed=check_seed(seed))
        chosen = (options or {}).get("condition")
        self.condition = self._episode_condition() if chosen is None else as_condition(chosen)
        self.flight = self._new_flight(self.condition)
        self._phi = 0.0
        return self._observation(), self._reset_info()

    def step(self, action):
        if self.flight is None:
            raise RuntimeError("call reset() before step()")
        a = float(check_actions(action, 1)[0])
        target = self._phi + float(np.clip(a, -self.max_dphi, self.max_dphi)) if self.action_mode == "dphi" else a
        self._phi = min(self.phi_limit, max(-self.phi_limit, target))
        before = self.flight.fitness
        n = min(self.frame_skip, self.n_steps - self.flight.steps)
        info: dict[str, Any] = {}
        terminated = False
        try:
            self.flight.step(n)
        except Diverged as exc:
            terminated, info["diverged"] = True, str(exc)
        reward = 0.0 if self.flight.was_reset else self.flight.fitness - before  # nothing after a MuJoCo reset counts
        obs = self._observation()
        if self.ground_m is not None and obs[4] < -self.ground_m:
            terminated, info["ground"] = True, True
        truncated = not terminated and self.flight.steps >= self.n_steps
        return obs, float(reward) if math.isfinite(reward) else 0.0, terminated, truncated, info

    def render(self):
        """``rgb_array``: the current state drawn offscreen (EGL or OSMesa; no display needed), an
        ``(height, width, 3)`` uint8 array, from ``camera`` (``follow``, ``side`` or ``chase``).
        ``human``: the MuJoCo viewer (needs a display). On either backend the MuJoCo model is drawn."""
        if self.render_mode is None or self.flight is None:
            return None
        self.flight.sync()
        if self.render_mode == "human":
            self._show_in_viewer(self.flight.model, self.flight.data, "butterfly")
            return None
        from lifelike_mj.butterfly.render import dress, flight_camera
        from lifelike_mj.render.offscreen import Offscreen

        if self._renderer is None or self._renderer_model is not self.flight.model:
            self.close()
            self._renderer = Offscreen(dress(self.flight.model), self.width, self.height)
            self._renderer_model = self.flight.model
        self._renderer.update(self.flight.model, self.flight.data, flight_camera(self.flight, self.camera))
        return self._renderer.draw()

    # ---- internals ------------------------------------------------------------------------------

    def _episode_condition(self) -> Condition:
        """The start altitude and wind of the next episode (fixed here; drawn in the wind variant)."""
        return self._own_condition

    def _reset_info(self) -> dict[str, Any]:
        return {"observation_names": OBSERVATION_NAMES}

    def _new_flight(self, condition: Condition) -> Flight:
        """A flight from ``condition``: the current one started again when the condition is the same."""
        if self.flight is not None and self.flight.condition == condition:
            self.flight.reset()
            return self.flight
        return Flight(self._controller, self.params, condition, dt_s=self.dt_s, pitch_law=self._law,
                      **self._flight_options)

    def _law(self, obs) -> float:
        return self._phi

    def _observation(self) -> np.ndarray:
        o = self.flight.observation()
        vy, vz = o.climb_m_s, o.forward_m_s
        if self.inputs == "air":
            vy, vz = vy - o.air_up_m_s, vz - o.air_forward_m_s
        out = np.array([o.phi_rad, o.omega_rad_s, o.theta_rad, vy, o.altitude_m, vz], dtype=np.float64)
        return np.where(np.isfinite(out), out, 0.0)

    # ---- pickling: the settings travel, the simulation is rebuilt by reset() ------------------------

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state.update(flight=None, _renderer=None, _renderer_model=None, _viewer=None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)


class ButterflyPitchWindEnv(ButterflyPitchEnv):
    """``lifelike_mj/ButterflyPitchWind-v0``: :class:`ButterflyPitchEnv` with the start altitude and the
    wind drawn per episode.

    Each ``reset`` draws one flight condition uniformly, with the environment's ``np_random`` (seeded by
    ``reset(seed=...)``), from the ``robust_map`` task of ``butterfly evolve``: starts at -10, -4, 0, +4,
    +10 m in still air, and from 0 m twelve winds over the wind map (2 and 3 m/s from each side, 2 m/s
    along both diagonals). ``conditions`` replaces that list: ``[(y0_m, (a, b)), ...]``.

    Everything else (spaces, reward, episode end, arguments) is as in :class:`ButterflyPitchEnv`. The
    reward is eq. 13's term, unweighted; ``info["flight_weight"]`` at reset is the weight the
    ``robust_map`` task gives this flight (its head-wind share of eq. 13's speed term), so that a weighted
    sum over episodes is that task's fitness.

    ## Version history

    * v0: the first version (lifelike-mj 0.3).
    """

    def __init__(self, conditions=None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        from lifelike_mj.butterfly.evolution import robust_map_conditions

        if conditions is None:
            self.conditions = robust_map_conditions()
        else:
            self.conditions = tuple(as_condition(c) for c in conditions)
            if not self.conditions:
                raise UserError("conditions must hold at least one (y0_m, (a, b)) pair.")

    def _episode_condition(self) -> Condition:
        return self.conditions[int(self.np_random.integers(len(self.conditions)))]

    def _reset_info(self) -> dict[str, Any]:
        from lifelike_mj.butterfly.evolution import flight_weight

        w = tuple(self.condition.wind_from_m_s)
        return {**super()._reset_info(), "y0_m": self.condition.y0_m, "wind_from_m_s": w, "wind_m_s": w,
                "flight_weight": flight_weight(w[0])}
