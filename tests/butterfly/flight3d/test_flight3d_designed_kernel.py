"""The designed controller in the compiled loop (``designed_kernel``) against its Python twin
(``designed.DesignedController``): the same flight, sample by sample, on a course in gusts (waypoint guidance, the
wind observer at work) and in a turn (a schedule's references)."""

import json
from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import controls as ct
from lifelike_mj.butterfly.flight3d import designed as D
from lifelike_mj.butterfly.flight3d import designed_kernel as DK
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.tasks import Task3D, course, turn

MODEL = Path(__file__).resolve().parents[3] / "benchmarks" / "results" / "monarch_model.json"


#: A waypoint inside the turn flown at 1.5 m/s: circled, then left and met again (``designed.orbit_direction``).
CIRCLED = Task3D("waypoints", ((3.0, 0.0, 0.0), (3.0, 0.7, 0.0), (4.5, 0.7, 0.0)), speed_m_s=1.5, name="circled")


@pytest.fixture(scope="module")
def spec():
    return D.design(json.loads(MODEL.read_text()))


def _flight(controller, task, seconds: float) -> np.ndarray:
    f = Flight3D(controller=controller, task=task)
    rows = []
    while f.time < seconds - 1e-9:
        f.step(40)
        rows.append(np.concatenate([f.data.qpos[:7], f.data.qvel[:6], [f.waypoints_passed]]))
    return np.array(rows)


@pytest.mark.parametrize("task,seconds", [
    (course(201).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5), 6.0),
    (turn(90.0, speed_m_s=1.2), 4.0), (CIRCLED, 8.0)], ids=["gusty course", "turn", "a circled waypoint"])
def test_the_compiled_controller_flies_as_its_python_twin(spec, task, seconds):
    python = _flight(D.DesignedController(spec), task, seconds)
    compiled = _flight(DK.CompiledDesigned(spec), task, seconds)
    assert np.ptp(python[:, 0]) > 1.0  # it flew somewhere
    np.testing.assert_allclose(compiled, python, rtol=0.0, atol=1e-9)


def test_a_waypoint_circled_is_left_and_met_again_from_straight_ahead(spec):
    """A waypoint 0.7 m to the left of the track just after the last one lies inside the turn the butterfly makes at
    1.5 m/s (0.75 m radius at the fastest turn): it circles it (before ``designed.ORBIT_M`` was the turn's diameter, for
    the rest of a minute); having swept one and a half turns of bearing near it, it flies out and comes back in, and
    passes it."""
    f = Flight3D(controller=DK.CompiledDesigned(spec), task=CIRCLED)
    went_out = False
    while f.time < 30.0 and f.waypoints_passed < 3:
        f.step(40)
        went_out |= bool(f._batch.designed_states[0][0][DK.ST_NAMES.index("going_out")])
    assert went_out and f.waypoints_passed == 3


def test_the_ring_keeps_the_last_beat_as_the_twins_deque_does():
    st, buf, _ = DK.new_state()
    R = np.eye(3)
    for k in range(30):
        DK.sample(st, buf, np.full(7, float(k)), np.zeros(6), R, 0.0, 20 if k < 25 else 12)
    assert st[0] == 30 and st[1] == 12  # a shorter beat drops the oldest samples at once
    kept = [DK._row(buf, st, j)[0] for j in range(int(st[1]))]
    assert kept == [float(k) for k in range(18, 30)]


