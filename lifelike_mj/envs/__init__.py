"""Gymnasium environments over the creatures' steppers (``pip install "lifelike-mj[gym]"``).

Importing this module registers them under the ``lifelike_mj`` namespace: ``import lifelike_mj.envs``
then ``gymnasium.make("lifelike_mj/ButterflyPitch-v0")``, or in one go (Gymnasium imports the module
named before the colon) ``gymnasium.make("lifelike_mj.envs:lifelike_mj/ButterflyPitch-v0")``:

* ``lifelike_mj/ButterflyPitch-v0``: :class:`~lifelike_mj.envs.butterfly.ButterflyPitchEnv`, the
  pitch task of Oe 2010 section 6.
* ``lifelike_mj/ButterflyPitchWind-v0``: :class:`~lifelike_mj.envs.butterfly.ButterflyPitchWindEnv`,
  the same with the start altitude and the wind drawn per episode (``butterfly evolve``'s
  ``robust_map`` task).
* ``lifelike_mj/ButterflyFlight3D-v0``: :class:`~lifelike_mj.envs.butterfly3d.ButterflyFlight3DEnv`, the
  free-flying 3D butterfly steered by its wing and abdomen kinematics through level flight, turns, courses and
  courses in wind; its vector form :class:`~lifelike_mj.envs.butterfly3d.ButterflyFlight3DVectorEnv` flies N
  on one compiled MuJoCo batch.
* :class:`~lifelike_mj.envs.vector.ButterflyPitchVectorEnv`: N of either planar one, on either backend, stepped in
  one native call
  (``gymnasium.make_vec("lifelike_mj/ButterflyPitch-v0", num_envs=N, vectorization_mode="vector_entry_point")``).
* :mod:`lifelike_mj.envs.policies`: controller files as policies of these environments, and networks
  trained through them (by an RL library) as controller files.

Each environment's docstring is its documentation page (spaces with names and units, reward,
starting state, episode end, arguments, version history); :mod:`lifelike_mj.envs.pages` renders those pages,
``docs/envs/*.md``, from the docstrings and the tables of names and units the environments use
(``python -m lifelike_mj.envs.pages``).
"""

from __future__ import annotations

from lifelike_mj._lazy import attach

#: The registered ids and their entry points.
ENVS = {
    "lifelike_mj/ButterflyPitch-v0": "lifelike_mj.envs.butterfly:ButterflyPitchEnv",
    "lifelike_mj/ButterflyPitchWind-v0": "lifelike_mj.envs.butterfly:ButterflyPitchWindEnv",
    "lifelike_mj/ButterflyFlight3D-v0": "lifelike_mj.envs.butterfly3d:ButterflyFlight3DEnv",
}


_VECTOR = {
    "lifelike_mj/ButterflyPitch-v0": "lifelike_mj.envs.vector:ButterflyPitchVectorEnv",
    "lifelike_mj/ButterflyPitchWind-v0": "lifelike_mj.envs.vector:ButterflyPitchWindVectorEnv",
    "lifelike_mj/ButterflyFlight3D-v0": "lifelike_mj.envs.butterfly3d:ButterflyFlight3DVectorEnv",
}


def register_envs() -> None:
    """Register every environment with Gymnasium (idempotent; done on import of this module)."""
    from gymnasium.envs.registration import register, registry

    for env_id, entry_point in ENVS.items():
        if env_id not in registry:
            register(id=env_id, entry_point=entry_point, disable_env_checker=False,
                     vector_entry_point=_VECTOR.get(env_id))


__getattr__, __dir__, _names = attach(__name__, {
    "ButterflyPitchEnv": "butterfly", "ButterflyPitchWindEnv": "butterfly", "ButterflyPitchVectorEnv": "vector",
    "ButterflyFlight3DEnv": "butterfly3d", "ButterflyFlight3DVectorEnv": "butterfly3d",
    "butterfly": ".", "vector": ".", "policies": ".", "butterfly3d": ".", "pages": ".",
}, globals())
__all__ = ["ENVS", "register_envs", *_names]

register_envs()
