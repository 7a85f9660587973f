"""The 3D butterfly on MuJoCo (``models/butterfly/butterfly3d.xml``): air, gravity and its own joints.

Nothing holds the body: it is a free body, moved by gravity, by the air's forces on its wings and body
and by the reactions of the joints its wings and abdomen turn on. Everything is in the compiled
passive callback, which MuJoCo calls at every Runge-Kutta stage:

* **wing force**, per wing, in one of these laws (Oe 2010 eq. 1, generalised to 3D, unless said):

  - ``"exact"`` (default): eq. 1 integrated exactly over each wing. The wing is rigid and flat, so the
    normal speed ``v_n`` of its points relative to the air is an affine function over it, and the
    integrals of ``v_n |v_n|`` and of its first moments over the planform-2 triangle have closed forms
    (cut along ``v_n = 0`` where the sign changes): the limit of ``"strip"`` with ever more panels, at
    about a fourteenth of the cost of 48 panels.
  - ``"strip"``: eq. 1 on panels of each wing. The planform-2 triangle (eq. 3: chord
    ``W r / L`` at span ``r``) is cut into spanwise strips (Gauss points) and each strip into chordwise
    panels (Gauss-Legendre). Each panel's velocity relative to the air is the wing's full rigid motion
    at that point (the body's translation and rotation, flapping, feathering) less the wind; its
    component ``v_n`` along the wing's normal gives ``dF = -1/2 rho C_d dA v_n |v_n|`` along the normal.
    The force and its moment about the wing's hinge are summed over the panels.
  - ``"quasi_steady"``: quasi-steady blade elements on the same panels (:func:`wing_panels`), with a revolving
    fruit-fly wing's coefficients.
  - ``"calibrated"``: the same blade elements with the lift and drag scaled to the filmed monarch's flight
    (:data:`CALIBRATED_QS`, :mod:`~lifelike_mj.butterfly.flight3d.calibrate`).
  - ``"tip"``: the paper's tip-speed formula (eq. 7-9), for the reduction to the planar flight:
    ``v' = L omega_flap - v_f sin(phi)`` with ``v_f`` the body's air-relative speed along its heading and
    ``phi`` its pitch; ``K/2 v'|v'|`` along the wing normal at the centre of pressure ``0.8 L``.

* **body drag** (eq. 10 in 3D): ``-1/2 rho C_d A_i v_i |v_i|`` per axis at the thorax's centre of mass,
  along the thorax's own axes (``drag_frame="body"``, areas ``A_x, A_y, A_z``) or the world's (``"world"``,
  as the planar backends).

* **the joints' drive**: the five driven joints (:data:`~lifelike_mj.butterfly.flight3d.kinematics.JOINTS`)
  follow the kinematics' references, evaluated at the stage's own time from the filter's closed form,
  with the exact torques of :mod:`lifelike_mj.physics.drive` (reference acceleration plus a PD term on
  the error). The torques act on the joints only: the body feels them as reactions.

* **attitude hold** (``assist="hold"``, for the reduction check only): the thorax's three rotations join
  the driven set with zero acceleration, while the stepper sets the attitude once per step as the
  planar paper model does. This is an external torque on the body, reported in the outputs.

Each simulation's parameters live in its own ``mjData.userdata`` (layout below), so one compiled
callback serves any number of models and threads. After each call the userdata holds the forces of
that call (:data:`U_OUT`: each wing's force and moment about its hinge, the body drag, the drive and
hold torques), which :func:`forces` reads. :func:`python_passive` is the plain Python twin the compiled
callback is tested against.
"""

from __future__ import annotations

import functools
import math

import mujoco
import numpy as np
from numba import njit

from lifelike_mj import checks
from lifelike_mj.butterfly.aero import strip_nodes
from lifelike_mj.butterfly.flight3d.kinematics import JOINTS, N_PARAMS, Kinematics, filter_at, joint_refs
from lifelike_mj.butterfly.model import CP_FRACTION
from lifelike_mj.butterfly.params import PARAM_MAX, ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.drive import native_torques, prescribed_torques
from lifelike_mj.physics.fluid import normal_drag_scalar, triangle_sq_abs

#: Wing-force laws of the 3D callback: none (gravity and the drive only), the paper's tip-speed
#: formula, eq. 1 on panels, the quasi-steady blade elements on panels, eq. 1 integrated exactly over the
#: wing's triangle.
FORCE_LAWS = {"none": 0, "tip": 1, "strip": 2, "quasi_steady": 3, "exact": 4, "calibrated": 5}
#: Quasi-steady coefficients of a revolving fruit-fly wing (Dickinson, Lehmann & Sane 1999, Science 284: the
#: fits C_L = 0.225 + 1.58 sin(2.13 alpha - 7.20), C_D = 1.92 - 1.55 cos(2.04 alpha - 9.82), alpha in deg).
QS_CL = (0.225, 1.58, 2.13, -7.20)
QS_CD = (1.92, -1.55, 2.04, -9.82)
#: Rotational-force coefficient pi (3/4 - x0) of Sane & Dickinson 2002 (J Exp Biol 205) for a wing pitching
#: about its mid-chord (x0 = 1/2).
QS_CROT = math.pi * (0.75 - 0.5)
#: The ``"calibrated"`` law's scales of the quasi-steady ``C_L``, ``C_D`` and ``C_rot``: fitted so that the filmed
#: monarch's stroke at its filmed body angle flies as the filmed monarch did (:mod:`~lifelike_mj.butterfly.flight3d.calibrate`).
CALIBRATED_QS = (0.571, 0.586, 0.571)
#: Frames of the body drag: the thorax's axes or the world's.
DRAG_FRAMES = {"world": 0, "body": 1}
#: Assists: none, or the attitude held (reduction check).
ASSISTS = {"none": 0, "hold": 1}

# ---- userdata layout (float64 slots) -------------------------------------------------------
U_MODE, U_DRAG_FRAME = 0, 1
U_AIR = 2  # 3: air velocity in the world (m/s)
U_RHO, U_CD, U_KHALF, U_L, U_CP = 5, 6, 7, 8, 9
U_AB = 10  # 3: body drag areas (m^2) along x, y, z
U_THORAX, U_WING = 13, 14  # body ids (2 wings)
U_NQ, U_NV, U_NBODY = 16, 17, 18
U_DRIVE, U_WN, U_NDRIVEN = 19, 20, 21  # drive on, PD natural frequency (rad/s), driven dofs
U_DRIVEN_Q = 22  # 5: qpos addresses of the driven joints
U_DRIVEN_D = 27  # 8: dof addresses of the driven dofs (5 joints, then the 3 rotations when held)
U_FREE_D = 35  # 6: the others
U_ASSIST = 41
U_T0, U_OMEGA_C, U_PSI0 = 42, 43, 44  # the kinematics at the step's start
U_P0 = 45  # N_PARAMS parameters
U_DP0 = U_P0 + N_PARAMS  # their rates
U_TARGET = U_DP0 + N_PARAMS  # the command
U_OUT = U_TARGET + N_PARAMS  # outputs of the last call, below
O_WING_FORCE, O_WING_MOMENT, O_BODY_DRAG, O_DRIVE, O_HOLD = 0, 6, 12, 15, 20  # within U_OUT
O_PARTS = 23  # per wing: translational lift (3), drag (3), rotational (3)
N_OUT = 41
U_SCR = U_OUT + N_OUT  # 15: force, torque, point, velocity (6)
U_WSCR = U_SCR + 15  # 21: a wing's hinge velocity (3), angular velocity (3), forces (15)
U_M = U_WSCR + 21  # MAX_NV * MAX_NV: the inertia matrix
MAX_NV = 11
U_C = U_M + MAX_NV * MAX_NV  # MAX_NV: the bias forces
U_ASTAR = U_C + MAX_NV  # 8: the driven dofs' accelerations asked
U_TAU = U_ASTAR + 8  # 8: their torques
U_REF = U_TAU + 8  # 15: the joints' references (5 x 3)
U_KIN = U_REF + 15  # 3 * N_PARAMS: the parameters at the stage (p, dp, ddp)
U_NPANEL = U_KIN + 3 * N_PARAMS
U_PANEL = U_NPANEL + 1  # per panel: chord position (m, + forward), span position (m, > 0), area (m^2), local chord (m)
MAX_PANELS = 240
N_PANEL = 4  # numbers per panel
U_DSCR = U_PANEL + N_PANEL * MAX_PANELS  # 48: the drive's scratch (the free block's Cholesky factor and two vectors)
U_NTRI = U_DSCR + 48  # triangles of the wing's outline (exact law)
U_RC = U_NTRI + 1  # span of the wing's area centroid (m): where the exact law splits its force into parts
U_TRI = U_RC + 1  # per triangle: three vertices (chord, span) of the left wing (m)
MAX_TRIS = 64
U_FEET = U_TRI + 6 * MAX_TRIS  # 12: the four feet's lowest points in the thorax's frame (m), legs or not (add_legs)
U_GRIP = U_FEET + 12  # the legs' grip actuator's index + 1 (add_legs), 0 without one
U_QS = U_GRIP + 1  # 3: the quasi-steady law's scales of C_L, C_D and C_rot (1 for "quasi_steady")
N_USERDATA = U_QS + 3

