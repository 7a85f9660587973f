"""The 3D butterfly on MuJoCo (``models/butterfly/butterfly3d.xml``): air, gravity and its own joints.

Nothing holds the body: it is a free body, moved by gravity, by the air's forces on its wings and body
and by the reactions of the joints its wings and abdomen turn on. Everything is in the compiled
passive callback, which MuJoCo calls at every Runge-Kutta stage:

* **wing force**, per wing, in one of two laws (Oe 2010 eq. 1, generalised to 3D):

  - ``"strip"`` (default): eq. 1 on panels of each wing. The planform-2 triangle (eq. 3: chord
    ``W r / L`` at span ``r``) is cut into spanwise strips (Gauss points) and each strip into chordwise
    panels (Gauss-Legendre). Each panel's velocity relative to the air is the wing's full rigid motion
    at that point (the body's translation and rotation, flapping, feathering) less the wind; its
    component ``v_n`` along the wing's normal gives ``dF = -1/2 rho C_d dA v_n |v_n|`` along the normal.
    The force and its moment about the wing's hinge are summed over the panels.
  - ``"tip"``: the paper's tip-speed formula (eq. 7-9), for the reduction to the planar flight:
    ``v' = L omega_flap - v_f sin(phi)`` with ``v_f`` the body's air-relative speed along its heading and
    ``phi`` its pitch; ``K/2 v'|v'|`` along the wing normal at the centre of pressure ``0.8 L``.

* **body drag** (eq. 10 in 3D): ``-1/2 rho C_d A_i v_i |v_i|`` per axis at the thorax's centre of mass,
  along the thorax's own axes (``drag_frame="body"``, areas ``A_x, A_y, A_z``) or the world's (``"world"``,
  as the planar backends).

* **the joints' drive**: the five driven joints (:data:`~lifelike_mj.butterfly.kinematics3d.JOINTS`)
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

import math

import mujoco
import numpy as np
from numba import njit

from lifelike_mj.butterfly.aero import strip_nodes
from lifelike_mj.butterfly.kinematics3d import JOINTS, N_PARAMS, Kinematics, filter_at, joint_refs
from lifelike_mj.butterfly.model import CP_FRACTION
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.physics import mjabi
from lifelike_mj.physics.drive import native_torques, prescribed_torques
from lifelike_mj.physics.fluid import normal_drag_scalar

#: Wing-force laws of the 3D callback: none (gravity and the drive only), the paper's tip-speed
#: formula, eq. 1 on panels.
FORCE_LAWS = {"none": 0, "tip": 1, "strip": 2}
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
N_OUT = 23
U_SCR = U_OUT + N_OUT  # 15: force, torque, point, velocity (6)
U_M = U_SCR + 15  # MAX_NV * MAX_NV: the inertia matrix
MAX_NV = 11
U_C = U_M + MAX_NV * MAX_NV  # MAX_NV: the bias forces
U_ASTAR = U_C + MAX_NV  # 8: the driven dofs' accelerations asked
U_TAU = U_ASTAR + 8  # 8: their torques
U_REF = U_TAU + 8  # 15: the joints' references (5 x 3)
U_KIN = U_REF + 15  # 3 * N_PARAMS: the parameters at the stage (p, dp, ddp)
U_NPANEL = U_KIN + 3 * N_PARAMS
U_PANEL = U_NPANEL + 1  # per panel: chord position (m, + forward), span position (m, > 0), area (m^2)
MAX_PANELS = 256
N_USERDATA = U_PANEL + 3 * MAX_PANELS

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
                ssx = fn * r * sx
                ssy = fn * r * sy
                ssz = fn * r * sz
                fsum = fn
            else:
                # eq. 1 on the wing's panels, each with its full air-relative velocity
                _mj_objectVelocity(m, d, np.int32(_OBJ_XBODY), np.int32(wing), _vp(vel), np.int32(0))
                wx = v6[0]
                wy = v6[1]
                wz = v6[2]
                lx = v6[3] - ax
                ly = v6[4] - ay
                lz = v6[5] - az
                cx = xmat[mw + 0]
                cy = xmat[mw + 3]
                cz = xmat[mw + 6]
                npan = int(ud[U_NPANEL])
                fsum = 0.0
                ssx = 0.0
                ssy = 0.0
                ssz = 0.0
                for j in range(npan):
                    xc = ud[U_PANEL + 3 * j]
                    r = side * ud[U_PANEL + 3 * j + 1]
                    rx = cx * xc + sx * r
                    ry = cy * xc + sy * r
                    rz = cz * xc + sz * r
                    vn = ((lx + wy * rz - wz * ry) * nx + (ly + wz * rx - wx * rz) * ny
                          + (lz + wx * ry - wy * rx) * nz)
                    dfn = normal_drag_scalar(ud[U_PANEL + 3 * j + 2], rho, cd, vn)
                    fsum += dfn
                    ssx += dfn * rx
                    ssy += dfn * ry
                    ssz += dfn * rz
            # force along the normal; moment about the hinge (sum of dF r) x n
            f[0] = fsum * nx
            f[1] = fsum * ny
            f[2] = fsum * nz
            tq[0] = ssy * nz - ssz * ny
            tq[1] = ssz * nx - ssx * nz
            tq[2] = ssx * ny - ssy * nx
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
                       _f64(uda + 8 * U_C, nv), tau)
        for r in range(nd):
            qfrc[driven[r]] += tau[r]
            if r < 5:
                out[O_DRIVE + r] = tau[r]
            else:
                out[O_HOLD + r - 5] = tau[r]


_PASSIVE = mjabi.compiled_passive(_passive_kernel, "butterfly3d")
#: The compiled passive callback (a ctypes function pointer MuJoCo accepts).
COMPILED_PASSIVE = _PASSIVE.ctypes


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
            chord, span, n = Rw[:, 0], Rw[:, 1], Rw[:, 2]
            if mode == 1:
                vp = ud[U_L] * d.qvel[int(ud[U_DRIVEN_D + i])] - v_fwd * R[2, 0]
                fn = -ud[U_KHALF] * vp * abs(vp)
                moment_arm = fn * side * ud[U_CP] * span
            else:
                mujoco.mj_objectVelocity(m, d, _OBJ_XBODY, wing, vel, 0)
                npan = int(ud[U_NPANEL])
                panels = ud[U_PANEL : U_PANEL + 3 * npan].reshape(npan, 3)
                r = panels[:, :1] * chord[None, :] + side * panels[:, 1:2] * span[None, :]
                v = (vel[3:] - air)[None, :] + np.cross(vel[:3][None, :], r)
                dfn = np.array([normal_drag_scalar(a, rho, cd, vn) for a, vn in zip(panels[:, 2], v @ n)])
                fn = float(dfn.sum())
                moment_arm = dfn @ r
            fw, mw = fn * n, np.cross(moment_arm, n)
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


def build_model(params: ButterflyParams | None = None, masses: str = "animal") -> mujoco.MjModel:
    """Compile the 3D model with the constants of ``params`` applied through ``MjSpec``: the wing meshes
    and tip sites scaled to ``L`` and ``W``; the parts' masses scaled to add up to ``m`` in the model
    file's proportions (``masses="animal"``), or all of ``m`` in the thorax (``"paper"``)."""
    p = params or ButterflyParams()
    if masses not in MASS_LAYOUTS:
        raise UserError(f"unknown mass layout {masses!r}; choose one of: {', '.join(MASS_LAYOUTS)}.")
    spec = mujoco.MjSpec.from_file(str(model_path()))
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
    return spec.compile()



