"""One interface over the two butterfly backends ("paper" and "mujoco").

``simulate(backend, controllers, params, conditions, duration_s, dt_s, record_every)`` returns a
list of :class:`~lifelike_mj.butterfly.trajectory.Trajectory`, sampled every ``record_every``
steps from ``t = 0``, whatever the backend.
"""

from __future__ import annotations

from lifelike_mj.errors import UserError

BACKENDS = ("paper", "mujoco")


def check_backend(name: str) -> str:
    if name not in BACKENDS:
        raise UserError(f"unknown backend {name!r}; choose one of: {', '.join(BACKENDS)}.")
    return name


def simulate(backend: str, controllers, params=None, conditions=None, duration_s: float = 20.0,
             dt_s: float = 1.0 / 1200.0, record_every: int = 1, **options):
    """Fly on the named backend. ``options`` go to the MuJoCo backend (``config``, ``force_mode``)."""
    check_backend(backend)
    if backend == "paper":
        from lifelike_mj.butterfly import paper

        return paper.simulate(controllers, params, conditions, duration_s, dt_s, record_every)
    from lifelike_mj.butterfly import mjbackend

    return mjbackend.simulate(controllers, params, conditions, duration_s, dt_s, record_every, **options)
