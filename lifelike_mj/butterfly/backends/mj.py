"""The MuJoCo backend: ``models/butterfly.xml`` flown with a compiled wing-force callback.

Forces (all in the passive callback, which MuJoCo calls at every RK4 stage):

* **wing force**, per wing, in one of two modes:

  - ``"tip"``: the paper's tip-speed formula. ``v' = L omega_i - v_x sin(phi)`` (Oe 2010 eq. 7,
    with the wing's own hinge rate ``omega_i`` and the body's air-relative forward speed), force
    ``K/2 v'|v'|`` per wing (eq. 8-9, ``K = rho C_d L W / 4`` for both wings) along the wing's
    normal, applied at the planform-2 centre of pressure ``0.8 L`` from the hinge, so that the
    hinge torque is eq. 6's ``tau_2``. In the paper-equivalent model the vertical and forward
    components are exactly eq. 11's ``F_y cos(theta)`` and ``F_z cos(theta)``.
  - ``"strip"``: eq. 1 on each strip ``dS = W x/L dx`` of the planform (eq. 3), with the strip's
    full air-relative velocity (body translation and rotation, flap, wind) projected on the
    wing normal; the paper's simplifications (vertical speed and theta ignored in ``v'``) dropped.

* **body drag** (eq. 10) on each world axis at the thorax's centre of mass;
* **flap servo**: a feed-forward plus PD torque on each flap hinge that makes the wing follow
  ``theta(t)`` of the controller's flap pattern (evaluated at the stage time);
* **attitude servo** (rich configuration only): a PD torque on the free thorax towards the
  commanded pitch (roll and yaw held at 0).

The pitch command itself comes from the controller once per step (Oe 2010 section 5.1): in the
paper-equivalent model it is written into the pitch hinge (whose large armature keeps it fixed
through the step); in the rich model it is the attitude servo's target.

Each simulation's parameters live in its own ``mjData.userdata`` (layout below), so one
compiled callback serves any number of models and threads. The stepping loop is compiled too:
it runs the controller and calls ``mj_step`` from native code. :func:`python_passive` is a plain
Python twin of the compiled callback, kept as the reference the compiled one is tested against.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import mujoco
import numpy as np
from numba import njit, prange

from lifelike_mj.butterfly.aero import strip_nodes
from lifelike_mj.butterfly.controllers import KIND_CONSTANT, ButterflyController
from lifelike_mj.butterfly.flight import (
    Condition,
    PitchObservation,
    builtin_law,
    fitness_term,
    pitch_command,
)
from lifelike_mj.butterfly.model import CP_FRACTION, FORCE_MODES, build_model, check_config, layout
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.callbacks import passive_callback
from lifelike_mj.physics.fluid import normal_drag_scalar
from lifelike_mj.physics.jit import njit_with
from lifelike_mj.physics.stability import Watch, watching

# ---- userdata layout (float64 slots) -------------------------------------------------------
U_MODE, U_RICH = 0, 1
U_AIR = 2  # 3: air velocity in world (m/s)
U_KHALF, U_L, U_W, U_RHO, U_CD, U_AB = 5, 6, 7, 8, 9, 10
U_FLAP = 11  # 3: theta_c (rad), theta_a (rad), 2 pi f (rad/s)
U_DRIVE_A, U_DRIVE_WN = 14, 15  # flap servo: armature (kg m^2), natural frequency (rad/s)
U_PHI_CMD, U_SERVO_I, U_SERVO_WN = 16, 17, 18  # attitude servo (rich)
U_THORAX = 19
U_WING = 20  # 2 body ids
U_FLAP_Q = 22  # 2 qpos addresses
U_FLAP_D = 24  # 2 dof addresses
U_CP = 26  # centre-of-pressure distance from the hinge (m)
U_NQ, U_NV, U_NBODY = 27, 28, 29
U_SCR = 30  # scratch: force 30-32, torque 33-35, point 36-38, velocity 39-44
U_NSTRIP = 60
U_STRIP = 61  # n x positions (m), then n areas (m^2)
MAX_STRIPS = 64
N_USERDATA = U_STRIP + 2 * MAX_STRIPS

#: Offsets of the mjData fields the kernels read (an argument of every cached kernel; mjabi).
_OFFSETS = mjabi.offsets_tuple()
_O_TIME, _O_QPOS, _O_QVEL, _O_QFRC, _O_UD = mjabi.O_TIME, mjabi.O_QPOS, mjabi.O_QVEL, mjabi.O_QFRC, mjabi.O_UD
_O_XPOS, _O_XMAT, _O_XIPOS = mjabi.O_XPOS, mjabi.O_XMAT, mjabi.O_XIPOS

_mj_step = mjabi.mj_step
_mj_applyFT = mjabi.mj_applyFT
_mj_objectVelocity = mjabi.mj_objectVelocity
_OBJ_BODY = int(mujoco.mjtObj.mjOBJ_BODY)
_OBJ_XBODY = int(mujoco.mjtObj.mjOBJ_XBODY)

_vp = mjabi.voidptr_from_int
_addr = mjabi.int_from_voidptr


_ptr_at = mjabi.ptr_at
_f64 = mjabi.f64_at


@njit(cache=True)
def _passive_kernel(m, d, off):
    """Body of the passive callback (see module docstring); adds to ``qfrc_passive``. ``off``: the
    mjData offsets (:func:`lifelike_mj.physics.mjabi.offsets_tuple`)."""
    base = _addr(d)
    uda = _ptr_at(base + off[_O_UD])
    ud = _f64(uda, N_USERDATA)
    mode = int(ud[U_MODE])
    nq = int(ud[U_NQ])
    nv = int(ud[U_NV])
    qpos = _f64(_ptr_at(base + off[_O_QPOS]), nq)
    qvel = _f64(_ptr_at(base + off[_O_QVEL]), nv)
    qfrc_addr = _ptr_at(base + off[_O_QFRC])
    qfrc = _f64(qfrc_addr, nv)
    t = _f64(base + off[_O_TIME], 1)[0]
    nbody = int(ud[U_NBODY])
    xpos = _f64(_ptr_at(base + off[_O_XPOS]), 3 * nbody)
    xmat = _f64(_ptr_at(base + off[_O_XMAT]), 9 * nbody)
    xipos = _f64(_ptr_at(base + off[_O_XIPOS]), 3 * nbody)
    force = uda + 8 * U_SCR
    torque = uda + 8 * (U_SCR + 3)
    point = uda + 8 * (U_SCR + 6)
    vel = uda + 8 * (U_SCR + 9)
    ax = ud[U_AIR]
    ay = ud[U_AIR + 1]
    az = ud[U_AIR + 2]
    thorax = int(ud[U_THORAX])

    # flap servo: feed-forward + PD towards theta(t) (Oe 2010 section 4.3 flap pattern)
    wt = ud[U_FLAP + 2] * t
    th_ref = ud[U_FLAP] + ud[U_FLAP + 1] * math.cos(wt)
    om_ref = -ud[U_FLAP + 1] * ud[U_FLAP + 2] * math.sin(wt)
    al_ref = -ud[U_FLAP + 1] * ud[U_FLAP + 2] * ud[U_FLAP + 2] * math.cos(wt)
    wn = ud[U_DRIVE_WN]
    for i in range(2):
        qa = int(ud[U_FLAP_Q + i])
        da = int(ud[U_FLAP_D + i])
        qfrc[da] += ud[U_DRIVE_A] * (al_ref + wn * wn * (th_ref - qpos[qa]) + 2.0 * wn * (om_ref - qvel[da]))

    # thorax pitch (nose up) from its forward axis, and air-relative velocity at its COM
    mb = 9 * thorax
    phi = math.atan2(xmat[mb + 6], xmat[mb + 0])
    _mj_objectVelocity(m, d, np.int32(_OBJ_BODY), np.int32(thorax), _vp(vel), np.int32(0))
    v6 = _f64(vel, 6)
    vbx = v6[3] - ax
    vby = v6[4] - ay
    vbz = v6[5] - az

    if mode > 0:
        # body drag, eq. 10, per world axis at the thorax COM
        f = _f64(force, 3)
        tq = _f64(torque, 3)
        pt = _f64(point, 3)
        f[0] = normal_drag_scalar(ud[U_AB], ud[U_RHO], ud[U_CD], vbx)
        f[1] = normal_drag_scalar(ud[U_AB], ud[U_RHO], ud[U_CD], vby)
        f[2] = normal_drag_scalar(ud[U_AB], ud[U_RHO], ud[U_CD], vbz)
        tq[0] = 0.0
        tq[1] = 0.0
        tq[2] = 0.0
        pt[0] = xipos[3 * thorax]
        pt[1] = xipos[3 * thorax + 1]
        pt[2] = xipos[3 * thorax + 2]
        _mj_applyFT(m, d, _vp(force), _vp(torque), _vp(point), np.int32(thorax), _vp(qfrc_addr))

        sphi = math.sin(phi)
        for i in range(2):
            wing = int(ud[U_WING + i])
            side = 1.0 if i == 0 else -1.0
            mw = 9 * wing
            nx = xmat[mw + 2]
            ny = xmat[mw + 5]
            nz = xmat[mw + 8]
            ox = xpos[3 * wing]
            oy = xpos[3 * wing + 1]
            oz = xpos[3 * wing + 2]
            if mode == 1:
                # tip-speed formula, eq. 7-9, per wing, at the centre of pressure
                vp = ud[U_L] * qvel[int(ud[U_FLAP_D + i])] - vbx * sphi
                fn = -ud[U_KHALF] * vp * abs(vp)
                r = side * ud[U_CP]
                f[0] = fn * nx
                f[1] = fn * ny
                f[2] = fn * nz
                pt[0] = ox + xmat[mw + 1] * r
                pt[1] = oy + xmat[mw + 4] * r
                pt[2] = oz + xmat[mw + 7] * r
            else:
                # strip integration of eq. 1 over dS = W x/L dx (eq. 3)
                _mj_objectVelocity(m, d, np.int32(_OBJ_XBODY), np.int32(wing), _vp(vel), np.int32(0))
                wx = v6[0]
                wy = v6[1]
                wz = v6[2]
                lx = v6[3] - ax
                ly = v6[4] - ay
                lz = v6[5] - az
                ns = int(ud[U_NSTRIP])
                fsum = 0.0
                msum = 0.0
                for j in range(ns):
                    r = side * ud[U_STRIP + j]
                    rx = xmat[mw + 1] * r
                    ry = xmat[mw + 4] * r
                    rz = xmat[mw + 7] * r
                    vx = lx + wy * rz - wz * ry
                    vy = ly + wz * rx - wx * rz
                    vz = lz + wx * ry - wy * rx
                    vn = vx * nx + vy * ny + vz * nz
                    dfn = normal_drag_scalar(ud[U_STRIP + ns + j], ud[U_RHO], ud[U_CD], vn)
                    fsum += dfn
                    msum += dfn * r
                # all strips lie on the wing's span axis: the total acts at msum/fsum along it
                f[0] = fsum * nx
                f[1] = fsum * ny
                f[2] = fsum * nz
                # torque of the strip forces about the wing origin: (span axis) x n * msum
                sx = xmat[mw + 1]
                sy = xmat[mw + 4]
                sz = xmat[mw + 7]
                tq[0] = (sy * nz - sz * ny) * msum
                tq[1] = (sz * nx - sx * nz) * msum
                tq[2] = (sx * ny - sy * nx) * msum
                pt[0] = ox
                pt[1] = oy
                pt[2] = oz
            _mj_applyFT(m, d, _vp(force), _vp(torque), _vp(point), np.int32(wing), _vp(qfrc_addr))
            tq[0] = 0.0
            tq[1] = 0.0
            tq[2] = 0.0

    if ud[U_RICH] > 0.5:
        # attitude servo: PD torque towards pitch phi_cmd, roll = yaw = 0 (rich model)
        pc = ud[U_PHI_CMD]
        cp = math.cos(pc)
        sp = math.sin(pc)
        # desired axes: x_d = (cp, 0, sp), y_d = (0, 1, 0), z_d = (-sp, 0, cp)
        bx0, bx1, bx2 = xmat[mb + 0], xmat[mb + 3], xmat[mb + 6]
        by0, by1, by2 = xmat[mb + 1], xmat[mb + 4], xmat[mb + 7]
        bz0, bz1, bz2 = xmat[mb + 2], xmat[mb + 5], xmat[mb + 8]
        ex = 0.5 * ((bx1 * sp - bx2 * 0.0) + (by1 * 0.0 - by2 * 1.0) + (bz1 * cp - bz2 * 0.0))
        ey = 0.5 * ((bx2 * cp - bx0 * sp) + (by2 * 0.0 - by0 * 0.0) + (bz2 * (-sp) - bz0 * cp))
        ez = 0.5 * ((bx0 * 0.0 - bx1 * cp) + (by0 * 1.0 - by1 * 0.0) + (bz0 * 0.0 - bz1 * (-sp)))
        _mj_objectVelocity(m, d, np.int32(_OBJ_XBODY), np.int32(thorax), _vp(vel), np.int32(0))
        v6 = _f64(vel, 6)
        sw = ud[U_SERVO_WN]
        si = ud[U_SERVO_I]
        f = _f64(force, 3)
        tq = _f64(torque, 3)
        pt = _f64(point, 3)
        f[0] = 0.0
        f[1] = 0.0
        f[2] = 0.0
        tq[0] = si * (sw * sw * ex - 2.0 * sw * v6[0])
        tq[1] = si * (sw * sw * ey - 2.0 * sw * v6[1])
        tq[2] = si * (sw * sw * ez - 2.0 * sw * v6[2])
        pt[0] = xipos[3 * thorax]
        pt[1] = xipos[3 * thorax + 1]
        pt[2] = xipos[3 * thorax + 2]
        _mj_applyFT(m, d, _vp(force), _vp(torque), _vp(point), np.int32(thorax), _vp(qfrc_addr))


#: The compiled passive callback (a ctypes function pointer MuJoCo accepts; mjabi.compiled_passive).
_PASSIVE = mjabi.compiled_passive(_passive_kernel, "butterfly")
COMPILED_PASSIVE = _PASSIVE.ctypes


def python_passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """Plain Python twin of the compiled callback (same userdata, same formulas): the reference."""
    ud = d.userdata
    mode = int(ud[U_MODE])
    air = ud[U_AIR : U_AIR + 3]
    thorax = int(ud[U_THORAX])
    t = d.time
    th_c, th_a, w = ud[U_FLAP], ud[U_FLAP + 1], ud[U_FLAP + 2]
    th_ref = th_c + th_a * math.cos(w * t)
    om_ref = -th_a * w * math.sin(w * t)
    al_ref = -th_a * w * w * math.cos(w * t)
    wn = ud[U_DRIVE_WN]
    for i in range(2):
        qa, da = int(ud[U_FLAP_Q + i]), int(ud[U_FLAP_D + i])
        d.qfrc_passive[da] += ud[U_DRIVE_A] * (al_ref + wn * wn * (th_ref - d.qpos[qa]) + 2.0 * wn * (om_ref - d.qvel[da]))
    R = d.xmat[thorax].reshape(3, 3)
    phi = math.atan2(R[2, 0], R[0, 0])
    vel = np.zeros(6)
    mujoco.mj_objectVelocity(m, d, _OBJ_BODY, thorax, vel, 0)
    vb = vel[3:] - air
    zero = np.zeros(3)
    if mode > 0:
        fb = np.array([normal_drag_scalar(ud[U_AB], ud[U_RHO], ud[U_CD], v) for v in vb])
        mujoco.mj_applyFT(m, d, fb, zero, d.xipos[thorax].copy(), thorax, d.qfrc_passive)
        for i, side in ((0, 1.0), (1, -1.0)):
            wing = int(ud[U_WING + i])
            Rw = d.xmat[wing].reshape(3, 3)
            n, span, origin = Rw[:, 2].copy(), Rw[:, 1].copy(), d.xpos[wing].copy()
            if mode == 1:
                vp = ud[U_L] * d.qvel[int(ud[U_FLAP_D + i])] - vb[0] * math.sin(phi)
                fn = -ud[U_KHALF] * vp * abs(vp)
                mujoco.mj_applyFT(m, d, fn * n, zero, origin + span * (side * ud[U_CP]), wing, d.qfrc_passive)
            else:
                mujoco.mj_objectVelocity(m, d, _OBJ_XBODY, wing, vel, 0)
                omega, lin = vel[:3], vel[3:] - air
                ns = int(ud[U_NSTRIP])
                r = side * ud[U_STRIP : U_STRIP + ns]
                areas = ud[U_STRIP + ns : U_STRIP + 2 * ns]
                v = lin[None, :] + np.cross(omega[None, :], r[:, None] * span[None, :])
                dfn = np.array([normal_drag_scalar(a, ud[U_RHO], ud[U_CD], vn) for a, vn in zip(areas, v @ n)])
                mujoco.mj_applyFT(m, d, dfn.sum() * n, np.cross(span, n) * float(np.dot(dfn, r)), origin, wing,
                                  d.qfrc_passive)
    if ud[U_RICH] > 0.5:
        pc = ud[U_PHI_CMD]
        Rd = np.array([[math.cos(pc), 0.0, -math.sin(pc)], [0.0, 1.0, 0.0], [math.sin(pc), 0.0, math.cos(pc)]])
        e = 0.5 * sum(np.cross(R[:, k], Rd[:, k]) for k in range(3))
        mujoco.mj_objectVelocity(m, d, _OBJ_XBODY, thorax, vel, 0)
        sw, si = ud[U_SERVO_WN], ud[U_SERVO_I]
        mujoco.mj_applyFT(m, d, zero, si * (sw * sw * e - 2.0 * sw * vel[:3]), d.xipos[thorax].copy(), thorax,
                          d.qfrc_passive)


# ---- model set-up ----------------------------------------------------------------------------


def setup_data(m: mujoco.MjModel, controller: ButterflyController, params: ButterflyParams | None = None,
               condition: Condition | None = None, force_mode: str = "tip", n_strips: int = 16) -> mujoco.MjData:
    """A fresh ``MjData`` at rest at the start altitude, its userdata filled for the callback."""
    p = params or ButterflyParams()
    cond = condition or Condition()
    check_config("paper", force_mode)
    if m.nuserdata < N_USERDATA:
        raise ValueError(f"model needs <size nuserdata='{N_USERDATA}'/>")
    d = mujoco.MjData(m)
    mjabi.verify_offsets(d)
    lay = layout(m)
    ud = d.userdata
    ud[:] = 0.0
    ud[U_MODE] = FORCE_MODES[force_mode]
    ud[U_RICH] = float(lay.rich)
    air_fwd, air_up = cond.air_velocity()
    ud[U_AIR : U_AIR + 3] = (air_fwd, 0.0, air_up)
    ud[U_KHALF] = 0.5 * p.k_wings
    ud[U_L], ud[U_W], ud[U_RHO], ud[U_CD], ud[U_AB] = p.span_m, p.width_m, p.rho, p.cd, p.body_area_m2
    ud[U_FLAP : U_FLAP + 3] = controller.flap.as_array()
    left, right = m.joint("flap_left"), m.joint("flap_right")
    ud[U_DRIVE_A] = float(m.dof_armature[m.jnt_dofadr[left.id]])
    ud[U_DRIVE_WN] = min(2.0 * math.pi * 50.0, 1.0 / m.opt.timestep)
    ud[U_THORAX] = m.body("butterfly").id
    ud[U_WING : U_WING + 2] = (m.body("wing_left").id, m.body("wing_right").id)
    ud[U_FLAP_Q : U_FLAP_Q + 2] = (m.jnt_qposadr[left.id], m.jnt_qposadr[right.id])
    ud[U_FLAP_D : U_FLAP_D + 2] = (m.jnt_dofadr[left.id], m.jnt_dofadr[right.id])
    ud[U_CP] = CP_FRACTION * p.span_m
    ud[U_NQ], ud[U_NV], ud[U_NBODY] = m.nq, m.nv, m.nbody
    if not 1 <= n_strips <= MAX_STRIPS // 3:
        raise UserError(f"number of strips must be between 1 and {MAX_STRIPS // 3}, got {n_strips}.")
    x, dx = strip_nodes(p.span_m, n_strips, "gauss3")
    ns = len(x)
    ud[U_NSTRIP] = ns
    ud[U_STRIP : U_STRIP + ns] = x
    ud[U_STRIP + ns : U_STRIP + 2 * ns] = p.width_m * x / p.span_m * dx  # dS_2 (eq. 3)
    # initial state: at rest at y0, wings at theta(0), pitch 0
    d.qpos[lay.q_height] = cond.y0_m
    th0 = controller.flap.theta(0.0)
    d.qpos[left.id and m.jnt_qposadr[left.id]] = th0
    d.qpos[m.jnt_qposadr[right.id]] = th0
    d.qvel[m.jnt_dofadr[left.id]] = controller.flap.omega(0.0)
    d.qvel[m.jnt_dofadr[right.id]] = controller.flap.omega(0.0)
    if lay.rich:
        mujoco.mj_forward(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        ud[U_SERVO_I] = M[lay.d_pitch + 1, lay.d_pitch + 1]  # pitch inertia of the whole butterfly
        ud[U_SERVO_WN] = min(2.0 * math.pi * 40.0, 0.5 / m.opt.timestep)
    return d


# ---- the compiled stepping loop -------------------------------------------------------------


def _advance_loop(mptr, dptr, qpos, qvel, ud, k0, n_steps, kind, cp, flap, y_ref, lay, dt, phi, diverged, fit):
    """Steps ``k0 .. k0 + n_steps - 1`` (time ``t = k dt``): the pitch law ``_law(kind, cp, obs)``
    (``obs`` a :class:`~lifelike_mj.butterfly.flight.PitchObservation`) sets the pitch once per step,
    then ``mj_step``. Returns the last pitch (rad); sets ``diverged[0]`` on a runaway and adds each
    step's fitness term (eq. 13) to ``fit[0]``. Altitudes are measured from ``y_ref`` (m), the target
    altitude (0 in every experiment; the start altitude is in the initial state)."""
    rich = lay[0] == 1
    qh, df, dh, qp, dp = lay[2], lay[3], lay[4], lay[5], lay[6]
    air_z = ud[U_AIR]
    air_y = ud[U_AIR + 2]
    for k in range(k0, k0 + n_steps):
        t = k * dt
        theta = flap[0] + flap[1] * math.cos(flap[2] * t)
        omega = -flap[1] * flap[2] * math.sin(flap[2] * t)
        phi = _law(kind, cp, PitchObservation(t, phi, omega, theta, qvel[dh], qpos[qh] - y_ref, qvel[df], air_y, air_z))
        if rich:
            ud[U_PHI_CMD] = phi
        else:
            qpos[qp] = phi
            qvel[dp] = 0.0
        _mj_step(_vp(mptr), _vp(dptr))
        if not (abs(qvel[dh]) + abs(qvel[df]) < 1e4):
            diverged[0] = k + 1
            return phi
        fit[0] += fitness_term(qpos[qh] - y_ref, qvel[df])
    return phi


_law = builtin_law
#: :func:`_advance_loop` with the built-in pitch laws.
advance = njit(cache=True)(_advance_loop)


@njit(cache=True, parallel=True)
def _fitness_batch(mptr, dptrs, kinds, cparams, flap, lay, dt, n_steps, diverged, fitness, off):
    """Fly ``len(dptrs)`` butterflies (one ``mjData`` each, sharing model ``mptr``) on parallel
    threads; writes each one's eq. 13 fitness and divergence step."""
    for b in prange(len(dptrs)):
        base = dptrs[b]
        ud = _f64(_ptr_at(base + off[_O_UD]), N_USERDATA)
        qpos = _f64(_ptr_at(base + off[_O_QPOS]), int(ud[U_NQ]))
        qvel = _f64(_ptr_at(base + off[_O_QVEL]), int(ud[U_NV]))
        dv = np.full(1, -1, dtype=np.int64)
        fit = np.zeros(1)
        advance(mptr, base, qpos, qvel, ud, 0, n_steps, kinds[b], cparams[b], flap, 0.0, lay, dt, 0.0, dv, fit)
        diverged[b] = dv[0]
        fitness[b] = fit[0]


