"""The butterfly averaged over its wing beat: forces and moments from the simulator itself, trim points across the
flight envelope, and the linear model about each (issue 42, point 1).

**Beat-averaged wrench** (:meth:`Averager.wrench`). The body moves at a constant velocity through the air and turns at
a constant rate; its wings and abdomen move as a kinematics command asks. At :data:`N_PHASES` phases of one wing beat
the simulator's own force callback (:mod:`~lifelike_mj.butterfly.flight3d.model`) is evaluated at that pose and
motion, and its forces (both wings' and the body's drag) and their moments are averaged: the trapezoidal rule,
spectrally accurate for a periodic integrand. The moments are taken about the whole butterfly's centre of mass
averaged over the beat, so that gravity, which pulls at the moving centre of mass, has no mean moment about it. This is
the averaging of Taylor & Thomas (2003) and Sun & Xiong (2005), with the forces of this package's wing law in place of
a flow solver's.

**The averaged body** (:meth:`Averager.derivative`): one rigid body with the whole butterfly's mass and its
beat-averaged inertia about that centre of mass, moved by the averaged wrench and gravity. The wings' own inertial
forces average to nothing over a beat and are left out, as in those papers.

**State and controls.** The state is the body-axis velocity ``u, v, w`` (x forward, y left, z up; m/s), the body-axis
rates ``p, q, r`` (rad/s) and a small rotation ``(a_x, a_y, a_z)`` of the body from the trim attitude, about its own
axes (rad; ``a_y > 0`` lowers the nose). The controls (:data:`CONTROLS`) are the symmetric and antisymmetric changes
of the kinematics a controller makes: the flap frequency, the stroke's offset and amplitude (both wings, and left
less right), the feathering's mean (both, and left less right), the feathering amplitude and the abdomen's angle.

**Trim** (:func:`trim`): for a forward speed and a climb rate in straight flight, the body angle and the kinematics
that make the averaged forces and the pitch moment vanish, as close as they can be to the filmed monarch's gait
(:data:`NATURAL`), within the natural envelope (:data:`ENVELOPE`). Lateral balance holds by symmetry.

**Linear model** (:func:`linearise`): the Jacobians ``A = df/dx`` and ``B = df/du`` at a trim by central
differences, and its modes (:func:`modes`): eigenvalues, each named as Sun (2014) names insects' modes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from lifelike_mj.butterfly.flight3d.controls import (  # noqa: F401  (here too: the model's names)
    CONTROLS,
    ENVELOPE,
    LATERAL,
    LONGITUDINAL,
    STATES,
    TOP_RANGE,
    command_from_controls,
    controls_of,
    rotation,
)
from lifelike_mj.butterfly.flight3d.controls import exp_rotation as _exp
from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
from lifelike_mj.butterfly.flight3d.parts import Butterfly

#: The rate step (rad/s) of the body's damping of its own turning within the beat (:meth:`Averager.wrench`).
DAMPING_STEP_RAD_S = 0.5
#: Phases of a wing beat the wrench is averaged over.
N_PHASES = 48
#: The lowest top of the stroke a trim may take (deg) at forward speeds (m/s), linear between and held beyond. Where a
#: wing's tip stops depends on its feathering as well as on the top, and the slow trims feather more (15 deg at 1 m/s,
#: 7.5 at 1.5), so the same top leaves the tips further apart in slow flight (flown at a top of 69 deg: 50.2 deg at
#: 1 m/s, 48.4 at 1.5, 45.7 at 2), and the closed loop flies about 1.5 deg below its trim's top at 1 m/s. A floor of
#: 72.5 deg at every speed held the gap at 1-1.5 m/s, but the 2 m/s trim then needed a 129 deg stroke and its altitude
#: wandered 4.8 cm rms in calm air (0.4 before), and the 0.75 m/s level trim had no balance (4.4 % of the weight left);
#: below the guidance's slowest airspeed, 1 m/s, the floor returns to the envelope's 69 deg, where the slow trims
#: balance.
TOP_FLOOR_DEG = ((0.75, 69.0), (1.0, 72.5), (2.0, 70.0))


def top_floor(speed_m_s: float) -> float:
    """The lowest top of the stroke (rad) a trim at ``speed_m_s`` may take (:data:`TOP_FLOOR_DEG`)."""
    speeds, tops = zip(*TOP_FLOOR_DEG)
    return math.radians(float(np.interp(speed_m_s, speeds, tops)))


def natural_command():
    """The filmed monarch's gait (:func:`~lifelike_mj.butterfly.flight3d.controllers.default_base`)."""
    from lifelike_mj.butterfly.flight3d.controllers import default_base

    return default_base("monarch")


