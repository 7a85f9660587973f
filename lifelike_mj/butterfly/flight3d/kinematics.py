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
from numba import njit

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: The joints the kinematics drive, in the order of :meth:`Kinematics.joint_references`.
JOINTS = ("flap_left", "flap_right", "feather_left", "feather_right", "abdomen")


#: The highest flap frequency a command may ask for (Hz).
MAX_FREQUENCY_HZ = 100.0


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
        checks.number("frequency_hz", self.frequency_hz, 0.0, MAX_FREQUENCY_HZ, lo_open=True, unit="Hz")
        for f in fields(self)[1:]:
            checks.number(f.name, getattr(self, f.name), -math.pi, math.pi, unit="rad")

    @staticmethod
    def json_schema() -> dict:
        """The JSON Schema of a command (the ``base`` of a 3D controller file): the bounds ``__post_init__`` checks."""
        from lifelike_mj.schema import number

        props = {"frequency_hz": number("flap frequency, Hz", maximum=MAX_FREQUENCY_HZ, exclusive_minimum=0.0)}
        for f in fields(KinematicsCommand)[1:]:
            props[f.name] = number("rad", -math.pi, math.pi)
        return {"type": "object", "properties": props, "additionalProperties": False,
                "description": "the kinematics (module lifelike_mj.butterfly.flight3d.kinematics); missing ones take the "
                               "defaults: 10 Hz over [-60, 75] deg"}

    def as_array(self) -> np.ndarray:
        return np.array([getattr(self, f.name) for f in fields(self)])

    @staticmethod
    def names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(KinematicsCommand))


@njit(cache=True)
def filter_at(p0, dp0, target, psi0, omega_c, tau, p, dp, ddp):
    """The kinematics ``tau`` seconds after the state ``p0, dp0, psi0`` under a constant ``target``: writes the
    parameters ``p``, their rates ``dp`` and accelerations ``ddp``; returns the flap phase (rad).

    The critically damped filter ``x'' = -omega_c^2 x - 2 omega_c x'`` (``x = p - target``) solved exactly:
    ``x(tau) = (x0 + b tau) e^(-omega_c tau)`` with ``b = v0 + omega_c x0``; the phase is the exact integral
    of ``2 pi f`` (``f = p[0]``) over ``[0, tau]``. Shared by :class:`Kinematics` and the compiled callback,
    which evaluates it at each Runge-Kutta stage."""
    w = omega_c
    e = math.exp(-w * tau)
    for i in range(len(p0)):
        x0 = p0[i] - target[i]
        b = dp0[i] + w * x0
        x = (x0 + b * tau) * e
        p[i] = target[i] + x
        dp[i] = (b - w * (x0 + b * tau)) * e
        ddp[i] = -w * w * x - 2.0 * w * dp[i]
    x0 = p0[0] - target[0]
    b = dp0[0] + w * x0
    # integral of x over [0, tau]: x0 (1 - e)/w + b (1 - e (1 + w tau))/w^2
    integral = x0 * (1.0 - e) / w + b * (1.0 - e * (1.0 + w * tau)) / (w * w)
    return psi0 + 2.0 * math.pi * (target[0] * tau + integral)


@njit(cache=True)
def joint_refs(p, dp, ddp, psi, out):
    """``out[j]``: angle (rad), rate (rad/s) and acceleration (rad/s^2) of joint ``j`` of :data:`JOINTS`, from
    the parameters, their rates and accelerations and the flap phase (module docstring)."""
    dpsi = 2.0 * math.pi * p[0]
    ddpsi = 2.0 * math.pi * dp[0]
    for j in range(5):
        im, ia, ip = _TERMS[j, 0], _TERMS[j, 1], _TERMS[j, 2]
        ph, dph, ddph = (p[ip], dp[ip], ddp[ip]) if ip >= 0 else (0.0, 0.0, 0.0)
        u, du, ddu = psi + ph, dpsi + dph, ddpsi + ddph
        c, s = math.cos(u), math.sin(u)
        a, da, dda = p[ia], dp[ia], ddp[ia]
        out[j, 0] = p[im] + a * c
        out[j, 1] = dp[im] + da * c - a * du * s
        out[j, 2] = ddp[im] + dda * c - 2.0 * da * du * s - a * ddu * s - a * du * du * c


#: Per joint of :data:`JOINTS`: the parameter indices of its mean, amplitude and phase (-1: none).
_TERMS = np.array([(1, 3, -1), (2, 4, -1), (5, 7, 9), (6, 8, 9), (10, 11, 12)], dtype=np.int64)
#: Number of kinematics parameters (the fields of :class:`KinematicsCommand`).
N_PARAMS = 13


class Kinematics:
    """The kinematics flown: the parameters, their rates and the flap phase, advanced step by step
    towards the latest :class:`KinematicsCommand` (module docstring)."""

    def __init__(self, command: KinematicsCommand | None = None, omega_c: float | None = None) -> None:
        self.command = command or KinematicsCommand()
        self.omega_c = (2.0 * math.pi * self.command.frequency_hz if omega_c is None
                        else checks.positive("omega_c", omega_c, "rad/s"))
        self.target = self.command.as_array()  # the command's parameters, as the filter reads them
        self.p = self.target.copy()  # the parameters flown
        self.dp = np.zeros_like(self.p)  # and their rates (per s)
        self.psi = 0.0  # the flap phase (rad)

    def set_command(self, command: KinematicsCommand) -> None:
        """The parameters head for ``command`` from now on (smoothly: module docstring)."""
        if not isinstance(command, KinematicsCommand):
            raise UserError(f"a kinematics command is a KinematicsCommand, got {command!r}.")
        self.command = command
        self.target = command.as_array()

    def advance(self, dt: float) -> None:
        """Advance ``dt`` seconds: the filter and the phase exactly (:func:`filter_at`, the command held)."""
        p, dp, ddp = np.empty(N_PARAMS), np.empty(N_PARAMS), np.empty(N_PARAMS)
        self.psi = filter_at(self.p, self.dp, self.target, self.psi, self.omega_c, dt, p, dp, ddp)
        self.p, self.dp = p, dp

    def joint_references(self) -> np.ndarray:
        """``(5, 3)``: angle (rad), rate (rad/s) and acceleration (rad/s^2) of each of :data:`JOINTS` now."""
        ddp = -self.omega_c ** 2 * (self.p - self.target) - 2.0 * self.omega_c * self.dp  # the filter's acceleration
        out = np.empty((5, 3))
        joint_refs(self.p, self.dp, ddp, self.psi, out)
        return out
