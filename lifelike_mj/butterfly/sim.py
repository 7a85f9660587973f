"""One butterfly in flight, on either backend, in the stepper shape every creature shares.

:class:`Flight` is built from a controller (its flap pattern and pitch law), the physical
constants, the conditions and a backend; then ``step(n)`` advances it ``n`` time steps,
``state()`` gives named arrays with units, ``record(...)`` a :class:`~lifelike_mj.butterfly.flight.Trajectory`,
and ``model``/``data`` the MuJoCo model and data to draw (on the paper backend a drawing model posed
from the state). The viewer, the video recorder and the experiments drive this class.

A pitch law of your own (Oe 2010 section 5-6: the pitch is set once per step) is given as
``pitch_law=``:

* any Python callable ``law(obs) -> phi`` of a :class:`~lifelike_mj.butterfly.flight.PitchObservation`
  (SI units, rad): run once per step from Python, on either backend;
* a numba ``@njit`` function of the same signature: compiled into the stepping loop, at the speed
  of the built-in laws.

Stepping in chunks gives the same numbers bit for bit as one long run, whatever the chunks.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly import controllers as _controllers
from lifelike_mj.butterfly.backends import check_backend, mujoco_options
from lifelike_mj.butterfly.controllers import KIND_CONSTANT, ButterflyController
from lifelike_mj.butterfly.flight import Condition, PitchObservation, Trajectory, check_timing, kernel_law
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.stepper import StepCounter

#: Names of :meth:`Flight.state` and their units.
STATE_UNITS = {
    "position_m": "m: forward distance z, altitude y (target altitude 0 m)",
    "velocity_m_s": "m/s: forward v_z, vertical v_y (ground frame)",
    "pitch_rad": "rad: body pitch phi (nose up > 0)",
    "flap_rad": "rad: flap angle theta of the wings",
}

_NO_ROWS = np.empty((0, 6))


def _is_numba(fn: object) -> bool:
    try:
        from numba.core.dispatcher import Dispatcher
    except ImportError:  # pragma: no cover
        return False
    return isinstance(fn, Dispatcher)


_MUJOCO_PARTS: tuple = ()


def _mujoco_parts() -> tuple:
    """What a MuJoCo step needs, imported once (MuJoCo is loaded only when a MuJoCo flight runs)."""
    global _MUJOCO_PARTS
    if not _MUJOCO_PARTS:
        from lifelike_mj.butterfly.backends.mj import COMPILED_PASSIVE
        from lifelike_mj.physics.callbacks import passive_callback
        from lifelike_mj.physics.stability import describe, reset_time, was_reset, watching

        _MUJOCO_PARTS = (COMPILED_PASSIVE, passive_callback, describe, reset_time, was_reset, watching)
    return _MUJOCO_PARTS


#: The fewest time steps per wing beat a flight accepts (the paper's coarsest step, 1/120 s, gives 12).
MIN_STEPS_PER_BEAT = 8


def likely_cause_sentence(params: ButterflyParams, dt_s: float) -> str:
    """The likely cause of a diverging flight: the physical constants furthest from the paper's
    (Oe 2010 Table 1) and the time step, as one clause."""
    from lifelike_mj.physics.stability import likely_cause

    raised = likely_cause(params, ButterflyParams())
    text = f"{raised}, " if raised else ""
    return (f"the likely cause is {text}the time step ({dt_s:.3g} s) or the controller: try a smaller --dt or the "
            "paper's constants.")


def runaway_message(step: int, dt_s: float, params: ButterflyParams) -> str:
    """The sentence for a flight whose speed ran away (above 10^4 m/s) at ``step``."""
    return (f"the flight diverged at step {step} (t = {step * dt_s:.4f} s): its speed ran away above 10^4 m/s; "
            + likely_cause_sentence(params, dt_s))


class Flight(StepCounter):
    """One butterfly flight (Oe 2010), stepped on the ``paper`` or ``mujoco`` backend.

    ``controller``: a :class:`~lifelike_mj.butterfly.controllers.ButterflyController`, or the name or
    path of a controller file (default ``simple_rule``). ``params``: the physical constants
    (:class:`~lifelike_mj.butterfly.params.ButterflyParams`); ``condition``: start altitude and wind
    (:class:`~lifelike_mj.butterfly.flight.Condition`); ``dt_s``: the time step, s. On the MuJoCo
    backend, ``config`` (``paper`` or ``rich``) and ``force_mode`` (``tip`` or ``strip``; default: the
    configuration's) choose the model and the wing force. ``pitch_law``: a law of your own (module
    docstring) instead of the controller's; the controller still gives the flap pattern.
    """

    @checks.known_keywords
    def __init__(self, controller: ButterflyController | str | Path = "simple_rule",
                 params: ButterflyParams | None = None, condition: Condition | None = None, *,
                 backend: str = "paper", config: str = "paper", force_mode: str | None = None,
                 dt_s: float = 1.0 / 1200.0, pitch_law: Callable | None = None, n_strips: int = 16,
                 _model=None) -> None:
        self.controller = controller if isinstance(controller, ButterflyController) else _controllers.load(controller)
        self.params = params or ButterflyParams()
        self.condition = condition or Condition()
        self.backend = check_backend(backend)
        check_timing(1.0, checks.number("time step dt_s", dt_s, unit="s"))
        self.dt = float(dt_s)
        self.options = mujoco_options(config, force_mode) if backend == "mujoco" else {}
        self.n_strips = n_strips
        if pitch_law is not None and not callable(pitch_law):
            raise UserError(f"pitch_law must be a function of the observation, got {pitch_law!r}.")
        self.pitch_law = pitch_law
        self._compiled_law = kernel_law(pitch_law) if pitch_law is not None and _is_numba(pitch_law) else None
        self._python_law = pitch_law is not None and self._compiled_law is None
        kind, cp = self.controller.compiled()
        self._kind = int(kind)
        self._cp = np.ascontiguousarray(cp, dtype=float)
        self._flap = self.controller.flap.as_array()
        period = 1.0 / self.controller.flap.frequency_hz
        if self.dt > period / MIN_STEPS_PER_BEAT:
            raise UserError(f"time step {self.dt:g} s does not resolve the wing beat: it must be at most "
                            f"1/{MIN_STEPS_PER_BEAT} of the {period:g} s beat ({period / MIN_STEPS_PER_BEAT:g} s; "
                            "the paper's coarsest is 1/120 s, 12 steps per beat).")
        self._air_z, self._air_y = self.condition.air_velocity()
        self._model = _model
        self._view = None
        self._kernels()
        self.reset()

    def _kernels(self) -> None:
        """The compiled stepping functions of this backend and pitch law, resolved once."""
        law = self._compiled_law
        if self.backend == "paper":
            from lifelike_mj.butterfly.backends import paper

            self._fly = paper.fly_steps if law is None else paper.fly_steps_with(law)
            return
        from lifelike_mj.butterfly.backends import mj

        self._advance_fn, self._record_fn = (mj.advance, mj.record_steps) if law is None else mj.steppers_with(law)

    # ---- the stepper shape ---------------------------------------------------------------------

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: at rest at the start altitude, wings at the top of the stroke, t = 0.
        The flight has no randomness; ``seed`` is accepted for the common shape and ignored."""
        self._k = 0
        self.diverged_step = -1
        self._cause = ""
        if self.backend == "paper":
            from lifelike_mj.butterfly.backends import paper

            self._s = paper.initial_state(self.condition.y0_m)
            self._consts = paper.constants_row(self.params)
            return
        from lifelike_mj.butterfly.backends import mj

        if self._model is None:
            self._model = mj.build_model(self.params, self.options["config"])
            self._model.opt.timestep = self.dt
        self._data = mj.setup_data(self._model, self.controller, self.params, self.condition,
                                   self.options["force_mode"], self.n_strips)
        self._lay = mj.layout(self._model)
        self._lay_a = self._lay.as_array()
        self._phi = 0.0
        self._diverged = np.full(1, -1, dtype=np.int64)
        self._fit = np.zeros(1)

    @property
    def fitness(self) -> float:
        """``H`` of Oe 2010 eq. 13 summed over the steps flown (dimensionless)."""
        if self.backend == "paper":
            from lifelike_mj.butterfly.backends.paper import S_FIT

            return float(self._s[S_FIT])
        return float(self._fit[0])

    @property
    def was_reset(self) -> bool:
        """Whether MuJoCo found this flight unstable and reset its simulation: then nothing after the
        last good step is valid (the fitness included) and the flight stays diverged until ``reset()``."""
        return bool(self._cause)

    def step(self, n: int = 1) -> None:
        """Advance ``n`` time steps. A runaway speed raises :class:`~lifelike_mj.errors.Diverged`
        naming the step; the flight then stays diverged (``reset()`` starts it again)."""
        n = checks.whole("the number of steps", n, 0)
        self._check_alive()
        if n:
            self._advance(n, 0, _NO_ROWS[:, :5] if self.backend == "paper" else _NO_ROWS, 0)
        self._check_alive()

    def record(self, n_steps: int | None = None, *, duration_s: float | None = None, every: int = 1) -> Trajectory:
        """Fly on ``n_steps`` steps (or ``duration_s`` seconds) and return the trajectory sampled every
        ``every`` steps, the current state first. A flight that diverges is returned with its
        ``diverged_step`` set and NaN from there on (as the batch functions do), not raised."""
        if (n_steps is None) == (duration_s is None):
            raise UserError("give either n_steps or duration_s.")
        every = checks.whole("every", every, 1)
        n = (checks.whole("the number of steps", n_steps, 1) if n_steps is not None
             else check_timing(checks.positive("duration", duration_s, "s"), self.dt, every))
        self._check_alive()
        n_rec = n // every + 1
        t = self.time + np.arange(n_rec) * (every * self.dt)
        if self.backend == "paper":
            out = np.empty((n_rec, 5))
            out[0] = self._s[:5]
            self._advance(n, every, out, 1)
            theta = self.controller.flap.theta(t)
        else:
            out = np.empty((n_rec, 6))
            out[0] = self._row()
            self._advance(n, every, out, 1)
            theta = out[:, 5]
        return Trajectory(t=t, y=out[:, 0], z=out[:, 1], vy=out[:, 2], vz=out[:, 3], phi=out[:, 4], theta=theta,
                          y0=self.condition.y0_m, flap_period_s=1.0 / self.controller.flap.frequency_hz,
                          backend=self.backend, diverged_step=self.diverged_step, fitness=self.fitness,
                          diverged_cause=self._cause)

    def state(self) -> dict[str, np.ndarray]:
        """The current state as named arrays (:data:`STATE_UNITS`)."""
        if self.backend == "paper":
            s = self._s
            return {"position_m": np.array([s[1], s[0]]), "velocity_m_s": np.array([s[3], s[2]]),
                    "pitch_rad": np.array(s[4]), "flap_rad": np.array(self.controller.flap.theta(self.time))}
        y, z, vy, vz, phi, theta = self._row()
        return {"position_m": np.array([z, y]), "velocity_m_s": np.array([vz, vy]), "pitch_rad": np.array(phi),
                "flap_rad": np.array(theta)}

    def observation(self) -> PitchObservation:
        """What the pitch law sees at the start of the next step (SI units)."""
        t = self.time
        f = self._flap
        if self.backend == "paper":
            s = self._s
            return PitchObservation(t, float(s[4]), float(-f[1] * f[2] * s[6]), float(f[0] + f[1] * s[5]),
                                    float(s[2]), float(s[0]), float(s[3]), self._air_y, self._air_z)
        q, v, lay = self._data.qpos, self._data.qvel, self._lay
        return PitchObservation(t, self._phi, -f[1] * f[2] * math.sin(f[2] * t), f[0] + f[1] * math.cos(f[2] * t),
                                float(v[lay.d_height]), float(q[lay.q_height]), float(v[lay.d_forward]),
                                self._air_y, self._air_z)

    @property
    def model(self):
        """The MuJoCo model to draw: the simulated one, or on the paper backend the paper-equivalent
        MuJoCo model posed by :meth:`sync`."""
        if self.backend == "mujoco":
            return self._model
        return self._view_pair()[0]

    @property
    def data(self):
        """The ``MjData`` to draw (see :attr:`model`)."""
        if self.backend == "mujoco":
            return self._data
        return self._view_pair()[1]

    def sync(self) -> None:
        """Bring :attr:`data`'s drawing quantities (body poses, cameras, lights) up to the current state.
        It writes only quantities that the next step recomputes, so it never changes the flight."""
        import mujoco

        m, d = self.model, self.data
        if self.backend == "paper":
            st = self.state()
            pose_paper_model(m, d, st["position_m"][1], st["position_m"][0], float(st["pitch_rad"]),
                             float(st["flap_rad"]))
            return
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)

    @property
    def body_id(self) -> int:
        """Id of the butterfly's body in :attr:`model` (for a tracking camera)."""
        return int(self.model.body("butterfly").id)

    # ---- internals ------------------------------------------------------------------------------

    def _check_alive(self) -> None:
        if self.diverged_step >= 0:
            raise Diverged(self._cause or runaway_message(self.diverged_step, self.dt, self.params), self.diverged_step)

    def _row(self) -> tuple[float, ...]:
        q, v, lay = self._data.qpos, self._data.qvel, self._lay
        if lay.rich:
            w, x, y, z = q[lay.q_pitch : lay.q_pitch + 4]
            phi = math.atan2(2.0 * (x * z - w * y), 1.0 - 2.0 * (y * y + z * z))
        else:
            phi = q[lay.q_pitch]
        return (q[lay.q_height], q[lay.q_forward], v[lay.d_height], v[lay.d_forward], phi, q[lay.q_flap_left])

    def _advance(self, n: int, every: int, out: np.ndarray, r0: int) -> None:
        """``n`` steps, recording every ``every`` (0: no recording) into ``out`` from row ``r0``. On the
        MuJoCo backend the compiled passive callback is installed for the whole call."""
        if self.backend == "paper":
            self._steps(self._paper, n, every, out, r0)
            return
        COMPILED_PASSIVE, passive_callback, describe, reset_time, was_reset, watching = _mujoco_parts()
        k0, t0 = self._k, float(self._data.time)
        with passive_callback(COMPILED_PASSIVE), watching():
            self._steps(self._mujoco, n, every, out, r0)
            if was_reset(self._data, t0, self._k - k0, self.dt):  # MuJoCo reset it: nothing from then on is valid
                t = reset_time()
                t = self._k * self.dt if t is None else t
                self._cause = (describe(self._data, "the flight") + " " + likely_cause_sentence(self.params, self.dt))
                bad = min(max(k0 + 1, int(round(t / self.dt)) + 1), k0 + n)
                self.diverged_step = self._k = bad
                if every:
                    out[r0 + max(0, -(-(bad - k0) // every) - 1):] = np.nan

    def _steps(self, kernel, n: int, every: int, out: np.ndarray, r0: int) -> None:
        if not self._python_law:
            kernel(self._kind, self._cp, n, every, out, r0)
            return
        # a Python pitch law: the law from Python, then one compiled step at that pitch
        for i in range(n):
            obs = self.observation()
            try:
                phi = float(self.pitch_law(obs))
            except (TypeError, ValueError) as exc:
                raise UserError(f"the pitch law did not return a number at step {self._k} ({exc}).") from None
            if not math.isfinite(phi):
                raise UserError(f"the pitch law returned {phi} at step {self._k}; a pitch is a finite angle in rad.")
            rec = bool(every) and (i + 1) % every == 0
            row = r0 + (i + 1) // every - 1 if every else 0
            kernel(KIND_CONSTANT, np.array([phi]), 1, 1 if rec else 0, out if rec else out[:0], row)
            if self.diverged_step >= 0:
                if every:
                    out[r0 + i // every:] = np.nan
                return

    def _paper(self, kind: int, cp: np.ndarray, n: int, every: int, out: np.ndarray, r0: int) -> None:
        dv, _ = self._fly(kind, cp, self._flap, self._air_z, self._air_y, self._consts, self._s, self._k, n, self.dt,
                          every if every else n + 1, out, r0)
        if dv >= 0:
            self.diverged_step = int(dv)
            self._k = int(dv)
        else:
            self._k += n

    def _mujoco(self, kind: int, cp: np.ndarray, n: int, every: int, out: np.ndarray, r0: int) -> None:
        m, d = self._model, self._data
        if every:
            self._phi = self._record_fn(m._address, d._address, d.qpos, d.qvel, d.userdata, self._k, n, every, kind, cp,
                                        self._flap, 0.0, self._lay_a, self.dt, self._phi, out, r0, self._diverged,
                                        self._fit)
        else:
            self._phi = self._advance_fn(m._address, d._address, d.qpos, d.qvel, d.userdata, self._k, n, kind, cp,
                                         self._flap, 0.0, self._lay_a, self.dt, self._phi, self._diverged, self._fit)
        if self._diverged[0] >= 0:
            self.diverged_step = int(self._diverged[0])
            self._k = self.diverged_step
        else:
            self._k += n

    def _view_pair(self):
        if self._view is None:
            import mujoco

            from lifelike_mj.butterfly.model import build_model

            m = build_model(self.params, "paper")
            self._view = (m, mujoco.MjData(m))
        return self._view


def pose_paper_model(m, d, y_m: float, z_m: float, phi_rad: float, theta_rad: float) -> None:
    """Place the paper-equivalent model (``models/butterfly/butterfly.xml``) at altitude ``y_m`` and
    forward distance ``z_m`` (m), pitch ``phi_rad`` and both wings at ``theta_rad`` (rad), and compute
    what drawing needs (kinematics, centres of mass, cameras and lights)."""
    import mujoco

    from lifelike_mj.butterfly.model import layout

    lay = layout(m)
    d.qpos[lay.q_forward] = z_m
    d.qpos[lay.q_height] = y_m
    d.qpos[lay.q_pitch] = phi_rad
    d.qpos[m.jnt_qposadr[m.joint("flap_left").id]] = theta_rad
    d.qpos[m.jnt_qposadr[m.joint("flap_right").id]] = theta_rad
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_camlight(m, d)