@njit(cache=True, parallel=True)
def step_batch(mptr, dptrs, rows, phis, ks, n_steps, flap, lay, dt, diverged, reset, fits, cols, off):
    """Advance the butterflies ``rows`` (indices into ``dptrs``, one ``mjData`` each on model ``mptr``)
    ``n_steps`` steps each at the pitch ``phis[b]`` (rad), in one native call on parallel threads: the
    vector environment's step on the MuJoCo backend. Per butterfly ``b``: ``ks[b]`` the step count
    (advanced), ``fits[b]`` the running eq. 13 fitness, ``diverged[b]`` set to the step of a runaway,
    ``reset[b]`` set to 1 when MuJoCo reset the simulation (its clock jumped back: nothing from that call
    on is valid), and ``cols[b]`` the observed ``y, v_y, v_z`` (m, m/s) and ``theta, omega`` (rad, rad/s)
    after the step. The compiled passive callback must be installed around the call."""
    for j in prange(len(rows)):
        b = rows[j]
        base = dptrs[b]
        ud = _f64(_ptr_at(base + off[_O_UD]), N_USERDATA)
        qpos = _f64(_ptr_at(base + off[_O_QPOS]), int(ud[U_NQ]))
        qvel = _f64(_ptr_at(base + off[_O_QVEL]), int(ud[U_NV]))
        clock = _f64(base + off[_O_TIME], 1)
        t0 = clock[0]
        k0 = ks[b]
        advance(mptr, base, qpos, qvel, ud, k0, n_steps, KIND_CONSTANT, phis[b : b + 1], flap, 0.0, lay, dt, phis[b],
                diverged[b : b + 1], fits[b : b + 1])
        if diverged[b] >= 0:
            ks[b] = diverged[b]
        else:
            ks[b] = k0 + n_steps
            if abs(clock[0] - (t0 + n_steps * dt)) > 0.5 * dt:
                reset[b] = 1
                diverged[b] = k0 + n_steps
        t = ks[b] * dt
        cols[b, 0] = qpos[lay[2]]
        cols[b, 1] = qvel[lay[4]]
        cols[b, 2] = qvel[lay[3]]
        cols[b, 3] = flap[0] + flap[1] * math.cos(flap[2] * t)
        cols[b, 4] = -flap[1] * flap[2] * math.sin(flap[2] * t)