@dataclass
class Averager:
    """The beat-averaged wrench of ``animal`` under ``force_law`` (module docstring), evaluated on a model of its own."""

    animal: str = "monarch"
    force_law: str = "calibrated"
    n_phases: int = N_PHASES
    #: whether the body turns within the beat (its own rocking), as well as moving
    rotation: bool = True
    _m: mujoco.MjModel = field(init=False, repr=False)
    _d: mujoco.MjData = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from lifelike_mj.butterfly.flight3d import model as mj3d
        from lifelike_mj.butterfly.flight3d.kinematics import Kinematics
        from lifelike_mj.butterfly.params import ButterflyParams

        self.params = ButterflyParams()
        self._m = mj3d.build_model(self.params, "animal", self.animal)
        self._m.opt.gravity[:] = (0.0, 0.0, -self.params.gravity)
        self._d = mj3d.setup_data(self._m, Kinematics(natural_command()), self.params, force_law=self.force_law,
                                  animal=self.animal)
        self._q, self._driven, _ = mj3d.driven_dofs(self._m)
        self._root = self._m.body("butterfly").id
        self.mass_kg = float(self._m.body_subtreemass[self._root])
        self.weight_N = self.mass_kg * self.params.gravity

    def _pose(self, p: np.ndarray, psi: float, v: np.ndarray, w: np.ndarray, tilt: np.ndarray | None = None) -> None:
        """Pose the butterfly at phase ``psi`` of the kinematics ``p`` (held), the body level at the origin, moving at
        ``v`` (m/s) and turning at ``w`` (rad/s), both in its own axes, in still air; forward kinematics and the
        force callback run; ``tilt``: a small rotation of the body (rad, a rotation vector), ``v`` and ``w`` then in the
        untilted axes."""
        from lifelike_mj.butterfly.flight3d import model as mj3d
        from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS, joint_refs
        from lifelike_mj.physics.callbacks import passive_callback

        d = self._d
        d.qpos[:7] = (0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)
        if tilt is not None:
            angle = float(np.linalg.norm(tilt))
            if angle > 0.0:
                mujoco.mju_axisAngle2Quat(d.qpos[3:7], tilt / angle, angle)
            w = _exp(tilt).T @ w  # a free joint's angular velocity is in the body's own axes
        ref = np.empty((5, 3))
        zero = np.zeros(N_PARAMS)
        joint_refs(p, zero, zero, psi, ref)
        d.qpos[self._q] = ref[:, 0]
        d.qvel[:] = 0.0
        d.qvel[0:3] = v
        d.qvel[3:6] = w
        d.qvel[self._driven[:5]] = ref[:, 1]
        ud = d.userdata
        ud[mj3d.U_T0] = d.time
        ud[mj3d.U_PSI0] = psi
        ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS] = p
        ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS] = 0.0
        ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = p
        with passive_callback(mj3d.COMPILED_PASSIVE):
            mujoco.mj_forward(self._m, d)

    def _inertia_about(self, point: np.ndarray) -> np.ndarray:
        """The whole butterfly's inertia (kg m^2, world axes) about ``point`` in the pose now."""
        m, d = self._m, self._d
        inertia = np.zeros((3, 3))
        for b in range(1, m.nbody):
            if m.body_rootid[b] != self._root:
                continue
            R = d.ximat[b].reshape(3, 3)
            r = d.xipos[b] - point
            inertia += R @ np.diag(m.body_inertia[b]) @ R.T + m.body_mass[b] * (r @ r * np.eye(3) - np.outer(r, r))
        return inertia

    def mass_properties(self, p: np.ndarray, inertia: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """The centre of mass averaged over a beat of the kinematics ``p`` (m, body axes from the thorax's origin) and
        the inertia about it, averaged (kg m^2, body axes; ``None`` unless ``inertia``)."""
        d = self._d
        coms, inertias = [], []
        for k in range(self.n_phases):
            self._pose(p, 2.0 * math.pi * k / self.n_phases, np.zeros(3), np.zeros(3))
            coms.append(d.subtree_com[self._root].copy())
        com = np.mean(coms, axis=0)
        if not inertia:
            return com, None
        for k in range(self.n_phases):
            self._pose(p, 2.0 * math.pi * k / self.n_phases, np.zeros(3), np.zeros(3))
            inertias.append(self._inertia_about(com))
        return com, np.mean(inertias, axis=0)

    def _periodic(self, x: np.ndarray, frequency_hz: float, integrate: bool) -> np.ndarray:
        """The zero-mean time integral (``integrate``) or derivative of the periodic samples ``x`` (rows: the beat's
        phases), spectrally, for a beat of ``frequency_hz``."""
        n = len(x)
        k = np.fft.rfftfreq(n, 1.0 / n)  # harmonics of the beat
        w = 2.0 * math.pi * frequency_hz * k
        X = np.fft.rfft(x, axis=0)
        X[0] = 0.0
        if integrate:
            X[1:] /= (1j * w[1:])[:, None]
        else:
            X *= (1j * w)[:, None]
        if n % 2 == 0:
            X[-1] = 0.0  # the Nyquist term has no derivative or integral that stays real
        return np.fft.irfft(X, n, axis=0)

    @staticmethod
    def _turning(moments: np.ndarray, spin: np.ndarray, inertia: np.ndarray, damping: np.ndarray,
                 frequency_hz: float) -> np.ndarray:
        """One preconditioned sweep toward the periodic rate of turn ``s`` with ``I ds/dt = M(t) - mean M``: per harmonic
        ``k`` of the beat, ``s_k <- (i k w I - D)^-1 (M_k - D s_k)`` with ``D`` the damping ``dM/dw`` (a fixed point of
        it solves the equation; where ``D`` is the true damping it converges at once)."""
        n = len(moments)
        w = 2.0 * math.pi * frequency_hz * np.fft.rfftfreq(n, 1.0 / n)
        Mk, Sk = np.fft.rfft(moments, axis=0), np.fft.rfft(spin, axis=0)
        out = np.zeros_like(Sk)
        top = len(w) - 1 if n % 2 == 0 else len(w)
        for i in range(1, top):
            out[i] = np.linalg.solve(1j * w[i] * inertia - damping, Mk[i] - damping @ Sk[i])
        return np.fft.irfft(out, n, axis=0)

    def wrench(self, p: np.ndarray, v, w, about: np.ndarray | None = None,
               iterations: int = 8) -> tuple[np.ndarray, np.ndarray]:
        """The air's force (N) and its moment about the point ``about`` (N m; body axes from the thorax's origin;
        default the centre of mass of ``p`` averaged over the beat, kept as :attr:`com_m`), both in the body's axes,
        averaged over one beat of the kinematics ``p`` with the body moving at a mean ``v`` (m/s) and turning at ``w``
        (rad/s) through still air (module docstring).

        Within the beat the body does not move at a constant velocity: the air's force, less its mean, accelerates
        the whole butterfly's centre of mass, and the wings and abdomen move the thorax about that centre. On a
        butterfly this shakes the thorax by about a metre per second within a beat (the filmed monarch: 1.0-1.6 m/s),
        and averaging the forces at the mean velocity alone gives 15 % more lift than the same flight's simulation.
        So the thorax's velocity is the periodic solution of ``m dv_com/dt = F(t) - mean F`` plus the kinematics'
        own motion of the thorax about the centre of mass, found by ``iterations`` fixed-point sweeps (spectral
        integration over the beat; the attitude held within the beat)."""
        from lifelike_mj.butterfly.flight3d import model as mj3d

        d, m = self._d, self._m
        v, w = np.asarray(v, float), np.asarray(w, float)
        n = self.n_phases
        wings = [int(d.userdata[mj3d.U_WING]), int(d.userdata[mj3d.U_WING + 1])]
        thorax = int(d.userdata[mj3d.U_THORAX])
        coms, rel, spin_momentum = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        inertia = np.zeros((3, 3))
        for k in range(n):
            self._pose(p, 2.0 * math.pi * k / n, np.zeros(3), np.zeros(3))
            coms[k] = d.subtree_com[self._root]
            rel[k] = coms[k] - d.xpos[thorax]
            if self.rotation:
                mujoco.mj_subtreeVel(m, d)
                spin_momentum[k] = d.subtree_angmom[self._root]
                inertia += self._inertia_about(d.subtree_com[self._root]) / n
        #: the whole butterfly's centre of mass averaged over the beat of the last call (m, body axes from the thorax's
        #: origin, which the poses put at the world's)
        self.com_m = coms.mean(axis=0)
        about = self.com_m if about is None else about
        own = -self._periodic(rel, p[0], integrate=False)  # the thorax's velocity from the kinematics alone
        shake = own.copy()
        tilt, spin = np.zeros((n, 3)), np.zeros((n, 3))
        if self.rotation:  # the body's turn from the kinematics alone: the whole butterfly keeps its angular momentum
            own_spin = -np.linalg.solve(inertia, (spin_momentum - spin_momentum.mean(axis=0)).T).T
            spin = own_spin.copy()
            tilt = self._periodic(spin, p[0], integrate=True)
        vel = np.empty(6)

        def sweep(dw=None) -> tuple[np.ndarray, np.ndarray, float]:
            """The forces and moments at each phase with the body on its motion now (and ``dw`` more rate), and the
            power the wings spend on the air."""
            forces, moments, power = np.empty((n, 3)), np.empty((n, 3)), 0.0
            for k in range(n):
                turn = w + spin[k] + (0.0 if dw is None else dw)
                self._pose(p, 2.0 * math.pi * k / n, v + shake[k] - np.cross(spin[k], rel[k]), turn,
                           tilt[k] if self.rotation else None)
                f = mj3d.forces(d)
                centre = _exp(tilt[k]) @ about if self.rotation else about
                force = f["body_drag_N"].copy()
                moment = np.cross(d.xipos[thorax] - centre, f["body_drag_N"])
                for i, b in enumerate(wings):
                    force += f["wing_force_N"][i]
                    moment += f["wing_moment_N_m"][i] + np.cross(d.xpos[b] - centre, f["wing_force_N"][i])
                    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_XBODY, b, vel, 0)
                    power -= float(f["wing_moment_N_m"][i] @ (vel[:3] - turn))
                forces[k], moments[k] = force, moment
            return forces, moments, power / n

        forces, moments, power = sweep()
        if self.rotation:
            # the body's damping of its own turning, dM/dw (N m s), averaged over the beat: it preconditions the
            # periodic solution, whose plain fixed-point sweeps diverge for the roll (its damping outruns the beat)
            damping = np.empty((3, 3))
            for j in range(3):
                e = np.zeros(3)
                e[j] = DAMPING_STEP_RAD_S
                damping[:, j] = (sweep(e)[1] - moments).mean(axis=0) / DAMPING_STEP_RAD_S
        for _ in range(iterations):
            shake = own + self._periodic(forces, p[0], integrate=True) / self.mass_kg
            if self.rotation:
                spin = own_spin + self._turning(moments, spin - own_spin, inertia, damping, p[0])
                tilt = self._periodic(spin, p[0], integrate=True)
            forces, moments, power = sweep()
        #: the mean power (W) the wings' turning about their hinges spends on the air (the muscles' work with perfect
        #: elastic storage of the wings' inertia), of the last call
        self.power_W = power
        #: the body's rotation (rad, rotation vectors), its rate of turn (rad/s) and the thorax's velocity shake (m/s)
        #: over the beat, of the last call (untilted axes)
        self.tilt, self.spin, self.shake = tilt, spin, shake
        return forces.mean(axis=0), moments.mean(axis=0)


