"""Flowers a 3D butterfly can land on: a stem, a blossom and its heart, with or without contact.

One flower is placed by its **blossom's centre** (x, y, z in m). The blossom is a flat ellipsoid
(:data:`BLOSSOM_SIZE_M`, semi-axes), so the surface a butterfly stands on lies :data:`BLOSSOM_SIZE_M` ``[2]``
above the centre (:func:`landing_surface`); the heart is a thin dome drawn on it, which nothing touches. With
``contact`` the blossom touches the butterfly's legs (:func:`~lifelike_mj.butterfly.flight3d.model.add_contact`),
the stem nothing. The garden draws its flowers with the same function, so that what is drawn is what is stood on.
"""

from __future__ import annotations

import mujoco
import numpy as np

#: The blossom's semi-axes (m): 10 cm across, 3 cm deep (a daisy-sized landing pad; a monarch's feet spread about
#: 2 cm).
BLOSSOM_SIZE_M = (0.05, 0.05, 0.015)
#: Petal colours (RGBA), one per flower in turn.
PETALS = ((0.92, 0.3, 0.55, 1), (0.98, 0.85, 0.2, 1), (0.55, 0.35, 0.85, 1), (0.98, 0.55, 0.2, 1), (1, 1, 1, 1))
_STEM = (0.25, 0.55, 0.2, 1.0)
_HEART = (0.95, 0.8, 0.1, 1.0)


def landing_surface(blossom) -> np.ndarray:
    """The point a butterfly stands on (m): the top of the blossom centred at ``blossom``."""
    return np.asarray(blossom, dtype=float) + np.array([0.0, 0.0, BLOSSOM_SIZE_M[2]])


def blossom_under(surface) -> np.ndarray:
    """The centre of the blossom whose landing surface is at ``surface`` (m): :func:`landing_surface`'s inverse."""
    return np.asarray(surface, dtype=float) - np.array([0.0, 0.0, BLOSSOM_SIZE_M[2]])


def add_flowers(spec: mujoco.MjSpec, blossoms, ground_m: float, contact: bool = False) -> None:
    """Add a flower per row of ``blossoms`` (``(n, 3)``, m) to ``spec``'s world: ``stem_k`` from the ground at
    ``ground_m`` (m) up to the blossom, ``blossom_k`` (touching the butterfly's legs when ``contact``) and
    ``heart_k``."""
    flag = 1 if contact else 0
    for k, b in enumerate(np.asarray(blossoms, dtype=float).reshape(-1, 3)):
        spec.worldbody.add_geom(name=f"stem_{k}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.006, 0, 0],
                                fromto=[b[0], b[1], ground_m, b[0], b[1], b[2] - 0.01], rgba=_STEM,
                                contype=0, conaffinity=0)
        spec.worldbody.add_geom(name=f"blossom_{k}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=list(BLOSSOM_SIZE_M),
                                pos=list(b), rgba=PETALS[k % len(PETALS)], contype=flag, conaffinity=flag)
        spec.worldbody.add_geom(name=f"heart_{k}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=[0.015, 0.015, 0.003],
                                pos=[b[0], b[1], b[2] + BLOSSOM_SIZE_M[2] - 0.0025], rgba=_HEART, contype=0,
                                conaffinity=0)


def place_flowers(seed: int, n: int = 12, size_m: float = 8.0, heights_m: float = 0.5) -> np.ndarray:
    """``(n, 3)``: the blossoms (m) of a garden drawn by ``seed``: spread over a ``size_m`` square at least
    1.2 m apart, at altitudes within ``+-heights_m / 2`` of the flight altitude 0."""
    rng = np.random.default_rng([seed, 1])
    pts: list[np.ndarray] = []
    while len(pts) < n:
        p = np.array([*rng.uniform(-size_m / 2, size_m / 2, 2), rng.uniform(-heights_m / 2, heights_m / 2)])
        if all(np.linalg.norm(p[:2] - q[:2]) >= 1.2 for q in pts):
            pts.append(p)
    return np.array(pts)
