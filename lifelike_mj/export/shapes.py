"""The MJCF geoms as triangle meshes, for the exporters: boxes, spheres, ellipsoids, capsules, cylinders,
planes (a finite quad: a plane of size 0 is drawn 10 m across) and meshes (flat-shaded). Metres, in each
geom's own frame."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lifelike_mj.errors import UserError

#: Size (m, half-width) of a plane whose MJCF size is 0 (infinite).
INFINITE_PLANE_HALF_M = 5.0
_SEGMENTS = 16  # around a sphere, capsule or cylinder
_RINGS = 8  # from pole to pole of a sphere (even: a capsule's equator is a ring)

# ---- shapes -------------------------------------------------------------------------------------

def _flat(pos: np.ndarray, tris: np.ndarray):
    """Flat-shaded triangles: each triangle its own three vertices and its face normal."""
    p = pos[tris.reshape(-1)]
    a, b, c = p[0::3], p[1::3], p[2::3]
    n = np.cross(b - a, c - a)
    norm = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(norm > 0, n / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 1.0]))
    return p, np.repeat(n, 3, axis=0), np.arange(len(p)).reshape(-1, 3)


def _box(hx: float, hy: float, hz: float):
    corners = np.array([[x, y, z] for x in (-hx, hx) for y in (-hy, hy) for z in (-hz, hz)])
    # corner index = 4 ix + 2 iy + iz; two triangles per face, counter-clockwise seen from outside
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = np.array([t for a, b, c, d in faces for t in ((a, b, c), (a, c, d))])
    return _flat(corners, tris)


def _sphere(r: float, scale=(1.0, 1.0, 1.0)):
    """A UV sphere of radius ``r`` (smooth), stretched by ``scale`` (an ellipsoid)."""
    th = np.linspace(0.0, math.pi, _RINGS + 1)
    ph = np.linspace(0.0, 2.0 * math.pi, _SEGMENTS + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    unit = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1).reshape(-1, 3)
    s = np.asarray(scale, dtype=float)
    pos = r * unit * s
    normals = unit / s
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return pos, normals, _grid_tris(_RINGS, _SEGMENTS)


def _grid_tris(rows: int, cols: int) -> np.ndarray:
    """Triangles of a (rows + 1) x (cols + 1) vertex grid, wound outwards for the sphere's parametrisation."""
    out = []
    w = cols + 1
    for i in range(rows):
        for j in range(cols):
            a, b, c, d = i * w + j, i * w + j + 1, (i + 1) * w + j, (i + 1) * w + j + 1
            out += [(a, c, d), (a, d, b)]
    return np.array(out)


