"""The calibrated wing-force law: the quasi-steady blade elements scaled so that the monarch's wings carry what the
filmed monarch's carried.

Flown with the filmed monarch's own wing motion (:func:`~lifelike_mj.butterfly.flight3d.controllers.default_base`:
120 deg strokes at 10.2 Hz, feathering +-39 deg, the abdomen's swing) at its filmed body angle, the quasi-steady law
with the coefficients of a revolving fruit-fly wing (Dickinson, Lehmann & Sane 1999) climbs at about 0.9 m/s, where
the filmed monarch climbed at 0.38 m/s at the same 1.3 m/s forward, and costs about 51 W/kg. Those coefficients were
measured at a Reynolds number of about 200 on a rigid wing; a monarch's wing flies near 5,000 and bends. No lift
and drag coefficients measured on a butterfly's wing were found, so the ``"calibrated"`` law
(:data:`~lifelike_mj.butterfly.flight3d.model.CALIBRATED_QS`) keeps the fruit fly's shapes of ``C_L(alpha)`` and
``C_D(alpha)`` and fits two numbers to the filmed flight: a scale ``k_L`` of the lift (and of the rotational force,
which is a lift of the same circulation) and a scale ``k_D`` of the drag.

**The filmed flight** (:data:`FILMED`): one free flight of a monarch (*Danaus plexippus*) filmed at 200 Hz, as fitted
in the public code of the group behind Tejaswi et al. 2021 (Bioinspir Biomim 16:046003): horizontal speed 1.30 m/s,
climb 0.38 m/s, the thorax pitched 18.6 deg on average with a first harmonic of +-8.3 deg, the nose highest near
mid-upstroke, the thorax bobbing about 10 mm from top to bottom in each beat.

**The fit** (:func:`fit`): the body's attitude is held to the filmed pitch, its swing included (an outside torque:
the attitude is the film's, the motion along the path free), the wings and abdomen move as filmed, and after
:data:`SETTLE_S` the mean horizontal and vertical speeds over :data:`WINDOW_S` are matched to the film's two by
least squares in ``(k_L, k_D)``.

**The checks on other quantities** (:func:`filmed_flight`): the same flight's bobbing (the film's ~10 mm), the share
of the weight carried in the downstroke and the upstroke (Dudley 1991, J Exp Biol 159:335, 15 species: the
downstroke gives about 18 % more vertical force than the weight, the upstroke little or a negative amount), and the
drive's power against Dudley's 12.5-20.2 W/kg for level flight (this flight climbs).
"""

from __future__ import annotations

import math

import numpy as np

#: The filmed monarch's free flight (module docstring): forward and vertical speeds (m/s), the thorax's mean pitch and
#: its first harmonic (deg) and the bobbing (mm, top to bottom).
FILMED = {"speed_m_s": 1.30, "climb_m_s": 0.38, "pitch_deg": 18.6, "pitch_amplitude_deg": 8.3, "bobbing_mm": 10.0}
#: Seconds flown before the measurement, and measured (the speeds have settled within 6 mm/s by 2 s).
SETTLE_S, WINDOW_S = 2.0, 2.0
#: The acceptance of issue 42: the filmed stroke at the filmed body angle within this fraction of each filmed speed.
TOLERANCE = 0.15


def filmed_pitch_rad(psi: float) -> float:
    """The filmed thorax pitch (rad, nose up) at flap phase ``psi`` (``psi = 0`` at the top of the stroke): the mean
    18.6 deg and the first harmonic 8.3 deg, highest at mid-upstroke (``psi = 3 pi / 2``)."""
    return math.radians(FILMED["pitch_deg"] - FILMED["pitch_amplitude_deg"] * math.sin(psi))


def filmed_flight(scales=None, force_law: str = "calibrated", settle_s: float = SETTLE_S,
                  window_s: float = WINDOW_S) -> dict:
    """The filmed wing motion at the filmed body angle (module docstring), flown with ``force_law`` (or with the
    quasi-steady law scaled by ``scales = (k_L, k_D)``): the mean speeds (m/s), the bobbing (mm), the drive's power
    (W/kg, without and with perfect elastic storage), the advance ratio, the dorsal gap (deg), and the vertical impulse
    of the air in the downstroke and in the upstroke, each as a fraction of the weight's impulse over the whole beats
    (Dudley 1991: about 1.18 and a little or below 0)."""
    from lifelike_mj.butterfly.flight3d import measures as M
    from lifelike_mj.butterfly.flight3d import model as mj3d
    from lifelike_mj.butterfly.flight3d.controllers import default_base
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.butterfly.flight3d.parts import Butterfly

    law = "quasi_steady" if scales is not None else force_law
    fl = Flight3D(default_base("monarch"), butterfly=Butterfly("monarch", force_law=law), assist="hold",
                  pitch_law=lambda f: filmed_pitch_rad(float(f.data.userdata[mj3d.U_PSI0])))
    if scales is not None:
        k_l, k_d = (float(x) for x in scales)
        fl.data.userdata[mj3d.U_QS : mj3d.U_QS + 3] = (k_l, k_d, k_l)
    fl.step(int(round(settle_s / fl.dt)))
    s = M.sample(fl, window_s)
    numbers = M.body_numbers(fl)
    m = M.measures(s, **numbers)
    weight = numbers["mass_kg"] * numbers["gravity"]
    up_force = s["air_force_N"][:, 2]
    down = s["rates_rad_s"][:, :2].mean(axis=1) < 0.0  # the wings falling
    pos, span = s["position_m"], s["t_s"][-1] - s["t_s"][0]
    return {"force_law": law, "scales": None if scales is None else [k_l, k_d],
            "speed_m_s": float((pos[-1, 0] - pos[0, 0]) / span), "climb_m_s": float((pos[-1, 2] - pos[0, 2]) / span),
            "bobbing_mm": m["bobbing_mm"], "power_W_kg": m["power_W_kg"], "power_net_W_kg": m["power_net_W_kg"],
            "advance_ratio": float(m["advance_ratio"]), "dorsal_gap_deg": m["dorsal_gap_deg"],
            "downstroke_weight_share": float(up_force[down].sum() / (weight * len(up_force))),
            "upstroke_weight_share": float(up_force[~down].sum() / (weight * len(up_force)))}


def fit(start=(0.5, 0.45), settle_s: float = SETTLE_S, window_s: float = WINDOW_S) -> dict:
    """``(k_L, k_D)`` that fly the filmed wing motion at the filmed body angle at the filmed speeds (module
    docstring), by least squares on the two relative errors, from ``start``; with the flight they give."""
    from scipy.optimize import least_squares

    def residual(k):
        r = filmed_flight(k, settle_s=settle_s, window_s=window_s)
        return [r["speed_m_s"] / FILMED["speed_m_s"] - 1.0, r["climb_m_s"] / FILMED["climb_m_s"] - 1.0]

    sol = least_squares(residual, np.asarray(start, float), bounds=([0.05, 0.05], [2.0, 2.0]), diff_step=0.02,
                        xtol=1e-4, ftol=1e-4)
    k = [round(float(x), 3) for x in sol.x]
    return {"scales": k, "evaluations": int(sol.nfev), "flight": filmed_flight(k, settle_s=settle_s, window_s=window_s)}