def _record_loop(mptr, dptr, qpos, qvel, ud, k0, n_steps, every, kind, cp, flap, y_ref, lay, dt, phi, out, r0,
                 diverged, fit):
    """:func:`_advance` over ``n_steps`` steps from step ``k0``, writing a row ``y, z, v_y, v_z,
    phi, theta_left`` (m, m/s, rad) into ``out`` every ``every`` steps from row ``r0`` on (rows after
    a runaway are NaN). Returns the last pitch (rad)."""
    rich = lay[0] == 1
    qf, qh, df, dh, qp, ql = lay[1], lay[2], lay[3], lay[4], lay[5], lay[7]
    r = r0
    k = k0
    while k < k0 + n_steps:
        n = min(every, k0 + n_steps - k)
        phi = _advance(mptr, dptr, qpos, qvel, ud, k, n, kind, cp, flap, y_ref, lay, dt, phi, diverged, fit)
        k += n
        if diverged[0] >= 0:
            for rr in range(r, out.shape[0]):
                for j in range(6):
                    out[rr, j] = np.nan
            return phi
        if n == every:
            out[r, 0] = qpos[qh]
            out[r, 1] = qpos[qf]
            out[r, 2] = qvel[dh]
            out[r, 3] = qvel[df]
            if rich:
                w, x, y, z = qpos[qp], qpos[qp + 1], qpos[qp + 2], qpos[qp + 3]
                out[r, 4] = math.atan2(2.0 * (x * z - w * y), 1.0 - 2.0 * (y * y + z * z))
            else:
                out[r, 4] = qpos[qp]
            out[r, 5] = qpos[ql]
            r += 1
    return phi


