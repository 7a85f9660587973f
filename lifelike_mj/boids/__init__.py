"""Heterogeneous boids after Nakamura (2013): agents of two (or more) types whose alignment and
cohesion weights depend on the pair of types, forming the paper's eight patterns.

Run a pattern and classify it::

    from lifelike_mj import boids

    flock = boids.Flock(boids.load_preset("4c"), n=300, seed=0)
    flock.step(3000)
    run, measures, label, reasons = boids.classified_run(boids.load_preset("4c"), n=300, seed=0)

What is here: the stepper :class:`Flock` (change weights or add agents between steps) and
:func:`simulate`, :class:`BoidParams`, presets (:func:`load_preset`, :func:`homogeneous`), the
measures and the classifier (:func:`measures`, :func:`classify`, :func:`classified_run`), sweeps
(:class:`Sweep`, :func:`run_sweep`), figures (:mod:`~lifelike_mj.boids.figures`, each returning a
``Figure``), on screen (:func:`render_boids`, :func:`film_flock`, :func:`playback`,
:func:`render_frame`, :func:`view_boids`) and :func:`reproduce` (the report).
"""

from lifelike_mj._lazy import attach

__getattr__, __dir__, __all__ = attach(__name__, {
    "Flock": "sim", "STATE_UNITS": "sim", "simulate": "sim", "BoidParams": "engine", "BoidRun": "engine",
    "load_preset": "presets", "homogeneous": "presets", "PATTERNS": "presets",
    "measures": "metrics", "classify": "metrics", "classified_run": "experiments", "Sweep": "experiments",
    "run_sweep": "experiments", "write_trajectories": "experiments", "measured_run": "experiments",
    "write_run": "experiments",
    "render_boids": "render", "film_flock": "render", "playback": "render", "render_frame": "render",
    "view_boids": "render", "reproduce": "report",
    "engine": ".", "metrics": ".", "figures": ".", "render": ".", "presets": ".", "sim": ".", "scene": ".",
    "experiments": ".", "report": ".",
    "bench": ".", "look": ".", "palette": ".",
}, globals())