_O_TIME, _O_QPOS, _O_QVEL, _O_QFRC, _O_UD = mjabi.O_TIME, mjabi.O_QPOS, mjabi.O_QVEL, mjabi.O_QFRC, mjabi.O_UD
_O_XPOS, _O_XMAT, _O_XIPOS = mjabi.O_XPOS, mjabi.O_XMAT, mjabi.O_XIPOS
_mj_applyFT = mjabi.mj_applyFT
_mj_objectVelocity = mjabi.mj_objectVelocity
_OBJ_BODY = int(mujoco.mjtObj.mjOBJ_BODY)
_OBJ_XBODY = int(mujoco.mjtObj.mjOBJ_XBODY)
_vp = mjabi.voidptr_from_int
_addr = mjabi.int_from_voidptr
_ptr_at = mjabi.ptr_at
_f64 = mjabi.f64_at


@njit(cache=True)
def wing_panels(mode, pan, npan, side, R, lin, omega, rho, cd, qs, out):
    """The air's force on one wing from its panels (``pan``: chord position, span position, area): ``out`` =
    force (3, N), moment about the hinge (3, N m), and the force split into translational lift (3), drag (3)
    and rotational force (3), world frame. ``R``: the wing's axes as columns (chord, span, normal); ``lin``,
    ``omega``: the hinge's velocity relative to the air and the wing's angular velocity.

    ``mode`` 2, eq. 1: ``-1/2 rho C_d dA v_n |v_n|`` along the normal (Oe 2010 eq. 1). ``mode`` 3, quasi-steady
    blade elements: with ``U`` the panel's air speed across the span and ``alpha`` its angle to the wing
    plane, lift ``1/2 rho C_L(alpha) U^2 dA`` across the flow, drag ``1/2 rho C_D(alpha) U^2 dA`` along it
    (:data:`QS_CL`, :data:`QS_CD`), and the rotational force ``C_rot rho U omega_p c dA`` along the normal
    (:data:`QS_CROT`; ``omega_p`` the pitching rate that raises ``alpha``, ``c`` the panel's local chord); ``mode``
    5 is the same law with ``C_L``, ``C_D`` and ``C_rot`` multiplied by ``qs[0]``, ``qs[1]``, ``qs[2]``
    (:data:`CALIBRATED_QS`; ``qs`` is ``1, 1, 1`` in mode 3). Either law's force is also split into its part along
    the flow (drag) and across it (lift)."""
    for k in range(15):
        out[k] = 0.0
    cx, cy, cz = R[0, 0], R[1, 0], R[2, 0]
    sx, sy, sz = R[0, 1], R[1, 1], R[2, 1]
    nx, ny, nz = R[0, 2], R[1, 2], R[2, 2]
    wx, wy, wz = omega[0], omega[1], omega[2]
    w_span = wx * sx + wy * sy + wz * sz
    for j in range(npan):
        xc = pan[N_PANEL * j]
        r = side * pan[N_PANEL * j + 1]
        area = pan[N_PANEL * j + 2]
        rx = cx * xc + sx * r
        ry = cy * xc + sy * r
        rz = cz * xc + sz * r
        vx = lin[0] + wy * rz - wz * ry
        vy = lin[1] + wz * rx - wx * rz
        vz = lin[2] + wx * ry - wy * rx
        vn = vx * nx + vy * ny + vz * nz
        vs = vx * sx + vy * sy + vz * sz
        ex = vx - vs * sx  # the flow across the span
        ey = vy - vs * sy
        ez = vz - vs * sz
        u2 = ex * ex + ey * ey + ez * ez
        rot = 0.0
        sgn = 1.0
        rox, roy, roz = 0.0, 0.0, 0.0
        if mode == 2:
            dfn = normal_drag_scalar(area, rho, cd, vn)
            fx, fy, fz = dfn * nx, dfn * ny, dfn * nz
        elif u2 > 0.0:
            u = math.sqrt(u2)
            sgn = 1.0 if vn > 0.0 else -1.0
            alpha = math.degrees(math.asin(min(1.0, abs(vn) / u)))
            q = 0.5 * rho * u2 * area
            c_l = qs[0] * (QS_CL[0] + QS_CL[1] * math.sin(math.radians(QS_CL[2] * alpha + QS_CL[3])))
            c_d = qs[1] * (QS_CD[0] + QS_CD[1] * math.cos(math.radians(QS_CD[2] * alpha + QS_CD[3])))
            # across the flow, on the side the normal force pushes: -sgn n less its part along the flow
            pn = -sgn * (nx * ex + ny * ey + nz * ez) / u2
            lx, ly, lz = -sgn * nx - pn * ex, -sgn * ny - pn * ey, -sgn * nz - pn * ez
            ln = math.sqrt(lx * lx + ly * ly + lz * lz)
            if ln > 0.0:
                lx, ly, lz = lx / ln, ly / ln, lz / ln
            fx = q * (c_l * lx - c_d * ex / u)
            fy = q * (c_l * ly - c_d * ey / u)
            fz = q * (c_l * lz - c_d * ez / u)
            # rotational force: the leading edge turning towards the pushed side raises alpha
            rot = qs[2] * QS_CROT * rho * u * (w_span * sgn) * pan[N_PANEL * j + 3] * area
            rox, roy, roz = -sgn * rot * nx, -sgn * rot * ny, -sgn * rot * nz
            out[12] += rox
            out[13] += roy
            out[14] += roz
        else:
            fx, fy, fz = 0.0, 0.0, 0.0
        if u2 > 0.0:
            along = (fx * ex + fy * ey + fz * ez) / u2
            out[9] += along * ex
            out[10] += along * ey
            out[11] += along * ez
            out[6] += fx - along * ex
            out[7] += fy - along * ey
            out[8] += fz - along * ez
        gx, gy, gz = fx + rox, fy + roy, fz + roz
        out[0] += gx
        out[1] += gy
        out[2] += gz
        out[3] += ry * gz - rz * gy
        out[4] += rz * gx - rx * gz
        out[5] += rx * gy - ry * gx


