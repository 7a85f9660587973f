"""The 3D butterfly's callback: air on wing panels and body, the joints' drive, nothing else on the body."""

import math

import mujoco
import numpy as np
import pytest

from lifelike_mj.butterfly import aero
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.kinematics import Kinematics, KinematicsCommand
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.physics.callbacks import passive_callback

#: A command that moves every driven joint: flap, feathering and abdomen.
BUSY = KinematicsCommand(frequency_hz=11.0, amplitude_left=1.0, amplitude_right=0.8, offset_right=0.2,
                         feather_mean_left=0.3, feather_amplitude_left=0.5, feather_amplitude_right=0.4,
                         feather_phase=1.0, abdomen_mean=0.2, abdomen_amplitude=0.4, abdomen_phase=0.5)


@pytest.fixture(scope="module")
def model():
    return mj3d.build_model()


def _random_state(m, law, assist, seed=1):
    k = Kinematics(BUSY)
    k.advance(0.013)
    d = mj3d.setup_data(m, k, force_law=law, air_m_s=(0.5, -0.3, 0.2), assist=assist)
    rng = np.random.default_rng(seed)
    d.qpos[:3] = rng.normal(size=3)
    q = rng.normal(size=4)
    d.qpos[3:7] = q / np.linalg.norm(q)
    d.qvel[:] = rng.normal(0, 2, m.nv)
    d.time = 0.0125
    mj3d.load_kinematics(d, k)
    return d, k