def _capsule(r: float, h: float):
    """A capsule along z: radius ``r``, cylinder half-length ``h`` (smooth)."""
    th = np.linspace(0.0, math.pi, _RINGS + 1)
    th = np.concatenate([th[: _RINGS // 2 + 1], th[_RINGS // 2 :]])  # the equator twice: the cylinder between
    ph = np.linspace(0.0, 2.0 * math.pi, _SEGMENTS + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    unit = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), np.cos(T)], axis=-1)
    shift = np.zeros_like(unit)
    shift[: _RINGS // 2 + 1, :, 2] = h
    shift[_RINGS // 2 + 1 :, :, 2] = -h
    pos = (r * unit + shift).reshape(-1, 3)
    return pos, unit.reshape(-1, 3), _grid_tris(_RINGS + 1, _SEGMENTS)


def _cylinder(r: float, h: float):
    """A closed cylinder along z: radius ``r``, half-length ``h`` (smooth side, flat caps)."""
    ph = np.linspace(0.0, 2.0 * math.pi, _SEGMENTS + 1)
    ring = np.stack([np.cos(ph), np.sin(ph), np.zeros_like(ph)], axis=1)
    side_pos = np.concatenate([r * ring + [0, 0, h], r * ring - [0, 0, h]])
    side_n = np.concatenate([ring, ring])
    w = _SEGMENTS + 1
    side_tris = np.array([t for j in range(_SEGMENTS) for t in ((j, w + j, w + j + 1), (j, w + j + 1, j + 1))])
    pos, normals, tris = [side_pos], [side_n], [side_tris]
    base = len(side_pos)
    for sign in (1.0, -1.0):
        cap = np.concatenate([[[0.0, 0.0, sign * h]], r * ring[:-1] + [0, 0, sign * h]])
        idx = [(0, 1 + j, 1 + (j + 1) % _SEGMENTS) for j in range(_SEGMENTS)]
        t = np.array(idx if sign > 0 else [(a, c, b) for a, b, c in idx]) + base
        pos.append(cap)
        normals.append(np.tile([0.0, 0.0, sign], (len(cap), 1)))
        tris.append(t)
        base += len(cap)
    return np.concatenate(pos), np.concatenate(normals), np.concatenate(tris)


def _plane(hx: float, hy: float):
    hx = hx if hx > 0 else INFINITE_PLANE_HALF_M
    hy = hy if hy > 0 else INFINITE_PLANE_HALF_M
    pos = np.array([[-hx, -hy, 0.0], [hx, -hy, 0.0], [hx, hy, 0.0], [-hx, hy, 0.0]])
    return pos, np.tile([0.0, 0.0, 1.0], (4, 1)), np.array([(0, 1, 2), (0, 2, 3)])


def _mesh(model: mujoco.MjModel, mesh_id: int):
    v0, nv = model.mesh_vertadr[mesh_id], model.mesh_vertnum[mesh_id]
    f0, nf = model.mesh_faceadr[mesh_id], model.mesh_facenum[mesh_id]
    return _flat(model.mesh_vert[v0 : v0 + nv].astype(float), model.mesh_face[f0 : f0 + nf].astype(np.int64))


def geom_shape(model: mujoco.MjModel, geom: int):
    """``(positions (n, 3), normals (n, 3), triangles (t, 3) of vertex indices)`` of geom ``geom`` in its own frame
    (m)."""
    t = model.geom_type[geom]
    s = model.geom_size[geom]
    T = mujoco.mjtGeom
    if t == T.mjGEOM_BOX:
        return _box(*s)
    if t == T.mjGEOM_SPHERE:
        return _sphere(s[0])
    if t == T.mjGEOM_ELLIPSOID:
        return _sphere(1.0, s)
    if t == T.mjGEOM_CAPSULE:
        return _capsule(s[0], s[1])
    if t == T.mjGEOM_CYLINDER:
        return _cylinder(s[0], s[1])
    if t == T.mjGEOM_PLANE:
        return _plane(s[0], s[1])
    if t == T.mjGEOM_MESH:
        return _mesh(model, int(model.geom_dataid[geom]))
    name = mujoco.mjtGeom(t).name.removeprefix("mjGEOM_").lower()
    raise UserError(f"geom {geom} is a {name}, which the exporters do not draw yet.")


def shape_key(model: mujoco.MjModel, geom: int) -> tuple:
    t = int(model.geom_type[geom])
    if t == mujoco.mjtGeom.mjGEOM_MESH:
        return (t, int(model.geom_dataid[geom]))
    return (t, *np.round(model.geom_size[geom], 12).tolist())



# ---- textures -----------------------------------------------------------------------------------

def geom_texture(model: mujoco.MjModel, geom: int) -> np.ndarray | None:
    """The 2D texture image (``(H, W, 4)`` uint8 RGBA) of a geom's material, or None (no material, no 2D RGB
    texture: a skybox or cube texture is not a surface's)."""
    mat = int(model.geom_matid[geom])
    if mat < 0:
        return None
    tex = int(model.mat_texid[mat, int(mujoco.mjtTextureRole.mjTEXROLE_RGB)])
    if tex < 0 or int(model.tex_type[tex]) != int(mujoco.mjtTexture.mjTEXTURE_2D):
        return None
    h, w, c = int(model.tex_height[tex]), int(model.tex_width[tex]), int(model.tex_nchannel[tex])
    data = np.asarray(model.tex_data[model.tex_adr[tex]: model.tex_adr[tex] + h * w * c], dtype=np.uint8)
    img = data.reshape(h, w, c)
    if c == 3:
        img = np.concatenate([img, np.full((h, w, 1), 255, dtype=np.uint8)], axis=-1)
    elif c == 1:
        img = np.concatenate([np.repeat(img, 3, axis=-1), np.full((h, w, 1), 255, dtype=np.uint8)], axis=-1)
    return img


def geom_uv(model: mujoco.MjModel, geom: int, pos: np.ndarray) -> np.ndarray:
    """Texture coordinates of a geom's vertices ``pos`` (in its own frame), laid flat in its x-y plane as MuJoCo
    repeats a material's texture: ``texrepeat`` times per metre with ``texuniform``, else per the geom's size (an
    infinite plane: per its grid spacing, the third size)."""
    mat = int(model.geom_matid[geom])
    rep = model.mat_texrepeat[mat] if mat >= 0 else np.ones(2)
    size = model.geom_size[geom]
    if mat >= 0 and model.mat_texuniform[mat]:
        unit = np.ones(2)
    elif int(model.geom_type[geom]) == int(mujoco.mjtGeom.mjGEOM_PLANE) and (size[0] <= 0 or size[1] <= 0):
        unit = np.full(2, size[2] if size[2] > 0 else 1.0)
    else:
        unit = 2.0 * np.maximum(size[:2], 1e-9)
    return np.column_stack([pos[:, 0] / unit[0] * rep[0], pos[:, 1] / unit[1] * rep[1]])
