"""The butterfly of Oe, Suzuki, Yamamoto and Furukawa (2010): hinged wings flown by a normal-pressure
fluid force, the pitch set once per step by a rule or an evolved network.

Fly one::

    from lifelike_mj import butterfly

    flight = butterfly.Flight("simple_rule", backend="mujoco")   # or backend="paper" (eq. 7-11)
    trajectory = flight.record(duration_s=20.0)                    # Trajectory: t, y, z, vy, vz, phi, theta
    print(trajectory.summary()["settled_forward_speed_cm_s"])

Your own pitch law, a function of a :class:`PitchObservation` (SI units) returning the pitch in rad,
in Python or compiled with numba (then it runs inside the compiled loop)::

    def law(obs):
        return 0.2229 if obs.omega_rad_s > 1e-9 else 0.0   # the simple rule at 12.77 deg
    butterfly.Flight("simple_rule", pitch_law=law).record(duration_s=20.0)

What is here:

* the stepper :class:`Flight` and its vocabulary: :class:`ButterflyParams`, :class:`FlapPattern`,
  :class:`Condition`, :class:`Trajectory`, :class:`PitchObservation`;
* controllers: :func:`load_controller` (a shipped name or a file), :func:`ann_controller`,
  :class:`ButterflyController`, :func:`controller_names`;
* batched flights: :func:`simulate` (either backend), :func:`fly`, :func:`compare`;
* the paper's experiments E1-E11 (:mod:`~lifelike_mj.butterfly.experiments`,
  :mod:`~lifelike_mj.butterfly.ann_experiments`), their figures (:mod:`~lifelike_mj.butterfly.figures`,
  :mod:`~lifelike_mj.butterfly.ann_figures`, each returning a matplotlib ``Figure``) and
  :func:`reproduce` (the whole report);
* evolution of the network: :class:`PitchProblem`, :func:`make_problem`, :func:`evolve_controller`,
  :data:`PAPER_FLAP` (the flap pattern of section 6);
* on screen: :func:`render_butterfly`, :func:`film_flight`, :func:`playback` (a trajectory you have),
  :func:`render_frame`, :func:`view_butterfly`, :func:`snapshot_figure`.
"""

from lifelike_mj._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Flight": "sim", "STATE_UNITS": "sim",
    "ButterflyParams": "params", "FlapPattern": "params",
    "Condition": "flight", "Trajectory": "flight", "PitchObservation": "flight",
    "ButterflyController": "controllers", "ann_controller": "controllers",
    "load_controller": "_api", "controller_names": "_api",
    "simulate": "batch", "fly": "experiments", "compare": "compare",
    "PitchProblem": "evolution", "make_problem": "evolution", "evolve_controller": "evolution", "PAPER_FLAP": "evolution",
    "reproduce": "report",
    "render_butterfly": "render", "film_flight": "render", "playback": "render", "render_frame": "render",
    "view_butterfly": "render", "snapshot_figure": "render",
    "experiments": ".", "ann_experiments": ".", "figures": ".", "ann_figures": ".", "backends": ".", "aero": ".",
    "controllers": ".", "ann": ".", "render": ".", "report": ".", "sim": ".", "flight": ".", "params": ".",
    "model": ".", "evolution": ".",
    "batch": ".", "bench": ".", "look": ".", "flight3d": ".",
}, globals())