@pytest.mark.parametrize("law", ["strip", "quasi_steady", "tip", "none", "exact"])
@pytest.mark.parametrize("assist", ["none", "hold"])
def test_the_compiled_callback_equals_its_python_twin(model, law, assist):
    d, _ = _random_state(model, law, assist)
    got = []
    for cb in (mj3d.COMPILED_PASSIVE, mj3d.python_passive):
        with passive_callback(cb):
            mujoco.mj_forward(model, d)
        got.append((d.qfrc_passive.copy(), d.userdata[mj3d.U_OUT : mj3d.U_OUT + mj3d.N_OUT].copy()))
    scale = np.abs(got[1][0]).max()
    assert scale > 1e-4
    np.testing.assert_allclose(got[0][0], got[1][0], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(got[0][1], got[1][1], rtol=0, atol=1e-12 * np.abs(got[1][1]).max())


@pytest.mark.parametrize("law", ["strip", "none"])
def test_the_driven_joints_move_exactly_as_the_kinematics_say(model, law):
    d, k = _random_state(model, law, "none")
    with passive_callback(mj3d.COMPILED_PASSIVE):
        mujoco.mj_forward(model, d)
    ref = k.joint_references()
    q, driven, _ = mj3d.driven_dofs(model)
    wn = 2 * math.pi * 50.0
    want = ref[:, 2] + wn * wn * (ref[:, 0] - d.qpos[q]) + 2 * wn * (ref[:, 1] - d.qvel[driven])
    np.testing.assert_allclose(d.qacc[driven], want, rtol=1e-9, atol=1e-6)


@pytest.mark.parametrize("law", ["strip", "exact"])
def test_one_strip_law_wing_at_rest_but_flapping_gives_the_closed_forms_of_eq_4_and_6(model, law):
    """A wing turning at omega about its flap hinge on a body at rest: every panel's normal speed is
    omega r, so the panels (or the exact integral) must add up to planform 2's closed forms (Oe 2010 eq. 4
    and 6)."""
    p = ButterflyParams()
    pan = mj3d.panels(p)
    assert pan[:, 2].sum() == pytest.approx(0.5 * p.width_m * p.span_m, rel=1e-12)
    d = mj3d.setup_data(model, Kinematics(), p, force_law=law)
    d.userdata[mj3d.U_DRIVE] = 0.0
    d.qvel[:] = 0.0
    q, driven, _ = mj3d.driven_dofs(model)
    d.qpos[q] = 0.0
    omega = 40.0
    d.qvel[driven[0]] = omega  # the left wing going up
    with passive_callback(mj3d.COMPILED_PASSIVE):
        mujoco.mj_forward(model, d)
    out = mj3d.forces(d)
    force, torque = aero.strip_force_torque(2, p, omega)
    np.testing.assert_allclose(out["wing_force_N"][0], [0.0, 0.0, -force], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out["wing_moment_N_m"][0], [-torque, 0.0, 0.0], rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(out["wing_force_N"][1], 0.0)  # the right wing is still


def _momenta(m, d):
    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_comVel(m, d)
    mujoco.mj_subtreeVel(m, d)
    mass = m.body_subtreemass[1]
    return mass * d.subtree_linvel[1].copy(), d.subtree_angmom[1].copy(), d.subtree_com[1].copy()


def _flap_in_vacuum(m, dt, assist="none", gravity=0.0, duration=0.5):
    """Momentum, angular momentum and centre of mass at the start and after ``duration`` of flapping."""
    pitch = {"none": None, "hold": lambda f: 0.3}[assist]
    f = Flight3D(BUSY, force_law="none", assist=assist, pitch_law=pitch, dt_s=dt, _model=m)
    m.opt.gravity[:] = (0.0, 0.0, -gravity)
    start = _momenta(f.model, f.data)
    f.step(int(round(duration / dt)))
    return f, start, _momenta(f.model, f.data)


def _drift(m, dt, **kw):
    _, (p0, l0, _), (p1, l1, _) = _flap_in_vacuum(m, dt, **kw)
    return np.abs(p1 - p0).max(), np.abs(l1 - l0).max()


def test_nothing_but_the_air_and_gravity_acts_on_the_free_body():
    """No actuator, constraint, contact or applied force, and the joints' drive only turns the parts against
    each other: without air and gravity the whole butterfly keeps its momentum and angular momentum while
    its wings feather and flap and its abdomen swings (to the integrator's accuracy: the drift falls as dt^4,
    Runge-Kutta's order, where any outside force would leave a drift that does not shrink), and under
    gravity alone its momentum grows by exactly ``M g t``."""
    m = mj3d.build_model()
    assert m.nu == 0 and m.neq == 0 and m.nmocap == 0 and not m.dof_armature.any()
    assert m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    f, (p0, l0, _), _ = _flap_in_vacuum(m, 1.0 / 1200.0)
    assert np.abs(f.data.qvel[3:6]).max() > 0.1  # the body turned and recoiled: it is not held
    assert not f.data.qfrc_applied.any() and not f.data.xfrc_applied.any()
    coarse, fine = _drift(m, 1.0 / 1200.0), _drift(m, 1.0 / 4800.0)
    for c, f_, scale in ((coarse[0], fine[0], np.abs(p0).max()), (coarse[1], fine[1], np.abs(l0).max())):
        assert scale > 1e-9  # the wings' own (linear, angular) momentum at the start: what is conserved
        assert c / f_ > 100.0  # 4x smaller steps, 256x smaller drift at 4th order
        assert f_ < 1e-5 * scale
    # gravity alone: the momentum grows by M g t (again to the integrator's accuracy)
    mass = m.body_subtreemass[1]
    f, (p0, _, _), (p1, _, _) = _flap_in_vacuum(m, 1.0 / 4800.0, gravity=9.8)
    np.testing.assert_allclose(p1 - p0, [0.0, 0.0, -mass * 9.8 * f.time], atol=1e-5 * np.abs(p0).max())


def test_the_attitude_hold_is_an_outside_torque_and_the_momentum_check_sees_it():
    """The check above can fail: the reduction's attitude hold turns the body from outside, and the angular
    momentum it leaves does not shrink with the step."""
    m = mj3d.build_model()
    coarse, fine = _drift(m, 1.0 / 1200.0, assist="hold"), _drift(m, 1.0 / 4800.0, assist="hold")
    assert fine[1] > 0.5 * coarse[1] > 1e-9


def test_with_air_the_body_feels_only_the_air_on_its_free_dofs(model):
    """The drive adds torque on the driven joints only: with it on or off, the free dofs' forces are the air's."""
    d, _ = _random_state(model, "strip", "none")
    with passive_callback(mj3d.COMPILED_PASSIVE):
        mujoco.mj_forward(model, d)
        on = d.qfrc_passive.copy()
        d.userdata[mj3d.U_DRIVE] = 0.0
        mujoco.mj_forward(model, d)
        off = d.qfrc_passive.copy()
    _, driven, free = mj3d.driven_dofs(model)
    np.testing.assert_array_equal(on[free], off[free])
    assert np.abs(on[driven] - off[driven]).max() > 1e-6


@pytest.mark.parametrize("controller, tol_m", [("simple_rule", 1e-3), ("ann_paper", 1e-6)])
def test_the_3d_model_reduced_to_the_plane_flies_the_planar_mujoco_flight_for_20_s(controller, tol_m):
    """Issue 15's reduction: within 1 cm of the planar MuJoCo backend over 20 s (measured: 0.24 mm with the
    simple rule, 1.3 nm with the paper's network), never leaving the sagittal plane."""
    from lifelike_mj.butterfly.flight3d.validate import reduction

    r = reduction(controller, duration_s=20.0)
    assert r["duration_s"] == pytest.approx(20.0)
    assert r["planar_end_m"][0] > 50.0  # it flew: ~66 m forward in 20 s
    assert r["max_forward_difference_m"] < tol_m
    assert r["max_altitude_difference_m"] < tol_m
    assert r["max_sideways_m"] < 1e-12


def test_bad_flight_options_are_one_sentence():
    with pytest.raises(UserError, match="wing-force law"):
        Flight3D(force_law="vortex")
    with pytest.raises(UserError, match="pitch_law"):
        Flight3D(assist="hold")
    with pytest.raises(UserError, match="wind_to_m_s must be 3 finite numbers"):
        Flight3D(wind_to_m_s=(1.0, float("nan"), 0.0))
    with pytest.raises(UserError, match="does not resolve"):
        Flight3D(dt_s=0.05)
    with pytest.raises(UserError, match="mass layout"):
        Flight3D(masses="heavy")


def _fruitfly(alpha_deg):
    c_l = 0.225 + 1.58 * math.sin(math.radians(2.13 * alpha_deg - 7.20))
    c_d = 1.92 - 1.55 * math.cos(math.radians(2.04 * alpha_deg - 9.82))
    return c_l, c_d


@pytest.mark.parametrize("alpha_deg", [10.0, 35.0, 60.0])
def test_the_quasi_steady_law_gives_dickinsons_lift_and_drag_on_a_translating_wing(alpha_deg):
    """A wing moving through still air at U and angle of attack alpha (no rotation): lift 1/2 rho C_L U^2 S
    across the flow, on the side the wing is pushed, and drag 1/2 rho C_D U^2 S against it, with the fruit-fly
    fits of Dickinson, Lehmann & Sane 1999 (S = W L / 2, the whole planform)."""
    p = ButterflyParams()
    pan = mj3d.panels(p)
    U, a = 2.0, math.radians(alpha_deg)
    v = np.array([U * math.cos(a), 0.0, -U * math.sin(a)])  # forward and down: the air pushes it up
    out = np.empty(15)
    mj3d.wing_panels(3, pan.ravel(), len(pan), 1.0, np.eye(3), v, np.zeros(3), p.rho, p.cd, np.ones(3), out)
    c_l, c_d = _fruitfly(alpha_deg)
    q = 0.5 * p.rho * U * U * 0.5 * p.width_m * p.span_m
    lift, drag, rot = out[6:9], out[9:12], out[12:15]
    np.testing.assert_allclose(drag, -q * c_d * v / U, rtol=1e-12, atol=1e-15)
    lift_dir = np.array([math.sin(a), 0.0, math.cos(a)])  # across the flow, upwards
    np.testing.assert_allclose(lift, q * c_l * lift_dir, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(rot, 0.0)
    np.testing.assert_allclose(out[0:3], lift + drag, rtol=1e-12, atol=1e-15)


def test_the_rotational_force_of_a_pitching_wing_is_sane_and_dickinsons():
    """Pitching about its span at omega while translating at U (alpha 30 deg): the rotational force is
    C_rot rho U omega times the integral of c^2 over the span, C_rot = pi (3/4 - 1/2), along the normal, on the
    pushed side when the leading edge turns that way (raising alpha)."""
    p = ButterflyParams()
    pan = mj3d.panels(p, n_strips=32, n_chord=1)
    U, a, w = 1.5, math.radians(30.0), 20.0
    v = np.array([U * math.cos(a), 0.0, -U * math.sin(a)])
    out = np.empty(15)
    # leading edge (+x) up, towards the pushed side +z: rotation about -y (the span axis is +y)
    mj3d.wing_panels(3, pan.ravel(), len(pan), 1.0, np.eye(3), v, np.array([0.0, -w, 0.0]), p.rho, p.cd, np.ones(3),
                     out)
    # the flow across the span is the same at every panel (no rotation about other axes moves the span)
    integral = (p.width_m / p.span_m) ** 2 * p.span_m ** 3 / 3.0
    want = math.pi * 0.25 * p.rho * U * w * integral
    np.testing.assert_allclose(out[12:15], [0.0, 0.0, want], rtol=1e-9)


def test_the_calibrated_law_scales_lift_rotation_and_drag_by_its_own_factors():
    """The calibrated law (mode 5) is the quasi-steady law with C_L and C_rot times k_L and C_D times k_D
    (model.CALIBRATED_QS), for a wing translating and pitching; the quasi-steady law itself is unscaled."""
    p = ButterflyParams()
    pan = mj3d.panels(p)
    U, a = 1.5, math.radians(30.0)
    v = np.array([U * math.cos(a), 0.0, -U * math.sin(a)])
    w = np.array([0.0, -20.0, 0.0])
    plain, scaled = np.empty(15), np.empty(15)
    mj3d.wing_panels(3, pan.ravel(), len(pan), 1.0, np.eye(3), v, w, p.rho, p.cd, np.ones(3), plain)
    k = np.array(mj3d.CALIBRATED_QS)
    mj3d.wing_panels(5, pan.ravel(), len(pan), 1.0, np.eye(3), v, w, p.rho, p.cd, k, scaled)
    np.testing.assert_allclose(scaled[6:9], k[0] * plain[6:9], rtol=1e-12)
    np.testing.assert_allclose(scaled[9:12], k[1] * plain[9:12], rtol=1e-12)
    np.testing.assert_allclose(scaled[12:15], k[2] * plain[12:15], rtol=1e-12)
    assert len(set(k)) > 1  # lift and drag are scaled apart, so a mix-up of the two would fail above
    m = mj3d.build_model(p, animal="monarch")
    for law, want in (("quasi_steady", (1.0, 1.0, 1.0)), ("calibrated", mj3d.CALIBRATED_QS)):
        d = mj3d.setup_data(m, Kinematics(), p, force_law=law, animal="monarch")
        assert tuple(d.userdata[mj3d.U_QS : mj3d.U_QS + 3]) == tuple(want)


def _midpoint_panels(p, n):
    """``n x n`` midpoint panels of the wing (chord position, span position, area, chord), as :func:`mj3d.panels`."""
    r = (np.arange(n) + 0.5) / n * p.span_m
    g = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    chord = p.width_m * r / p.span_m
    xc = 0.5 * chord[:, None] * g[None, :]
    area = np.repeat(chord * p.span_m / n / n, n)
    return np.stack([xc.ravel(), np.repeat(r, n), area, np.repeat(chord, n)], axis=1)


def test_the_exact_integral_of_eq_1_is_the_limit_of_ever_more_panels(model):
    """Eq. 1 integrated exactly over the wing: the panel law converges to it (states where the normal speed
    changes sign on the wing, so the cut along v_n = 0 is used), and a cheap triangle check of the formula."""
    from lifelike_mj.physics.fluid import triangle_sq_abs

    out = np.zeros(3)
    triangle_sq_abs(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, out)  # s = 1: the area and its first moments
    np.testing.assert_allclose(out, [0.5, 1 / 6, 1 / 6], rtol=1e-14)
    triangle_sq_abs(0.0, 0.0, 1.0, 0.0, 0.0, 1.0, -1.0, 1.0, -1.0, out)  # s = 2x - 1 - 0 y... cut at x = 1/2
    x = (np.arange(400_000) + 0.5) / 400_000  # int_0^1 (1 - x) (2x - 1)|2x - 1| dx and its x moment
    f = (1 - x) * (2 * x - 1) * np.abs(2 * x - 1)
    np.testing.assert_allclose(out[:2], [f.mean(), (x * f).mean()], rtol=1e-6, atol=1e-12)
    # a wing whose normal speed changes sign across it (where the panels' Gauss rules stop being exact)
    p = ButterflyParams()
    rng = np.random.default_rng(5)
    errors = {}
    for trial in range(4):
        q = rng.normal(size=4)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
        R = R.reshape(3, 3)
        s0 = rng.uniform(0.3, 1.0)
        # omega about the chord makes the speed fall along the span to -2 s0 at the tip; about the span, vary
        # it along the chord
        omega = R @ np.array([-3.0 * s0 / p.span_m, rng.normal(0, 40.0), rng.normal(0, 5.0)])
        lin = R @ np.array([rng.normal(), rng.normal(), s0])
        side = 1.0 if trial % 2 == 0 else -1.0
        exact = np.zeros(15)
        tris, rc = mj3d.wing_triangles(p)
        mj3d.wing_exact(side, R, lin, omega, p.rho, p.cd, tris.ravel(), len(tris), rc, exact)
        for n in (10, 40, 160):
            got = np.zeros(15)
            pan = _midpoint_panels(p, n).ravel()
            mj3d.wing_panels(2, pan, len(pan) // 4, side, R, lin, omega, p.rho, p.cd, np.ones(3), got)
            err = max(np.abs(got[:3] - exact[:3]).max() / np.abs(exact[:3]).max(),
                      np.abs(got[3:6] - exact[3:6]).max() / np.abs(exact[3:6]).max())
            errors.setdefault(n, []).append(err)
    worst = {k: max(v) for k, v in errors.items()}
    # the midpoint rule's error falls as 1/n^2 (16-fold per 4-fold n; a little less where v_n |v_n| kinks)
    assert worst[160] < 1e-4 and worst[160] < worst[40] / 8 < worst[10] / 64, worst


def test_the_normal_law_split_into_lift_and_drag_adds_up():
    m = mj3d.build_model()
    d, _ = _random_state(m, "strip", "none")
    with passive_callback(mj3d.COMPILED_PASSIVE):
        mujoco.mj_forward(m, d)
    f = mj3d.forces(d)
    np.testing.assert_allclose(f["wing_lift_N"] + f["wing_drag_N"], f["wing_force_N"], rtol=1e-10, atol=1e-14)
    assert not f["wing_rotational_N"].any() and np.abs(f["wing_lift_N"]).max() > 0
