"""Prescribed joint motion on a free-floating body: the joint torques that give chosen accelerations.

A flying animal moves its wings by muscles between the wings and the body. No force holds the body
itself, so the body recoils. To make some joints ``j`` follow prescribed accelerations ``a*`` while
the other degrees of freedom ``b`` (the free body's) move only as the dynamics say, split the
equations of motion ``M qacc = tau - c`` (``c``: Coriolis, centrifugal and gravity terms and every
other force, with its sign flipped) into the two blocks, and solve:

    qacc_b = -M_bb^-1 (c_b + M_bj a*)
    tau_j  = (M_jj - M_jb M_bb^-1 M_bj) a* + c_j - M_jb M_bb^-1 c_b

``tau`` is non-zero only on the driven joints: the free body feels nothing but their reactions,
which are the muscles' reactions and therefore physical. This is exact: with ``a*`` the reference
acceleration plus a PD term on the error, the joints track their references to rounding. A servo
that uses only the joint's own inertia ``M_jj`` ignores the body's recoil and goes unstable on a
light body.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from lifelike_mj.physics import mjabi

_vp = mjabi.voidptr_from_int
_ptr_at = mjabi.ptr_at
_f64 = mjabi.f64_at
_mj_fullM = mjabi.mj_fullM
_mj_rne = mjabi.mj_rne
_O_QFRC = mjabi.O_QFRC


@njit(cache=True)
def _torques(M, c, driven, free, a_star, out, scratch):
    """``out[r]``: the torque on ``driven[r]`` (module docstring), as
    ``tau_j = M_jj a* + c_j - M_jb z`` with ``z = M_bb^-1 (M_bj a* + c_b)``: one solve, ``M_bb`` factored by
    Cholesky (it is the free body's inertia seen through the joints: symmetric positive definite).
    ``scratch``: at least ``nb * nb + 2 * nb`` floats (``nb = len(free)``); nothing is allocated."""
    nb, k = len(free), len(driven)
    L = scratch[: nb * nb]
    z = scratch[nb * nb : nb * nb + nb]
    y = scratch[nb * nb + nb : nb * nb + 2 * nb]
    for i in range(nb):
        fi = free[i]
        s = c[fi]
        for q in range(k):
            s += M[fi, driven[q]] * a_star[q]
        z[i] = s
        for j in range(i + 1):
            s = M[fi, free[j]]
            for p in range(j):
                s -= L[i * nb + p] * L[j * nb + p]
            L[i * nb + j] = math.sqrt(s) if i == j else s / L[j * nb + j]
    for i in range(nb):  # L y = rhs
        s = z[i]
        for p in range(i):
            s -= L[i * nb + p] * y[p]
        y[i] = s / L[i * nb + i]
    for i in range(nb - 1, -1, -1):  # L^T z = y
        s = y[i]
        for p in range(i + 1, nb):
            s -= L[p * nb + i] * z[p]
        z[i] = s / L[i * nb + i]
    for r in range(k):
        dr = driven[r]
        t = c[dr]
        for q in range(k):
            t += M[dr, driven[q]] * a_star[q]
        for p in range(nb):
            t -= M[dr, free[p]] * z[p]
        out[r] = t


def prescribed_torques(M: np.ndarray, c: np.ndarray, driven: np.ndarray, a_star: np.ndarray) -> np.ndarray:
    """The generalized forces (N m on hinges) on the ``driven`` degrees of freedom that give them the
    accelerations ``a_star`` (rad/s^2), with the others free: see the module docstring. ``M``: the
    dense ``(nv, nv)`` inertia matrix; ``c``: the ``nv`` bias forces less the applied ones."""
    driven = np.ascontiguousarray(driven, dtype=np.int64)
    free = np.setdiff1d(np.arange(M.shape[0]), driven).astype(np.int64)
    out = np.empty(len(driven))
    _torques(np.ascontiguousarray(M, dtype=np.float64), np.ascontiguousarray(c, dtype=np.float64), driven, free,
             np.ascontiguousarray(a_star, dtype=np.float64), out, np.empty(len(free) * (len(free) + 2)))
    return out


@njit(cache=True)
def native_torques(mptr, dptr, off, nv, driven, free, a_star, M, c, out, scratch):
    """:func:`prescribed_torques` from inside a compiled passive callback: ``M`` from ``mj_fullM``,
    ``c`` from ``mj_rne`` less what ``qfrc_passive`` holds so far (the air's forces added before the
    call count as applied). ``M`` (``nv * nv``), ``c`` (``nv``) and ``scratch`` (``nb * (nb + 2)``, ``nb``
    the free dofs) are scratch; ``off``: the mjData offsets (:func:`lifelike_mj.physics.mjabi.offsets_tuple`)."""
    _mj_fullM(_vp(mptr), _vp(dptr), _vp(M.ctypes.data))
    _mj_rne(_vp(mptr), _vp(dptr), np.int32(0), _vp(c.ctypes.data))
    qfrc = _f64(_ptr_at(dptr + off[_O_QFRC]), nv)
    for i in range(nv):
        c[i] -= qfrc[i]
    _torques(M.reshape((nv, nv)), c, driven, free, a_star, out, scratch)
