"""Landing on a flower by a manoeuvre shot in advance and tracked in closed loop (issue 42, point 3): the designed
controller's landing.

The approach (:mod:`~lifelike_mj.butterfly.flight3d.designed_kernel`) flies level at :data:`APPROACH_M_S` toward the
flower's axis, :data:`RISE_M` above the butterfly's standing point on the blossom. Nearing it, at a distance that
depends on where the wing beat then is, a **manoeuvre** starts: a short open-loop sequence of kinematics (two held
symmetric commands, then the wings spread and held) that brings the body down onto the blossom slowly and nose up, as
Cory and Tedrake's perching glider brings itself onto its perch (Cory & Tedrake 2008, AIAA 2008-7256). One manoeuvre
(a *nominal*) is shot per eighth of the wing beat at which it may start (:data:`N_BINS`), each by CMA-ES
(Hansen 2016) from settled level flight at that phase (:func:`shoot`).

Open loop, a manoeuvre lands only from the entry it was shot from; flown from the entries the approach delivers it
is **tracked** by a time-varying LQR (Tedrake 2009; Moore, Cory & Tedrake 2014, *Bioinspir. Biomim.* 9:025013):
along the nominal the simulator's map over one control step (10 ms) is linearised by central differences, in
:data:`N_STATE` states (the thorax's position and velocity relative to the flower, its attitude and rates, the five
driven joints and their rates, the stroke's phase, and the kinematics' parameters and rates) and
:data:`N_CONTROL` controls (frequency, stroke offset and amplitude, the offset's and amplitude's and feathering's
left-right differences), and a backward Riccati recursion gives a gain for each step (:func:`track`).

Units: m, s, rad, Hz.
"""

from __future__ import annotations

import copy
import math

import mujoco
import numpy as np

from lifelike_mj.butterfly.flight3d import controls as ct
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS
from lifelike_mj.butterfly.flight3d.landing import up
from lifelike_mj.butterfly.flight3d.perch_layout import (  # noqa: F401 - the layout, read here too
    APPROACH_M_S,
    BELOW_M,
    CONTROL_LIMIT,
    CONTROL_SCALE,
    END_SCALE,
    EVERY,
    FINAL_LOOKAHEAD_M,
    FINAL_MIN_M,
    FINAL_OUT_M,
    MAX_GLIDE_S,
    N_BINS,
    N_CONTROL,
    N_STATE,
    RISE_M,
    RUN_SCALE,
    START_HEIGHT_M,
    START_PHASE_GAP_RAD,
    START_SIDE_M,
    START_WINDOW_M,
    TAKE_OFF_STRAIGHT_S,
    TRACKED_CONTROLS,
    check_landing,
)

#: The manoeuvre's decision variables (:func:`command_of`): for each of its two held commands the changes of
#: frequency (Hz), stroke offset, amplitude, feathering mean and abdomen (rad) from the approach's trim and how long it
#: is held (s); the spread wings' flap angle and feathering (rad); the start's distance before the flower's axis (m).
N_DECISION = 2 * 6 + 2 + 1
#: Where the shooting starts (:func:`design_landing`'s first manoeuvre, at half a beat): a manoeuvre that an earlier,
#: longer search found (2026-11-29: 150 generations of CMA-ES at phase 0 from a gentle flare, then each next eighth of
#: the beat from its neighbour, 50 generations each; its phase-4 manoeuvre touched down at 0.03-0.11 m/s from every
#: start it was scored on), rounded: slower and with a larger, higher stroke for 0.16 s, then faster with a smaller
#: stroke for 0.36 s, then the wings spread 48 deg up, starting 0.43 m before the flower's axis.
DECISION_START = np.array([-1.0, 0.17, 0.4, -0.5, 0.59, 0.16, 0.42, 0.36, -0.14, -0.19, -0.09, 0.36, 0.84, 0.58, 0.43])
DECISION_SCALE = np.array([1.0, 0.3, 0.3, 0.3, 0.3, 0.1, 1.0, 0.3, 0.3, 0.3, 0.3, 0.1, 0.5, 0.3, 0.1])
#: The bounds the decisions are kept in.
DECISION_LO = np.array([-3.0, -0.6, -0.9, -0.6, -0.6, 0.02, -3.0, -0.6, -0.9, -0.6, -0.6, 0.02, -0.8, -0.8, 0.3])
DECISION_HI = np.array([2.0, 0.8, 0.4, 0.6, 0.6, 0.4, 2.0, 0.8, 0.4, 0.6, 0.6, 0.4, 1.2, 0.8, 0.9])


def standing_point() -> np.ndarray:
    """The thorax's point when standing on the manoeuvres' flower (m): the approach flies at height 0, the flower's
    blossom stands :data:`RISE_M` below, on the axis ``x = y = 0``."""
    return np.array([0.0, 0.0, -RISE_M])


