"""Aerodynamics of one flapping wing (Oe 2010 eq. 2-10): closed forms, strips, Fig. 3, speed limit.

Units: SI throughout (m, m/s, rad, N, N m); ``phi`` arrays in rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.physics.fluid import normal_drag, pressure_force_magnitude

#: Planform widths ``dS_k/dx`` of Oe 2010 eq. 3 as functions of ``x`` (m), ``L`` and ``W`` (m).
PLANFORMS = {
    1: lambda x, L, W: W * (1.0 - x / L),  # widest at the root
    2: lambda x, L, W: W * x / L,  # widest at the tip (the paper's choice)
    3: lambda x, L, W: np.full_like(np.asarray(x, dtype=float), W / 2.0),  # rectangle
}
#: Denominators of the closed forms: ``F_k = alpha/a_k v_w^2`` (eq. 4), ``tau_k = alpha/b_k L v_w^2`` (eq. 6).
FORCE_DENOM = {1: 24.0, 2: 8.0, 3: 12.0}
TORQUE_DENOM = {1: 40.0, 2: 10.0, 3: 16.0}


def closed_form_force(planform: int, p: ButterflyParams, omega):
    """Force on one wing flapping at ``omega`` (rad/s), Oe 2010 eq. 4: ``alpha/a_k (L omega)^2``, N."""
    vw = p.span_m * np.asarray(omega, dtype=float)
    return p.alpha / FORCE_DENOM[planform] * vw**2


def closed_form_torque(planform: int, p: ButterflyParams, omega):
    """Hinge torque resisting the flap, Oe 2010 eq. 6: ``alpha/b_k L (L omega)^2``, N m."""
    vw = p.span_m * np.asarray(omega, dtype=float)
    return p.alpha / TORQUE_DENOM[planform] * p.span_m * vw**2


def strip_nodes(span_m: float, n_strips: int, rule: str = "gauss3"):
    """Strip positions ``x`` (m) and lengths ``dx`` (m) covering ``[0, L]``.

    ``rule="midpoint"`` is the classic strip sum (error O(n^-2)); ``rule="gauss3"`` splits each
    strip at its three Gauss-Legendre points, exact for the cubic and quartic integrands of
    eq. 4 and 6, so it agrees with the closed forms to rounding.
    """
    edges = np.linspace(0.0, span_m, n_strips + 1)
    h = np.diff(edges)
    mid = 0.5 * (edges[:-1] + edges[1:])
    if rule == "midpoint":
        return mid, h
    if rule != "gauss3":
        raise ValueError(f"unknown strip rule {rule!r}")
    g = math.sqrt(3.0 / 5.0) / 2.0
    x = np.concatenate([mid - g * h, mid, mid + g * h])
    w = np.concatenate([5.0 / 18.0 * h, 8.0 / 18.0 * h, 5.0 / 18.0 * h])
    return x, w


def strip_force_torque(planform: int, p: ButterflyParams, omega: float, n_strips: int = 64, rule: str = "gauss3"):
    """Force (N) and hinge torque (N m) on one wing by summing eq. 2 over strips ``dS_k`` (eq. 3)."""
    x, dx = strip_nodes(p.span_m, n_strips, rule)
    dS = PLANFORMS[planform](x, p.span_m, p.width_m) * dx
    dF = pressure_force_magnitude(dS, p.rho, p.cd, x * omega)
    return float(np.sum(dF)), float(np.sum(x * dF))


@dataclass(frozen=True)
class ClosedFormCheck:
    """E1: the six closed forms of eq. 4 and 6 against strip integration."""

    omega_rad_s: float
    rows: list = field(default_factory=list)  # (quantity, planform, closed, strips, rel_error)
    convergence: list = field(default_factory=list)  # (n_strips, max rel error, midpoint rule)
    closed_form_max_rel_error: float = 0.0
    velocity_efficiency: dict = field(default_factory=dict)  # F_k / omega^2, N s^2
    torque_efficiency: dict = field(default_factory=dict)  # F_k / tau_k, 1/m

    def to_dict(self) -> dict:
        return {
            "omega_rad_s": self.omega_rad_s,
            "closed_form_max_rel_error": self.closed_form_max_rel_error,
            "rows": [
                {"quantity": q, "planform": k, "closed_form": c, "strips": s, "rel_error": e}
                for q, k, c, s, e in self.rows
            ],
            "midpoint_convergence": [{"n_strips": n, "max_rel_error": e} for n, e in self.convergence],
            "velocity_efficiency_N_s2": {str(k): v for k, v in self.velocity_efficiency.items()},
            "torque_efficiency_per_m": {str(k): v for k, v in self.torque_efficiency.items()},
            "best_velocity_efficiency_planform": max(self.velocity_efficiency, key=self.velocity_efficiency.get),
            "best_torque_efficiency_planform": max(self.torque_efficiency, key=self.torque_efficiency.get),
        }


def check_closed_forms(p: ButterflyParams | None = None, omega: float = 20.0 * math.pi) -> ClosedFormCheck:
    """E1: compare eq. 4 and 6 with strip sums; also the paper's two efficiencies (section 4.1)."""
    p = p or ButterflyParams()
    rows = []
    for k in (1, 2, 3):
        f_strip, t_strip = strip_force_torque(k, p, omega)
        f_cf, t_cf = float(closed_form_force(k, p, omega)), float(closed_form_torque(k, p, omega))
        rows.append(("force", k, f_cf, f_strip, abs(f_strip - f_cf) / abs(f_cf)))
        rows.append(("torque", k, t_cf, t_strip, abs(t_strip - t_cf) / abs(t_cf)))
    conv = []
    for n in (10, 100, 1000):
        err = 0.0
        for k in (1, 2, 3):
            f, t = strip_force_torque(k, p, omega, n, "midpoint")
            err = max(err, abs(f / closed_form_force(k, p, omega) - 1.0), abs(t / closed_form_torque(k, p, omega) - 1.0))
        conv.append((n, float(err)))
    vel = {k: float(closed_form_force(k, p, omega) / omega**2) for k in (1, 2, 3)}
    tor = {k: float(closed_form_force(k, p, omega) / closed_form_torque(k, p, omega)) for k in (1, 2, 3)}
    return ClosedFormCheck(omega, rows, conv, max(r[4] for r in rows), vel, tor)