@njit(cache=True)
def wing_exact(side, R, lin, omega, rho, cd, tri, ntri, rc, out):
    """Eq. 1 (Oe 2010) integrated exactly over one wing's outline, cut into ``ntri`` triangles (``tri``: per
    triangle three vertices (chord, span) of the left wing, m; the right wing, ``side = -1``, is their mirror):
    the same ``out`` as :func:`wing_panels` (force, moment about the hinge, parts; N, N m, world frame). The wing
    is rigid, so its normal speed is affine over it and the integral of ``v_n |v_n|`` over each triangle has a
    closed form (:func:`~lifelike_mj.physics.fluid.triangle_sq_abs`): the limit of :func:`wing_panels` with ever
    more panels. The parts are split along and across the flow at the span ``rc`` of the wing's area centroid."""
    cx, cy, cz = R[0, 0], R[1, 0], R[2, 0]
    sx, sy, sz = R[0, 1], R[1, 1], R[2, 1]
    nx, ny, nz = R[0, 2], R[1, 2], R[2, 2]
    wx, wy, wz = omega[0], omega[1], omega[2]
    s0 = lin[0] * nx + lin[1] * ny + lin[2] * nz
    # n . (omega x p) = p . (n x omega): the normal speed's gradient along the chord and the span
    gx, gy, gz = ny * wz - nz * wy, nz * wx - nx * wz, nx * wy - ny * wx
    g_c = gx * cx + gy * cy + gz * cz
    g_s = gx * sx + gy * sy + gz * sz
    integ = out[12:15]  # scratch, cleared below
    i0, i1, i2 = 0.0, 0.0, 0.0
    for k in range(ntri):
        b = 6 * k
        x0, r0 = tri[b], side * tri[b + 1]
        x1, r1 = tri[b + 2], side * tri[b + 3]
        x2, r2 = tri[b + 4], side * tri[b + 5]
        triangle_sq_abs(x0, r0, x1, r1, x2, r2, s0 + x0 * g_c + r0 * g_s, s0 + x1 * g_c + r1 * g_s,
                        s0 + x2 * g_c + r2 * g_s, integ)
        i0 += integ[0]
        i1 += integ[1]
        i2 += integ[2]
    k = -0.5 * rho * cd
    fn = k * i0
    mc, ms = k * i1, k * i2  # the moment arm's chord and span parts (times the force density)
    ax, ay, az = mc * cx + ms * sx, mc * cy + ms * sy, mc * cz + ms * sz
    fx, fy, fz = fn * nx, fn * ny, fn * nz
    for j in range(6, 15):
        out[j] = 0.0
    out[0], out[1], out[2] = fx, fy, fz
    out[3] = ay * nz - az * ny
    out[4] = az * nx - ax * nz
    out[5] = ax * ny - ay * nx
    # the parts, by the flow across the span at the centroid
    r_c = side * rc
    px, py, pz = sx * r_c, sy * r_c, sz * r_c
    vx = lin[0] + wy * pz - wz * py
    vy = lin[1] + wz * px - wx * pz
    vz = lin[2] + wx * py - wy * px
    vs = vx * sx + vy * sy + vz * sz
    ex, ey, ez = vx - vs * sx, vy - vs * sy, vz - vs * sz
    u2 = ex * ex + ey * ey + ez * ez
    if u2 > 0.0:
        along = (fx * ex + fy * ey + fz * ez) / u2
        out[9], out[10], out[11] = along * ex, along * ey, along * ez
        out[6], out[7], out[8] = fx - along * ex, fy - along * ey, fz - along * ez


@njit(cache=True)
def _passive_kernel(m, d, off):
    """Body of the passive callback (module docstring); adds to ``qfrc_passive`` and writes the outputs."""
    base = _addr(d)
    mptr = _addr(m)
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
    f = _f64(force, 3)
    tq = _f64(torque, 3)
    pt = _f64(point, 3)
    v6 = _f64(vel, 6)
    out = _f64(uda + 8 * U_OUT, N_OUT)
    for i in range(N_OUT):
        out[i] = 0.0
    ax = ud[U_AIR]
    ay = ud[U_AIR + 1]
    az = ud[U_AIR + 2]
    rho = ud[U_RHO]
    cd = ud[U_CD]
    thorax = int(ud[U_THORAX])
    mb = 9 * thorax

    if mode > 0:
        # body drag, eq. 10 per axis, at the thorax's centre of mass
        _mj_objectVelocity(m, d, np.int32(_OBJ_BODY), np.int32(thorax), _vp(vel), np.int32(0))
        vbx = v6[3] - ax
        vby = v6[4] - ay
        vbz = v6[5] - az
        if ud[U_DRAG_FRAME] > 0.5:
            ux = xmat[mb + 0] * vbx + xmat[mb + 3] * vby + xmat[mb + 6] * vbz
            uy = xmat[mb + 1] * vbx + xmat[mb + 4] * vby + xmat[mb + 7] * vbz
            uz = xmat[mb + 2] * vbx + xmat[mb + 5] * vby + xmat[mb + 8] * vbz
            gx = normal_drag_scalar(ud[U_AB], rho, cd, ux)
            gy = normal_drag_scalar(ud[U_AB + 1], rho, cd, uy)
            gz = normal_drag_scalar(ud[U_AB + 2], rho, cd, uz)
            f[0] = xmat[mb + 0] * gx + xmat[mb + 1] * gy + xmat[mb + 2] * gz
            f[1] = xmat[mb + 3] * gx + xmat[mb + 4] * gy + xmat[mb + 5] * gz
            f[2] = xmat[mb + 6] * gx + xmat[mb + 7] * gy + xmat[mb + 8] * gz
        else:
            f[0] = normal_drag_scalar(ud[U_AB], rho, cd, vbx)
            f[1] = normal_drag_scalar(ud[U_AB + 1], rho, cd, vby)
            f[2] = normal_drag_scalar(ud[U_AB + 2], rho, cd, vbz)
        for k in range(3):
            tq[k] = 0.0
            pt[k] = xipos[3 * thorax + k]
            out[O_BODY_DRAG + k] = f[k]
        _mj_applyFT(m, d, _vp(force), _vp(torque), _vp(point), np.int32(thorax), _vp(qfrc_addr))

        # the body's pitch and its air-relative speed along its heading (tip-speed law)
        hx = xmat[mb + 0]
        hy = xmat[mb + 3]
        hn = math.sqrt(hx * hx + hy * hy)
        sphi = xmat[mb + 6]
        v_fwd = (vbx * hx + vby * hy) / hn if hn > 0.0 else 0.0
        wscr = _f64(uda + 8 * U_WSCR, 21)
        lin = wscr[0:3]
        omega = wscr[3:6]
        npan = int(ud[U_NPANEL])
        pan = _f64(uda + 8 * U_PANEL, N_PANEL * MAX_PANELS)
        tri = _f64(uda + 8 * U_TRI, 6 * MAX_TRIS)
        ntri = int(ud[U_NTRI])
        for i in range(2):
            wing = int(ud[U_WING + i])
            side = 1.0 if i == 0 else -1.0
            mw = 9 * wing
            nx = xmat[mw + 2]
            ny = xmat[mw + 5]
            nz = xmat[mw + 8]
            sx = xmat[mw + 1]
            sy = xmat[mw + 4]
            sz = xmat[mw + 7]
            if mode == 1:
                # the paper's tip-speed formula (eq. 7-9), at the centre of pressure
                vp = ud[U_L] * qvel[int(ud[U_DRIVEN_D + i])] - v_fwd * sphi
                fn = -ud[U_KHALF] * vp * abs(vp)
                r = side * ud[U_CP]
                f[0] = fn * nx
                f[1] = fn * ny
                f[2] = fn * nz
                # moment about the hinge: (r span) x (fn n)
                tq[0] = fn * r * (sy * nz - sz * ny)
                tq[1] = fn * r * (sz * nx - sx * nz)
                tq[2] = fn * r * (sx * ny - sy * nx)
            else:
                # eq. 1 or the quasi-steady law on the wing's panels, each with its full air-relative velocity
                _mj_objectVelocity(m, d, np.int32(_OBJ_XBODY), np.int32(wing), _vp(vel), np.int32(0))
                lin[0] = v6[3] - ax
                lin[1] = v6[4] - ay
                lin[2] = v6[5] - az
                for k in range(3):
                    omega[k] = v6[k]
                wout = wscr[6:21]
                if mode == 4:
                    wing_exact(side, xmat[mw : mw + 9].reshape((3, 3)), lin, omega, rho, cd, tri, ntri, ud[U_RC], wout)
                else:
                    wing_panels(mode, pan, npan, side, xmat[mw : mw + 9].reshape((3, 3)), lin, omega, rho, cd,
                                ud[U_QS : U_QS + 3], wout)
                for k in range(3):
                    f[k] = wout[k]
                    tq[k] = wout[3 + k]
                for k in range(9):
                    out[O_PARTS + 9 * i + k] = wout[6 + k]
            pt[0] = xpos[3 * wing]
            pt[1] = xpos[3 * wing + 1]
            pt[2] = xpos[3 * wing + 2]
            for k in range(3):
                out[O_WING_FORCE + 3 * i + k] = f[k]
                out[O_WING_MOMENT + 3 * i + k] = tq[k]
            _mj_applyFT(m, d, _vp(force), _vp(torque), _vp(point), np.int32(wing), _vp(qfrc_addr))

    if ud[U_DRIVE] > 0.5:
        # the joints' drive: the references at this stage's time, then the exact torques (physics.drive)
        kin = _f64(uda + 8 * U_KIN, 3 * N_PARAMS)
        psi = filter_at(_f64(uda + 8 * U_P0, N_PARAMS), _f64(uda + 8 * U_DP0, N_PARAMS),
                        _f64(uda + 8 * U_TARGET, N_PARAMS), ud[U_PSI0], ud[U_OMEGA_C], t - ud[U_T0],
                        kin[:N_PARAMS], kin[N_PARAMS:2 * N_PARAMS], kin[2 * N_PARAMS:])
        ref = _f64(uda + 8 * U_REF, 15).reshape((5, 3))
        joint_refs(kin[:N_PARAMS], kin[N_PARAMS:2 * N_PARAMS], kin[2 * N_PARAMS:], psi, ref)
        nd = int(ud[U_NDRIVEN])
        a_star = _f64(uda + 8 * U_ASTAR, nd)
        wn = ud[U_WN]
        driven = np.empty(nd, np.int64)
        free = np.empty(nv - nd, np.int64)
        for r in range(nd):
            driven[r] = int(ud[U_DRIVEN_D + r])
            if r < 5:
                qa = int(ud[U_DRIVEN_Q + r])
                a_star[r] = ref[r, 2] + wn * wn * (ref[r, 0] - qpos[qa]) + 2.0 * wn * (ref[r, 1] - qvel[driven[r]])
            else:
                a_star[r] = 0.0  # attitude held: the stepper zeroes the rotation at each step's start
        for r in range(nv - nd):
            free[r] = int(ud[U_FREE_D + r])
        tau = _f64(uda + 8 * U_TAU, nd)
        native_torques(mptr, base, off, nv, driven, free, a_star, _f64(uda + 8 * U_M, nv * nv),
                       _f64(uda + 8 * U_C, nv), tau, _f64(uda + 8 * U_DSCR, 48))
        for r in range(nd):
            qfrc[driven[r]] += tau[r]
            if r < 5:
                out[O_DRIVE + r] = tau[r]
            else:
                out[O_HOLD + r - 5] = tau[r]