@dataclass
class Trim:
    """A trimmed straight flight: forward (horizontal) speed and climb (m/s), the body angle (rad, nose up), the
    kinematics (``KinematicsCommand.as_array`` order), the beat-averaged centre of mass and inertia there, and the
    largest residual force (fraction of the weight) and moment (N m) the trim left."""

    speed_m_s: float
    climb_m_s: float
    pitch_rad: float
    command: np.ndarray
    com_m: np.ndarray
    inertia_kg_m2: np.ndarray
    residual_force: float
    residual_moment_N_m: float

    @classmethod
    def from_point(cls, point: dict) -> Trim:
        """The trim of one point of a built model (:func:`build`'s ``points``, e.g. read from ``model3d``'s file)."""
        return cls(float(point["speed_m_s"]), float(point["climb_m_s"]), math.radians(point["body_angle_deg"]),
                   np.array(list(point["command"].values()), dtype=float), np.array(point["com_m"], dtype=float),
                   np.array(point["inertia_kg_m2"], dtype=float), float(point["residual_force_per_weight"]),
                   float(point["residual_moment_N_m"]))

    def velocity_body(self) -> np.ndarray:
        """The trim's velocity in the body's axes (m/s)."""
        return rotation(0.0, self.pitch_rad, 0.0).T @ np.array([self.speed_m_s, 0.0, self.climb_m_s])