def test_a_batch_flies_each_butterfly_as_it_would_fly_alone(spec):
    """Two butterflies on two gusty courses in one compiled batch (threads over the copies, each with its own
    controller state): each flies as it does in a batch of one."""
    from lifelike_mj.butterfly.flight3d.loop import Batch
    from lifelike_mj.butterfly.flight3d.tasks import new_record

    ctl = DK.CompiledDesigned(spec)
    tasks = [course(s).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5)
             for s in (202, 203)]
    alone = [Flight3D(controller=ctl, task=t) for t in tasks]
    for f in alone:
        f.step(2400)
    pair = [Flight3D(controller=ctl, task=t, _model=alone[0].model) for t in tasks]
    rows = max(len(t.rows) for t in tasks)
    batch = Batch(pair[0].model, [f.data for f in pair], np.stack([t.as_array(rows) for t in tasks]), dt_s=pair[0].dt,
                  records=new_record(2, rows), base=pair[0].command.as_array(), designed=ctl)
    batch.advance(2400)
    for f, g in zip(alone, pair):
        np.testing.assert_allclose(g.data.qpos, f.data.qpos, rtol=0.0, atol=1e-9)
    assert np.linalg.norm(alone[0].data.qpos[:2] - alone[1].data.qpos[:2]) > 0.5  # two flights, not one twice


def test_a_designed_controller_converts_for_the_compiled_loop(spec):
    ctl = DK.CompiledDesigned.of(D.DesignedController(spec, name="d"))
    assert isinstance(ctl, DK.CompiledDesigned) and ctl.name == "d"
    f = Flight3D(controller=ctl, task=turn(90.0, speed_m_s=1.2))
    assert f.controller is None and f.designed is ctl  # no Python call per step
    from lifelike_mj.errors import UserError

    with pytest.raises(UserError, match="decide needs a 3D controller"):
        Flight3D(task=turn(90.0, speed_m_s=1.2)).decide(np.zeros(9))


def test_a_residual_of_zeros_flies_the_designed_controller_bit_for_bit(spec):
    """Flight3D.decide with a designed controller: a residual policy's decisions at the controller's own control
    steps (every 8 steps); zeros fly the same flight as step() to the last bit, a residual another flight."""
    task = course(204).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5, seed=204)
    ctl = DK.CompiledDesigned(spec)
    alone = Flight3D(controller=ctl, task=task)
    alone.step(2400)
    zeros, pushed = Flight3D(controller=ctl, task=task), Flight3D(controller=ctl, task=task)
    for f, a in ((zeros, np.zeros(9)), (pushed, np.full(9, 0.5))):
        f.decide()
        decisions = 0
        while f.steps < 2400:
            f.decide(a, max_steps=2400)
            decisions += 1
        assert decisions == 2400 // ctl.every
    assert np.array_equal(zeros.data.qpos, alone.data.qpos) and zeros.reward == alone.reward
    assert np.linalg.norm(pushed.data.qpos[:3] - alone.data.qpos[:3]) > 0.05
    assert zeros.baseline_command.shape == (13,) and Flight3D(task=task).baseline_command is None


def test_a_residual_is_added_to_each_control_within_the_limits():
    from lifelike_mj.butterfly.flight3d import averaged as av

    lo, hi = D.limits()
    base = np.array([10.9, 0.1, 0.12, 1.0, 1.02, 0.2, 0.18, 0.6, 0.6, -1.571, -0.2, 0.244, 2.54])
    action = np.array([1.0, -0.5, 0.25, 1.0, -1.0, 0.0, 0.5, -0.25, 1.0])
    target = np.empty(13)
    DK.residual_command(base, action, D.RESIDUAL_SCALE, lo, hi, target)
    want = np.clip(av.controls_of(base) + action * D.RESIDUAL_SCALE, lo, hi)
    np.testing.assert_allclose(av.controls_of(target), want, rtol=0.0, atol=1e-12)
    assert target[0] == hi[0]  # 10.9 Hz + 0.5 Hz is held at the envelope's 11 Hz
    # the feathering's difference moved by half its scale, split between the wings; its mean did not move
    assert target[5] - target[6] == pytest.approx(base[5] - base[6] + 0.5 * 0.06, abs=1e-12)
    assert target[5] + target[6] == pytest.approx(base[5] + base[6], abs=1e-12)


