"""Normal-pressure fluid force of Oe 2010 eq. 1, as pure vectorised functions.

Oe 2010 eq. 1: ``P = 1/2 * A * rho * C_d * v^2`` where ``v`` is the component, normal to the
surface, of the surface's velocity relative to the fluid. The force acts along the surface
normal and opposes that normal velocity, so with a signed normal speed ``v_n`` the signed force
along the normal is ``-1/2 * A * rho * C_d * v_n * |v_n|``.

Everything here is in SI units (m, m^2, m/s, kg/m^3, N) and works element-wise on NumPy arrays
(scalars broadcast). These functions are the single source of the formula: the butterfly's
closed forms, its paper backend and its MuJoCo callbacks, and later the fish's drag, all call
them (the compiled callbacks call the ``numba``-compiled twins below, which are tested equal).
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Air density used by the paper (about 5 degC), kg/m^3 (Oe 2010 section 3).
RHO_AIR: float = 1.28
#: Drag coefficient used by the paper (Oe 2010 section 3), dimensionless.
CD_PAPER: float = 2.2


def pressure_force_magnitude(area_m2, rho, cd, v_normal):
    """Magnitude of the normal-pressure force ``P = 1/2 A rho C_d v^2`` (Oe 2010 eq. 1), in N.

    ``area_m2`` in m^2, ``rho`` in kg/m^3, ``cd`` dimensionless, ``v_normal`` in m/s (its sign is
    ignored). Broadcasts like NumPy.
    """
    v = np.asarray(v_normal, dtype=float)
    return 0.5 * np.asarray(area_m2, dtype=float) * rho * cd * v * v


def normal_drag(area_m2, rho, cd, v_normal):
    """Signed force along the normal that opposes the signed normal speed (Oe 2010 eq. 1), in N.

    Returns ``-1/2 * A * rho * C_d * v_n * |v_n|``: negative when ``v_n > 0``. Used for the body
    drag of Oe 2010 eq. 10 (per axis) and each wing strip.
    """
    v = np.asarray(v_normal, dtype=float)
    return -0.5 * np.asarray(area_m2, dtype=float) * rho * cd * v * np.abs(v)


def normal_drag_vector(area_m2, rho, cd, velocity, normal):
    """Force vector (N) on a flat surface moving with ``velocity`` (m/s, relative to the fluid).

    Only the component of the velocity along the unit ``normal`` produces force (Oe 2010 eq. 1),
    and the force acts along the normal against that component. ``velocity`` and ``normal``
    have shape ``(..., 3)``; ``area_m2`` broadcasts over the leading axes.
    """
    vel = np.asarray(velocity, dtype=float)
    n = np.asarray(normal, dtype=float)
    vn = np.sum(vel * n, axis=-1)
    return normal_drag(area_m2, rho, cd, vn)[..., None] * n


def per_axis_drag(areas_m2, rho, cd, velocity):
    """Quadratic drag applied independently along each axis, in N.

    ``f_i = -1/2 rho C_d A_i v_i |v_i|`` for each axis ``i`` (Oe 2010 eq. 10 for the butterfly's
    body; the same form as MuJoCo's inertia-box fluid model with ``C_d = 1``). ``areas_m2`` and
    ``velocity`` broadcast, last axis = axes.
    """
    return normal_drag(areas_m2, rho, cd, velocity)


@njit(cache=True, inline="always")
def normal_drag_scalar(area_m2: float, rho: float, cd: float, v_normal: float) -> float:
    """Compiled scalar twin of :func:`normal_drag` (Oe 2010 eq. 1), in N."""
    return -0.5 * area_m2 * rho * cd * v_normal * abs(v_normal)


@njit(cache=True, inline="always")
def _tri_sq(ax, ay, bx, by, cx, cy, sa, sb, sc, out):
    """Adds ``sign * (int s^2 dA, int x s^2 dA, int y s^2 dA)`` over the triangle ``a, b, c`` to ``out``, for an
    affine ``s`` with these vertex values, all of one sign (or zero). Exact, from the integrals of the
    barycentric monomials ``int l_a^i l_b^j l_c^k dA = 2 A i! j! k! / (i + j + k + 2)!``."""
    area = 0.5 * abs((bx - ax) * (cy - ay) - (cx - ax) * (by - ay))
    sign = 1.0 if sa + sb + sc > 0.0 else -1.0
    i0 = area / 6.0 * (sa * sa + sb * sb + sc * sc + sa * sb + sa * sc + sb * sc)
    # int l_a s^2 dA = A (s_a^2 / 10 + (2 s_a (s_b + s_c) + s_b^2 + s_c^2 + s_b s_c) / 30), and round
    la = area * (sa * sa / 10.0 + (2.0 * sa * (sb + sc) + sb * sb + sc * sc + sb * sc) / 30.0)
    lb = area * (sb * sb / 10.0 + (2.0 * sb * (sa + sc) + sa * sa + sc * sc + sa * sc) / 30.0)
    lc = area * (sc * sc / 10.0 + (2.0 * sc * (sa + sb) + sa * sa + sb * sb + sa * sb) / 30.0)
    out[0] += sign * i0
    out[1] += sign * (la * ax + lb * bx + lc * cx)
    out[2] += sign * (la * ay + lb * by + lc * cy)


@njit(cache=True)
def triangle_sq_abs(ax, ay, bx, by, cx, cy, sa, sb, sc, out):
    """``out`` = ``(int s|s| dA, int x s|s| dA, int y s|s| dA)`` over the triangle ``a, b, c`` (m; ``x, y`` in
    its plane) for the affine field ``s`` with vertex values ``sa, sb, sc``, exactly: where ``s`` changes sign
    the triangle is cut along ``s = 0`` into a triangle and a quadrilateral (two triangles) of one sign each.

    With ``s`` the normal speed of a rigid flat wing (affine over it: ``v(p) = v_0 + omega x p``), the force of
    Oe 2010 eq. 1 integrated over the wing is ``-1/2 rho C_d out[0]`` along the normal, and its moment about
    the origin ``-1/2 rho C_d (out[1], out[2]) x n``: the limit of any number of strips, at the cost of one."""
    out[0] = 0.0
    out[1] = 0.0
    out[2] = 0.0
    pa, pb, pc = sa > 0.0, sb > 0.0, sc > 0.0
    na, nb, nc = sa < 0.0, sb < 0.0, sc < 0.0
    if not ((pa or pb or pc) and (na or nb or nc)):
        _tri_sq(ax, ay, bx, by, cx, cy, sa, sb, sc, out)
        return
    # the lone vertex: the one whose sign neither other shares (a zero vertex joins either side)
    if (pa and not pb and not pc) or (na and not nb and not nc):
        lx, ly, l_s, ux, uy, u_s, wx, wy, w_s = ax, ay, sa, bx, by, sb, cx, cy, sc
    elif (pb and not pa and not pc) or (nb and not na and not nc):
        lx, ly, l_s, ux, uy, u_s, wx, wy, w_s = bx, by, sb, cx, cy, sc, ax, ay, sa
    else:
        lx, ly, l_s, ux, uy, u_s, wx, wy, w_s = cx, cy, sc, ax, ay, sa, bx, by, sb
    t1 = l_s / (l_s - u_s)
    t2 = l_s / (l_s - w_s)
    q1x, q1y = lx + t1 * (ux - lx), ly + t1 * (uy - ly)
    q2x, q2y = lx + t2 * (wx - lx), ly + t2 * (wy - ly)
    _tri_sq(lx, ly, q1x, q1y, q2x, q2y, l_s, 0.0, 0.0, out)
    _tri_sq(q1x, q1y, ux, uy, wx, wy, 0.0, u_s, w_s, out)
    _tri_sq(q1x, q1y, wx, wy, q2x, q2y, 0.0, w_s, 0.0, out)