@functools.lru_cache(maxsize=1)
def _compiled_passive():
    return mjabi.compiled_passive(_passive_kernel, "butterfly3d")


def __getattr__(name: str):
    # COMPILED_PASSIVE, the compiled passive callback (a ctypes function pointer MuJoCo accepts), is made on
    # first use: importing this module (to read a controller file, say) compiles nothing
    if name == "COMPILED_PASSIVE":
        return _compiled_passive().ctypes
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def python_passive(m: mujoco.MjModel, d: mujoco.MjData) -> None:
    """Plain Python twin of the compiled callback (same userdata, same formulas): the reference."""
    ud = d.userdata
    mode = int(ud[U_MODE])
    air = ud[U_AIR : U_AIR + 3]
    rho, cd = ud[U_RHO], ud[U_CD]
    thorax = int(ud[U_THORAX])
    out = ud[U_OUT : U_OUT + N_OUT]
    out[:] = 0.0
    vel = np.zeros(6)
    zero = np.zeros(3)
    if mode > 0:
        R = d.xmat[thorax].reshape(3, 3)
        mujoco.mj_objectVelocity(m, d, _OBJ_BODY, thorax, vel, 0)
        vb = vel[3:] - air
        areas = ud[U_AB : U_AB + 3]
        if ud[U_DRAG_FRAME] > 0.5:
            fb = R @ np.array([normal_drag_scalar(a, rho, cd, v) for a, v in zip(areas, R.T @ vb)])
        else:
            fb = np.array([normal_drag_scalar(a, rho, cd, v) for a, v in zip(areas, vb)])
        out[O_BODY_DRAG : O_BODY_DRAG + 3] = fb
        mujoco.mj_applyFT(m, d, fb, zero, d.xipos[thorax].copy(), thorax, d.qfrc_passive)
        heading = np.array([R[0, 0], R[1, 0], 0.0])
        hn = np.linalg.norm(heading)
        v_fwd = float(vb @ heading / hn) if hn > 0 else 0.0
        for i, side in ((0, 1.0), (1, -1.0)):
            wing = int(ud[U_WING + i])
            Rw = d.xmat[wing].reshape(3, 3)
            span, n = Rw[:, 1], Rw[:, 2]
            if mode == 1:
                vp = ud[U_L] * d.qvel[int(ud[U_DRIVEN_D + i])] - v_fwd * R[2, 0]
                fn = -ud[U_KHALF] * vp * abs(vp)
                moment_arm = fn * side * ud[U_CP] * span
                fw, mw = fn * n, np.cross(moment_arm, n)
            else:
                mujoco.mj_objectVelocity(m, d, _OBJ_XBODY, wing, vel, 0)
                fw, mw, parts = _python_wing(mode, ud, side, Rw, vel[3:] - air, vel[:3].copy())
                out[O_PARTS + 9 * i : O_PARTS + 9 * i + 9] = parts
            out[O_WING_FORCE + 3 * i : O_WING_FORCE + 3 * i + 3] = fw
            out[O_WING_MOMENT + 3 * i : O_WING_MOMENT + 3 * i + 3] = mw
            mujoco.mj_applyFT(m, d, fw, mw, d.xpos[wing].copy(), wing, d.qfrc_passive)
    if ud[U_DRIVE] > 0.5:
        p, dp, ddp = np.empty(N_PARAMS), np.empty(N_PARAMS), np.empty(N_PARAMS)
        psi = filter_at(ud[U_P0 : U_P0 + N_PARAMS].copy(), ud[U_DP0 : U_DP0 + N_PARAMS].copy(),
                        ud[U_TARGET : U_TARGET + N_PARAMS].copy(), ud[U_PSI0], ud[U_OMEGA_C], d.time - ud[U_T0],
                        p, dp, ddp)
        ref = np.empty((5, 3))
        joint_refs(p, dp, ddp, psi, ref)
        nd = int(ud[U_NDRIVEN])
        driven = ud[U_DRIVEN_D : U_DRIVEN_D + nd].astype(np.int64)
        qa = ud[U_DRIVEN_Q : U_DRIVEN_Q + 5].astype(np.int64)
        wn = ud[U_WN]
        a_star = np.zeros(nd)
        a_star[:5] = ref[:, 2] + wn * wn * (ref[:, 0] - d.qpos[qa]) + 2.0 * wn * (ref[:, 1] - d.qvel[driven[:5]])
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        c = np.zeros(m.nv)
        mujoco.mj_rne(m, d, 0, c)
        tau = prescribed_torques(M, c - d.qfrc_passive, driven, a_star)
        d.qfrc_passive[driven] += tau
        out[O_DRIVE : O_DRIVE + 5] = tau[:5]
        out[O_HOLD : O_HOLD + nd - 5] = tau[5:]