def panels(params: ButterflyParams, n_strips: int = 16, n_chord: int = 3) -> np.ndarray:
    """``(n, 3)``: chord position (m, + towards the leading edge), span position (m) and area (m^2) of
    each panel of one wing: the planform-2 triangle (Oe 2010 eq. 3, chord ``W r / L`` at span ``r``)
    cut into ``n_strips`` strips (three Gauss points each) and each strip into ``n_chord`` Gauss-Legendre
    panels. The areas add up to the wing's ``W L / 2``."""
    if not 1 <= n_strips or not 1 <= n_chord or 3 * n_strips * n_chord > MAX_PANELS:
        raise UserError(f"a wing has at most {MAX_PANELS} panels (3 per strip and chordwise panel); "
                        f"got {n_strips} strips of {n_chord} panels.")
    r, dr = strip_nodes(params.span_m, n_strips, "gauss3")
    g, w = np.polynomial.legendre.leggauss(n_chord)
    chord = params.width_m * r / params.span_m
    xc = 0.5 * chord[:, None] * g[None, :]
    area = (chord * dr)[:, None] * (0.5 * w)[None, :]
    return np.stack([xc.ravel(), np.repeat(r, n_chord), area.ravel()], axis=1)


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
               force_law: str = "strip", air_m_s=(0.0, 0.0, 0.0), body_areas_m2=None, drag_frame: str = "body",
               assist: str = "none", drive_hz: float = 50.0, n_strips: int = 16, n_chord: int = 3) -> mujoco.MjData:
    """A fresh ``MjData`` of the 3D model, its userdata filled for the callback; the wings and abdomen at
    the kinematics' angles and rates, the body at rest at the origin, level."""
    p = params or ButterflyParams()
    if force_law not in FORCE_LAWS:
        raise UserError(f"unknown wing-force law {force_law!r}; choose one of: {', '.join(FORCE_LAWS)}.")
    if drag_frame not in DRAG_FRAMES:
        raise UserError(f"unknown body-drag frame {drag_frame!r}; choose one of: {', '.join(DRAG_FRAMES)}.")
    if assist not in ASSISTS:
        raise UserError(f"unknown assist {assist!r}; choose one of: {', '.join(ASSISTS)}.")
    if m.nuserdata < N_USERDATA or m.nv > MAX_NV:
        raise ValueError(f"model needs <size nuserdata='{N_USERDATA}'/> and at most {MAX_NV} dofs")
    d = mujoco.MjData(m)
    mjabi.verify_offsets(d)
    ud = d.userdata
    ud[:] = 0.0
    ud[U_MODE] = FORCE_LAWS[force_law]
    ud[U_DRAG_FRAME] = DRAG_FRAMES[drag_frame]
    ud[U_AIR : U_AIR + 3] = air_m_s
    ud[U_RHO], ud[U_CD], ud[U_KHALF], ud[U_L] = p.rho, p.cd, 0.5 * p.k_wings, p.span_m
    ud[U_CP] = CP_FRACTION * p.span_m
    ud[U_AB : U_AB + 3] = (p.body_area_m2,) * 3 if body_areas_m2 is None else body_areas_m2
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
    pan = panels(p, n_strips, n_chord)
    ud[U_NPANEL] = len(pan)
    ud[U_PANEL : U_PANEL + pan.size] = pan.ravel()
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
    and the attitude hold's three torques (zero unless held)."""
    o = d.userdata[U_OUT : U_OUT + N_OUT]
    return {"wing_force_N": o[O_WING_FORCE : O_WING_FORCE + 6].reshape(2, 3).copy(),
            "wing_moment_N_m": o[O_WING_MOMENT : O_WING_MOMENT + 6].reshape(2, 3).copy(),
            "body_drag_N": o[O_BODY_DRAG : O_BODY_DRAG + 3].copy(),
            "drive_torque_N_m": o[O_DRIVE : O_DRIVE + 5].copy(),
            "hold_torque_N_m": o[O_HOLD : O_HOLD + 3].copy()}
