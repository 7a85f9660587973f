"""Tropical fish after Satoi, Nakadai and Hoshino (2015): free rigid bodies in a tank, moved by four
stochastic motion units (accelerate, coast, cruise, brake) chosen by a Markov chain, with quadratic
drag, ray-cast vision, wall avoidance and pitch balance.

Swim a tank and read its measures::

    from lifelike_mj import fish

    tank = fish.Tank(fish.load_preset("B-D"), n_fish=10, seed=0)
    result = tank.record(duration_s=30.0)        # SwimResult: times, positions, quaternions, MU log
    print(fish.swim_summary(result)["burstiness"])

What is here: the stepper :class:`Tank` (and :func:`swim`), presets (:class:`FishParams`,
:func:`load_preset`, :func:`preset_names`), the measures read from tracks alone
(:func:`swim_summary`, :func:`track_measures` and :mod:`~lifelike_mj.fish.metrics`; the measures of fish living
together, :func:`group_measures` and :mod:`~lifelike_mj.fish.shoal`), the four-pattern
table (:func:`pattern_table`), :func:`drag_check`, figures (:mod:`~lifelike_mj.fish.figures`, each
returning a ``Figure``), on screen (:func:`render_fish`, :func:`film_tank`, :func:`playback`,
:func:`render_frame`, :func:`view_fish`) and :func:`reproduce` (the report).
"""

from lifelike_mj._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Tank": "sim", "swim": "sim", "SwimResult": "sim", "STATE_UNITS": "sim", "MU_NAMES": "params",
    "FishParams": "params", "load_preset": "params", "preset_names": "params",
    "swim_summary": "experiments", "pattern_table": "experiments", "drag_check": "experiments",
    "write_swim": "experiments", "track_measures": "metrics", "group_measures": "shoal",
    "render_fish": "render", "film_tank": "render", "playback": "render", "render_frame": "render",
    "view_fish": "render", "reproduce": "report",
    "metrics": ".", "figures": ".", "render": ".", "params": ".", "sim": ".", "scene": ".", "experiments": ".",
    "report": ".",
    "aquarium": ".", "bench": ".", "look": ".", "shoal": ".",
}, globals())