def _python_wing(mode: int, ud: np.ndarray, side: float, Rw: np.ndarray, lin: np.ndarray, omega: np.ndarray):
    """NumPy twin of :func:`wing_panels` and :func:`wing_exact`: force, moment about the hinge, parts (lift,
    drag, rotational)."""
    rho, cd = ud[U_RHO], ud[U_CD]
    if mode == 4:
        chord, span, n = Rw[:, 0], Rw[:, 1], Rw[:, 2]
        tris = ud[U_TRI : U_TRI + 6 * int(ud[U_NTRI])].reshape(-1, 3, 2) * np.array([1.0, side])
        total = np.zeros(3)
        for verts in tris:
            pts = verts[:, :1] * chord[None, :] + verts[:, 1:] * span[None, :]
            s = (lin[None, :] + np.cross(omega[None, :], pts)) @ n
            integ = np.zeros(3)
            triangle_sq_abs(*verts.ravel(), *s, integ)
            total += integ
        fw = -0.5 * rho * cd * total[0] * n
        arm = -0.5 * rho * cd * (total[1] * chord + total[2] * span)
        v = lin + np.cross(omega, side * ud[U_RC] * span)
        e = v - (v @ span) * span
        drag = (fw @ e) / (e @ e) * e if e @ e > 0 else np.zeros(3)
        return fw, np.cross(arm, n), np.concatenate([fw - drag, drag, np.zeros(3)])
    npan = int(ud[U_NPANEL])
    panels = ud[U_PANEL : U_PANEL + N_PANEL * npan].reshape(npan, N_PANEL)
    chord, span, n = Rw[:, 0], Rw[:, 1], Rw[:, 2]
    r = panels[:, :1] * chord[None, :] + side * panels[:, 1:2] * span[None, :]
    v = lin[None, :] + np.cross(omega[None, :], r)
    vn = v @ n
    e = v - np.outer(v @ span, span)  # the flow across the span
    u2 = np.sum(e * e, axis=1)
    rot = np.zeros_like(r)
    if mode == 2:
        dF = np.array([normal_drag_scalar(a, rho, cd, x) for a, x in zip(panels[:, 2], vn)])[:, None] * n[None, :]
    else:
        u = np.sqrt(u2)
        sgn = np.where(vn > 0, 1.0, -1.0)
        alpha = np.degrees(np.arcsin(np.minimum(1.0, np.abs(vn) / u)))
        q = 0.5 * rho * u2 * panels[:, 2]
        c_l = ud[U_QS] * (QS_CL[0] + QS_CL[1] * np.sin(np.radians(QS_CL[2] * alpha + QS_CL[3])))
        c_d = ud[U_QS + 1] * (QS_CD[0] + QS_CD[1] * np.cos(np.radians(QS_CD[2] * alpha + QS_CD[3])))
        side_n = -sgn[:, None] * n[None, :]
        lift_dir = side_n - (np.sum(side_n * e, axis=1) / u2)[:, None] * e
        lift_dir /= np.linalg.norm(lift_dir, axis=1)[:, None]
        dF = (q * c_l)[:, None] * lift_dir - (q * c_d / u)[:, None] * e
        w_span = float(omega @ span)
        mag = ud[U_QS + 2] * QS_CROT * rho * u * (w_span * sgn) * panels[:, 3] * panels[:, 2]
        rot = mag[:, None] * side_n
    drag = (np.sum(dF * e, axis=1) / u2)[:, None] * e
    total = dF + rot
    parts = np.concatenate([(dF - drag).sum(0), drag.sum(0), rot.sum(0)])
    return total.sum(0), np.cross(r, total).sum(0), parts


# ---- set-up ----------------------------------------------------------------------------------

#: Mass layouts of :func:`build_model`: the animal's (the model file's proportions) or the paper's planar
#: model's (all the mass in the thorax, wings and abdomen weightless: the reduction check).
MASS_LAYOUTS = ("animal", "paper")
_MASS_GEOMS = ("thorax_mass", "head_mass", "abdomen_mass", "wing_left_mass", "wing_right_mass")
#: The mass (kg) a "weightless" part keeps, so that its joint's inertia stays positive.
WEIGHTLESS_KG = 1e-8


def model_path():
    """Path of the 3D model's MJCF file."""
    from lifelike_mj import paths

    return paths.model_path("butterfly", "butterfly3d.xml")


def build_model(params: ButterflyParams | None = None, masses: str = "animal", animal: str = "swallowtail",
                contact: bool = False, flowers=None, ground_m: float | None = None) -> mujoco.MjModel:
    """Compile the 3D model of ``animal`` (one of :data:`~lifelike_mj.butterfly.flight3d.animals.ANIMALS`):
    :func:`build_spec`, compiled; ``contact``: with legs that touch the ground (:func:`add_contact`); ``flowers``:
    blossoms' centres (``(n, 3)``, m) whose blossoms the legs touch too
    (:func:`~lifelike_mj.butterfly.flight3d.flowers.add_flowers`; implies ``contact``); ``ground_m``: the ground's
    height (m; default the model file's)."""
    spec = build_spec(params, masses, animal)
    if ground_m is not None:
        spec.geom("ground").pos = [0.0, 0.0, float(ground_m)]
    if contact or flowers is not None:
        add_contact(spec)
    if flowers is not None:
        from lifelike_mj.butterfly.flight3d.flowers import add_flowers

        add_flowers(spec, flowers, float(spec.geom("ground").pos[2]), contact=True)
    m = spec.compile()
    set_grip(m)
    return m


def set_grip(m: mujoco.MjModel) -> None:
    """Size the grip of the butterfly of ``m`` (:func:`add_legs`; nothing without legs): its full hold
    :data:`GRIP_BODY_WEIGHTS` times the butterfly's weight (N)."""
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "grip")
    if a >= 0:
        weight = float(m.body_subtreemass[m.body("butterfly").id]) * float(np.linalg.norm(m.opt.gravity))
        m.actuator_gainprm[a, 0] = GRIP_BODY_WEIGHTS * weight


#: The legs' friction with what they stand on: sliding, torsional, rolling (a foot's claws grip).
LEG_FRICTION = (1.5, 0.01, 0.001)
#: The legs' radius (m), and where the feet stand, as fractions of the thorax's length (forward of its centre) and
#: width (out from the middle line): two pairs, as a nymphalid walks (its forelegs are folded), and how far below
#: the thorax's axis (in thorax widths).
LEG_RADIUS_M = 0.0003
FEET = ((0.3, 1.3), (-0.6, 1.4))
FOOT_DEPTH = 1.3
#: How hard a perched butterfly's feet hold on to the flower (its weight's multiple, pulled along the contact normal
#: at full grip): a chosen value. Insects' tarsal claws and pads hold on with more than their weight (Gorb et al.
#: 2004, J Exp Biol 207:2917: shear forces above body weight even for a bug's smooth pads); three weights keep a
#: monarch on a blossom as it settles after a touchdown at up to about 1 m/s without it looking stuck.
GRIP_BODY_WEIGHTS = 3.0


