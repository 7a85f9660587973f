"""Procedural mesh pieces for the creatures' rigs (:mod:`lifelike_mj.export.rig`): lofted bodies, sheets (wings,
fins), spheres and tubes, each with normals, texture coordinates and bone weights, assembled into one skinned
:class:`~lifelike_mj.export.rig.Mesh`. Metres, in the rig's bind frame (x forward, z up)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lifelike_mj.export.rig import Look, Mesh


@dataclass
class Piece:
    """Part of a mesh: vertices ``positions``/``normals`` ``(V, 3)``, ``uv`` ``(V, 2)``, ``triangles``
    ``(T, 3)``, bone ``joints``/``weights`` ``(V, 4)`` and its ``look``."""

    positions: np.ndarray
    normals: np.ndarray
    uv: np.ndarray
    triangles: np.ndarray
    joints: np.ndarray
    weights: np.ndarray
    look: Look


def rigid(n: int, bone: int) -> tuple[np.ndarray, np.ndarray]:
    """Joints and weights of ``n`` vertices bound wholly to ``bone``."""
    j = np.zeros((n, 4), dtype=np.int64)
    j[:, 0] = bone
    w = np.zeros((n, 4))
    w[:, 0] = 1.0
    return j, w


def blend(x: np.ndarray, stations: np.ndarray, bones: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Joints and weights that blend linearly between the two bones whose ``stations`` (increasing positions
    along one axis) bracket each coordinate ``x``; beyond the ends, the end bone alone."""
    x = np.asarray(x, dtype=float)
    k = np.clip(np.searchsorted(stations, x) - 1, 0, len(stations) - 2)
    u = np.clip((x - stations[k]) / (stations[k + 1] - stations[k]), 0.0, 1.0)
    b = np.asarray(bones)
    j = np.zeros((len(x), 4), dtype=np.int64)
    w = np.zeros((len(x), 4))
    j[:, 0], j[:, 1] = b[k], b[k + 1]
    w[:, 0], w[:, 1] = 1.0 - u, u
    return j, w


def _grid_triangles(rows: int, cols: int, wrap: bool = False) -> np.ndarray:
    """Two triangles per cell of a ``rows x cols`` vertex grid (columns closed into a ring with ``wrap``)."""
    tris = []
    cells = cols if wrap else cols - 1
    for r in range(rows - 1):
        for c in range(cells):
            a, b = r * cols + c, r * cols + (c + 1) % cols
            d, e = a + cols, b + cols
            tris += [(a, b, e), (a, e, d)]
    return np.array(tris, dtype=np.int64)


def _smooth_normals(pos: np.ndarray, tris: np.ndarray) -> np.ndarray:
    n = np.zeros_like(pos)
    face = np.cross(pos[tris[:, 1]] - pos[tris[:, 0]], pos[tris[:, 2]] - pos[tris[:, 0]])
    for j in range(3):
        np.add.at(n, tris[:, j], face)
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(norm > 0, n / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 1.0]))


def loft(x: np.ndarray, half_width: np.ndarray, half_height: np.ndarray, look: Look, bones, centre_z=None,
         segments: int = 16) -> Piece:
    """A body lofted along x through elliptical sections (``half_width`` in y, ``half_height`` in z at each
    ``x``, centred at ``centre_z``), closed at both ends where a half-size is 0. Texture: u along the body (first
    ``x`` at u = 0), v around it from the back (v = 0) down the left side to the belly (0.5) and up the right.
    ``bones``: ``(joints, weights)`` of the vertices, or a function of their positions giving them."""
    x = np.asarray(x, dtype=float)
    cz = np.zeros_like(x) if centre_z is None else np.asarray(centre_z, dtype=float)
    a = np.linspace(0.0, 2.0 * np.pi, segments + 1)  # the seam repeated, for the texture
    ring = np.stack([np.sin(a), np.cos(a)], axis=1)  # (y, z) from the top, to the left first
    pos = np.concatenate([np.column_stack([np.full(len(a), xi), wy * ring[:, 0], zc + hz * ring[:, 1]])
                          for xi, wy, hz, zc in zip(x, half_width, half_height, cz)])
    uv = np.concatenate([np.column_stack([np.full(len(a), (xi - x[0]) / (x[-1] - x[0])), a / (2 * np.pi)])
                         for xi in x])
    tris = _grid_triangles(len(x), len(a))
    tris = tris[:, [0, 2, 1]] if x[-1] > x[0] else tris  # outward
    nrm = _smooth_normals(pos, tris)
    j, w = bones(pos) if callable(bones) else bones
    if not callable(bones) and len(j) != len(pos):
        j, w = np.repeat(j[:1], len(pos), axis=0), np.repeat(w[:1], len(pos), axis=0)
    return Piece(pos, nrm, uv, tris, j, w, look)