_advance = advance
#: :func:`_record_loop` with the built-in pitch laws.
record_steps = njit(cache=True)(_record_loop)


@functools.lru_cache(maxsize=64)
def steppers_with(law) -> tuple[Callable, Callable]:
    """``(advance, record_steps)`` compiled with the pitch law ``law(kind, cp, obs)`` (see
    :func:`~lifelike_mj.butterfly.flight.kernel_law`) instead of the built-in laws."""
    adv = njit_with(_advance_loop, "advance_with", {"_law": law})
    rec = njit_with(_record_loop, "record_steps_with", {"_advance": adv})
    return adv, rec


_MODEL_CACHE: dict = {}


def fitness_batch(cparams: np.ndarray, flap, params: ButterflyParams | None, condition: Condition, n_steps: int,
                  dt_s: float, config: str = "paper", force_mode: str = "tip", kind: int | None = None) -> np.ndarray:
    """Eq. 13 fitness of a batch of compiled ann controllers (rows of ``cparams``) flown on MuJoCo
    under one condition: one ``mjData`` per individual, stepped on parallel native threads with the
    compiled callback and the compiled controller (weights per simulation)."""
    from lifelike_mj.butterfly import ann
    from lifelike_mj.butterfly.controllers import KIND_ANN, ann_controller

    p = params or ButterflyParams()
    key = (p, config, float(dt_s))
    if key not in _MODEL_CACHE:
        m = build_model(p, config)
        m.opt.timestep = float(dt_s)
        _MODEL_CACHE[key] = m
    m = _MODEL_CACHE[key]
    proto = ann_controller(np.zeros(ann.N_WEIGHTS), flap)  # setup_data needs only its flap
    datas = [setup_data(m, proto, p, condition, force_mode) for _ in range(len(cparams))]
    dptrs = np.array([d._address for d in datas], dtype=np.int64)
    n = len(datas)
    diverged = np.full(n, -1, dtype=np.int64)
    fitness = np.zeros(n)
    watch = Watch(datas)
    with passive_callback(COMPILED_PASSIVE), watching():
        kinds = np.full(n, KIND_ANN if kind is None else kind, dtype=np.int64)
        _fitness_batch(m._address, dptrs, kinds, np.ascontiguousarray(cparams),
                       flap.as_array(), layout(m).as_array(), float(dt_s), int(n_steps), diverged, fitness, _OFFSETS)
    fitness[watch.new()] = np.nan  # MuJoCo reset these flights: no valid fitness (the optimiser counts it worst)
    del datas
    return fitness