def _torqued(spec, axis: int, torque_n_m: float, tau_s: float, monkeypatch) -> tuple[float, float]:
    """Level flight at 1.5 m/s, a steady torque about the world's ``axis`` (0: x, the roll at heading 0; 2: the
    vertical, the yaw) on the thorax from 2 s on: the mean |roll| or |yaw| (deg) over the last 2 s of 5, and the moment
    observer's estimate about the body's same axis (rad/s^2) at the end."""
    from lifelike_mj.butterfly.flight3d.flight import euler_from_quat
    from lifelike_mj.butterfly.flight3d.tasks import level

    monkeypatch.setattr(D, "MOMENT_TAU_S", tau_s)
    f = Flight3D(controller=DK.CompiledDesigned(spec), task=level(1.5))  # the constants are read here
    f.step(int(round(2.0 / f.dt)))
    f.data.xfrc_applied[f.model.body("butterfly").id, 3 + axis] = torque_n_m
    angles = []
    while f.time < 5.0 - 1e-9:
        f.step(8)
        angles.append(euler_from_quat(f.data.qpos[3:7])[axis])
    angles = np.degrees(np.unwrap(angles))
    estimate = f._batch.designed_states[0][0][DK.ST_NAMES.index("moment_" + "xyz"[axis])]
    return float(np.abs(angles[len(angles) // 3 :]).mean()), float(estimate)


@pytest.mark.parametrize("axis", [0, 2], ids=["roll", "yaw"])
def test_the_moment_observer_finds_a_steady_torque_and_cancels_it(spec, axis, monkeypatch):
    """A torque of 3e-7 N m that the model does not know, about the roll axis (5.0 rad/s^2 on the averaged model's
    roll inertia at 1.5 m/s) or the vertical (4.7 rad/s^2 on its yaw inertia): the observer's estimate about that axis
    moves by about torque / inertia (measured 0.78 times in roll, 1.3 in yaw: the torque is about the world's axes,
    the body pitched 23 deg), and the roll or heading holds more than twice as close as with the observer held at zero
    (measured 0.14 against 0.35 deg in roll, 0.08 against 0.36 deg in yaw). Its sign is what this checks; which axes
    are cancelled, the upset tests and the test below."""
    points = json.loads(MODEL.read_text())["points"]
    inertia = next(p["inertia_kg_m2"][axis][axis] for p in points if p["speed_m_s"] == 1.5 and p["climb_m_s"] == 0.0)
    torque, tau = 3e-7, D.MOMENT_TAU_S
    off_angle, _ = _torqued(spec, axis, torque, 1e12, monkeypatch)
    on_angle, on_est = _torqued(spec, axis, torque, tau, monkeypatch)
    _, calm_est = _torqued(spec, axis, 0.0, tau, monkeypatch)
    assert 0.5 < (on_est - calm_est) / (torque / inertia) < 2.0
    assert on_angle < 0.5 * off_angle


def test_the_moment_observers_correction_cancels_roll_and_yaw_and_leaves_the_symmetric_controls(spec):
    """The correction (``DesignedController.moment``) is the least change of the controls whose angular acceleration
    through the model's ``B`` is the estimate's roll and yaw, negated, and none in pitch; the model's roll and yaw rows
    hold only the left-right differences (its symmetry), so the symmetric controls (frequency, offset, amplitude,
    feathering mean and amplitude, abdomen) stay where they are, to a rounding of the model's near-zero entries."""
    ctl = D.DesignedController(spec)
    A, B = ctl._at(1.5, "A"), ctl._at(1.5, "B")
    ctl.moment_hat = np.array([2.0, -3.0, 1.5])  # rad/s^2: the estimate as the observer holds it
    u = ctl.moment(np.zeros(3), np.zeros(D.N_AUG), A, B, 0.01)  # its first call sets the rates, keeps the estimate
    np.testing.assert_allclose(B[3:6] @ u, [-2.0, 0.0, -1.5], rtol=0.0, atol=1e-9)
    differences = [i for i, n in enumerate(ct.CONTROLS) if n.endswith("_difference")]
    symmetric = [i for i in range(len(ct.CONTROLS)) if i not in differences]
    assert np.abs(u[differences]).max() > 1e-4
    assert np.abs(u[symmetric]).max() < 1e-5 * np.abs(u[differences]).max()