def add_contact(spec: mujoco.MjSpec) -> None:
    """Give the butterfly of ``spec`` legs and let them touch: contact switched on, two pairs of legs under the
    thorax (drawn, massless capsules from the thorax's underside to the feet, with :data:`LEG_FRICTION`), and the
    ground touching them. Nothing else touches: the wings, the body and the abdomen have no contact, so the legs
    carry the butterfly when it stands (on the ground, or on a flower added with ``contype=conaffinity=1``)."""
    spec.option.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    ground = spec.geom("ground")
    ground.contype, ground.conaffinity = 1, 1
    ground.friction = list(LEG_FRICTION)
    add_legs(spec)


def legs(half_m: float, width_m: float) -> list[tuple[str, list[float], list[float]]]:
    """The legs under a thorax ``2 half_m`` long and ``width_m`` wide: ``(name, top, foot)`` per leg, the points in
    the thorax's frame (m; :data:`FEET`, :data:`FOOT_DEPTH`)."""
    out = []
    for k, (fx, fy) in enumerate(FEET):
        for side, sign in (("left", 1.0), ("right", -1.0)):
            out.append((f"leg_{k}_{side}", [fx * 2.0 * half_m, sign * 0.25 * width_m, -0.35 * width_m],
                        [fx * 2.0 * half_m * 1.2, sign * fy * width_m, -FOOT_DEPTH * width_m]))
    return out


def _thorax_size(type_: int, size, fromto=None) -> tuple[float, float]:
    """Half the length and the width (m) of a thorax geom: an ellipsoid (semi-axes) or a capsule (radius, and its
    ``fromto`` or, compiled, its half-length)."""
    if type_ == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return float(size[0]), 2.0 * float(size[1])
    if fromto is not None:
        return 0.5 * float(np.linalg.norm(np.subtract(fromto[3:], fromto[:3]))), 2.0 * float(size[0])
    return float(size[1]), 2.0 * float(size[0])


def feet_m(m: mujoco.MjModel) -> np.ndarray:
    """``(4, 3)``: the lowest points of the butterfly's feet in its thorax's frame (m), whether the model has legs or
    not: each leg's foot end less its radius (:func:`legs`)."""
    g = m.geom("thorax")
    half, width = _thorax_size(int(g.type[0]), g.size)
    return np.array([[foot[0], foot[1], foot[2] - LEG_RADIUS_M] for _, _, foot in legs(half, width)])


def add_legs(spec: mujoco.MjSpec, prefix: str = "") -> None:
    """The legs of :func:`add_contact` on the butterfly ``{prefix}butterfly`` of ``spec`` (capsules that touch
    whatever has ``contype=conaffinity=1``, when contact is on)."""
    thorax = spec.geom(f"{prefix}thorax")
    fromto = None if thorax.type == mujoco.mjtGeom.mjGEOM_ELLIPSOID else thorax.fromto
    half, width = _thorax_size(thorax.type, thorax.size, fromto)
    body = spec.body(f"{prefix}butterfly")
    for name, top, foot in legs(half, width):
        body.add_geom(name=f"{prefix}{name}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=top + foot,
                      size=[LEG_RADIUS_M, 0.0, 0.0], mass=0.0, contype=1, conaffinity=1, condim=3,
                      friction=list(LEG_FRICTION), rgba=[0.1, 0.08, 0.06, 1.0], group=0)
    # the feet's grip: MuJoCo's adhesion on the body's contacts (its gain set by set_grip once compiled), held while
    # perched and let go at take-off (loop.grip)
    spec.add_actuator(name=f"{prefix}grip", trntype=mujoco.mjtTrn.mjTRN_BODY, target=f"{prefix}butterfly",
                      gainprm=[0.0] * 10, ctrlrange=[0.0, 1.0], ctrllimited=1)


@functools.cache
def standing_height_m(animal: str = "swallowtail") -> float:
    """How high the thorax's origin stands above a level surface on the legs of :func:`add_contact` (m), the body
    level: the lowest point of the feet, below the origin (:func:`feet_m`)."""
    return -float(feet_m(build_model(animal=animal))[:, 2].min())


def build_spec(params: ButterflyParams | None = None, masses: str = "animal", animal: str = "swallowtail"
               ) -> mujoco.MjSpec:
    """The 3D model of ``animal``, before compiling.

    The swallowtail: the model file with the constants of ``params`` applied: the wing meshes and tip sites
    scaled to ``L`` and ``W``; the parts' masses scaled to add up to ``m`` in the model file's proportions
    (``masses="animal"``), or all of ``m`` in the thorax (``"paper"``). A measured species (the monarch): its own
    body, masses, hinges, stroke plane and wing outline (:func:`_apply_animal`); ``params`` then only give the
    air and gravity."""
    from lifelike_mj.butterfly.flight3d.animals import animal as _animal

    p = params or ButterflyParams()
    if masses not in MASS_LAYOUTS:
        raise UserError(f"unknown mass layout {masses!r}; choose one of: {', '.join(MASS_LAYOUTS)}.")
    a = _animal(animal)
    spec = mujoco.MjSpec.from_file(str(model_path()))
    spec.nuserdata = N_USERDATA
    if a.measured:
        if masses != "animal":
            raise UserError(f"the {masses!r} mass layout is the paper's swallowtail's; the {a.name} has its own masses.")
        _apply_animal(spec, a)
        return spec
    geoms = {name: spec.geom(name) for name in _MASS_GEOMS}
    if masses == "animal":
        scale = p.mass_kg / sum(g.mass for g in geoms.values())
        for g in geoms.values():
            g.mass *= scale
    else:
        for name in ("abdomen_mass", "wing_left_mass", "wing_right_mass"):
            geoms[name].mass = WEIGHTLESS_KG
        geoms["head_mass"].mass = 0.0
        geoms["thorax_mass"].mass = p.mass_kg - 3 * WEIGHTLESS_KG
    for side, sign in (("left", 1.0), ("right", -1.0)):
        spec.mesh(f"wing_{side}").scale = [p.width_m, p.span_m, 1.0]
        spec.site(f"wing_{side}_tip").pos = [0.0, sign * p.span_m, 0.0]
    return spec


#: Half the thickness (m) of the drawn wing: a flat slab, so that it has a volume and both faces.
WING_HALF_THICKNESS_M = 0.0002


def slab_mesh(polygon: np.ndarray, sign: float = 1.0, half_thickness: float = WING_HALF_THICKNESS_M):
    """Vertices ``(2n, 3)`` and faces ``(m, 3)`` of a flat slab of the polygon ``(n, 2)`` (chord, span; the span
    times ``sign``, -1 for the right wing): the polygon's triangles on top and below, and its rim."""
    from lifelike_mj.physics.planform import signed_area, triangulate

    poly = np.asarray(polygon, dtype=float) * np.array([1.0, sign])
    if signed_area(poly) < 0.0:
        poly = poly[::-1]
    n = len(poly)
    verts = np.concatenate([np.c_[poly, np.full(n, half_thickness)], np.c_[poly, np.full(n, -half_thickness)]])
    tris = triangulate(poly)
    index = {tuple(v): k for k, v in enumerate(poly)}
    top = np.array([[index[tuple(v)] for v in t] for t in tris])
    faces = [top, top[:, ::-1] + n]
    rim = np.array([[k, (k + 1) % n + n, (k + 1) % n] for k in range(n)]
                   + [[k, k + n, (k + 1) % n + n] for k in range(n)])
    return verts, np.concatenate(faces + [rim])