def _run_python(m, d, n_steps, record_every, controller, cond, lay, dt, out, diverged, fit):
    """The stepping loop of :func:`record_loop` with the Python callback and controller (reference)."""
    kind, cp = controller.compiled()
    flap = controller.flap.as_array()
    qpos, qvel = d.qpos, d.qvel
    air_z, air_y = cond.air_velocity()
    phi, r = 0.0, 1
    with passive_callback(python_passive):
        for k in range(n_steps):
            t = k * dt
            theta = flap[0] + flap[1] * math.cos(flap[2] * t)
            omega = -flap[1] * flap[2] * math.sin(flap[2] * t)
            phi = pitch_command.py_func(kind, cp, t, theta, omega, qpos[lay.q_height],
                                        qpos[lay.q_forward], qvel[lay.d_height], qvel[lay.d_forward], air_y, air_z, phi)
            if lay.rich:
                d.userdata[U_PHI_CMD] = phi
            else:
                qpos[lay.q_pitch] = phi
                qvel[lay.d_pitch] = 0.0
            mujoco.mj_step(m, d)
            if not abs(qvel[lay.d_height]) + abs(qvel[lay.d_forward]) < 1e4:
                diverged[0] = k + 1
                out[r:] = np.nan
                return
            fit[0] += fitness_term.py_func(qpos[lay.q_height], qvel[lay.d_forward])
            if (k + 1) % record_every == 0:
                if lay.rich:
                    w, x, y, z = qpos[lay.q_pitch : lay.q_pitch + 4]
                    ph = math.atan2(2.0 * (x * z - w * y), 1.0 - 2.0 * (y * y + z * z))
                else:
                    ph = qpos[lay.q_pitch]
                out[r] = (qpos[lay.q_height], qpos[lay.q_forward], qvel[lay.d_height], qvel[lay.d_forward], ph,
                          qpos[lay.q_flap_left])
                r += 1
