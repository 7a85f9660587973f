"""The 3D butterfly's kinematics: sinusoids of one flap phase, and commands that change smoothly."""

import math

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d.kinematics import JOINTS, Kinematics, KinematicsCommand
from lifelike_mj.errors import UserError

DT = 1.0 / 1200.0


def test_a_steady_command_flies_its_sinusoids():
    cmd = KinematicsCommand(frequency_hz=9.2572, offset_left=0.44, offset_right=0.40, amplitude_left=1.04,
                            amplitude_right=1.0, feather_mean_left=0.42, feather_amplitude_left=0.59,
                            feather_phase=1.7, abdomen_mean=0.19, abdomen_amplitude=0.83, abdomen_phase=1.1)
    k = Kinematics(cmd)
    for _ in range(500):
        k.advance(DT)
    t = 500 * DT
    w = 2 * math.pi * cmd.frequency_hz
    ref = k.joint_references()
    assert ref[0, 0] == pytest.approx(0.44 + 1.04 * math.cos(w * t), abs=1e-12)
    assert ref[1, 1] == pytest.approx(-1.0 * w * math.sin(w * t), abs=1e-9)
    assert ref[2, 0] == pytest.approx(0.42 + 0.59 * math.cos(w * t + 1.7), abs=1e-12)
    assert ref[3, 0] == 0.0 and ref[3, 1] == 0.0  # the right wing is not feathered in this command
    assert ref[4, 2] == pytest.approx(-0.83 * w * w * math.cos(w * t + 1.1), rel=1e-9)
    assert len(JOINTS) == ref.shape[0] == 5


def _run(k: Kinematics, n: int, dt: float) -> np.ndarray:
    out = []
    for _ in range(n):
        out.append(k.joint_references())
        k.advance(dt)
    return np.array(out)


def test_a_jump_in_the_command_moves_no_angle_or_rate_at_once():
    k = Kinematics()
    _run(k, 300, DT)
    before = k.joint_references()
    k.set_command(KinematicsCommand(frequency_hz=12.0, amplitude_left=0.6, offset_right=-0.3, feather_mean_left=0.5,
                                    abdomen_mean=0.4, abdomen_amplitude=0.2))
    after = k.joint_references()
    np.testing.assert_array_equal(before[:, :2], after[:, :2])  # angles and rates: unchanged by the command
    assert not np.allclose(before[:, 2], after[:, 2])  # only the accelerations change at once
    # and from then on every angle and rate changes by O(dt) per step, as it does in steady flight
    track = _run(k, 1200, DT)
    steps = np.abs(np.diff(track, axis=0))
    assert steps[:, :, 0].max() <= 1.01 * DT * np.abs(track[:, :, 1]).max()  # no step beyond what the rates allow
    assert steps[:, :, 1].max() <= 1.01 * DT * np.abs(track[:, :, 2]).max()
    # the flown parameters reach the command (critically damped, one wing beat's time constant)
    np.testing.assert_allclose(k.p, k.command.as_array(), atol=1e-6)


def test_rates_and_accelerations_are_the_derivatives_of_the_angles():
    k = Kinematics()
    k.set_command(KinematicsCommand(frequency_hz=8.0, amplitude_right=0.9, feather_amplitude_left=0.5,
                                    feather_phase=0.3, abdomen_amplitude=0.4, abdomen_phase=-1.0))
    h = 1e-5
    track = _run(k, 3000, h)  # a transient: the parameters are moving
    q, dq, ddq = track[:, :, 0], track[:, :, 1], track[:, :, 2]
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * h), dq[1:-1], rtol=1e-5, atol=1e-4)
    np.testing.assert_allclose((dq[2:] - dq[:-2]) / (2 * h), ddq[1:-1], rtol=1e-4, atol=1e-1)


def test_bad_commands_are_one_sentence():
    with pytest.raises(UserError, match="frequency_hz"):
        KinematicsCommand(frequency_hz=0.0)
    with pytest.raises(UserError, match="amplitude_left"):
        KinematicsCommand(amplitude_left=float("nan"))
    with pytest.raises(UserError, match="KinematicsCommand"):
        Kinematics().set_command({"frequency_hz": 10.0})


def test_the_phase_is_the_exact_integral_of_the_frequency_whatever_the_steps():
    """One long step and many short ones give the same state (the filter and the phase are solved exactly),
    and the phase is the integral of 2 pi f along the way (checked by a fine trapezoid)."""
    cmd = KinematicsCommand(frequency_hz=14.0, amplitude_left=0.7)
    one, many = Kinematics(), Kinematics()
    one.set_command(cmd)
    many.set_command(cmd)
    one.advance(0.05)
    fs = [many.p[0]]
    for _ in range(5000):
        many.advance(0.05 / 5000)
        fs.append(many.p[0])
    np.testing.assert_allclose(one.p, many.p, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(one.dp, many.dp, rtol=1e-9, atol=1e-9)
    assert one.psi == pytest.approx(many.psi, rel=1e-12)
    assert one.psi == pytest.approx(2 * math.pi * np.trapezoid(fs, dx=0.05 / 5000), rel=1e-8)
    assert one.psi > 2 * math.pi * 10.0 * 0.05  # the frequency rose from 10 Hz towards 14 Hz