def blossom_centre(animal: str = "monarch") -> np.ndarray:
    """The centre of the blossom the manoeuvres land on (m): under :func:`standing_point` by the animal's standing
    height and the blossom's half height."""
    from lifelike_mj.butterfly.flight3d.flowers import blossom_under

    return blossom_under(standing_point() - np.array([0.0, 0.0, mj3d.standing_height_m(animal)]))


def commands_of(trim: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float, float]:
    """The manoeuvre of decisions ``z`` (:data:`N_DECISION`) flown from the trim kinematics ``trim``: its first and
    second held commands and the spread wings' command (kinematics parameters), how long the first and second are
    held (s)."""
    out = []
    for j in range(2):
        f, off, amp, fm, ab, _ = z[6 * j : 6 * j + 6]
        out.append(ct.command_from_controls(trim, [f, off, amp, 0.0, 0.0, fm, 0.0, 0.0, ab]))
    spread = np.array(trim, float).copy()
    spread[1] = spread[2] = z[12]
    spread[3] = spread[4] = 0.0
    spread[5] = spread[6] = z[13]
    spread[7] = spread[8] = 0.0
    return out[0], out[1], spread, float(z[5]), float(z[11])


class Plant:
    """The simulator the manoeuvres are shot and linearised on: one flower (:func:`blossom_centre`) with its landing
    task, no controller (each step's kinematics target is set from outside), and the settled approach at each phase
    (:meth:`settled`)."""

    def __init__(self, spec: dict) -> None:
        from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned
        from lifelike_mj.butterfly.flight3d.flight import Flight3D
        from lifelike_mj.butterfly.flight3d.flowers import landing_surface
        from lifelike_mj.butterfly.flight3d.parts import Butterfly, World
        from lifelike_mj.butterfly.flight3d.tasks import land, level

        self.spec, self.ctrl = spec, CompiledDesigned(spec)
        animal, law = self.ctrl.animal, self.ctrl.force_law
        self.trim = self.ctrl.start_command(APPROACH_M_S).as_array()
        blossom = blossom_centre(animal)
        world = World(flowers=[blossom])
        self.butterfly = Butterfly(animal=animal, force_law=law)
        self.approach = Flight3D(controller=self.ctrl, butterfly=self.butterfly, world=world, task=level(APPROACH_M_S),
                                 start_m=(-6.0, 0.0, 0.0))
        self.task = land(landing_surface(blossom), mj3d.standing_height_m(animal))
        self.f = Flight3D(command=self.ctrl.start_command(APPROACH_M_S), butterfly=self.butterfly, world=world,
                          task=self.task, _model=self.approach.model)
        self.m, self.d = self.f.model, self.f.data
        self.rec0 = self.f._rec.copy()
        self.task0 = self.f._task.copy()
        self.dt = self.f.dt

    def settled(self, phase: float, settle_s: float = 3.0) -> mujoco.MjData:
        """The approach's state (a copy of its ``MjData``) at the first step, after ``settle_s`` s of level flight at
        :data:`APPROACH_M_S`, at which the stroke's phase passes ``phase`` (rad), moved to height 0 and ``y = 0``."""
        a = self.approach
        a.reset()
        a.step(int(round(settle_s / a.dt)))
        two_pi = 2.0 * math.pi
        last = a.data.userdata[mj3d.U_PSI0] % two_pi
        for _ in range(int(2.0 / a.dt)):
            a.step(1)
            now = a.data.userdata[mj3d.U_PSI0] % two_pi
            if (now - phase) % two_pi < (last - phase) % two_pi:  # passed it
                break
            last = now
        snap = copy.copy(a.data)
        snap.qpos[1:3] = 0.0
        return snap

    def restore(self, snap: mujoco.MjData, task: np.ndarray | None = None) -> None:
        """The simulation back at ``snap`` (an ``MjData`` of this plant), the landing task (or ``task``, a task array)
        and its record afresh."""
        mujoco.mj_copyData(self.d, self.m, snap)
        self.f._rec[:] = self.rec0
        self.f._task[:] = self.task0 if task is None else task
        self.f._diverged = ""

    def load(self, snap: mujoco.MjData, start_x: float) -> None:
        """Start a run from ``snap`` (:meth:`restore`) with the thorax ``start_x`` m along the approach's line
        (``x``)."""
        self.restore(snap)
        self.d.qpos[0] = start_x

    def fly(self, target: np.ndarray, n: int) -> None:
        """``n`` steps with the kinematics' target ``target`` (stops stepping once perched: the perch's own)."""
        from lifelike_mj.butterfly.flight3d.tasks import TASK_PERCH

        ud = self.d.userdata
        if int(self.f._task[0]) != TASK_PERCH:
            ud[mj3d.U_TARGET : mj3d.U_TARGET + N_PARAMS] = target
        self.f._batch.advance(n)

    @property
    def perched(self) -> bool:
        return self.f.perched




