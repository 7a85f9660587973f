"""The compiled, batched paper model of Oe 2010 eq. 7-11 (lifelike_mj/butterfly/paper.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lifelike_mj.butterfly import controllers
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.butterfly.params import ButterflyParams, FlapPattern

DT = 1.0 / 1200.0


@pytest.fixture(scope="module")
def simple():
    return controllers.load("simple_rule")


def _frozen(theta_deg: float = 0.0, phi_deg: float = 0.0) -> controllers.ButterflyController:
    """Wings held still at ``theta`` (omega = 0) and a constant pitch: no wing force at phi = 0."""
    return controllers.ButterflyController("constant", FlapPattern(10.0, theta_deg, theta_deg), {"phi_deg": phi_deg})


@pytest.mark.parametrize(
    "ctrl_args, params, cond",
    [
        ({"phi_up_deg": 12.77}, ButterflyParams(), paper.Condition()),
        ({"phi_up_deg": 14.0, "phi_down_deg": -3.0}, ButterflyParams(body_area_m2=1.53e-4),
         paper.Condition(y0_m=2.0, wind_from_m_s=(2.0, -0.5))),
    ],
)
def test_compiled_equals_naive_loop_after_2s(simple, ctrl_args, params, cond):
    ctrl = simple.with_parameters(**ctrl_args)
    n = 2400  # 2 s at 1/1200 s
    (tr,) = paper.simulate(ctrl, params, cond, n * DT, DT, n)
    y, z, vy, vz = paper.simulate_naive(ctrl, params, cond, n, DT)
    assert tr.t[-1] == pytest.approx(2.0, abs=1e-12)
    assert abs(tr.y[-1] - y) < 1e-9 and abs(tr.z[-1] - z) < 1e-9
    assert abs(tr.vy[-1] - vy) < 1e-9 and abs(tr.vz[-1] - vz) < 1e-9
    assert abs(tr.z[-1]) > 0.5  # it really flew forward


def test_batch_equals_each_flown_alone_bitwise(simple):
    ctrls = [
        simple,
        simple.with_parameters(phi_up_deg=14.0),
        controllers.load("glide"),
        simple.with_parameters(phi_up_deg=11.0, phi_down_deg=2.0),
        _frozen(30.0, 5.0),
    ]
    params = [ButterflyParams(), ButterflyParams(mass_kg=0.4e-3), ButterflyParams(), ButterflyParams(body_area_m2=2e-4),
              ButterflyParams()]
    conds = [paper.Condition(), paper.Condition(wind_from_m_s=(0.0, 2.0)), paper.Condition(y0_m=10.0),
             paper.Condition(y0_m=-1.0, wind_from_m_s=(-2.0, 0.0)), paper.Condition(wind_from_m_s=(1.0, 1.0))]
    batch = paper.simulate(ctrls, params, conds, 1.0, DT, 3)
    assert len(batch) == 5
    for i, tr in enumerate(batch):
        (alone,) = paper.simulate([ctrls[i]], params[i], conds[i], 1.0, DT, 3)
        for key in ("t", "y", "z", "vy", "vz", "phi", "theta"):
            assert np.array_equal(getattr(tr, key), getattr(alone, key)), (i, key)
        assert tr.y0 == conds[i].y0_m and tr.diverged_step == -1
    # and the flights differ from one another (the batch does not mix them up)
    finals = {float(tr.y[-1]) for tr in batch}
    assert len(finals) == 5


def test_wind_enters_as_air_relative_velocity_first_step():
    # wings frozen at theta = 0 and phi = 0: the wing's normal speed is v_w' = L*0 - v_z sin 0 = 0, so
    # only body drag (eq. 10) of the air-relative speed acts. A head wind (2, 0) means air moving at
    # -2 m/s along z: the air-relative forward speed starts at +2 m/s and the drag decelerates the body.
    p = ButterflyParams()
    c = 0.5 * p.rho * p.cd * p.body_area_m2 / p.mass_kg  # 1/m
    for wind, sign in (((2.0, 0.0), -1.0), ((-2.0, 0.0), +1.0)):
        (tr,) = paper.simulate(_frozen(), p, paper.Condition(wind_from_m_s=wind), 10 * DT, DT, 1)
        # dv/dt = -c u|u| with u = v_z + 2 (head) or v_z - 2 (tail): u(t) = u0 / (1 + c |u0| t)
        u0 = -sign * 2.0
        expected_vz = u0 / (1.0 + c * abs(u0) * tr.t) - u0
        assert np.allclose(tr.vz, expected_vz, rtol=1e-9, atol=1e-15)
        assert sign * tr.vz[1] > 0
        assert math.isclose(tr.vz[1] / DT, sign * c * 4.0, rel_tol=1e-3)  # first-step acceleration
    # wind from above (0, 2): air moving down, air-relative v_y = +2 m/s, drag pushes down beyond gravity
    (still,) = paper.simulate(_frozen(), p, paper.Condition(), 10 * DT, DT, 1)
    (above,) = paper.simulate(_frozen(), p, paper.Condition(wind_from_m_s=(0.0, 2.0)), 10 * DT, DT, 1)
    assert math.isclose((above.vy[1] - still.vy[1]) / DT, -c * 4.0, rel_tol=1e-2)


def test_head_wind_raises_air_relative_forward_speed_and_lift(simple):
    # On the upstroke phi_up > 0: v_w' = L omega - v_zr sin(phi) (eq. 7) is smaller with the larger
    # air-relative forward speed v_zr of a head wind, so the downward wing force of the upstroke
    # shrinks and the butterfly ends higher than in still air (paper section 7.2: holds ~0 m).
    still, head = paper.simulate([simple, simple], None, [paper.Condition(), paper.Condition(wind_from_m_s=(2.0, 0.0))],
                                 1.0, DT, 1)
    air_rel_still = still.vz - 0.0
    air_rel_head = head.vz + 2.0  # air velocity is -(2, 0)
    assert np.all(air_rel_head[1:] > air_rel_still[1:])
    assert head.y[-1] > still.y[-1] + 0.1
    assert head.z[-1] < still.z[-1]  # but the ground speed is lower


def test_divergence_is_flagged_with_step_and_nan_after(simple):
    # a 3000x lighter butterfly: the body-drag term becomes so stiff that RK4 at 1/1200 s runs away
    light = ButterflyParams(mass_kg=1e-6)
    bad, good = paper.simulate([simple, simple], [light, ButterflyParams()], None, 0.5, DT, 1)
    k = bad.diverged_step
    assert k >= 1
    assert np.all(np.isfinite(bad.y[:k])) and np.all(np.isnan(bad.y[k:]))
    assert np.all(np.isnan(bad.vz[k:])) and not bad.finite
    assert np.nanmax(np.abs(bad.vy[:k]) + np.abs(bad.vz[:k])) < 1e4  # flagged at the first runaway sample
    assert good.diverged_step == -1 and good.finite
    (alone,) = paper.simulate(simple, ButterflyParams(), None, 0.5, DT, 1)
    assert np.array_equal(good.y, alone.y)  # the runaway did not disturb its neighbour


def test_gravity_only_glide_starts_as_free_fall():
    glide = controllers.load("glide")  # wings fixed at 75 deg, phi = 0: no wing force
    assert glide.flap.theta_a == 0.0
    p = ButterflyParams()
    n = 24  # 0.02 s
    (tr,) = paper.simulate(glide, p, None, n * DT, DT, 1)
    free = -0.5 * p.gravity * tr.t**2
    c = 0.5 * p.rho * p.cd * p.body_area_m2 / p.mass_kg
    drag_bound = 0.5 * c * (p.gravity * tr.t) ** 2 * tr.t**2  # |drag accel| <= c (g t)^2
    assert np.all(tr.y[1:] >= free[1:])  # drag only slows the fall
    assert np.all(tr.y - free <= drag_bound + 1e-15)
    assert abs(tr.y[-1] / free[-1] - 1.0) < 1e-3
    assert np.all(tr.z == 0.0) and np.all(tr.vz == 0.0)


def test_the_paper_backend_does_not_import_mujoco():
    """`butterfly fly` on the paper backend must not pay for MuJoCo (issue 12, start-up)."""
    import subprocess
    import sys

    code = ("import sys\nimport lifelike_mj\nassert 'mujoco' not in sys.modules and 'numba' not in sys.modules\n"
            "from lifelike_mj.cli import main\nmain(['butterfly', 'fly', '--controller', 'simple_rule', '--duration', "
            "'1', '--json'])\nprint('mujoco' in sys.modules)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.strip().splitlines()[-1] == "False"
