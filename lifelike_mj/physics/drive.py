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

import numpy as np


def prescribed_torques(M: np.ndarray, c: np.ndarray, driven: np.ndarray, a_star: np.ndarray) -> np.ndarray:
    """The generalized forces (N m on hinges) on the ``driven`` degrees of freedom that give them the
    accelerations ``a_star`` (rad/s^2), with the others free: see the module docstring. ``M``: the
    dense ``(nv, nv)`` inertia matrix; ``c``: the ``nv`` bias forces less the applied ones."""
    nv = M.shape[0]
    driven = np.asarray(driven, dtype=np.int64)
    free = np.setdiff1d(np.arange(nv), driven)
    m_bb, m_bj = M[np.ix_(free, free)], M[np.ix_(free, driven)]
    m_jb, m_jj = M[np.ix_(driven, free)], M[np.ix_(driven, driven)]
    x = np.linalg.solve(m_bb, np.column_stack([m_bj, c[free]]))
    k = len(driven)
    return (m_jj - m_jb @ x[:, :k]) @ np.asarray(a_star, dtype=np.float64) + c[driven] - m_jb @ x[:, k]
