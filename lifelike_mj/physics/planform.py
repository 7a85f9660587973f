"""Flat outlines (planforms) of wings and fins: triangulation, area moments and the inertia of a lamina.

A planform is a simple polygon in its own plane, ``(x, y)`` in m: ``x`` along the chord (+ towards the leading
edge), ``y`` along the span from the hinge (``y >= 0``). Everything here is exact for the polygon (no
sampling): the polygon is cut into triangles by ear clipping (:func:`triangulate`), and every integral is a
sum of closed forms over the triangles, from the barycentric monomials
``int l_a^i l_b^j l_c^k dA = 2 A i! j! k! / (i + j + k + 2)!``.

* :func:`area_moments`: the area ``S`` and the radii of its first three moments about the hinge,
  ``r_k = (int y^k dA / (S R^k))^(1/k)`` (Ellington 1984, Phil Trans R Soc B 305:17, part II, with ``R`` the
  span), which set the aerodynamic force (``r_2``) and power (``r_3``) of a flapping wing;
* :func:`lamina_inertia`: the mass centre and the inertia tensor of the polygon as a thin plate of uniform
  areal density.
"""

from __future__ import annotations

import math
from itertools import product

import numpy as np

from lifelike_mj.errors import UserError


def signed_area(polygon: np.ndarray) -> float:
    """Signed area (m^2) of a polygon ``(n, 2)``: positive when its vertices run counter-clockwise."""
    p = np.asarray(polygon, dtype=float)
    x, y = p[:, 0], p[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _inside(p, a, b, c) -> bool:
    # p strictly inside or on the counter-clockwise triangle a, b, c
    def cross(o, u, v):
        return (u[0] - o[0]) * (v[1] - o[1]) - (u[1] - o[1]) * (v[0] - o[0])

    return cross(a, b, p) >= 0.0 and cross(b, c, p) >= 0.0 and cross(c, a, p) >= 0.0


def _crosses_itself(p: np.ndarray) -> bool:
    """Whether two edges of the closed polygon that share no vertex cross or touch."""
    n = len(p)

    def orient(a, b, c):
        v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        return 1 if v > 0.0 else (-1 if v < 0.0 else 0)

    def within(a, b, c):  # c, on the line a b, lies on the segment a b
        return min(a[0], b[0]) <= c[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= c[1] <= max(a[1], b[1])

    for i in range(n):
        a, b = p[i], p[(i + 1) % n]
        for j in range(i + 2, n):
            if (j + 1) % n == i:
                continue
            c, d = p[j], p[(j + 1) % n]
            o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
            if o1 * o2 < 0 and o3 * o4 < 0:
                return True
            if ((o1 == 0 and within(a, b, c)) or (o2 == 0 and within(a, b, d)) or (o3 == 0 and within(c, d, a))
                    or (o4 == 0 and within(c, d, b))):
                return True
    return False


def triangulate(polygon: np.ndarray) -> np.ndarray:
    """Triangles ``(n - 2, 3, 2)`` covering the simple polygon ``(n, 2)`` exactly, each counter-clockwise:
    ear clipping (an ear: three consecutive convex vertices whose triangle holds no other vertex). Raises
    :class:`~lifelike_mj.errors.UserError` for fewer than three vertices, a zero area or a polygon that
    crosses itself (no ear left)."""
    p = np.asarray(polygon, dtype=float)
    if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.all(np.isfinite(p)):
        raise UserError("a planform is a polygon of at least three finite (x, y) vertices.")
    if _crosses_itself(p):
        raise UserError("a planform's polygon crosses itself.")
    area = signed_area(p)
    if area == 0.0:
        raise UserError("a planform's polygon has zero area.")
    if area < 0.0:
        p = p[::-1]
    idx = list(range(len(p)))
    tris = []
    while len(idx) > 3:
        n = len(idx)
        for k in range(n):
            i0, i1, i2 = idx[(k - 1) % n], idx[k], idx[(k + 1) % n]
            a, b, c = p[i0], p[i1], p[i2]
            turn = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
            if turn <= 0.0:
                continue  # a reflex (or straight) vertex is no ear
            if any(_inside(p[j], a, b, c) for j in idx if j not in (i0, i1, i2)):
                continue
            tris.append((i0, i1, i2))
            del idx[k]
            break
        else:
            raise UserError("a planform's polygon crosses itself (no triangle can be cut off it).")  # pragma: no cover
    tris.append(tuple(idx))
    return p[np.array(tris)]


def _tri_areas(tris: np.ndarray) -> np.ndarray:
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    return 0.5 * ((b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1]))


def _monomial(tris: np.ndarray, i: int, j: int) -> float:
    """``int x^i y^j dA`` over the triangles (signed by their orientation), exactly (i + j <= 3)."""
    areas = _tri_areas(tris)
    total = 0.0
    n = i + j
    # expand x^i y^j in the barycentric coordinates: x = sum_k l_k x_k; average the monomial's value over
    # the exact rule of degree n (every l_a^p l_b^q l_c^r with p + q + r = n)
    for t, area in zip(tris, areas):
        s = 0.0
        for combo in product(range(3), repeat=n):
            counts = [combo.count(0), combo.count(1), combo.count(2)]
            term = 1.0
            for m, v in enumerate(combo):
                term *= t[v, 0] if m < i else t[v, 1]
            s += term * math.factorial(counts[0]) * math.factorial(counts[1]) * math.factorial(counts[2])
        total += area * 2.0 * s / math.factorial(n + 2)
    return total


def area_moments(tris: np.ndarray, span_m: float | None = None) -> dict:
    """The area ``S`` (m^2), the span ``R`` (m; the largest ``y`` unless given) and the non-dimensional radii
    ``r1, r2, r3`` of the first three moments of area about the hinge line ``y = 0`` (Ellington 1984:
    ``r_k^k = int y^k dA / (S R^k)``) of the triangles ``(n, 3, 2)``; with ``centroid_m`` (x, y)."""
    tris = np.asarray(tris, dtype=float)
    S = _monomial(tris, 0, 0)
    R = float(tris[:, :, 1].max()) if span_m is None else float(span_m)
    out = {"area_m2": S, "span_m": R,
           "centroid_m": [_monomial(tris, 1, 0) / S, _monomial(tris, 0, 1) / S]}
    for k in (1, 2, 3):
        out[f"r{k}"] = (_monomial(tris, 0, k) / (S * R**k)) ** (1.0 / k)
    return out


def lamina_inertia(tris: np.ndarray, mass_kg: float) -> tuple[np.ndarray, np.ndarray]:
    """Mass centre ``(3,)`` (m; ``z = 0``, the plane) and inertia tensor ``(3, 3)`` about it (kg m^2; axes
    ``x, y`` in the plane, ``z`` its normal) of the triangles as a thin plate of ``mass_kg`` spread evenly."""
    tris = np.asarray(tris, dtype=float)
    S = _monomial(tris, 0, 0)
    sigma = mass_kg / S
    cx, cy = _monomial(tris, 1, 0) / S, _monomial(tris, 0, 1) / S
    ixx = sigma * _monomial(tris, 2, 0) - mass_kg * cx * cx  # int x^2 about the centre
    iyy = sigma * _monomial(tris, 0, 2) - mass_kg * cy * cy
    ixy = sigma * _monomial(tris, 1, 1) - mass_kg * cx * cy
    inertia = np.array([[iyy, -ixy, 0.0], [-ixy, ixx, 0.0], [0.0, 0.0, ixx + iyy]])
    return np.array([cx, cy, 0.0]), inertia