def sheet(points: np.ndarray, uv: np.ndarray, look: Look, bones, thickness: float = 0.0) -> Piece:
    """A surface through a ``(rows, cols, 3)`` grid of points with texture coordinates ``(rows, cols, 2)``;
    seen from both faces (its look double-sided), or, with ``thickness``, as two faces that far apart."""
    rows, cols = points.shape[:2]
    pos = points.reshape(-1, 3)
    tris = _grid_triangles(rows, cols)
    nrm = _smooth_normals(pos, tris)
    uvs = uv.reshape(-1, 2)
    if thickness > 0:
        pos = np.concatenate([pos + nrm * thickness / 2, pos - nrm * thickness / 2])
        tris = np.concatenate([tris, tris[:, [0, 2, 1]] + rows * cols])
        nrm = np.concatenate([nrm, -nrm])
        uvs = np.concatenate([uvs, uvs])
    j, w = bones(pos) if callable(bones) else (np.repeat(bones[0][:1], len(pos), 0), np.repeat(bones[1][:1], len(pos), 0))
    return Piece(pos, nrm, uvs, tris, j, w, look)


def sphere(centre, radii, look: Look, bones, segments: int = 12) -> Piece:
    """An ellipsoid of semi-axes ``radii`` about ``centre``."""
    c = np.asarray(centre, dtype=float)
    r = np.broadcast_to(np.asarray(radii, dtype=float), (3,))
    t = np.linspace(0.0, 1.0, segments // 2 + 1)
    x = c[0] + r[0] * np.cos(np.pi * t)[::-1]
    s = np.sin(np.pi * t)[::-1]
    p = loft(x, r[1] * s, r[2] * s, look, bones, centre_z=np.full(len(x), c[2]), segments=segments)
    p.positions = p.positions + np.array([0.0, c[1], 0.0])
    return p


def tube(path: np.ndarray, radius: np.ndarray, look: Look, bones, segments: int = 6) -> Piece:
    """A thin tube along the points ``path`` ``(n, 3)`` with ``radius`` at each (an antenna, a leg)."""
    path = np.asarray(path, dtype=float)
    d = np.gradient(path, axis=0)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    up = np.where(np.abs(d[:, 2:3]) < 0.9, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    e1 = np.cross(d, up)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(d, e1)
    a = np.linspace(0.0, 2 * np.pi, segments + 1)
    pos = (path[:, None, :] + radius[:, None, None] * (np.cos(a)[None, :, None] * e1[:, None, :]
                                                         + np.sin(a)[None, :, None] * e2[:, None, :])).reshape(-1, 3)
    uv = np.stack(np.meshgrid(a / (2 * np.pi), np.linspace(0, 1, len(path))), axis=-1).reshape(-1, 2)[:, ::-1]
    tris = _grid_triangles(len(path), len(a))
    nrm = _smooth_normals(pos, tris)
    j, w = bones(pos) if callable(bones) else (np.repeat(bones[0][:1], len(pos), 0), np.repeat(bones[1][:1], len(pos), 0))
    return Piece(pos, nrm, uv, tris, j, w, look)


def assemble(name: str, pieces: list[Piece]) -> Mesh:
    """One mesh of ``pieces``, its triangles grouped by look (one part per material)."""
    offset = np.cumsum([0] + [len(p.positions) for p in pieces])
    parts: dict[int, tuple[Look, list[np.ndarray]]] = {}
    for p, o in zip(pieces, offset):
        parts.setdefault(id(p.look), (p.look, []))[1].append(p.triangles + o)
    w = np.concatenate([p.weights for p in pieces])
    w = w / w.sum(axis=1, keepdims=True)
    j = np.concatenate([p.joints for p in pieces])
    j[w == 0.0] = 0  # glTF: a joint of zero weight is joint 0
    return Mesh(name, np.concatenate([p.positions for p in pieces]), np.concatenate([p.normals for p in pieces]),
                np.concatenate([p.uv for p in pieces]), j, w,
                [(look, np.concatenate(tris)) for look, tris in parts.values()])