#: How long after its touchdown a manoeuvre's perch is judged (s): a body going over backwards has done so by then.
JUDGE_S = 0.3
#: The entries a manoeuvre is scored from: (along, height) offsets of its start (m), across the start window.
SHOT_OFFSETS = ((0.0, 0.0), (0.02, 0.0), (-0.02, 0.0))


def run(plant: Plant, snap: mujoco.MjData, z: np.ndarray, along_m: float = 0.0, height_m: float = 0.0,
        record: bool = False) -> dict:
    """Fly the manoeuvre of decisions ``z`` open loop from ``snap`` (:meth:`Plant.settled`), its start moved
    ``along_m`` toward the flower and ``height_m`` up. Returns ``touched`` (bool), ``speed_m_s`` at touchdown,
    ``up`` (:func:`up`) :data:`JUDGE_S` after it, ``miss_m`` (the closest the thorax came to its standing point), and
    with ``record`` the ``states`` (``MjData`` copies) and ``commands`` at each control step up to the touchdown."""
    from lifelike_mj.butterfly.flight3d.tasks import R_TOUCH_SPEED

    c1, c2, spread, t1, t2 = commands_of(plant.trim, z)
    plant.load(snap, -float(z[14]) + along_m)
    plant.d.qpos[2] += height_m
    goal = standing_point()
    n1, n2 = int(round(t1 / (EVERY * plant.dt))), int(round(t2 / (EVERY * plant.dt)))
    n_max = n1 + n2 + int(round(MAX_GLIDE_S / (EVERY * plant.dt)))
    miss, states, commands = math.inf, [], []
    for k in range(n_max):
        cmd = c1 if k < n1 else (c2 if k < n1 + n2 else spread)
        if record:
            states.append(copy.copy(plant.d))
            commands.append(cmd)
        plant.fly(cmd, EVERY)
        miss = min(miss, float(np.linalg.norm(plant.d.qpos[0:3] - goal)))
        if plant.perched or plant.d.qpos[2] < goal[2] - 0.1 or plant.d.qpos[0] > 0.15:
            break
    out = {"touched": plant.perched, "miss_m": miss, "speed_m_s": math.inf, "up": -1.0}
    if plant.perched:
        out["speed_m_s"] = float(plant.f._rec[R_TOUCH_SPEED])
        if record:
            states.append(copy.copy(plant.d))
        plant.fly(spread, int(round(JUDGE_S / plant.dt)))
        out["up"] = up(plant.d) if plant.perched else -1.0
    if record:
        out.update(states=states, commands=np.array(commands))
    return out


def cost(outcome: dict) -> float:
    """A run's cost (lower is better): a miss costs its closest approach beyond 5; a touchdown its speed above
    0.1 m/s (4 per m/s) and how far from upright the perch stands :data:`JUDGE_S` later (2 when on its side)."""
    if not outcome["touched"]:
        return 5.0 + 10.0 * outcome["miss_m"]
    return 4.0 * max(0.0, outcome["speed_m_s"] - 0.1) + 2.0 * (1.0 - outcome["up"])


def score(plant: Plant, snap: mujoco.MjData, z: np.ndarray) -> float:
    """The mean :func:`cost` of the manoeuvre ``z`` over :data:`SHOT_OFFSETS`."""
    z = np.clip(z, DECISION_LO, DECISION_HI)
    return float(np.mean([cost(run(plant, snap, z, a, h)) for a, h in SHOT_OFFSETS]))


def _search(f, x0: np.ndarray, scale: np.ndarray, lo: np.ndarray, hi: np.ndarray, seed: int, generations: int,
            population: int, sigma: float, log=None) -> tuple[np.ndarray, float]:
    """CMA-ES (Hansen 2016; ``seed``, ``generations``, ``population``, step ``sigma``) minimising ``f`` over
    ``x0 + scale * x`` kept within ``lo`` and ``hi``. Returns the best point met (clipped to the bounds) and its
    value; ``log(generation, best)`` after each generation."""
    import cma

    es = cma.CMAEvolutionStrategy(np.zeros(len(x0)), sigma, {"seed": seed, "popsize": population,
                                                              "bounds": [list((lo - x0) / scale), list((hi - x0) / scale)],
                                                              "verbose": -9, "maxiter": generations})
    best, best_f = x0, f(x0)
    while not es.stop():
        xs = es.ask()
        fs = [f(x0 + scale * x) for x in xs]
        es.tell(xs, fs)
        i = int(np.argmin(fs))
        if fs[i] < best_f:
            best, best_f = x0 + scale * xs[i], fs[i]
        if log is not None:
            log(es.countiter, best_f)
    return np.clip(best, lo, hi), float(best_f)