def wing_forces(p: ButterflyParams, omega, v_forward, phi, theta=0.0):
    """Forces of both wings (planform 2), Oe 2010 eq. 7-9, returned as ``(F_y, F_z)`` in N.

    ``v_w' = L omega - v_z sin(phi)`` (eq. 7, ``v_forward`` relative to the air, m/s);
    ``F = K v_w'|v_w'|`` with ``K = rho C_d L W / 4``; ``F_y = -F cos(phi)``, ``F_z = F sin(phi)``
    (signs as stated below eq. 9), each multiplied by ``cos(theta)`` as in eq. 11.
    """
    phi = np.asarray(phi, dtype=float)
    vp = p.span_m * np.asarray(omega, dtype=float) - np.asarray(v_forward, dtype=float) * np.sin(phi)
    # eq. 1 with the area of the two wings folded into K: signed force along the wing normal
    f_normal = -normal_drag(2.0 * p.k_wings / (p.rho * p.cd), p.rho, p.cd, vp)  # = K v'|v'|
    c = np.cos(theta)
    return -f_normal * np.cos(phi) * c, f_normal * np.sin(phi) * c


def body_drag(p: ButterflyParams, v):
    """Body drag along one axis, Oe 2010 eq. 10: ``-1/2 rho C_d A_b v|v|`` (N), ``v`` in m/s."""
    return normal_drag(p.body_area_m2, p.rho, p.cd, v)


@dataclass(frozen=True)
class Fig3Curves:
    """E2: ``F_y``, ``F_z`` against ``phi`` for ``v_z`` = 0, 2, 4 m/s, upstroke and downstroke."""

    phi_deg: np.ndarray
    curves: dict  # (v_z, "up"|"down") -> (F_y, F_z) arrays in N

    def to_dict(self) -> dict:
        return {
            "phi_deg": self.phi_deg.tolist(),
            "curves": [
                {"v_z_m_s": v, "stroke": s, "F_y_N": fy.tolist(), "F_z_N": fz.tolist()}
                for (v, s), (fy, fz) in self.curves.items()
            ],
        }


def fig3_curves(
    p: ButterflyParams | None = None, omega: float = 20.0 * math.pi, speeds=(0.0, 2.0, 4.0), n: int = 361
) -> Fig3Curves:
    """E2 (Fig. 3): eq. 8-9 at ``theta = 0`` over ``phi`` in [-90, 90] deg."""
    p = p or ButterflyParams()
    phi_deg = np.linspace(-90.0, 90.0, n)
    phi = np.radians(phi_deg)
    curves = {}
    for v in speeds:
        for stroke, sign in (("up", 1.0), ("down", -1.0)):
            curves[(float(v), stroke)] = wing_forces(p, sign * omega, v, phi)
    return Fig3Curves(phi_deg, curves)


def max_forward_force(p: ButterflyParams, omega: float, v_forward):
    """Largest ``F_z`` over ``phi`` (and over both strokes) at forward speed ``v_forward`` (m/s), N.

    With ``a = L|omega|`` and ``s = sin(phi)``, ``F_z = K s (a - v s)^2`` on the upstroke is
    maximal at ``s = a/(3v)`` (``4 K a^3 / (27 v)``) when ``v >= a/3``, else at ``s = 1``; the
    downstroke gives the same maximum at ``-phi``. Checked against a dense grid in the tests.
    """
    v = np.asarray(v_forward, dtype=float)
    a = p.span_m * abs(omega)
    s = np.minimum(1.0, a / (3.0 * np.maximum(v, 1e-300)))
    return p.k_wings * s * (a - v * s) ** 2


@dataclass(frozen=True)
class SpeedLimit:
    """E3: the quasi-static forward-speed limit of Oe 2010 section 4.3."""

    speed_limit_cm_s: int
    body_area_cm2: float
    omega_rad_s: float
    closed_form_m_s: float  # continuous solution a (2 L W / (27 A_b))^(1/3)

    def to_dict(self) -> dict:
        return dict(self.__dict__)


def speed_limit(p: ButterflyParams | None = None, omega: float = 20.0 * math.pi, max_cm_s: int = 5000) -> SpeedLimit:
    """E3: largest ``v_z`` on a 1 cm/s grid with ``max_phi F_z > |F_bz|`` (section 4.3)."""
    p = p or ButterflyParams()
    v = np.arange(1, max_cm_s + 1) / 100.0
    ok = max_forward_force(p, omega, v) > -body_drag(p, v)
    if ok.all():
        raise ValueError("speed limit above the search range")
    first_fail = int(np.argmin(ok))
    limit = int(round(v[first_fail - 1] * 100)) if first_fail > 0 else 0
    a = p.span_m * abs(omega)
    cont = a * (2.0 * p.span_m * p.width_m / (27.0 * p.body_area_m2)) ** (1.0 / 3.0)
    return SpeedLimit(limit, p.body_area_m2 * 1e4, omega, cont)
