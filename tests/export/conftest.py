"""One short run of each creature, recorded once per test session for the exporters' tests."""

import pytest

from lifelike_mj.export.poses import record_poses

#: The creatures every exporter is checked on.
CREATURES = ("butterfly3d", "butterfly2d", "fish", "boids")


def _run(creature: str):
    if creature == "butterfly3d":
        from lifelike_mj.butterfly import evolve3d
        from lifelike_mj.butterfly.sim3d import Flight3D

        sim = Flight3D(controller="steer", task=evolve3d.course(100))
        return sim, record_poses(sim, 1.0, fps=30.0)
    if creature == "butterfly2d":
        from lifelike_mj.butterfly import Flight

        sim = Flight(controller="simple_rule", backend="mujoco", config="rich")
        return sim, record_poses(sim, 1.0, fps=30.0)
    if creature == "fish":
        from lifelike_mj.fish import Tank

        sim = Tank(n_fish=10, seed=1)
        return sim, record_poses(sim, 1.0, fps=30.0)
    from lifelike_mj.boids import Flock

    sim = Flock(n=300, seed=1)  # a flock's steps have no seconds: a frame every 5 steps, 30 frames a second
    return sim, record_poses(sim, 150.0, fps=0.2, time_scale=1.0 / 150.0)


@pytest.fixture(scope="session")
def runs():
    """``runs(creature)``: ``(simulation at its last frame, poses)``, recorded on first use."""
    cache: dict = {}

    def get(creature: str):
        if creature not in cache:
            cache[creature] = _run(creature)
        return cache[creature]

    return get


@pytest.fixture(params=CREATURES)
def creature(request) -> str:
    """Each creature in turn."""
    return request.param
