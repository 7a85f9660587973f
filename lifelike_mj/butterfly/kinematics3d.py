"""The 3D butterfly's controls: wing and abdomen kinematics that change smoothly.

A 3D butterfly is steered only by how it moves its wings and abdomen (no force or torque acts on its
body but the air's, gravity and its joints' reactions). The kinematics are sinusoids of one shared
flap phase ``psi`` (rad), with ``dpsi/dt = 2 pi f``:

* flap of wing ``i`` (left 0, right 1): ``offset_i + amplitude_i cos(psi)`` (rad; wing up positive);
* feathering of wing ``i``: ``feather_mean_i + feather_amplitude_i cos(psi + feather_phase)`` (rad;
  leading edge down positive);
* abdomen: ``abdomen_mean + abdomen_amplitude cos(psi + abdomen_phase)`` (rad; tip up positive).

A controller sets a new command at any step; the parameters actually flown follow it through a
critically damped second-order filter with natural frequency ``omega_c`` (rad/s; by default one
wing beat's 2 pi f), solved exactly over each step. The parameters and their rates are therefore
continuous, so every joint angle and its rate are continuous too (no jump when a command jumps);
only the angular accelerations change at once. :meth:`Kinematics.joint_references` gives each
joint's angle, rate and acceleration, which the joint drive makes the wings follow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: The joints the kinematics drive, in the order of :meth:`Kinematics.joint_references`.
JOINTS = ("flap_left", "flap_right", "feather_left", "feather_right", "abdomen")


@dataclass(frozen=True)
class KinematicsCommand:
    """One command: every parameter of the kinematics (Hz, rad). Defaults: the paper's section 6 flap
    (10 Hz over [-60, 75] deg: offset 7.5 deg, amplitude 67.5 deg), wings not feathered, abdomen still."""

    frequency_hz: float = 10.0
    offset_left: float = math.radians(7.5)
    offset_right: float = math.radians(7.5)
    amplitude_left: float = math.radians(67.5)
    amplitude_right: float = math.radians(67.5)
    feather_mean_left: float = 0.0
    feather_mean_right: float = 0.0
    feather_amplitude_left: float = 0.0
    feather_amplitude_right: float = 0.0
    feather_phase: float = 0.0
    abdomen_mean: float = 0.0
    abdomen_amplitude: float = 0.0
    abdomen_phase: float = 0.0

    def __post_init__(self) -> None:
        checks.number("frequency_hz", self.frequency_hz, 0.0, 100.0, lo_open=True, unit="Hz")
        for f in fields(self)[1:]:
            checks.number(f.name, getattr(self, f.name), -math.pi, math.pi, unit="rad")

    def as_array(self) -> np.ndarray:
        return np.array([getattr(self, f.name) for f in fields(self)])

    @staticmethod
    def names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(KinematicsCommand))


class Kinematics:
    """The kinematics flown: the parameters, their rates and the flap phase, advanced step by step
    towards the latest :class:`KinematicsCommand` (module docstring)."""

    def __init__(self, command: KinematicsCommand | None = None, omega_c: float | None = None) -> None:
        self.command = command or KinematicsCommand()
        self.omega_c = (2.0 * math.pi * self.command.frequency_hz if omega_c is None
                        else checks.positive("omega_c", omega_c, "rad/s"))
        self._target = self.command.as_array()  # the command's parameters, as the filter reads them
        self.p = self._target.copy()  # the parameters flown
        self.dp = np.zeros_like(self.p)  # and their rates (per s)
        self.psi = 0.0  # the flap phase (rad)

    def set_command(self, command: KinematicsCommand) -> None:
        """The parameters head for ``command`` from now on (smoothly: module docstring)."""
        if not isinstance(command, KinematicsCommand):
            raise UserError(f"a kinematics command is a KinematicsCommand, got {command!r}.")
        self.command = command
        self._target = command.as_array()

    def advance(self, dt: float) -> None:
        """Advance ``dt`` seconds: the filter exactly (critically damped, constant command over the step),
        the phase by the trapezoid of the frequency (exact for a frequency linear over the step)."""
        w = self.omega_c
        e = math.exp(-w * dt)
        x0 = self.p - self._target
        v0 = self.dp
        # x(t) = (x0 + (v0 + w x0) t) e^{-wt}: the critically damped solution
        b = v0 + w * x0
        f0 = self.p[0]
        self.p = self._target + (x0 + b * dt) * e
        self.dp = (b - w * (x0 + b * dt)) * e
        self.psi += math.pi * (f0 + self.p[0]) * dt

    def joint_references(self) -> np.ndarray:
        """``(5, 3)``: angle (rad), rate (rad/s) and acceleration (rad/s^2) of each of :data:`JOINTS` now."""
        p, dp = self.p, self.dp
        x = p - self._target
        ddp = -self.omega_c ** 2 * x - 2.0 * self.omega_c * dp  # the filter's acceleration
        psi, dpsi, ddpsi = self.psi, 2.0 * math.pi * p[0], 2.0 * math.pi * dp[0]
        out = np.empty((5, 3))
        # (mean index, amplitude index, phase index or -1) per joint
        terms = ((1, 3, -1), (2, 4, -1), (5, 7, 9), (6, 8, 9), (10, 11, 12))
        for j, (im, ia, ip) in enumerate(terms):
            ph, dph, ddph = (p[ip], dp[ip], ddp[ip]) if ip >= 0 else (0.0, 0.0, 0.0)
            u, du, ddu = psi + ph, dpsi + dph, ddpsi + ddph
            c, s = math.cos(u), math.sin(u)
            a, da, dda = p[ia], dp[ia], ddp[ia]
            out[j, 0] = p[im] + a * c
            out[j, 1] = dp[im] + da * c - a * du * s
            out[j, 2] = ddp[im] + dda * c - 2.0 * da * du * s - a * ddu * s - a * du * du * c
        return out
