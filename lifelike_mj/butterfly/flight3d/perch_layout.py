"""The layout of a designed controller's landing, shared by its design (:mod:`~lifelike_mj.butterfly.flight3d.
perching`) and the compiled loop that flies it (:mod:`~lifelike_mj.butterfly.flight3d.designed_kernel`): the
approach's and the start's constants, the tracked state's and controls' sizes, the tracking's scales, and the check of
a controller file's ``landing`` (issue 42, point 3). Units: m, s, rad, Hz."""

from __future__ import annotations

import numpy as np

from lifelike_mj.butterfly.flight3d.kinematics import N_PARAMS

#: The approach's speed over the ground (m/s): the designed controller's level trim the manoeuvres start from.
APPROACH_M_S = 1.5
#: How far above the butterfly's standing point on the blossom the approach flies (m); every manoeuvre ends that much
#: lower than it starts.
RISE_M = 0.28
#: Manoeuvres per wing beat: one for each eighth of the beat at which it may start.
N_BINS = 8
#: Physics steps per control step of the manoeuvre (the designed controller's rate, 10 ms at 800 Hz).
EVERY = 8
#: The tracked state's and controls' sizes (module docstring).
N_STATE, N_CONTROL = 12 + 10 + 1 + 2 * N_PARAMS, 6
#: The controls the tracking moves (indices into :data:`~lifelike_mj.butterfly.flight3d.controls.CONTROLS`).
TRACKED_CONTROLS = (0, 1, 2, 3, 4, 6)

#: The longest a manoeuvre may fly after its held commands before it counts as missed (s).
MAX_GLIDE_S = 0.8

#: Bryson's scales of the tracking: controls (Hz, rad; the largest change it may make is three of these), the running
#: state (position, velocity, attitude; the rest unweighted) and the touchdown's (along, aside, height; velocity,
#: attitude, rates).
CONTROL_SCALE = np.array([1.0, 0.1, 0.1, 0.1, 0.1, 0.1])
RUN_SCALE = (0.05, 0.3, 0.2)
END_SCALE = ((0.005, 0.01, 0.003), 0.1, 0.05, 1.0)

#: A manoeuvre starts when the thorax's distance from the flower's axis is within half this of its start distance (m),
#: flying toward the axis within ``START_SIDE_M`` (m) aside and within ``START_HEIGHT_M`` (m) of the approach's height.
START_WINDOW_M, START_SIDE_M, START_HEIGHT_M = 0.05, 0.06, 0.3
#: ... and when the beat's phase is within this of the manoeuvre's own (rad); further, the approach flies on to the next
#: chance (a beat later for that manoeuvre, sooner for another). Without it (the nearest of eight phases, up to pi/8
#: off) one manoeuvre in eight, the phase-0 one, came down too fast on 4 of 39 landings of tuning gardens 100-139.
START_PHASE_GAP_RAD = 0.2
#: A manoeuvre that sinks this far below the standing point without touching down is given up (m).
BELOW_M = 0.1
#: The most the tracking may change a control, in its Bryson scales (:data:`CONTROL_SCALE`).
CONTROL_LIMIT = 3.0
#: The approach's final (``designed_kernel.approach``): it aims this far ahead along its line (m); begun nearer the
#: flower than ``FINAL_MIN_M`` it first flies out to ``FINAL_OUT_M`` (m) and turns back.
FINAL_LOOKAHEAD_M, FINAL_MIN_M, FINAL_OUT_M = 0.9, 1.8, 2.4
#: After a take-off the approach flies straight ahead this long (s) before it turns for its final.
TAKE_OFF_STRAIGHT_S = 0.5


def check_landing(landing: dict, where: str) -> None:
    """A controller file's ``landing`` checked for what the compiled loop reads (one sentence, else nothing): each
    manoeuvre's, and the take-off's, states, commands and gains of matching lengths and sizes, all finite."""
    from lifelike_mj.errors import UserError

    named = [(f"manoeuvre {i}", m) for i, m in enumerate(landing["manoeuvres"])]
    if "take_off" in landing:
        named.append(("take-off", landing["take_off"]))
    for name, m in named:
        try:
            s = np.array(m["states"], dtype=float)
            u = np.array(m["commands"], dtype=float)
            k = np.array(m["gains"], dtype=float)
        except (TypeError, ValueError):
            raise UserError(f"{where}: the landing's {name} holds something other than arrays of numbers.") from None
        t = len(u)
        if (t < 1 or s.shape != (t + 1, N_STATE + 1) or u.shape != (t, N_PARAMS)
                or k.shape != (t, N_CONTROL, N_STATE)):
            raise UserError(f"{where}: the landing's {name} has states, commands and gains of shapes "
                            f"{s.shape}, {u.shape}, {k.shape}; (T + 1, {N_STATE + 1}), (T, {N_PARAMS}) and "
                            f"(T, {N_CONTROL}, {N_STATE}) are asked.")
        if not (np.isfinite(s).all() and np.isfinite(u).all() and np.isfinite(k).all()):
            raise UserError(f"{where}: the landing's {name} holds a number that is not finite.")