def shoot(plant: Plant, phase: float, seed: int, generations: int = 150, population: int = 12, sigma: float = 0.4,
          start: np.ndarray | None = None, log=None) -> tuple[np.ndarray, float]:
    """A manoeuvre for starts at the wing beat's ``phase`` (rad): CMA-ES (``seed``) over the decisions, scaled by
    :data:`DECISION_SCALE`, from ``start`` (default :data:`DECISION_START`), minimising :func:`score`. Returns the
    decisions and their score."""
    snap = plant.settled(phase)
    x0 = DECISION_START if start is None else np.asarray(start, float)
    return _search(lambda z: score(plant, snap, z), x0, DECISION_SCALE, DECISION_LO, DECISION_HI, seed, generations,
                   population, sigma, log)


def _quat_log_diff(qn: np.ndarray, q: np.ndarray) -> np.ndarray:
    """The rotation vector (rad, in the body's frame) taking the attitude ``qn`` to ``q`` (unit quaternions)."""
    from lifelike_mj.butterfly.flight3d.designed import _log, quat2mat

    return _log(quat2mat(qn).T @ quat2mat(q))


def state_vector(d: mujoco.MjData, q_joints: np.ndarray, d_joints: np.ndarray) -> np.ndarray:
    """The state the tracking reads from ``d`` (:data:`N_STATE` + 1 numbers, the attitude as a quaternion): position
    and velocity of the thorax (m, m/s; the nominal's frame), its quaternion and body rates (rad/s), the driven joints
    and their rates, the stroke's phase (rad), the kinematics' parameters and their rates."""
    ud = d.userdata
    return np.concatenate([d.qpos[0:3], d.qvel[0:3], d.qpos[3:7], d.qvel[3:6], d.qpos[q_joints], d.qvel[d_joints],
                           [ud[mj3d.U_PSI0]], ud[mj3d.U_P0 : mj3d.U_P0 + N_PARAMS], ud[mj3d.U_DP0 : mj3d.U_DP0 + N_PARAMS]])


def state_error(s: np.ndarray, s_nom: np.ndarray) -> np.ndarray:
    """``s`` less the nominal's ``s_nom`` (both :func:`state_vector`), :data:`N_STATE` numbers: the attitude as the
    body-frame rotation from the nominal's, the phase wrapped to ``[-pi, pi)``."""
    e = np.empty(N_STATE)
    e[0:6] = s[0:6] - s_nom[0:6]
    e[6:9] = _quat_log_diff(s_nom[6:10], s[6:10])
    e[9:22] = s[10:23] - s_nom[10:23]
    e[22] = (s[23] - s_nom[23] + math.pi) % (2.0 * math.pi) - math.pi
    e[23:] = s[24:] - s_nom[24:]
    return e


def _perturb(d: mujoco.MjData, i: int, h: float, q_joints: np.ndarray, d_joints: np.ndarray) -> None:
    """Move ``d``'s state by ``h`` along the tracked state's ``i``-th coordinate (:func:`state_error`'s order)."""
    ud = d.userdata
    if i < 3:
        d.qpos[i] += h
    elif i < 6:
        d.qvel[i - 3] += h
    elif i < 9:
        a = np.zeros(3)
        a[i - 6] = h
        dq = np.empty(4)
        mujoco.mju_axisAngle2Quat(dq, a / h if h != 0 else np.array([1.0, 0, 0]), h)
        q = np.empty(4)
        mujoco.mju_mulQuat(q, d.qpos[3:7].copy(), dq)
        d.qpos[3:7] = q
    elif i < 12:
        d.qvel[3 + i - 9] += h
    elif i < 17:
        d.qpos[q_joints[i - 12]] += h
    elif i < 22:
        d.qvel[d_joints[i - 17]] += h
    elif i == 22:
        ud[mj3d.U_PSI0] += h
    elif i < 23 + N_PARAMS:
        ud[mj3d.U_P0 + i - 23] += h
    else:
        ud[mj3d.U_DP0 + i - 23 - N_PARAMS] += h


#: The finite-difference steps per tracked state coordinate (:func:`state_error`'s order) and control.
STATE_STEP = np.concatenate([np.full(3, 1e-3), np.full(3, 1e-2), np.full(3, 1e-3), np.full(3, 1e-2), np.full(5, 1e-3),
                             np.full(5, 1e-1), [1e-3], np.full(N_PARAMS, 1e-3), np.full(N_PARAMS, 1e-2)])
CONTROL_STEP = np.array([0.05, 0.005, 0.005, 0.005, 0.005, 0.005])