def derivative(av: Averager, trim: Trim, x, u) -> np.ndarray:
    """The averaged body's rates of change (module docstring) at the state ``x`` (:data:`STATES`: the centre of mass's
    velocity in body axes, the body rates, the small rotation from the trim's attitude) under the controls ``u``
    (:data:`CONTROLS`, changes from the trim's kinematics): ``m (dv/dt + w x v) = F + m g``, ``I dw/dt + w x I w = M``,
    ``da/dt = w`` (the last exact at ``a = 0``, where the model is linearised)."""
    x, u = np.asarray(x, float), np.asarray(u, float)
    v, w, a = x[0:3], x[3:6], x[6:9]
    p = command_from_controls(trim.command, u)
    R = rotation(0.0, trim.pitch_rad, 0.0) @ _exp(a)
    g = R.T @ np.array([0.0, 0.0, -av.params.gravity])
    v_thorax = v - np.cross(w, trim.com_m)
    force, moment = av.wrench(p, v_thorax, w, trim.com_m)
    com = av.com_m if np.any(u != 0.0) else trim.com_m  # the kinematics' own centre of mass, where gravity pulls
    moment = moment + np.cross(com - trim.com_m, av.mass_kg * g)
    I = trim.inertia_kg_m2
    dv = force / av.mass_kg + g - np.cross(w, v)
    dw = np.linalg.solve(I, moment - np.cross(w, I @ w))
    return np.concatenate([dv, dw, w])