def _apply_animal(spec: mujoco.MjSpec, a) -> None:
    """Reshape the model file's swallowtail into the measured species ``a``
    (:class:`~lifelike_mj.butterfly.flight3d.animals.Animal`): the thorax and abdomen as ellipsoids of its sizes
    and masses (the head within the thorax's), the abdomen hinged at the thorax's rear end, the wing hinges
    half the thorax's width out, tilted by the stroke plane (the flap axis turned about the body's y axis, the
    top of the stroke rearward), and each wing's surfaces as drawn slabs, its mass a plate over the outline."""
    from lifelike_mj.physics.planform import lamina_inertia

    (lt, wt), (la, wa) = a.thorax_m, a.abdomen_m
    for name in ("thorax", "thorax_mass"):
        g = spec.geom(name)
        g.type = mujoco.mjtGeom.mjGEOM_ELLIPSOID
        g.size = [lt / 2.0, wt / 2.0, wt / 2.0]
        g.fromto = [np.nan] * 6
        g.pos = [0.0, 0.0, 0.0]
    spec.geom("thorax_mass").mass = a.mass_body_kg
    head = spec.geom("head")
    head.size = [0.42 * wt, 0.0, 0.0]
    head.pos = [lt / 2.0 + 0.25 * wt, 0.0, 0.0]
    spec.geom("head_mass").mass = 0.0
    spec.body("abdomen").pos = [-lt / 2.0, 0.0, 0.0]
    for name in ("abdomen", "abdomen_mass"):
        g = spec.geom(name)
        g.type = mujoco.mjtGeom.mjGEOM_ELLIPSOID
        g.size = [la / 2.0, wa / 2.0, wa / 2.0]
        g.fromto = [np.nan] * 6
        g.pos = [-la / 2.0, 0.0, 0.0]
    spec.geom("abdomen_mass").mass = a.mass_abdomen_kg
    beta = math.radians(a.stroke_plane_deg)
    tris = a.triangles
    for k, rgba in enumerate(a.colours):
        spec.add_material(name=f"{a.name}_{k}", rgba=list(rgba))
    tip = max((v for s in a.surfaces for v in s), key=lambda v: v[1])
    for side, sign in (("left", 1.0), ("right", -1.0)):
        body = spec.body(f"wing_{side}")
        body.pos = [0.0, sign * wt / 2.0, 0.0]
        body.quat = [math.cos(beta / 2.0), 0.0, -math.sin(beta / 2.0), 0.0]  # about y by -beta: top rearward
        spec.delete(spec.geom(f"wing_{side}_mass"))
        spec.delete(spec.geom(f"wing_{side}"))
        spec.delete(spec.mesh(f"wing_{side}"))
        for k, surface in enumerate(a.surfaces):
            verts, faces = slab_mesh(surface, sign)
            mesh = spec.add_mesh(name=f"wing_{side}_{k}", uservert=verts.ravel().tolist(),
                                 userface=faces.ravel().tolist())
            body.add_geom(name=f"wing_{side}" if k == 0 else f"wing_{side}_{k}", type=mujoco.mjtGeom.mjGEOM_MESH,
                          meshname=mesh.name, material=f"{a.name}_{k}", group=0, mass=0.0, contype=0, conaffinity=0)
        com, inertia = lamina_inertia(tris * np.array([1.0, sign]), a.mass_wing_kg)
        vals, vecs = np.linalg.eigh(inertia)
        if np.linalg.det(vecs) < 0:
            vecs[:, 0] = -vecs[:, 0]
        q = np.empty(4)
        mujoco.mju_mat2Quat(q, vecs.ravel())
        body.explicitinertial = True
        body.mass, body.ipos, body.inertia, body.iquat = a.mass_wing_kg, com, vals, q
        spec.site(f"wing_{side}_tip").pos = [float(tip[0]), sign * float(tip[1]), 0.0]


def panels(params: ButterflyParams, n_strips: int = 8, n_chord: int = 2) -> np.ndarray:
    """``(n, 4)``: chord position (m, + towards the leading edge), span position (m), area (m^2) and local chord
    (m) of each panel of one wing: the planform-2 triangle (Oe 2010 eq. 3, chord ``W r / L`` at span ``r``)
    cut into ``n_strips`` strips (three Gauss points each) and each strip into ``n_chord`` Gauss-Legendre
    panels. The areas add up to the wing's ``W L / 2``."""
    _check_panels(n_strips, n_chord)
    r, dr = strip_nodes(params.span_m, n_strips, "gauss3")
    g, w = np.polynomial.legendre.leggauss(n_chord)
    chord = params.width_m * r / params.span_m
    xc = 0.5 * chord[:, None] * g[None, :]
    area = (chord * dr)[:, None] * (0.5 * w)[None, :]
    local = np.repeat((params.width_m / params.span_m) * r, n_chord)
    return np.stack([xc.ravel(), np.repeat(r, n_chord), area.ravel(), local], axis=1)


def outline_panels(animal, n_strips: int = 8, n_chord: int = 2) -> np.ndarray:
    """:func:`panels` of a measured wing outline (:class:`~lifelike_mj.butterfly.flight3d.animals.Animal`): at each
    strip's Gauss points the chord runs from the outline's rearmost to its foremost point at that span (the
    outlines here cross each span line once), cut into ``n_chord`` Gauss-Legendre panels."""
    _check_panels(n_strips, n_chord)
    r, dr = strip_nodes(animal.span_m, n_strips, "gauss3")
    g, w = np.polynomial.legendre.leggauss(n_chord)
    lo, hi = np.full(len(r), np.inf), np.full(len(r), -np.inf)
    for poly in animal.surfaces:
        a, b = poly, np.roll(poly, -1, axis=0)
        for (xa, ya), (xb, yb) in zip(a, b):
            if ya == yb:
                hit = (r == ya)
                xs = [np.where(hit, xa, np.nan), np.where(hit, xb, np.nan)]
            else:
                t = (r - ya) / (yb - ya)
                xs = [np.where((t >= 0.0) & (t <= 1.0), xa + t * (xb - xa), np.nan)]
            for x in xs:
                lo, hi = np.fmin(lo, x), np.fmax(hi, x)
    chord = hi - lo
    xc = 0.5 * (lo + hi)[:, None] + 0.5 * chord[:, None] * g[None, :]
    area = (chord * dr)[:, None] * (0.5 * w)[None, :]
    return np.stack([xc.ravel(), np.repeat(r, n_chord), area.ravel(), np.repeat(chord, n_chord)], axis=1)


