"""Flowers a 3D butterfly can land on: a stem, a blossom and its heart, with or without contact.

One flower is placed by its **blossom's centre** (x, y, z in m). The blossom is a flat ellipsoid
(:data:`BLOSSOM_SIZE_M`, semi-axes), so the surface a butterfly stands on lies :data:`BLOSSOM_SIZE_M` ``[2]``
above the centre (:func:`landing_surface`); the heart is a thin dome drawn on it, which nothing touches. With
``contact`` the blossom touches the butterfly's legs (:func:`~lifelike_mj.butterfly.flight3d.model.add_contact`),
the stem nothing. The garden draws its flowers with the same function, so that what is drawn is what is stood on.
"""

from __future__ import annotations

import math

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
    ``heart_k``. A blossom less than :data:`MIN_STEM_M` above the ground is refused (:func:`check_flowers`)."""
    flag = 1 if contact else 0
    for k, b in enumerate(check_flowers(blossoms, ground_m)):
        spec.worldbody.add_geom(name=f"stem_{k}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.006, 0, 0],
                                fromto=[b[0], b[1], ground_m, b[0], b[1], b[2] - 0.01], rgba=_STEM,
                                contype=0, conaffinity=0)
        spec.worldbody.add_geom(name=f"blossom_{k}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=list(BLOSSOM_SIZE_M),
                                pos=list(b), rgba=PETALS[k % len(PETALS)], contype=flag, conaffinity=flag)
        spec.worldbody.add_geom(name=f"heart_{k}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=[0.015, 0.015, 0.003],
                                pos=[b[0], b[1], b[2] + BLOSSOM_SIZE_M[2] - 0.0025], rgba=_HEART, contype=0,
                                conaffinity=0)


#: The least distance between two flowers' stems in a drawn garden (m).
SPACING_M = 1.2
#: The least height of a blossom's centre above the ground (m): room for the blossom and a stem.
MIN_STEM_M = 0.05
#: How many positions :func:`place_flowers` draws per flower before it lays the flowers on a lattice instead.
DRAWS_PER_FLOWER = 200


def check_flowers(blossoms, ground_m: float, name: str = "flowers") -> np.ndarray:
    """``blossoms`` (``(n, 3)``, m) checked against the ground at ``ground_m`` (m): a :class:`UserError` naming the
    first blossom whose centre is less than :data:`MIN_STEM_M` above the ground (a flower under the ground, or
    with no room for its stem)."""
    from lifelike_mj.errors import UserError

    b = np.asarray(blossoms, dtype=float).reshape(-1, 3)
    low = np.flatnonzero(b[:, 2] < ground_m + MIN_STEM_M)
    if len(low):
        k = int(low[0])
        raise UserError(f"{name}: flower {k}'s blossom at z = {b[k, 2]:g} m is not above the ground at {ground_m:g} m; "
                        f"a blossom's centre must be at least {MIN_STEM_M:g} m above it (z >= {ground_m + MIN_STEM_M:g} m).")
    return b


def lattice_sites(size_m: float, spacing_m: float = SPACING_M) -> np.ndarray:
    """``(k, 2)``: the densest of two lattices of points ``spacing_m`` apart that fit in a ``size_m`` square centred
    on the origin (m): a square lattice, and a triangular one (rows ``spacing_m sqrt(3)/2`` apart, every other row
    shifted by half a spacing). Its length is :func:`max_flowers`."""
    half = size_m / 2.0
    per_row = int(math.floor(size_m / spacing_m + 1e-9)) + 1
    xs = -half + spacing_m * np.arange(per_row)
    square = np.array([(x, y) for y in xs for x in xs])
    rise = spacing_m * math.sqrt(3.0) / 2.0
    rows = int(math.floor(size_m / rise + 1e-9)) + 1
    tri = []
    for r in range(rows):
        shift = spacing_m / 2.0 if r % 2 else 0.0
        n = int(math.floor((size_m - shift) / spacing_m + 1e-9)) + 1
        tri += [(-half + shift + spacing_m * i, -half + rise * r) for i in range(n)]
    return square if len(square) >= len(tri) else np.array(tri)


def max_flowers(size_m: float, spacing_m: float = SPACING_M) -> int:
    """The most flowers :func:`place_flowers` lays in a ``size_m`` square at least ``spacing_m`` apart (the number of
    :func:`lattice_sites`)."""
    return len(lattice_sites(size_m, spacing_m))


def check_room(n: int, size_m: float, count_name: str = "n", size_name: str = "size_m") -> None:
    """A :class:`UserError`, before any work, unless ``n`` flowers fit in a ``size_m`` square :data:`SPACING_M`
    apart; the sentence names the arguments (``count_name``, ``size_name``) and gives the most that fit
    (:func:`max_flowers`) and the side of a square that holds ``n``."""
    from lifelike_mj.errors import UserError

    most = max_flowers(size_m)
    if n > most:
        need = size_m
        while max_flowers(need) < n:  # bounded: each pass adds a row and a column of the square lattice
            need += SPACING_M
        raise UserError(f"{count_name} {n} cannot be met: a {size_m:g} m square ({size_name}) holds at most {most} "
                        f"flowers {SPACING_M:g} m apart; ask for at most {most}, or a {size_name} of at least {need:g} m.")


def place_flowers(seed: int, n: int = 12, size_m: float = 8.0, heights_m: float = 0.5) -> np.ndarray:
    """``(n, 3)``: the blossoms (m) of a garden drawn by ``seed``: spread over a ``size_m`` square at least
    :data:`SPACING_M` apart, at altitudes within ``+-heights_m / 2`` of the flight altitude 0.

    Positions are drawn uniformly, each kept if it is far enough from those kept before; a garden too crowded for
    that to end within :data:`DRAWS_PER_FLOWER` draws per flower takes ``n`` sites of :func:`lattice_sites` instead,
    chosen by the same seed. A count that no layout here fits (more than :func:`max_flowers`) is refused before any
    draw (:func:`check_room`)."""
    check_room(int(n), float(size_m))
    rng = np.random.default_rng([seed, 1])
    pts = np.empty((n, 3))
    k = 0
    for _ in range(DRAWS_PER_FLOWER * n):
        if k == n:
            break
        p = np.array([*rng.uniform(-size_m / 2, size_m / 2, 2), rng.uniform(-heights_m / 2, heights_m / 2)])
        if k == 0 or np.sqrt(((pts[:k, :2] - p[:2]) ** 2).sum(axis=1)).min() >= SPACING_M:
            pts[k] = p
            k += 1
    if k == n:
        return pts
    sites = lattice_sites(size_m)
    pick = rng.permutation(len(sites))[:n]
    return np.column_stack([sites[pick], rng.uniform(-heights_m / 2, heights_m / 2, n)])
