"""The normal-pressure force of Oe 2010 eq. 1 (lifelike_mj/physics/fluid.py)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lifelike_mj.physics import fluid

speeds = st.floats(min_value=-50.0, max_value=50.0, allow_nan=False)
areas = st.floats(min_value=1e-6, max_value=10.0)
rhos = st.floats(min_value=0.1, max_value=1000.0)
cds = st.floats(min_value=0.1, max_value=3.0)
unit = st.floats(min_value=-1.0, max_value=1.0)


def test_constants_are_the_papers():
    # Oe 2010 section 3: rho = 1.28 kg/m^3 (about 5 degC), C_d = 2.2
    assert fluid.RHO_AIR == 1.28
    assert fluid.CD_PAPER == 2.2


def test_eq1_value_by_hand():
    # P = 1/2 A rho C_d v^2 with A = 0.5 m^2, v = 2 m/s: 0.5 * 0.5 * 1.28 * 2.2 * 4 = 2.816 N
    assert math.isclose(float(fluid.pressure_force_magnitude(0.5, 1.28, 2.2, 2.0)), 2.816, rel_tol=1e-15)
    assert math.isclose(float(fluid.normal_drag(0.5, 1.28, 2.2, 2.0)), -2.816, rel_tol=1e-15)
    assert math.isclose(float(fluid.normal_drag(0.5, 1.28, 2.2, -2.0)), 2.816, rel_tol=1e-15)
    assert float(fluid.normal_drag(0.5, 1.28, 2.2, 0.0)) == 0.0


@settings(max_examples=200, deadline=None)
@given(a=areas, rho=rhos, cd=cds, v=speeds)
def test_drag_opposes_the_normal_speed_with_magnitude_of_eq1(a, rho, cd, v):
    f = float(fluid.normal_drag(a, rho, cd, v))
    p = float(fluid.pressure_force_magnitude(a, rho, cd, v))
    assert p >= 0.0
    assert abs(f) == p  # |force| is P of eq. 1
    if v > 0:
        assert f < 0 or p == 0.0
    elif v < 0:
        assert f > 0 or p == 0.0
    assert float(fluid.normal_drag(a, rho, cd, -v)) == -f  # odd in v


@settings(max_examples=200, deadline=None)
@given(a=areas, rho=rhos, cd=cds, v=st.floats(min_value=0.01, max_value=50.0), k=st.floats(min_value=0.1, max_value=10))
def test_scaling_quadratic_in_speed_linear_in_area_density_cd(a, rho, cd, v, k):
    f = float(fluid.normal_drag(a, rho, cd, v))
    assert math.isclose(float(fluid.normal_drag(a, rho, cd, k * v)), k * k * f, rel_tol=1e-13)
    assert math.isclose(float(fluid.normal_drag(k * a, rho, cd, v)), k * f, rel_tol=1e-13)
    assert math.isclose(float(fluid.normal_drag(a, k * rho, cd, v)), k * f, rel_tol=1e-13)
    assert math.isclose(float(fluid.normal_drag(a, rho, k * cd, v)), k * f, rel_tol=1e-13)


@settings(max_examples=200, deadline=None)
@given(a=areas, v=st.tuples(speeds, speeds, speeds), n=st.tuples(unit, unit, unit))
def test_vector_form_equals_the_per_normal_formula(a, v, n):
    n = np.asarray(n)
    norm = np.linalg.norm(n)
    if norm < 1e-3:
        return
    n = n / norm
    vel = np.asarray(v)
    f = fluid.normal_drag_vector(a, 1.28, 2.2, vel, n)
    vn = float(vel @ n)
    expected = -0.5 * a * 1.28 * 2.2 * vn * abs(vn) * n
    assert np.allclose(f, expected, rtol=1e-12, atol=1e-12 * (1 + np.abs(expected).max()))
    # along the normal only, never pushing along the motion (dissipative), same for the flipped normal
    assert np.linalg.norm(np.cross(f, n)) <= 1e-12 * (1.0 + np.linalg.norm(f))
    assert float(f @ vel) <= 1e-12 * (1.0 + np.linalg.norm(f) * np.linalg.norm(vel))
    assert np.allclose(fluid.normal_drag_vector(a, 1.28, 2.2, vel, -n), f, rtol=1e-12, atol=1e-12)


def test_vector_form_ignores_tangential_motion_and_broadcasts():
    n = np.array([0.0, 0.0, 1.0])
    assert np.array_equal(fluid.normal_drag_vector(1.0, 1.28, 2.2, [3.0, -4.0, 0.0], n), np.zeros(3))
    vel = np.array([[0.0, 0.0, 2.0], [1.0, 0.0, -1.0], [5.0, 5.0, 0.5]])
    areas_ = np.array([1.0, 2.0, 3.0])
    f = fluid.normal_drag_vector(areas_, 1.28, 2.2, vel, n)
    assert f.shape == (3, 3)
    for i in range(3):
        assert np.allclose(f[i], fluid.normal_drag_vector(areas_[i], 1.28, 2.2, vel[i], n), rtol=0, atol=0)


@settings(max_examples=100, deadline=None)
@given(ax=areas, ay=areas, az=areas, v=st.tuples(speeds, speeds, speeds))
def test_per_axis_drag_is_the_sum_of_three_normal_forces(ax, ay, az, v):
    # Oe 2010 eq. 10 per axis = eq. 1 on three faces with normals along the axes
    f = fluid.per_axis_drag(np.array([ax, ay, az]), 1.28, 2.2, np.asarray(v))
    faces = zip((ax, ay, az), np.eye(3), strict=True)
    parts = sum(fluid.normal_drag_vector(a, 1.28, 2.2, np.asarray(v), e) for a, e in faces)
    assert np.allclose(f, parts, rtol=1e-14, atol=0.0)


@settings(max_examples=300, deadline=None)
@given(a=areas, rho=rhos, cd=cds, v=speeds)
def test_compiled_scalar_twin_equals_numpy(a, rho, cd, v):
    assert fluid.normal_drag_scalar(a, rho, cd, v) == float(fluid.normal_drag(a, rho, cd, v))