#: Trim's unknowns besides the body angle, each with its bounds (the natural envelope: :data:`ENVELOPE`, the top of the
#: stroke from :func:`top_floor` to :data:`TOP_RANGE`'s top) and the size of a change from the filmed gait that costs
#: as much as any other (Hz or rad): trim keeps as close to the filmed monarch's gait as the balance allows.
TRIM_UNKNOWNS = {"frequency_hz": 0.5, "top": math.radians(3.0), "amplitude": math.radians(3.0),
                 "feather_mean": math.radians(3.0), "feather_amplitude": math.radians(5.0),
                 "abdomen_mean": math.radians(5.0)}
#: How far (rad) from the body angle asked of straight flight (``evolution.body_angle_target_deg``: 20 deg at 1 m/s,
#: falling 10 deg per m/s, at least 5) a trim's body angle costs as much as a change of the gait by its scale: a weak
#: preference that picks one trim where the balance leaves the body angle and the feathering free to trade.
BODY_ANGLE_SCALE = math.radians(5.0)
#: The mechanical power (W/kg, the wings' work on the air) that costs a trim as much as a change of the gait by its
#: scale: trims prefer the cheaper of two balances, as Dudley (1991) finds butterflies' gaits economical.
POWER_SCALE_W_KG = 3.0
#: The moment arm (m) that turns a pitch moment into a force for the trim's residual.
ARM_M = 0.01


def _gait(p: np.ndarray) -> np.ndarray:
    """The trim's unknowns (:data:`TRIM_UNKNOWNS`) of the kinematics ``p`` (symmetric: the wings' means)."""
    f, off, amp, _, _, fm, _, fa, ab = controls_of(p)
    return np.array([f, off + amp, amp, fm, fa, ab])


def _command(g: np.ndarray) -> np.ndarray:
    """The kinematics of the filmed gait with the trim's unknowns ``g`` in place."""
    p = natural_command().as_array().copy()
    f, top, amp, fm, fa, ab = (float(x) for x in g)
    p[0] = f
    p[1] = p[2] = top - amp
    p[3] = p[4] = amp
    p[5] = p[6] = fm
    p[7] = p[8] = fa
    p[10] = ab
    return p


#: Averagers made in a worker process, by their settings (:func:`_averager`).
_OWN: dict = {}


def _averager(settings: tuple) -> Averager:
    """This process's Averager of ``settings`` (animal, force law, phases, rotation), made once: a worker's twin of
    the one the caller holds (an Averager poses its model afresh at every call, so twins give the same numbers to the
    bit)."""
    if settings not in _OWN:
        animal, force_law, n_phases, turns = settings
        _OWN[settings] = Averager(animal=animal, force_law=force_law, n_phases=n_phases, rotation=turns)
    return _OWN[settings]


class _Own:
    """A function of an Averager that can be sent to a worker process: there it runs on the worker's twin of ``av``
    (:func:`_averager`); here, on ``av`` itself."""

    def __init__(self, av: Averager) -> None:
        self.av: Averager | None = av
        self.settings = (av.animal, av.force_law, av.n_phases, av.rotation)

    def __getstate__(self) -> dict:
        return dict(self.__dict__, av=None)

    def averager(self) -> Averager:
        return self.av if self.av is not None else _averager(self.settings)


