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
