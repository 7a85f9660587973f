"""The paper's point-mass flight model (Oe 2010 eq. 7-11), compiled and batched.

State per butterfly: altitude ``y`` (m, up), forward position ``z`` (m), velocities ``v_y``,
``v_z`` (m/s). Per RK4 step of ``dt`` seconds:

* the pitch ``phi`` (rad) is set once, at the start of the step, by the controller;
* the flap angle ``theta(t)`` and rate ``omega(t)`` are evaluated at each RK4 stage time;
* forces: ``v_w' = L omega - v_z sin(phi)`` (eq. 7), ``F = K v_w'|v_w'|``, ``F_y = -F cos(phi)``,
  ``F_z = F sin(phi)`` (eq. 8-9), body drag ``-1/2 rho C_d A_b v|v|`` per axis (eq. 10), and
  ``m y'' = F_y cos(theta) + F_by - m g``, ``m z'' = F_z cos(theta) + F_bz`` (eq. 11 with the
  gravity the text requires). All velocities in force terms are relative to the air (section 7.2):
  ``wind (a, b)`` gives an air velocity ``-(a, b)`` in (forward, up).

One call of :func:`simulate` integrates many butterflies (different controllers, conditions or
constants) in parallel threads. :func:`simulate_naive` is the same model as a plain Python loop,
kept as the speed baseline and as an independent check of the compiled code.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence

import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly.ann import ann_pitch
from lifelike_mj.butterfly.controllers import KIND_ANN, KIND_CONSTANT, KIND_SIMPLE_RULE, OMEGA_EPS, ButterflyController
from lifelike_mj.butterfly.flight import (
    Condition,
    PitchObservation,
    Trajectory,
    builtin_law,
    check_timing,
    fitness_term,
)
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.physics.fluid import normal_drag_scalar
from lifelike_mj.physics.jit import njit_with

# columns of the per-butterfly constants array
_MASS, _K, _AB, _RHO, _CD, _L, _G = range(7)


def constants_row(p: ButterflyParams) -> np.ndarray:
    """Constants of one butterfly for compiled code: m, K, A_b, rho, C_d, L, g (SI)."""
    return np.array([p.mass_kg, p.k_wings, p.body_area_m2, p.rho, p.cd, p.span_m, p.gravity])


@njit(cache=True, inline="always", error_model="numpy")
def _accel(vy, vz, sphi, cphi, omega, ctheta, air_z, air_y, c):
    """Accelerations (m/s^2), Oe 2010 eq. 7-11, for pitch ``(sin phi, cos phi)``, flap rate
    ``omega`` (rad/s) and ``cos(theta)`` at one RK4 stage."""
    vzr = vz - air_z
    vyr = vy - air_y
    vp = c[_L] * omega - vzr * sphi  # eq. 7
    f = c[_K] * vp * abs(vp)  # eq. 8-9: F = K v'|v'|
    fby = normal_drag_scalar(c[_AB], c[_RHO], c[_CD], vyr)  # eq. 10
    fbz = normal_drag_scalar(c[_AB], c[_RHO], c[_CD], vzr)
    ay = (-f * cphi * ctheta + fby) / c[_MASS] - c[_G]  # eq. 11 (+ gravity)
    az = (f * sphi * ctheta + fbz) / c[_MASS]
    return ay, az


@njit(cache=True, inline="always", error_model="numpy")
def _flap_from(flap, cw, sw):
    """``(omega, cos theta)`` of the cosine flap given ``cos(2 pi f t)``, ``sin(2 pi f t)``."""
    return -flap[1] * flap[2] * sw, math.cos(flap[0] + flap[1] * cw)


# ---- one butterfly, resumable ------------------------------------------------------------------

#: Columns of a butterfly's state array (for :func:`fly_steps`): altitude y (m), forward z (m),
#: velocities v_y, v_z (m/s), the last pitch phi (rad), cos and sin of the flap phase 2 pi f t at the
#: next step, and the fitness H summed so far (eq. 13).
S_Y, S_Z, S_VY, S_VZ, S_PHI, S_CW, S_SW, S_FIT = range(8)
N_STATE = 8


def initial_state(y0_m: float) -> np.ndarray:
    """The state array of a butterfly at rest at altitude ``y0_m`` (m), wings at the top, step 0."""
    s = np.zeros(N_STATE)
    s[S_Y] = y0_m
    s[S_CW] = 1.0
    return s


def _fly_loop(kind, cp, flap, air_z, air_y, c, s, k0, n_steps, dt, every, out, r0):
    """Steps ``k0 .. k0 + n_steps - 1`` of one butterfly (Oe 2010 eq. 7-11, RK4; module docstring),
    from and back into its state array ``s`` (:data:`S_Y` ...). The pitch of step ``k`` is
    ``_law(kind, cp, obs)`` with ``obs`` a :class:`~lifelike_mj.butterfly.flight.PitchObservation`
    (the built-in laws in :func:`fly_steps`; a law of your own in :func:`fly_steps_with`).
    Every ``every`` steps (counted from ``k0``) a row ``y, z, v_y, v_z, phi`` is written into ``out``
    from row ``r0`` on. Returns ``(diverged, r)``: the step count at a runaway (rows from there on
    are NaN) or -1, and the next row. Stepping in chunks gives the same numbers bit for bit as one
    call: everything carried from step to step is in ``s`` or recomputed exactly from it."""
    h = 0.5 * dt
    # cos/sin of 2 pi f t advanced by exact rotations of 2 pi f h (two per step), re-synced with
    # math.cos/sin every 256 steps: the same values to ~1e-15, at a third of the cost
    cdh = math.cos(flap[2] * h)
    sdh = math.sin(flap[2] * h)
    y = s[S_Y]
    z = s[S_Z]
    vy = s[S_VY]
    vz = s[S_VZ]
    phi = s[S_PHI]
    cw0 = s[S_CW]
    sw0 = s[S_SW]
    fit = s[S_FIT]
    om0, ct0 = _flap_from(flap, cw0, sw0)
    phi_prev = np.nan
    sphi = 0.0
    cphi = 1.0
    r = r0
    countdown = every
    for k in range(k0, k0 + n_steps):
        t = k * dt
        theta0 = flap[0] + flap[1] * cw0
        phi = _law(kind, cp, PitchObservation(t, phi, om0, theta0, vy, y, vz, air_y, air_z))
        if phi != phi_prev:
            sphi = math.sin(phi)
            cphi = math.cos(phi)
            phi_prev = phi
        cwh = cw0 * cdh - sw0 * sdh
        swh = sw0 * cdh + cw0 * sdh
        omh, cth = _flap_from(flap, cwh, swh)
        if (k + 1) & 255 == 0:  # re-sync the rotation with exact values
            w1 = flap[2] * ((k + 1) * dt)
            cw1 = math.cos(w1)
            sw1 = math.sin(w1)
        else:
            cw1 = cwh * cdh - swh * sdh
            sw1 = swh * cdh + cwh * sdh
        om1, ct1 = _flap_from(flap, cw1, sw1)
        a1y, a1z = _accel(vy, vz, sphi, cphi, om0, ct0, air_z, air_y, c)
        v2y = vy + h * a1y
        v2z = vz + h * a1z
        a2y, a2z = _accel(v2y, v2z, sphi, cphi, omh, cth, air_z, air_y, c)
        v3y = vy + h * a2y
        v3z = vz + h * a2z
        a3y, a3z = _accel(v3y, v3z, sphi, cphi, omh, cth, air_z, air_y, c)
        v4y = vy + dt * a3y
        v4z = vz + dt * a3z
        a4y, a4z = _accel(v4y, v4z, sphi, cphi, om1, ct1, air_z, air_y, c)
        y += dt / 6.0 * (vy + 2.0 * v2y + 2.0 * v3y + v4y)
        z += dt / 6.0 * (vz + 2.0 * v2z + 2.0 * v3z + v4z)
        vy += dt / 6.0 * (a1y + 2.0 * a2y + 2.0 * a3y + a4y)
        vz += dt / 6.0 * (a1z + 2.0 * a2z + 2.0 * a3z + a4z)
        cw0 = cw1
        sw0 = sw1
        om0 = om1
        ct0 = ct1
        if not (abs(vy) + abs(vz) < 1e4):  # also catches NaN
            for rr in range(r, out.shape[0]):
                for j in range(5):
                    out[rr, j] = np.nan
            _store(s, y, z, vy, vz, phi, cw0, sw0, fit)
            return k + 1, r
        fit += fitness_term(y, vz)
        countdown -= 1
        if countdown == 0:
            countdown = every
            out[r, 0] = y
            out[r, 1] = z
            out[r, 2] = vy
            out[r, 3] = vz
            out[r, 4] = phi
            r += 1
    _store(s, y, z, vy, vz, phi, cw0, sw0, fit)
    return -1, r


@njit(inline="always")
def _store(s, y, z, vy, vz, phi, cw, sw, fit):
    s[S_Y] = y
    s[S_Z] = z
    s[S_VY] = vy
    s[S_VZ] = vz
    s[S_PHI] = phi
    s[S_CW] = cw
    s[S_SW] = sw
    s[S_FIT] = fit


_law = builtin_law
#: :func:`_fly_loop` with the built-in pitch laws (compiled once, cached).
fly_steps = njit(cache=True, error_model="numpy")(_fly_loop)


def _step_batch_loop(phis, flaps, airs, consts, states, ks, n_steps, dt, diverged):
    """Advance ``len(phis)`` butterflies ``n_steps`` steps each at the pitch ``phis[b]`` (rad), in one
    native call on parallel threads (Oe 2010 eq. 7-11, RK4, as :func:`fly_steps`): rows of ``flaps``
    (the flap pattern), ``airs`` (air velocity forward, up; m/s), ``consts`` (:func:`constants_row`)
    and ``states`` (the state arrays, :data:`S_Y` ...) per butterfly; ``ks`` the step counts, advanced;
    ``diverged[b]`` set to the step of a runaway (such a butterfly is not stepped again). For a few
    butterflies :func:`step_batch_serial` is faster (starting threads costs tens of microseconds)."""
    no_rows = np.empty((0, 5))
    for b in prange(len(phis)):
        if diverged[b] >= 0:
            continue
        cp = np.empty(1)
        cp[0] = phis[b]
        dv, _ = fly_steps(KIND_CONSTANT, cp, flaps[b], airs[b, 0], airs[b, 1], consts[b], states[b], ks[b], n_steps,
                          dt, n_steps + 1, no_rows, 0)
        if dv >= 0:
            diverged[b] = dv
            ks[b] = dv
        else:
            ks[b] += n_steps


step_batch = njit(cache=True, parallel=True, error_model="numpy")(_step_batch_loop)
#: :func:`step_batch` on the calling thread (the same arithmetic, so the same numbers).
step_batch_serial = njit(cache=True, error_model="numpy")(_step_batch_loop)


@functools.lru_cache(maxsize=64)
def fly_steps_with(law) -> Callable:
    """:func:`_fly_loop` compiled with the pitch law ``law(kind, cp, obs)`` (see
    :func:`~lifelike_mj.butterfly.flight.kernel_law`), inlined as the built-in laws are."""
    return njit_with(_fly_loop, "fly_steps_with", {"_law": law}, error_model="numpy")


@njit(cache=True, parallel=True, error_model="numpy")
def _simulate(kinds, cparams, flaps, airs, y0s, consts, n_steps, dt, record_every, out, diverged, fitness):
    for b in prange(kinds.shape[0]):
        s = np.zeros(N_STATE)
        s[S_Y] = y0s[b]
        s[S_CW] = 1.0
        for j in range(5):
            out[b, 0, j] = s[j]
        dv, _ = fly_steps(kinds[b], cparams[b], flaps[b], airs[b, 0], airs[b, 1], consts[b], s, 0, n_steps, dt,
                          record_every, out[b], 1)
        diverged[b] = dv
        fitness[b] = s[S_FIT]


def simulate(
    controllers: Sequence[ButterflyController] | ButterflyController,
    params: Sequence[ButterflyParams] | ButterflyParams | None = None,
    conditions: Sequence[Condition] | Condition | None = None,
    duration_s: float = 20.0,
    dt_s: float = 1.0 / 1200.0,
    record_every: int = 1,
) -> list[Trajectory]:
    """Fly a batch on the paper backend; scalars broadcast over the batch. Returns trajectories."""
    ctrls = [controllers] if isinstance(controllers, ButterflyController) else list(controllers)
    n = len(ctrls)
    ps = _broadcast(params if params is not None else ButterflyParams(), ButterflyParams, n)
    cs = _broadcast(conditions if conditions is not None else Condition(), Condition, n)
    n = max(n, len(ps), len(cs))
    ctrls, ps, cs = _stretch(ctrls, n), _stretch(ps, n), _stretch(cs, n)
    n_steps = check_timing(duration_s, dt_s, record_every)
    kinds, cparams = compile_controllers(ctrls)
    flaps = np.array([c.flap.as_array() for c in ctrls])
    airs = np.array([c.air_velocity() for c in cs])
    y0s = np.array([c.y0_m for c in cs], dtype=float)
    consts = np.array([constants_row(p) for p in ps])
    out, diverged, fitness = run_batch(kinds, cparams, flaps, airs, y0s, consts, n_steps, dt_s, record_every)
    n_rec = out.shape[1]
    t = np.arange(n_rec) * (record_every * dt_s)
    return [
        Trajectory(
            t=t, y=out[i, :, 0], z=out[i, :, 1], vy=out[i, :, 2], vz=out[i, :, 3], phi=out[i, :, 4],
            theta=ctrls[i].flap.theta(t), y0=cs[i].y0_m, flap_period_s=1.0 / ctrls[i].flap.frequency_hz,
            backend="paper", diverged_step=int(diverged[i]), fitness=float(fitness[i]),
        )
        for i in range(n)
    ]


def compile_controllers(ctrls: Sequence[ButterflyController]) -> tuple[np.ndarray, np.ndarray]:
    """``(kinds, cparams)`` arrays of a batch of controllers for compiled code (rows zero-padded)."""
    compiled = [c.compiled() for c in ctrls]
    width = max(1, max(len(p) for _, p in compiled))
    kinds = np.array([k for k, _ in compiled], dtype=np.int64)
    cparams = np.zeros((len(ctrls), width))
    for i, (_, p) in enumerate(compiled):
        cparams[i, : len(p)] = p
    return kinds, cparams


def run_batch(kinds: np.ndarray, cparams: np.ndarray, flaps: np.ndarray, airs: np.ndarray, y0s: np.ndarray,
              consts: np.ndarray, n_steps: int, dt_s: float, record_every: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Fly a batch given as arrays (one row per butterfly; see :func:`simulate`).

    Returns ``out`` (batch, records, 5: y, z, v_y, v_z, phi in m, m/s, rad), ``diverged`` (step of a
    runaway or -1) and ``fitness`` (``H`` of eq. 13 summed over the steps flown)."""
    n = len(kinds)
    n_rec = n_steps // record_every + 1
    out = np.empty((n, n_rec, 5))
    diverged = np.full(n, -1, dtype=np.int64)
    fitness = np.zeros(n)
    _simulate(np.ascontiguousarray(kinds, dtype=np.int64), np.ascontiguousarray(cparams, dtype=float),
              np.ascontiguousarray(flaps, dtype=float), np.ascontiguousarray(airs, dtype=float),
              np.ascontiguousarray(y0s, dtype=float), np.ascontiguousarray(consts, dtype=float),
              int(n_steps), float(dt_s), int(record_every), out, diverged, fitness)
    return out, diverged, fitness


