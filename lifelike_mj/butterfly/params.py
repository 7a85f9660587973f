"""Physical constants of the butterfly model and its flap pattern (Oe 2010 sections 3-4)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

from lifelike_mj.errors import UserError
from lifelike_mj.physics.fluid import CD_PAPER, RHO_AIR

#: Gravity, m/s^2 (the printed Oe 2010 eq. 11 omits -m g; the text needs it: docs/models/butterfly.md).
GRAVITY: float = 9.8


#: Each constant's largest value (SI): far beyond a butterfly, and finite in the compiled code.
PARAM_MAX = {"mass_kg": 1.0, "span_m": 1.0, "width_m": 1.0, "rho": 2000.0, "cd": 10.0, "body_area_m2": 1.0,
             "gravity": 100.0}


@dataclass(frozen=True)
class ButterflyParams:
    """Constants of the swallowtail model (Oe 2010 sections 3, 4.3), SI units.

    ``body_area_m2`` (``A_b`` of eq. 10) is not given by the paper: 1.0 cm^2 reproduces the
    straight flight of section 5.1, 1.53 cm^2 the speed limit of section 4.3 (docs/models/butterfly.md).
    """

    mass_kg: float = 0.319e-3  #: m, kg (Oe 2010 section 4.2)
    span_m: float = 0.055  #: L, wing length from the flap axis, m (section 4.3)
    width_m: float = 0.050  #: W, wing width, m (section 4.3)
    rho: float = RHO_AIR  #: air density, kg/m^3 (section 3)
    cd: float = CD_PAPER  #: drag coefficient (section 3)
    body_area_m2: float = 1.0e-4  #: A_b, body's projected area, m^2 (not in the paper)
    gravity: float = GRAVITY  #: g, m/s^2

    def __post_init__(self) -> None:
        from lifelike_mj import checks

        for name, value in asdict(self).items():
            checks.number(f"butterfly parameter {name}", value, 0.0, PARAM_MAX[name], lo_open=True)

    @property
    def alpha(self) -> float:
        """``alpha = rho C_d L W`` of Oe 2010 eq. 5, kg/m."""
        return self.rho * self.cd * self.span_m * self.width_m

    @property
    def k_wings(self) -> float:
        """``K = rho C_d L W / 4``: both planform-2 wings, ``F = K v|v|`` (eq. 8-9), kg/m."""
        return self.alpha / 4.0

    def with_overrides(self, **cgs: float | None) -> ButterflyParams:
        """Copy with overrides given in the command line's units (``*_cm2``, ``*_cm``, ``*_g``)."""
        conv = {
            "body_area_cm2": ("body_area_m2", 1e-4),
            "mass_g": ("mass_kg", 1e-3),
            "span_cm": ("span_m", 1e-2),
            "width_cm": ("width_m", 1e-2),
            "rho": ("rho", 1.0),
            "cd": ("cd", 1.0),
        }
        from lifelike_mj import checks
        from lifelike_mj.errors import check_names

        check_names(cgs, conv, "unknown butterfly parameter")
        changes = {conv[k][0]: checks.number(k, v) * conv[k][1] for k, v in cgs.items() if v is not None}
        return replace(self, **changes)


#: The highest flap frequency (Hz) of a flap pattern: far above any insect's, and a period the time step can
#: still be compared with.
MAX_FLAP_HZ = 1000.0


@dataclass(frozen=True)
class FlapPattern:
    """Cosine flap ``theta(t) = theta_c + theta_a cos(2 pi f t)`` (Oe 2010 sections 4.3, 5.1, 6.3).

    Angles in degrees at this edge (``theta_min_deg``, ``theta_max_deg``), frequency in Hz.
    At ``t = 0`` the wings are at the top of the stroke; ``omega = d theta/dt`` is positive on the
    upstroke.
    """

    frequency_hz: float = 10.0
    theta_min_deg: float = -90.0
    theta_max_deg: float = 90.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frequency_hz) and 0 < self.frequency_hz <= MAX_FLAP_HZ):
            raise UserError(f"flap frequency must be in (0, {MAX_FLAP_HZ:g}] Hz, got {self.frequency_hz} Hz.")
        lo, hi = self.theta_min_deg, self.theta_max_deg
        if not (math.isfinite(lo) and math.isfinite(hi) and -180.0 <= lo <= hi <= 180.0):
            raise UserError(f"flap range must satisfy -180 <= min <= max <= 180 degrees, got [{lo}, {hi}].")

    @property
    def theta_c(self) -> float:
        """Centre angle, rad."""
        return math.radians(0.5 * (self.theta_max_deg + self.theta_min_deg))

    @property
    def theta_a(self) -> float:
        """Amplitude, rad."""
        return math.radians(0.5 * (self.theta_max_deg - self.theta_min_deg))

    def theta(self, t):
        """Flap angle (rad) at time ``t`` (s); works on arrays."""
        import numpy as np

        return self.theta_c + self.theta_a * np.cos(2.0 * math.pi * self.frequency_hz * np.asarray(t))

    def omega(self, t):
        """Flap rate ``d theta/dt`` (rad/s) at time ``t`` (s), positive on the upstroke."""
        import numpy as np

        w = 2.0 * math.pi * self.frequency_hz
        return -self.theta_a * w * np.sin(w * np.asarray(t))

    def as_array(self):
        """``[theta_c, theta_a, 2 pi f]`` (rad, rad, rad/s) for compiled code."""
        import numpy as np

        return np.array([self.theta_c, self.theta_a, 2.0 * math.pi * self.frequency_hz])

    def mean_rate(self) -> float:
        """Mean flap rate over a half stroke, rad/s (section 4.3: pi rad per half period -> 62.8)."""
        return 2.0 * self.theta_a * 2.0 * self.frequency_hz
