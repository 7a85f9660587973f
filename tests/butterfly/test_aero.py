"""Wing aerodynamics of Oe 2010 eq. 2-10 (lifelike_mj/butterfly/aero.py) and experiments E1-E3."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lifelike_mj.butterfly import aero, experiments
from lifelike_mj.butterfly.params import ButterflyParams

P = ButterflyParams()
OMEGA = 20.0 * math.pi  # the mean flap rate of section 4.3, rad/s


def _exact_integrals(planform: int, p: ButterflyParams, omega: float) -> tuple[float, float]:
    """Eq. 2 integrated exactly with numpy polynomials: F = int dF, tau = int x dF over [0, L]."""
    L, W = p.span_m, p.width_m
    width = {1: [W, -W / L], 2: [0.0, W / L], 3: [W / 2.0]}[planform]  # dS/dx as a polynomial in x
    dF = np.polynomial.Polynomial([0.0, 0.0, 0.5 * p.rho * p.cd * omega**2]) * np.polynomial.Polynomial(width)
    x = np.polynomial.Polynomial([0.0, 1.0])
    F = dF.integ()(L) - dF.integ()(0.0)
    tau = (x * dF).integ()(L) - (x * dF).integ()(0.0)
    return float(F), float(tau)


@pytest.mark.parametrize("planform", [1, 2, 3])
def test_closed_forms_eq4_eq6_are_the_exact_integrals(planform):
    F, tau = _exact_integrals(planform, P, OMEGA)
    assert math.isclose(float(aero.closed_form_force(planform, P, OMEGA)), F, rel_tol=1e-13)
    assert math.isclose(float(aero.closed_form_torque(planform, P, OMEGA)), tau, rel_tol=1e-13)


@settings(max_examples=40, deadline=None)
@given(
    span=st.floats(min_value=0.005, max_value=0.5),
    width=st.floats(min_value=0.005, max_value=0.5),
    omega=st.floats(min_value=-200.0, max_value=200.0).filter(lambda w: abs(w) > 1e-3),
    planform=st.sampled_from([1, 2, 3]),
)
def test_gauss_strips_match_closed_forms_to_rounding(span, width, omega, planform):
    p = ButterflyParams(span_m=span, width_m=width)
    f, t = aero.strip_force_torque(planform, p, omega, 64, "gauss3")
    assert abs(f / float(aero.closed_form_force(planform, p, omega)) - 1.0) < 1e-12
    assert abs(t / float(aero.closed_form_torque(planform, p, omega)) - 1.0) < 1e-12


def test_e1_report_gauss_error_below_1e_12_and_midpoint_converges_as_n_minus_2():
    check = experiments.e1_closed_forms()
    assert len(check.rows) == 6
    assert check.closed_form_max_rel_error < 1e-12
    for planform in (1, 2, 3):
        errs = []
        for n in (10, 20, 40, 80, 160):
            f, t = aero.strip_force_torque(planform, P, OMEGA, n, "midpoint")
            errs.append(max(abs(f / aero.closed_form_force(planform, P, OMEGA) - 1.0),
                            abs(t / aero.closed_form_torque(planform, P, OMEGA) - 1.0)))
        ratios = [a / b for a, b in zip(errs, errs[1:], strict=False)]
        assert all(3.9 < r < 4.1 for r in ratios), ratios  # halving the strip width quarters the error
    conv = check.convergence  # decades of n: error down by 100 each
    for (n0, e0), (n1, e1) in zip(conv, conv[1:], strict=False):
        assert n1 == 10 * n0
        assert 95.0 < e0 / e1 < 105.0


def test_efficiencies_pick_the_papers_planforms():
    # section 4.1: velocity efficiency (F for a given omega) is highest for the tip-heavy planform 2,
    # torque efficiency (F per tau) for the root-heavy planform 1
    check = experiments.e1_closed_forms()
    d = check.to_dict()
    assert d["best_velocity_efficiency_planform"] == 2
    assert d["best_torque_efficiency_planform"] == 1
    vel, tor = check.velocity_efficiency, check.torque_efficiency
    assert vel[2] > vel[3] > vel[1]
    assert tor[1] > tor[3] > tor[2]
    # and the numbers are the eq. 4 / eq. 6 ratios: F/tau = b_k / (a_k L)
    for k, (a, b) in {1: (24, 40), 2: (8, 10), 3: (12, 16)}.items():
        assert math.isclose(tor[k], b / (a * P.span_m), rel_tol=1e-13)
        assert math.isclose(vel[k], P.alpha * P.span_m**2 / a, rel_tol=1e-13)


def test_wing_forces_are_eq8_eq9_with_signs():
    phi = np.radians(np.linspace(-89.0, 89.0, 179))
    K = P.rho * P.cd * P.span_m * P.width_m / 4.0
    for omega in (OMEGA, -OMEGA):
        for v in (0.0, 1.5, 4.0):
            fy, fz = aero.wing_forces(P, omega, v, phi)
            vp = P.span_m * omega - v * np.sin(phi)
            assert np.allclose(np.abs(fy), K * vp**2 * np.cos(phi), rtol=1e-13, atol=0)
            assert np.allclose(np.abs(fz), K * vp**2 * np.abs(np.sin(phi)), rtol=1e-13, atol=0)
            fy2, fz2 = aero.wing_forces(P, omega, v, phi, theta=math.radians(60.0))
            assert np.allclose(fy2, 0.5 * fy, rtol=1e-12) and np.allclose(fz2, 0.5 * fz, rtol=1e-12)


def test_fig3_sign_rules_stated_below_eq9():
    # F_y > 0 iff v_z sin(phi) > L omega; F_z > 0 iff L omega > v_z sin(phi) for phi > 0
    curves = experiments.e2_fig3()
    phi = np.radians(curves.phi_deg)
    assert sorted(curves.curves) == sorted((v, s) for v in (0.0, 2.0, 4.0) for s in ("up", "down"))
    checked = 0
    for (v, stroke), (fy, fz) in curves.curves.items():
        omega = OMEGA if stroke == "up" else -OMEGA
        lhs, rhs = v * np.sin(phi), P.span_m * omega
        clear = (np.abs(lhs - rhs) > 1e-9) & (np.abs(np.cos(phi)) > 1e-9)
        assert np.array_equal(fy[clear] > 0, (lhs > rhs)[clear])
        pos = clear & (phi > 0)
        assert np.array_equal(fz[pos] > 0, (rhs > lhs)[pos])
        checked += int(pos.sum())
    assert checked > 1000
    # section 4.3: the maximum of F_z decreases as v_z grows, the range of F_y widens
    fzmax = [max(curves.curves[(v, s)][1].max() for s in ("up", "down")) for v in (0.0, 2.0, 4.0)]
    fyspan = [max(np.ptp(curves.curves[(v, s)][0]) for s in ("up", "down")) for v in (0.0, 2.0, 4.0)]
    assert fzmax[0] > fzmax[1] > fzmax[2]
    assert fyspan[0] < fyspan[1] < fyspan[2]


@pytest.mark.parametrize("v", [0.0, 0.3, 1.0, 1.15, 2.0, 3.8, 4.38, 6.0, 10.0])
def test_max_forward_force_is_the_max_over_a_dense_phi_grid(v):
    phi = np.radians(np.linspace(-90.0, 90.0, 360_001))
    grid_max = max(float(aero.wing_forces(P, w, v, phi)[1].max()) for w in (OMEGA, -OMEGA))
    assert math.isclose(float(aero.max_forward_force(P, OMEGA, v)), grid_max, rel_tol=1e-6)
    assert math.isclose(float(aero.max_forward_force(P, -OMEGA, v)), grid_max, rel_tol=1e-6)


def _limit_by_grid(p: ButterflyParams) -> int:
    """The section 4.3 search done independently: 1 cm/s steps, max of F_z over a dense phi grid."""
    phi = np.radians(np.linspace(-90.0, 90.0, 20_001))
    v = 3.0
    while True:
        nxt = round(v + 0.01, 2)
        fz = max(float(aero.wing_forces(p, w, nxt, phi)[1].max()) for w in (OMEGA, -OMEGA))
        if fz <= 0.5 * p.rho * p.cd * p.body_area_m2 * nxt**2:
            return int(round(100 * v))
        v = nxt


def test_speed_limit_380_at_1_53_cm2_and_438_at_1_cm2():
    assert experiments.e3_speed_limit(ButterflyParams(body_area_m2=1.53e-4)).speed_limit_cm_s == 380
    assert experiments.e3_speed_limit().speed_limit_cm_s == 438
    assert _limit_by_grid(ButterflyParams(body_area_m2=1.53e-4)) == 380
    assert _limit_by_grid(P) == 438


def test_speed_limit_sweep_over_body_area():
    sweep = experiments.e3_speed_limit_vs_area()
    assert sweep.limit_at_1cm2_cm_s == 438
    assert sweep.limit_at_1_53cm2_cm_s == 380
    assert 1.53 <= sweep.area_at_380_cm2 < 1.54
    assert sweep.grid_areas_380_cm2 is not None and sweep.grid_areas_380_cm2[0] <= 1.53 + 1e-9
    assert np.all(np.diff(sweep.limits_cm_s) <= 0)  # more body drag, lower limit
    assert len(sweep.areas_cm2) == len(sweep.limits_cm_s) == 201
    # at the reported area, drag at 3.80 m/s equals the largest forward force exactly
    p = ButterflyParams(body_area_m2=sweep.area_at_380_cm2 * 1e-4)
    assert math.isclose(float(aero.max_forward_force(p, OMEGA, 3.8)), -float(aero.body_drag(p, 3.8)), rel_tol=1e-12)
    d = sweep.to_dict()
    assert d["paper_speed_limit_cm_s"] == 380 and d["limits_cm_s"][50] == 438