def _check_panels(n_strips: int, n_chord: int) -> None:
    checks.whole("n_strips (strips per wing)", n_strips, 1, MAX_PANELS // 3)
    checks.whole("n_chord (chordwise panels per strip)", n_chord, 1, MAX_PANELS // 3)
    if 3 * n_strips * n_chord > MAX_PANELS:
        raise UserError(f"a wing has at most {MAX_PANELS} panels (3 per strip and chordwise panel); "
                        f"{n_strips} strips of {n_chord} panels make {3 * n_strips * n_chord}.")


def wing_triangles(params: ButterflyParams, animal: str = "swallowtail") -> tuple[np.ndarray, float]:
    """The left wing's outline as triangles ``(n, 3, 2)`` (chord, span; m) and its area centroid's span (m):
    the planform-2 triangle of ``params`` (hinge, then the tip chord's ends), or the species' outline."""
    from lifelike_mj.butterfly.flight3d.animals import animal as _animal

    a = _animal(animal)
    if a.measured:
        return a.triangles, float(a.moments["centroid_m"][1])
    half = 0.5 * (params.width_m / params.span_m) * params.span_m
    L = params.span_m
    return np.array([[[0.0, 0.0], [-half, L], [half, L]]]), 2.0 * L / 3.0


def driven_dofs(m: mujoco.MjModel, assist: str = "none") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The driven joints' qpos addresses and the driven and free dof addresses (attitude hold adds the
    free joint's three rotations to the driven dofs)."""
    q = np.array([m.jnt_qposadr[m.joint(n).id] for n in JOINTS], dtype=np.int64)
    dofs = [int(m.jnt_dofadr[m.joint(n).id]) for n in JOINTS]
    root = int(m.jnt_dofadr[m.joint("root").id])
    if assist == "hold":
        dofs += [root + 3, root + 4, root + 5]
    driven = np.array(dofs, dtype=np.int64)
    return q, driven, np.setdiff1d(np.arange(m.nv), driven).astype(np.int64)


def setup_data(m: mujoco.MjModel, kinematics: Kinematics, params: ButterflyParams | None = None, *,
               force_law: str = "exact", air_m_s=(0.0, 0.0, 0.0), body_areas_m2=None, drag_frame: str = "body",
               assist: str = "none", drive_hz: float = 50.0, n_strips: int = 8, n_chord: int = 2,
               animal: str = "swallowtail") -> mujoco.MjData:
    """A fresh ``MjData`` of the 3D model of ``animal`` (built by :func:`build_model` for the same species), its
    userdata filled for the callback; the wings and abdomen at the kinematics' angles and rates, the body at
    rest at the origin, level. The paper's tip-speed law needs the swallowtail's triangle."""
    from lifelike_mj.butterfly.flight3d.animals import animal as _animal

    p = params or ButterflyParams()
    a = _animal(animal)
    if force_law not in FORCE_LAWS:
        raise UserError(f"unknown wing-force law {force_law!r}; choose one of: {', '.join(FORCE_LAWS)}.")
    if force_law == "tip" and a.measured:
        raise UserError(f"the paper's tip-speed law is for its triangular wing; the {a.name}'s measured wing takes "
                        "'exact', 'strip', 'quasi_steady' or 'calibrated'.")
    if drag_frame not in DRAG_FRAMES:
        raise UserError(f"unknown body-drag frame {drag_frame!r}; choose one of: {', '.join(DRAG_FRAMES)}.")
    if assist not in ASSISTS:
        raise UserError(f"unknown assist {assist!r}; choose one of: {', '.join(ASSISTS)}.")
    if m.nuserdata < N_USERDATA or m.nv > MAX_NV:
        raise ValueError(f"model needs <size nuserdata='{N_USERDATA}'/> and at most {MAX_NV} dofs")
    air_m_s = checks.vector("the air's velocity air_m_s", air_m_s, 3, "m/s")
    if body_areas_m2 is not None:
        body_areas_m2 = checks.vector("body_areas_m2 (the body's drag areas along x, y, z)", body_areas_m2, 3, "m^2")
        for a in body_areas_m2:
            checks.number("each of body_areas_m2", a, 0.0, PARAM_MAX["body_area_m2"], unit="m^2")
    drive_hz = checks.number("drive_hz", drive_hz, 0.0, 10_000.0, lo_open=True, unit="Hz")
    d = mujoco.MjData(m)
    mjabi.verify_offsets(d)
    ud = d.userdata
    ud[:] = 0.0
    ud[U_MODE] = FORCE_LAWS[force_law]
    ud[U_DRAG_FRAME] = DRAG_FRAMES[drag_frame]
    ud[U_AIR : U_AIR + 3] = air_m_s
    ud[U_RHO], ud[U_CD], ud[U_KHALF], ud[U_L] = p.rho, p.cd, 0.5 * p.k_wings, p.span_m
    ud[U_CP] = CP_FRACTION * p.span_m
    if body_areas_m2 is None:
        body_areas_m2 = a.body_areas_m2() if a.measured else (p.body_area_m2,) * 3
    ud[U_AB : U_AB + 3] = body_areas_m2
    ud[U_THORAX] = m.body("butterfly").id
    ud[U_WING : U_WING + 2] = (m.body("wing_left").id, m.body("wing_right").id)
    ud[U_NQ], ud[U_NV], ud[U_NBODY] = m.nq, m.nv, m.nbody
    q, driven, free = driven_dofs(m, assist)
    ud[U_DRIVE] = 1.0
    ud[U_WN] = 2.0 * math.pi * drive_hz
    ud[U_NDRIVEN] = len(driven)
    ud[U_DRIVEN_Q : U_DRIVEN_Q + 5] = q
    ud[U_DRIVEN_D : U_DRIVEN_D + len(driven)] = driven
    ud[U_FREE_D : U_FREE_D + len(free)] = free
    ud[U_ASSIST] = ASSISTS[assist]
    pan = outline_panels(a, n_strips, n_chord) if a.measured else panels(p, n_strips, n_chord)
    ud[U_NPANEL] = len(pan)
    ud[U_PANEL : U_PANEL + pan.size] = pan.ravel()
    tris, rc = wing_triangles(p, a.name)
    if len(tris) > MAX_TRIS:
        raise UserError(f"a wing outline has at most {MAX_TRIS} triangles, the {a.name}'s has {len(tris)}.")
    ud[U_NTRI], ud[U_RC] = len(tris), rc
    ud[U_TRI : U_TRI + tris.size] = tris.ravel()
    ud[U_FEET : U_FEET + 12] = feet_m(m).ravel()
    ud[U_GRIP] = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "grip") + 1
    ud[U_QS : U_QS + 3] = CALIBRATED_QS if force_law == "calibrated" else (1.0, 1.0, 1.0)
    if a.measured:
        ud[U_L] = a.span_m
    d.qpos[m.jnt_qposadr[m.joint("root").id] + 3] = 1.0
    ref = kinematics.joint_references()
    d.qpos[q] = ref[:, 0]
    d.qvel[driven[:5]] = ref[:, 1]
    load_kinematics(d, kinematics)
    return d


def load_kinematics(d: mujoco.MjData, kinematics: Kinematics) -> None:
    """Write the kinematics' state at the step about to start (time ``d.time``) for the callback."""
    ud = d.userdata
    ud[U_T0] = d.time
    ud[U_OMEGA_C] = kinematics.omega_c
    ud[U_PSI0] = kinematics.psi
    ud[U_P0 : U_P0 + N_PARAMS] = kinematics.p
    ud[U_DP0 : U_DP0 + N_PARAMS] = kinematics.dp
    ud[U_TARGET : U_TARGET + N_PARAMS] = kinematics.target


def forces(d: mujoco.MjData) -> dict[str, np.ndarray]:
    """The forces of the callback's last call (N, N m; world frame): each wing's air force and its
    moment about the wing's hinge (rows left, right), the body drag, the drive's five joint torques
    and the attitude hold's three torques (zero unless held); and each wing's force in parts: translational
    lift (across each panel's flow), drag (along it) and the rotational force. The exact law splits its
    force by the flow at the wing's centroid; the tip-speed law reports no parts."""
    o = d.userdata[U_OUT : U_OUT + N_OUT]
    return {"wing_force_N": o[O_WING_FORCE : O_WING_FORCE + 6].reshape(2, 3).copy(),
            "wing_moment_N_m": o[O_WING_MOMENT : O_WING_MOMENT + 6].reshape(2, 3).copy(),
            "body_drag_N": o[O_BODY_DRAG : O_BODY_DRAG + 3].copy(),
            "drive_torque_N_m": o[O_DRIVE : O_DRIVE + 5].copy(),
            "wing_lift_N": o[O_PARTS : O_PARTS + 18].reshape(2, 9)[:, 0:3].copy(),
            "wing_drag_N": o[O_PARTS : O_PARTS + 18].reshape(2, 9)[:, 3:6].copy(),
            "wing_rotational_N": o[O_PARTS : O_PARTS + 18].reshape(2, 9)[:, 6:9].copy(),
            "hold_torque_N_m": o[O_HOLD : O_HOLD + 3].copy()}