def controls_to_command(command: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The kinematics ``command`` changed by the tracking's controls ``u`` (:data:`TRACKED_CONTROLS`)."""
    full = np.zeros(len(ct.CONTROLS))
    full[list(TRACKED_CONTROLS)] = u
    return ct.command_from_controls(command, full)


def linearise(plant: Plant, states: list, commands: np.ndarray,
              task: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The nominal's state vectors (``(T + 1, N_STATE + 1)``) and the simulator's map over each of its ``T`` control
    steps linearised about it by central differences: ``A`` (``(T, N_STATE, N_STATE)``) and ``B`` (``(T, N_STATE,
    N_CONTROL)``). ``task``: the task array flown (default the landing's, :meth:`Plant.restore`)."""
    qj, dj, _ = mj3d.driven_dofs(plant.m)
    S = np.array([state_vector(s, qj, dj) for s in states])
    T = len(commands)
    A, B = np.zeros((T, N_STATE, N_STATE)), np.zeros((T, N_STATE, N_CONTROL))

    def after(k, i=-1, h=0.0, du=None):
        plant.restore(states[k], task)
        if i >= 0:
            _perturb(plant.d, i, h, qj, dj)
        cmd = commands[k] if du is None else controls_to_command(commands[k], du)
        plant.fly(cmd, EVERY)
        return state_error(state_vector(plant.d, qj, dj), S[k + 1])

    for k in range(T):
        for i in range(N_STATE):
            h = STATE_STEP[i]
            A[k, :, i] = (after(k, i, h) - after(k, i, -h)) / (2 * h)
        for j in range(N_CONTROL):
            du = np.zeros(N_CONTROL)
            du[j] = CONTROL_STEP[j]
            B[k, :, j] = (after(k, du=du) - after(k, du=-du)) / (2 * CONTROL_STEP[j])
    return S, A, B


def riccati(A: np.ndarray, B: np.ndarray, end: tuple = END_SCALE) -> np.ndarray:
    """The time-varying LQR's gains ``K`` (``(T, N_CONTROL, N_STATE)``, ``u = -K x``) of the linearised nominal, with
    Bryson's weights (:data:`CONTROL_SCALE`, :data:`RUN_SCALE`, and at the end ``end``: :data:`END_SCALE`'s
    layout)."""
    q = np.zeros(N_STATE)
    q[0:3], q[3:6], q[6:9] = RUN_SCALE[0] ** -2, RUN_SCALE[1] ** -2, RUN_SCALE[2] ** -2
    Q = np.diag(q)
    R = np.diag(CONTROL_SCALE ** -2.0)
    qf = np.zeros(N_STATE)
    qf[0:3] = np.array(end[0]) ** -2.0
    qf[3:6], qf[6:9], qf[9:12] = end[1] ** -2, end[2] ** -2, end[3] ** -2
    P = np.diag(qf)
    T = len(A)
    K = np.zeros((T, N_CONTROL, N_STATE))
    for k in range(T - 1, -1, -1):
        a, b = A[k], B[k]
        K[k] = np.linalg.solve(R + b.T @ P @ b, b.T @ P @ a)
        P = Q + a.T @ P @ (a - b @ K[k])
        P = 0.5 * (P + P.T)
    return K


def manoeuvre(plant: Plant, phase: float, z: np.ndarray) -> dict | None:
    """The manoeuvre of decisions ``z`` started at the beat's ``phase`` (rad) as the controller file keeps it: its
    start distance, its nominal (states and commands at each control step, to the touchdown) and its tracking's gains
    (:func:`linearise`, :func:`riccati`), with how the nominal itself lands (``touchdown_m_s``, ``up``). ``None`` if
    the nominal does not touch down."""
    snap = plant.settled(phase)
    o = run(plant, snap, z, record=True)
    if not o["touched"]:
        return None
    S, A, B = linearise(plant, o["states"], o["commands"])
    K = riccati(A, B)
    r = _rounded
    return {"phase_rad": float(phase), "start_m": float(z[14]), "decisions": r(z), "touchdown_m_s": o["speed_m_s"],
            "up": o["up"], "states": r(S, 9), "commands": r(o["commands"], 9), "gains": r(K, 6)}


#: The take-off's decisions (:func:`take_off_commands`): for each of its two held commands the changes of frequency
#: (Hz), stroke offset, amplitude, feathering mean and abdomen (rad) from the approach's trim and how long it is held
#: (s); then the trim itself is flown for :data:`TAKE_OFF_HOLD_S`, and the regulator takes over.
N_TAKE_OFF = 12
#: Where the take-off's shooting starts: what a first search found (2026-11-29: 30 generations from the trim held
#: throughout, which drops the body 0.34 m), rounded: a faster beat with a larger, lower stroke and the abdomen raised
#: for 0.09 s, then a still faster one with the wings' offset raised for 0.13 s.
TAKE_OFF_START = np.array([0.04, -0.1, 0.4, 0.0, -0.22, 0.09, 1.16, 0.02, 0.33, 0.14, 0.01, 0.13])
TAKE_OFF_SCALE = DECISION_SCALE[:12]
TAKE_OFF_LO = DECISION_LO[:12]
TAKE_OFF_HI = np.array([2.0, 0.8, 0.6, 0.6, 0.6, 0.4] * 2)
#: How long the trim is flown at the end of the take-off's nominal (s), the last beat of it scored.
TAKE_OFF_HOLD_S = 0.25
#: The perches the take-off is shot from: the landings of :data:`DECISION_START` begun at these eighths of the beat
#: and these (along, height) offsets (m), each then perched for a second (one still upright then: :func:`perches`):
#: bodies pitched -0.24 to +0.10 rad on their blossom.
TAKE_OFF_PERCHES = ((4, 0.0, 0.0), (4, 0.02, 0.0), (4, -0.02, 0.0), (5, -0.02, 0.0))
#: The take-off's tracking: Bryson's scales at its end (:data:`END_SCALE`'s layout: position, velocity, attitude,
#: rates), looser than a touchdown's: it hands over to the regulator, which holds the trim.
TAKE_OFF_END_SCALE = ((0.05, 0.05, 0.05), 0.2, 0.1, 1.0)
#: The take-off's shooting: CMA-ES generations, step, population (the seed is the landing's).
TAKE_OFF_GENERATIONS, TAKE_OFF_SIGMA, TAKE_OFF_POPULATION = 30, 0.3, 12


def take_off_commands(trim: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The take-off of decisions ``z`` (:data:`N_TAKE_OFF`) from the trim kinematics ``trim``: its first and second
    held commands and how long each is held (s)."""
    c1, c2, _, t1, t2 = commands_of(trim, np.concatenate([z, [0.0, 0.0, 0.0]]))
    return c1, c2, t1, t2


def perches(plant: Plant) -> list:
    """The perched states the take-off is shot from (:data:`TAKE_OFF_PERCHES`; those still perched and upright,
    :func:`~lifelike_mj.butterfly.flight3d.landing.up` above 0.9, after a second): ``MjData`` copies."""
    out = []
    for b, along, height in TAKE_OFF_PERCHES:
        run(plant, plant.settled(2.0 * math.pi * b / N_BINS), DECISION_START, along, height)
        if plant.perched:
            plant.fly(plant.trim, int(round(1.0 / plant.dt)))
            if plant.perched and up(plant.d) > 0.9:
                out.append(copy.copy(plant.d))
    return out


def take_off_task(plant: Plant) -> np.ndarray:
    """The task flown after a take-off on the plant: the landing's, its flower 30 m ahead (no touchdown on the
    flower just left)."""
    from lifelike_mj.butterfly.flight3d.tasks import T_ROW0

    task = plant.task0.copy()
    task[T_ROW0] += 30.0
    return task


def trim_pitch(plant: Plant) -> float:
    """The approach trim's pitch (rad, nose up), averaged over a beat of settled flight."""
    from lifelike_mj.butterfly.flight3d.loop import attitude

    plant.restore(plant.settled(0.0))
    pitch = []
    for _ in range(int(round(0.1 / plant.dt))):
        plant.fly(plant.trim, 1)
        pitch.append(attitude(plant.d.qpos[3:7])[1])
    return float(np.mean(pitch))


def take_off_run(plant: Plant, perch: mujoco.MjData, z: np.ndarray, pitch_ref: float, record: bool = False) -> dict:
    """Take off from ``perch`` (:func:`perches`) flying the decisions ``z`` open loop, as a garden's butterfly takes
    off (:func:`~lifelike_mj.butterfly.flight3d.loop.take_off_kinematics`, the task then :func:`take_off_task`).
    Returns ``drop_m`` (the most the thorax sank below its perch), ``tilt_rad`` (the largest roll or pitch from
    ``pitch_ref``), ``gain_m`` (height gained at the end), and over the last beat: ``forward_m_s``, ``side_m_s``,
    ``climb_m_s`` (along, across and up from the heading at the start), ``pitch_rad``, ``roll_rad``, ``yaw_rad`` (turned
    since the start), ``rates_rad_s`` (norm); ``failed`` if it diverged or touched down; with ``record`` the
    ``states`` and ``commands`` at each control step."""
    from lifelike_mj.butterfly.flight3d.loop import attitude, take_off_kinematics

    c1, c2, t1, t2 = take_off_commands(plant.trim, z)
    plant.restore(perch, take_off_task(plant))
    take_off_kinematics(plant.d.userdata, plant.f._batch.base)
    d, step = plant.d, EVERY * plant.dt
    z0, yaw0 = float(d.qpos[2]), attitude(d.qpos[3:7])[2]
    n1, n2, n3 = int(round(t1 / step)), int(round(t2 / step)), int(round(TAKE_OFF_HOLD_S / step))
    n_last = max(1, int(round(0.1 / step)))
    low, tilt, last, states, commands = z0, 0.0, [], [], []
    for k in range(n1 + n2 + n3):
        cmd = c1 if k < n1 else (c2 if k < n1 + n2 else plant.trim)
        if record:
            states.append(copy.copy(d))
            commands.append(cmd)
        plant.fly(cmd, EVERY)
        if plant.f._diverged or plant.perched:
            return {"failed": True}
        roll, pitch, yaw = attitude(d.qpos[3:7])
        low, tilt = min(low, float(d.qpos[2])), max(tilt, abs(roll), abs(pitch - pitch_ref))
        if k >= n1 + n2 + n3 - n_last:
            last.append([roll, pitch, (yaw - yaw0 + math.pi) % (2.0 * math.pi) - math.pi, *d.qvel[0:6]])
    m = np.mean(last, axis=0)
    c, s = math.cos(yaw0), math.sin(yaw0)
    out = {"failed": False, "drop_m": z0 - low, "tilt_rad": tilt, "gain_m": float(d.qpos[2]) - z0,
           "forward_m_s": c * m[3] + s * m[4], "side_m_s": -s * m[3] + c * m[4], "climb_m_s": m[5],
           "pitch_rad": m[1], "roll_rad": m[0], "yaw_rad": m[2], "rates_rad_s": float(np.linalg.norm(m[6:9]))}
    if record:
        states.append(copy.copy(d))
        out.update(states=states, commands=np.array(commands))
    return out


def take_off_cost(o: dict, pitch_ref: float) -> float:
    """A take-off's cost (lower is better; :func:`take_off_run`'s outcome ``o``): 20 per m of drop below the perch,
    2 per rad of tilt beyond 0.4 rad, 10 per m short of a 5 cm gain, and a quarter of the hand-over's squared
    distance from the approach's trim in Bryson's scales (0.3 m/s along and across, sinking or climbing faster than
    0.5 m/s; 0.2 rad of pitch and roll, 0.3 rad of turn; 1 rad/s of rates). A failed run costs 50."""
    if o["failed"]:
        return 50.0
    climb = o["climb_m_s"]
    climb_off = climb if climb < 0.0 else max(0.0, climb - 0.5)
    end = (((o["forward_m_s"] - APPROACH_M_S) / 0.3) ** 2 + (o["side_m_s"] / 0.3) ** 2 + (climb_off / 0.3) ** 2
           + ((o["pitch_rad"] - pitch_ref) / 0.2) ** 2 + (o["roll_rad"] / 0.2) ** 2 + (o["yaw_rad"] / 0.3) ** 2
           + o["rates_rad_s"] ** 2)
    return (20.0 * o["drop_m"] + 2.0 * max(0.0, o["tilt_rad"] - 0.4) + 10.0 * max(0.0, 0.05 - o["gain_m"])
            + 0.25 * end)


def design_take_off(spec: dict, seed: int = 1, generations: int = TAKE_OFF_GENERATIONS) -> dict:
    """The designed controller ``spec``'s take-off (its file's ``landing["take_off"]``): decisions shot by CMA-ES
    (``seed``, ``generations``) from :data:`TAKE_OFF_START`, minimising the mean :func:`take_off_cost` over
    :func:`perches`; its nominal flown from the first perch and tracked by a time-varying LQR (:func:`linearise`,
    :func:`riccati` with :data:`TAKE_OFF_END_SCALE`), as the landing's manoeuvres are."""
    plant = Plant(spec)
    snaps, pitch_ref = perches(plant), trim_pitch(plant)

    def score(z):
        z = np.clip(z, TAKE_OFF_LO, TAKE_OFF_HI)
        return float(np.mean([take_off_cost(take_off_run(plant, p, z, pitch_ref), pitch_ref) for p in snaps]))

    best, best_f = _search(score, TAKE_OFF_START, TAKE_OFF_SCALE, TAKE_OFF_LO, TAKE_OFF_HI, seed, generations,
                           TAKE_OFF_POPULATION, TAKE_OFF_SIGMA)
    o = take_off_run(plant, snaps[0], best, pitch_ref, record=True)
    task = take_off_task(plant)
    S, A, B = linearise(plant, o["states"], o["commands"], task)
    K = riccati(A, B, TAKE_OFF_END_SCALE)
    outcomes = [take_off_run(plant, p, best, pitch_ref) for p in snaps]
    return {"decisions": _rounded(best), "score": best_f, "pitch_ref_rad": pitch_ref,
            "drop_m": [o["drop_m"] for o in outcomes], "gain_m": [o["gain_m"] for o in outcomes],
            "states": _rounded(S, 9), "commands": _rounded(o["commands"], 9), "gains": _rounded(K, 6),
            "shooting": {"seed": seed, "generations": generations, "sigma": TAKE_OFF_SIGMA,
                         "population": TAKE_OFF_POPULATION, "start": TAKE_OFF_START.tolist(),
                         "perches": [list(p) for p in TAKE_OFF_PERCHES], "hold_s": TAKE_OFF_HOLD_S}}


def _rounded(a, digits: int = 7):
    """``a`` (an array or a list of them) as nested lists of floats with ``digits`` significant digits."""
    return [float(f"{v:.{digits}g}") for v in a] if np.ndim(a) == 1 else [_rounded(x, digits) for x in a]


#: The shooting's settings (:func:`design_landing`): CMA-ES generations and step for each chain's first manoeuvre and
#: for each next one (started from its neighbour's decisions), the population, the seed.
FIRST_GENERATIONS, FIRST_SIGMA, NEXT_GENERATIONS, NEXT_SIGMA, POPULATION, SEED = 40, 0.2, 35, 0.15, 12, 1
#: The design's two chains around the beat, shot at once: each first shoots phase bin 4 (half a beat) from
#: :data:`DECISION_START` (each with its own seed; the better is kept), then its other bins, each from the decisions
#: of the bin named with it.
HALVES = ((4, ((3, 4), (2, 3), (1, 2), (0, 1))), (4, ((5, 4), (6, 5), (7, 6))))


def _half(spec: dict, first: int, rest: tuple, seed: int, generations: tuple[int, int]) -> list:
    """One chain around the beat (:data:`HALVES`): its first bin shot from :data:`DECISION_START`, the rest each from the
    decisions of the bin named with it; each built (:func:`manoeuvre`). Returns ``(bin, decisions, score,
    manoeuvre)``."""
    plant = Plant(spec)

    def phase(b):
        return 2 * math.pi * b / N_BINS

    z, f = shoot(plant, phase(first), seed, generations[0], POPULATION, FIRST_SIGMA)
    found = {first: (z, f)}
    for b, start in rest:
        found[b] = shoot(plant, phase(b), seed, generations[1], POPULATION, NEXT_SIGMA, start=found[start][0])
    return [(b, z.tolist(), f, manoeuvre(plant, phase(b), z)) for b, (z, f) in found.items()]


def design_landing(spec: dict, seed: int = SEED, workers: int = 2, progress=None,
                   generations: tuple[int, int] = (FIRST_GENERATIONS, NEXT_GENERATIONS), halves: tuple = HALVES,
                   take_off: int | None = TAKE_OFF_GENERATIONS) -> dict:
    """The designed controller ``spec``'s landing (its file's ``landing``): one manoeuvre per eighth of the wing
    beat, shot in two chains at once (:data:`HALVES`, on ``workers`` processes, seeds ``seed`` and ``seed + 1``):
    each chain's first from :data:`DECISION_START`, its others each from a neighbour's decisions (a manoeuvre for the
    next eighth of the beat is near its neighbour's); each built with its tracking (:func:`manoeuvre`).
    ``generations``: CMA-ES's for each chain's first and for each next manoeuvre; ``halves``: the chains (each its
    first bin, then ``(bin, from bin)`` pairs; a test shoots fewer). ``progress(done, total)`` as chains
    are done. A manoeuvre whose nominal does not touch down is left out (its
    phases then start the nearest other). The take-off (:func:`design_take_off`, ``take_off`` generations; ``None``:
    none) is shot on the same pool, by the first worker free (the chains are of unequal length)."""
    import concurrent.futures
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    results: list = []
    with concurrent.futures.ProcessPoolExecutor(max_workers=max(1, min(workers, len(halves))), mp_context=ctx) as pool:
        futures = [pool.submit(_half, spec, first, rest, seed + i, generations)
                   for i, (first, rest) in enumerate(halves)]
        rising = None if take_off is None else pool.submit(design_take_off, spec, seed, take_off)
        for fu in concurrent.futures.as_completed(futures):
            results += fu.result()
            if progress:
                progress(len({r[0] for r in results}), N_BINS)
        rising = None if rising is None else rising.result()
    best: dict = {}
    for r in results:  # a bin shot by both chains: the better kept
        if r[0] not in best or r[2] < best[r[0]][2]:
            best[r[0]] = r
    results = [best[b] for b in sorted(best)]
    return {"manoeuvres": [r[3] for r in results if r[3] is not None], **({"take_off": rising} if rising else {}),
            "shooting": {"bins": N_BINS, "seed": seed, "halves": [[h[0], [list(r) for r in h[1]]] for h in halves],
                         "first_generations": generations[0], "first_sigma": FIRST_SIGMA,
                         "next_generations": generations[1], "population": POPULATION, "next_sigma": NEXT_SIGMA,
                         "start": DECISION_START.tolist(), "scores": [r[2] for r in results],
                         "touched": [r[3] is not None for r in results], "offsets_m": [list(o) for o in SHOT_OFFSETS],
                         "rise_m": RISE_M, "approach_m_s": APPROACH_M_S}}