def simulate_naive(controller: ButterflyController, params: ButterflyParams | None = None,
                   condition: Condition | None = None, n_steps: int = 24000, dt_s: float = 1.0 / 1200.0):
    """The same model as a plain per-step Python loop (speed baseline). Returns final (y, z, vy, vz)."""
    p = params or ButterflyParams()
    cond = condition or Condition()
    kind, cp = controller.compiled()
    cp = [float(x) for x in cp]
    th_c, th_a, w = (float(x) for x in controller.flap.as_array())
    air_z, air_y = cond.air_velocity()
    m, K, L, g = p.mass_kg, p.k_wings, p.span_m, p.gravity
    cb = 0.5 * p.rho * p.cd * p.body_area_m2

    def acc(t, vy, vz, phi):
        theta = th_c + th_a * math.cos(w * t)
        omega = -th_a * w * math.sin(w * t)
        vzr, vyr = vz - air_z, vy - air_y
        vp = L * omega - vzr * math.sin(phi)
        f = K * vp * abs(vp)
        ct = math.cos(theta)
        return ((-f * math.cos(phi) * ct - cb * vyr * abs(vyr)) / m - g,
                (f * math.sin(phi) * ct - cb * vzr * abs(vzr)) / m)

    y, z, vy, vz = cond.y0_m, 0.0, 0.0, 0.0
    phi = 0.0
    h = 0.5 * dt_s
    cp_arr = np.asarray(cp)
    for k in range(n_steps):
        t = k * dt_s
        if kind == KIND_SIMPLE_RULE:
            phi = cp[0] if -th_a * w * math.sin(w * t) > OMEGA_EPS else cp[1]
        elif kind == KIND_ANN:
            phi = ann_pitch.py_func(cp_arr, th_c + th_a * math.cos(w * t), -th_a * w * math.sin(w * t), y,
                                    vy, vz, air_y, air_z, phi)
        else:
            assert kind == KIND_CONSTANT
            phi = cp[0]
        a1 = acc(t, vy, vz, phi)
        a2 = acc(t + h, vy + h * a1[0], vz + h * a1[1], phi)
        a3 = acc(t + h, vy + h * a2[0], vz + h * a2[1], phi)
        a4 = acc((k + 1) * dt_s, vy + dt_s * a3[0], vz + dt_s * a3[1], phi)
        y += dt_s / 6.0 * (vy + 2 * (vy + h * a1[0]) + 2 * (vy + h * a2[0]) + (vy + dt_s * a3[0]))
        z += dt_s / 6.0 * (vz + 2 * (vz + h * a1[1]) + 2 * (vz + h * a2[1]) + (vz + dt_s * a3[1]))
        vy += dt_s / 6.0 * (a1[0] + 2 * a2[0] + 2 * a3[0] + a4[0])
        vz += dt_s / 6.0 * (a1[1] + 2 * a2[1] + 2 * a3[1] + a4[1])
    return y, z, vy, vz


def _broadcast(value, kind, n):
    return [value] if isinstance(value, kind) else list(value)


def _stretch(items, n):
    if len(items) == n:
        return items
    if len(items) == 1:
        return items * n
    raise UserError(f"batch sizes disagree: got {len(items)} items for a batch of {n}.")