class _Balance(_Own):
    """:func:`trim`'s balance and residual at a speed and climb (m/s)."""

    def __init__(self, av: Averager, speed_m_s: float, climb_m_s: float) -> None:
        super().__init__(av)
        self.v_world = np.array([speed_m_s, 0.0, climb_m_s])
        self.nat = _gait(natural_command().as_array())
        self.scales = np.array(list(TRIM_UNKNOWNS.values()))
        from lifelike_mj.butterfly.flight3d.evolution import body_angle_target_deg

        self.body = math.radians(body_angle_target_deg(speed_m_s))

    def balance(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The averaged force (per weight) and pitch moment (per weight and :data:`ARM_M`) left over at the body
        angle and gait ``z``."""
        av = self.averager()
        p = _command(z[1:])
        R = rotation(0.0, z[0], 0.0)
        g = R.T @ np.array([0.0, 0.0, -av.params.gravity])
        force, moment = av.wrench(p, R.T @ self.v_world, np.zeros(3))  # moments about p's own centre of mass
        return (force + av.mass_kg * g) / av.weight_N, moment / (av.weight_N * ARM_M)

    def __call__(self, z: np.ndarray) -> np.ndarray:
        f, m = self.balance(z)
        av = self.averager()
        return np.concatenate([1e4 * np.array([f[0], f[2], m[1]]), (z[1:] - self.nat) / self.scales,
                               [(z[0] - self.body) / BODY_ANGLE_SCALE, av.power_W / av.mass_kg / POWER_SCALE_W_KG]])


def trim(av: Averager, speed_m_s: float, climb_m_s: float = 0.0, start: Trim | None = None, workers=map) -> Trim:
    """The trimmed straight flight at ``speed_m_s`` forward and ``climb_m_s`` up (module docstring): the body angle and
    the symmetric kinematics (:data:`TRIM_UNKNOWNS`) that zero the averaged force and pitch moment, as close to the
    filmed gait as they can be, inside the natural envelope; from ``start`` if given. ``workers``: a map-like callable
    (a process pool's ``map``) the Jacobian's columns are evaluated with; the result is the same to the bit."""
    from scipy.optimize import least_squares

    bounds = {"frequency_hz": ENVELOPE["frequency_hz"], "top": (top_floor(speed_m_s), TOP_RANGE[1]),
              "amplitude": ENVELOPE["amplitude"], "feather_mean": ENVELOPE["feather_mean"],
              "feather_amplitude": ENVELOPE["feather_amplitude"], "abdomen_mean": ENVELOPE["abdomen_mean"]}
    lo = [math.radians(-30.0)] + [bounds[k][0] for k in TRIM_UNKNOWNS]
    hi = [math.radians(60.0)] + [bounds[k][1] for k in TRIM_UNKNOWNS]
    residual = _Balance(av, speed_m_s, climb_m_s)

    # from the filmed gait, or from the neighbouring trim (continuation along the envelope)
    z0 = (np.concatenate([[residual.body], residual.nat]) if start is None
          else np.concatenate([[start.pitch_rad], _gait(start.command)]))
    sol = least_squares(residual, np.clip(z0, lo, hi), bounds=(lo, hi), diff_step=1e-3, xtol=1e-10, ftol=1e-10,
                        gtol=1e-10, workers=workers)
    f, m = residual.balance(sol.x)
    p = _command(sol.x[1:])
    com, inertia = av.mass_properties(p)
    return Trim(float(speed_m_s), float(climb_m_s), float(sol.x[0]), p, com, inertia,
                float(np.abs(f).max()), float(np.abs(m).max() * av.weight_N * ARM_M))


#: Central-difference steps of the states (m/s, rad/s, rad) and of the controls (Hz, rad).
STATE_STEPS = np.array([0.02, 0.02, 0.02, 0.2, 0.2, 0.2, 0.01, 0.01, 0.01])
CONTROL_STEPS = np.array([0.1] + [0.01] * (len(CONTROLS) - 1))


class _Derivative(_Own):
    """:func:`derivative` at a trim, of a state and controls ``(x, u)``."""

    def __init__(self, av: Averager, trim: Trim) -> None:
        super().__init__(av)
        self.trim = trim

    def __call__(self, xu: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        return derivative(self.averager(), self.trim, *xu)


def linearise(av: Averager, trim: Trim, workers=map) -> tuple[np.ndarray, np.ndarray]:
    """``A = df/dx`` (9 x 9) and ``B = df/du`` (9 x 9) of :func:`derivative` at ``trim`` (module docstring), by central
    differences of whole-beat averages (:data:`STATE_STEPS`, :data:`CONTROL_STEPS`); ``workers``: a map-like callable
    the differences are evaluated with (the same to the bit)."""
    x0 = np.concatenate([trim.velocity_body(), np.zeros(6)])
    u0 = np.zeros(len(CONTROLS))
    points = []
    for j, h in enumerate(STATE_STEPS):
        e = np.zeros(9)
        e[j] = h
        points += [(x0 + e, u0), (x0 - e, u0)]
    for j, h in enumerate(CONTROL_STEPS):
        e = np.zeros(len(CONTROLS))
        e[j] = h
        points += [(x0, u0 + e), (x0, u0 - e)]
    f = list(workers(_Derivative(av, trim), points))
    steps = np.concatenate([STATE_STEPS, CONTROL_STEPS])
    J = np.array([(f[2 * j] - f[2 * j + 1]) / (2.0 * h) for j, h in enumerate(steps)]).T
    return J[:, :9].copy(), J[:, 9:].copy()


def name_modes(eigenvalues: np.ndarray, tol: float = 1e-6) -> list[str]:
    """A name for each eigenvalue (1/s) as Sun (2014) names insects' modes: an oscillatory mode (a complex pair),
    stable or unstable; a subsidence (real, negative), the fastest and the slowest so named; a divergence
    (real, positive); neutral (zero: the heading, which nothing in the averaged forces fixes)."""
    reals = [abs(e.real) for e in eigenvalues if abs(e.imag) <= tol and e.real < -tol]
    names = []
    for e in eigenvalues:
        if abs(e.imag) > tol:
            names.append(("unstable" if e.real > tol else "stable") + " oscillatory")
        elif e.real > tol:
            names.append("divergence")
        elif e.real < -tol:
            rank = "fast " if abs(e.real) == max(reals) else "slow " if abs(e.real) == min(reals) else ""
            names.append(rank + "subsidence")
        else:
            names.append("neutral")
    return names


def modes(A: np.ndarray) -> dict:
    """The longitudinal and lateral modes of ``A`` (:data:`LONGITUDINAL`, :data:`LATERAL`): eigenvalues (1/s), their
    names (:func:`name_modes`), and for the unstable ones the time to double (s); also how far the two blocks are
    coupled (the largest cross term against the largest term: zero by symmetry in straight flight)."""
    out = {}
    for name, idx in (("longitudinal", LONGITUDINAL), ("lateral", LATERAL)):
        ev = np.linalg.eigvals(A[np.ix_(idx, idx)])
        ev = ev[np.argsort(-ev.real)]
        out[name] = [{"real_per_s": float(e.real), "imag_rad_s": float(e.imag), "name": n,
                      "time_to_double_s": (math.log(2.0) / e.real) if e.real > 1e-6 else None}
                     for e, n in zip(ev, name_modes(ev))]
    cross = np.abs(A[np.ix_(LONGITUDINAL, LATERAL)]).max() + np.abs(A[np.ix_(LATERAL, LONGITUDINAL)]).max()
    out["coupling"] = float(cross / np.abs(A).max())
    return out


#: A trim whose largest residual force is within this fraction of the weight balances; one beyond it has no balance
#: inside the natural envelope (the nearest one is kept, and marked).
TRIMMED_RESIDUAL = 1e-3
#: The envelope of trims :func:`build` computes: forward speeds and climb rates (m/s).
SPEEDS_M_S = (0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5)
CLIMBS_M_S = (-0.5, 0.0, 0.5)


def flown(av: Averager, trim: Trim, beats: int = 6) -> dict:
    """The trim checked in free flight: the simulator started on the periodic motion the averaging predicts at the
    trim's phase 0 (the body's attitude and rates, the thorax's velocity, within the beat) and flown open loop with the
    trim's kinematics for ``beats`` whole beats. It reports the mean speeds (m/s: a trim keeps its own), the change of
    the body angle and roll over the last beat against the first (deg: a trim keeps them), and the drive's power
    (W/kg, without and with perfect elastic storage), the stroke, dorsal gap and frequency flown."""
    from lifelike_mj.butterfly.flight3d import measures as M
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    R0 = rotation(0.0, trim.pitch_rad, 0.0)
    v_body = trim.velocity_body()
    av.wrench(trim.command, v_body, np.zeros(3), trim.com_m)
    fl = Flight3D(KinematicsCommand(*trim.command), butterfly=Butterfly(av.animal, force_law=av.force_law))
    R = R0 @ _exp(av.tilt[0])
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, R.ravel())
    fl.data.qpos[3:7] = q
    fl.data.qvel[0:3] = R0 @ (v_body + av.shake[0])
    fl.data.qvel[3:6] = _exp(av.tilt[0]).T @ av.spin[0]
    n = int(round(beats / (trim.command[0] * fl.dt)))
    s = M.sample(fl, n * fl.dt)
    m = M.measures(s, **M.body_numbers(fl))
    bb = M.beats(0.5 * (s["joints_rad"][:, 0] + s["joints_rad"][:, 1]))
    (a0, b0), (a1, b1) = bb[0], bb[-1]
    span = s["t_s"][b1] - s["t_s"][a0]
    d = s["position_m"][b1] - s["position_m"][a0]
    att = np.degrees(s["attitude_rad"])
    return {"speed_m_s": float(d[0] / span), "climb_m_s": float(d[2] / span), "side_m_s": float(d[1] / span),
            "body_angle_change_deg": float(att[a1:b1, 1].mean() - att[a0:b0, 1].mean()),
            "roll_change_deg": float(att[a1:b1, 0].mean() - att[a0:b0, 0].mean()),
            "power_W_kg": m["power_W_kg"], "power_net_W_kg": m["power_net_W_kg"], "dorsal_gap_deg": m["dorsal_gap_deg"],
            "stroke_deg": 0.5 * (m["stroke_left_deg"] + m["stroke_right_deg"]), "frequency_hz": m["flap_frequency_hz"],
            "body_pitch_swing_deg": m["body_pitch_swing_deg"], "beats": len(bb)}


def build(speeds=SPEEDS_M_S, climbs=CLIMBS_M_S, force_law: str = "calibrated", progress=None,
          workers: int = 1) -> dict:
    """The averaged model over the envelope (module docstring): at each forward speed and climb rate the trim, its
    check in the simulator with its power (:func:`flown`), the linear model ``A, B`` and its modes. Level trims are
    found from the fastest down, each from the one before (one branch of trims, continuous in speed); climbing and
    sinking trims from the level trim at their speed. ``progress(done, total)`` is told after each trim is found.
    ``workers`` > 1: the trims' and the linear models' differences are evaluated on that many processes (the model is
    the same to the bit)."""
    import concurrent.futures
    import contextlib
    import multiprocessing

    av = Averager(force_law=force_law)
    climbs = sorted(set(float(c) for c in climbs) | {0.0})  # the level trims are where the others start
    total, done = len(speeds) * len(climbs), 0
    level = {}
    prev = None
    pool = (concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
            if workers > 1 else contextlib.nullcontext())
    with pool:
        pmap = pool.map if workers > 1 else map
        for v in sorted(speeds, reverse=True):
            prev = level[v] = trim(av, v, 0.0, start=prev, workers=pmap)
            done += 1
            if progress is not None:
                progress(done, total)
        points = []
        for v in sorted(speeds):
            for c in climbs:
                t = level[v] if c == 0.0 else trim(av, v, c, start=level[v], workers=pmap)
                A, B = linearise(av, t, workers=pmap)
                points.append({"speed_m_s": v, "climb_m_s": c, "body_angle_deg": math.degrees(t.pitch_rad),
                               "command": dict(zip(KinematicsCommand.names(), (float(x) for x in t.command))),
                               "com_m": t.com_m.tolist(), "inertia_kg_m2": t.inertia_kg_m2.tolist(),
                               "residual_force_per_weight": t.residual_force,
                               "residual_moment_N_m": t.residual_moment_N_m,
                               "trimmed": bool(t.residual_force <= TRIMMED_RESIDUAL),
                               "flown": flown(av, t), "A": A.tolist(), "B": B.tolist(), "modes": modes(A)})
                if c != 0.0:
                    done += 1
                    if progress is not None:
                        progress(done, total)
    return {"animal": av.animal, "force_law": force_law, "mass_kg": av.mass_kg, "states": list(STATES),
            "controls": list(CONTROLS), "n_phases": av.n_phases, "points": points}

