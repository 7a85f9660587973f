"""lifelike-mj: creatures that move like living things, by physics on MuJoCo.

Three creatures, each a package with the same vocabulary (parameters, a stepper, experiments,
measures, figures, rendering, a report)::

    from lifelike_mj import butterfly, fish, boids

    flight = butterfly.Flight("simple_rule")            # Oe 2010: a butterfly, paper or MuJoCo backend
    tank = fish.Tank(fish.load_preset("B-D"), n_fish=10)  # Satoi 2015: tropical fish in a tank
    flock = boids.Flock(boids.load_preset("4c"), n=300)   # Nakamura 2013: two-type boids
    for sim in (flight, tank, flock):
        sim.step(100)                                      # the same stepper shape (lifelike_mj.stepper)

:mod:`lifelike_mj.evolve` optimises any function of a vector (the papers' GA, CMA-ES, nlopt) on one
machine or a Ray cluster; :mod:`lifelike_mj.render` films and views any stepper. Every name is
imported on first use: ``import lifelike_mj`` does not load MuJoCo.
"""

from lifelike_mj._lazy import attach
from lifelike_mj._numba_cache import configure as _configure_numba_cache

__version__ = "0.2.0"
_configure_numba_cache()  # before anything imports numba: a cache that cannot serve stale code

__getattr__, __dir__, __all__ = attach(__name__, {
    "butterfly": ".", "fish": ".", "boids": ".", "evolve": ".", "render": ".", "physics": ".", "stepper": ".",
    "envs": ".", "export": ".", "checks": ".", "errors": ".", "io": ".", "machine": ".", "paths": ".",
    "progress": ".", "provenance": ".", "schema": ".",
    "Stepper": "stepper", "Playback": "stepper", "UserError": "errors", "Diverged": "errors",
}, globals())
__all__ = [*__all__, "__version__"]
