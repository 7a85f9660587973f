"""Animated glTF 2.0 (``.glb`` or ``.gltf``) of recorded body poses (:class:`~lifelike_mj.export.poses.Poses`).

Layout of the file:

* one root node, ``lifelike-mj``, turning MuJoCo's Z-up world into glTF's Y-up (-90 deg about X); metres;
* under it, one node per exported body, animated (translation and rotation, linear, at the recorded
  frames), and one still node per drawn geom of the world body (ground, tank, flowers);
* under each body node, one still node per drawn geom, at the geom's place in the body, holding its mesh;
* one mesh per distinct shape (type, size, mesh) and one material per distinct colour, shared by every
  geom that has them, so a flock of hundreds stores one bird's mesh.

Shapes are triangulated from the MJCF geoms: boxes, spheres, ellipsoids, capsules, cylinders, planes
(a finite quad: a plane of size 0 is drawn 10 m across) and meshes (flat-shaded). The colour is the
geom's (or its material's) RGBA as the base colour, not metallic; translucent ones blend.

The whole buffer is written in the file: binary in a ``.glb``, base64 in a ``.gltf`` (one file either
way), atomically.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pygltflib as g

from lifelike_mj import __version__
from lifelike_mj.errors import UserError
from lifelike_mj.export.poses import Poses, drawn_geoms, geom_rgba
from lifelike_mj.io import atomic_path, strict
from lifelike_mj.provenance import provenance

#: The root's rotation (glTF x, y, z, w): -90 deg about X takes MuJoCo's Z-up to glTF's Y-up.
Z_UP_TO_Y_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))
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
    return p, np.repeat(n, 3, axis=0), np.arange(len(p))


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
    """``(positions, normals, triangle indices)`` of geom ``geom`` in its own frame (m)."""
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
    raise UserError(f"geom {geom} is a {name}, which glTF export does not draw yet.")


def _shape_key(model: mujoco.MjModel, geom: int) -> tuple:
    t = int(model.geom_type[geom])
    if t == mujoco.mjtGeom.mjGEOM_MESH:
        return (t, int(model.geom_dataid[geom]))
    return (t, *np.round(model.geom_size[geom], 12).tolist())


# ---- the file -----------------------------------------------------------------------------------

class _Buffer:
    """One binary buffer with its views and accessors."""

    def __init__(self, gltf: g.GLTF2) -> None:
        self.gltf = gltf
        self.data = bytearray()

    def add(self, array: np.ndarray, kind: str, target: int | None = None, minmax: bool = False) -> int:
        arr = np.ascontiguousarray(array)
        while len(self.data) % 4:
            self.data.append(0)
        view = g.BufferView(buffer=0, byteOffset=len(self.data), byteLength=arr.nbytes, target=target)
        self.data += arr.tobytes()
        self.gltf.bufferViews.append(view)
        ctype = {np.dtype(np.float32): g.FLOAT, np.dtype(np.uint32): g.UNSIGNED_INT,
                 np.dtype(np.uint16): g.UNSIGNED_SHORT}[arr.dtype]
        acc = g.Accessor(bufferView=len(self.gltf.bufferViews) - 1, componentType=ctype, count=len(arr), type=kind)
        if minmax:
            flat = arr.reshape(len(arr), -1)
            acc.min = [float(v) for v in flat.min(axis=0)]
            acc.max = [float(v) for v in flat.max(axis=0)]
        self.gltf.accessors.append(acc)
        return len(self.gltf.accessors) - 1


def _xyzw(q_wxyz) -> list[float]:
    return [float(q_wxyz[1]), float(q_wxyz[2]), float(q_wxyz[3]), float(q_wxyz[0])]


def build_gltf(poses: Poses, name: str = "lifelike-mj run", parameters: dict | None = None) -> g.GLTF2:
    """The glTF document (module docstring) of ``poses``; :func:`write_gltf` writes it. The asset's
    ``extras`` hold the provenance: the versions, the command, the time and ``parameters`` (what made the
    run), with the frames' count, rate and times."""
    m = poses.model
    fps = (poses.n_frames - 1) / (poses.t_s[-1] - poses.t_s[0]) if poses.t_s[-1] > poses.t_s[0] else 0.0
    prov = provenance(**(parameters or {}))
    prov["frames"] = {"count": poses.n_frames, "per_s": float(fps), "start_s": float(poses.t_s[0]),
                      "end_s": float(poses.t_s[-1]), "bodies": len(poses.body_ids)}
    gl = g.GLTF2(asset=g.Asset(version="2.0", generator=f"lifelike-mj {__version__}", extras=strict(prov)))
    gl.scenes = [g.Scene(name=name, nodes=[0])]
    gl.scene = 0
    root = g.Node(name="lifelike-mj", rotation=list(Z_UP_TO_Y_UP), children=[])
    gl.nodes.append(root)
    buf = _Buffer(gl)
    meshes: dict[tuple, int] = {}
    materials: dict[tuple, int] = {}
    rgba = geom_rgba(m)

    def mesh_of(geom: int) -> int:
        key = _shape_key(m, geom)
        colour = tuple(np.round(rgba[geom], 6).tolist())
        full = (key, colour)
        if full not in meshes:
            if colour not in materials:
                mat = g.Material(name=f"rgba {colour}", doubleSided=True,
                                 pbrMetallicRoughness=g.PbrMetallicRoughness(
                                     baseColorFactor=[float(c) for c in colour], metallicFactor=0.0,
                                     roughnessFactor=0.8))
                if colour[3] < 1.0:
                    mat.alphaMode = g.BLEND
                gl.materials.append(mat)
                materials[colour] = len(gl.materials) - 1
            pos, nrm, tri = geom_shape(m, geom)
            a_pos = buf.add(pos.astype(np.float32), g.VEC3, g.ARRAY_BUFFER, minmax=True)
            a_nrm = buf.add(nrm.astype(np.float32), g.VEC3, g.ARRAY_BUFFER)
            idx = tri.reshape(-1).astype(np.uint16 if len(pos) < 65536 else np.uint32)
            a_idx = buf.add(idx, g.SCALAR, g.ELEMENT_ARRAY_BUFFER)
            gl.meshes.append(g.Mesh(primitives=[g.Primitive(attributes=g.Attributes(POSITION=a_pos, NORMAL=a_nrm),
                                                            indices=a_idx, material=materials[colour])]))
            meshes[full] = len(gl.meshes) - 1
        return meshes[full]

    def geom_node(geom: int) -> int:
        gname = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, geom) or f"geom{geom}"
        gl.nodes.append(g.Node(name=gname, mesh=mesh_of(geom), translation=[float(v) for v in m.geom_pos[geom]],
                               rotation=_xyzw(m.geom_quat[geom])))
        return len(gl.nodes) - 1

    drawn = drawn_geoms(m)
    for geom in drawn[m.geom_bodyid[drawn] == 0]:  # the world's still geoms
        root.children.append(geom_node(int(geom)))
    times = buf.add(poses.t_s.astype(np.float32) - np.float32(poses.t_s[0]), g.SCALAR, minmax=True)
    anim = g.Animation(name=name, samplers=[], channels=[])
    for b, (body, bname) in enumerate(zip(poses.body_ids, poses.body_names)):
        node = g.Node(name=bname, translation=[float(v) for v in poses.position_m[0, b]],
                      rotation=_xyzw(poses.quat_wxyz[0, b]), children=[])
        gl.nodes.append(node)
        idx = len(gl.nodes) - 1
        root.children.append(idx)
        for geom in drawn[m.geom_bodyid[drawn] == body]:
            node.children.append(geom_node(int(geom)))
        a_t = buf.add(poses.position_m[:, b].astype(np.float32), g.VEC3)
        a_r = buf.add(poses.quat_wxyz[:, b][:, [1, 2, 3, 0]].astype(np.float32), g.VEC4)
        for path, acc in (("translation", a_t), ("rotation", a_r)):
            anim.samplers.append(g.AnimationSampler(input=times, output=acc, interpolation="LINEAR"))
            anim.channels.append(g.AnimationChannel(sampler=len(anim.samplers) - 1,
                                                    target=g.AnimationChannelTarget(node=idx, path=path)))
    gl.animations = [anim]
    gl.buffers = [g.Buffer(byteLength=len(buf.data))]
    gl.set_binary_blob(bytes(buf.data))
    return gl


def write_gltf(poses: Poses, path: str | Path, name: str = "lifelike-mj run", parameters: dict | None = None) -> Path:
    """Write ``poses`` as animated glTF 2.0: binary (``.glb``) or JSON with the buffer inside (``.gltf``),
    atomically, with the provenance (:func:`build_gltf`; ``parameters``: what made the run). Returns the
    path."""
    path = Path(path)
    if path.suffix.lower() not in (".glb", ".gltf"):
        raise UserError(f"a glTF file ends in .glb or .gltf, got {path.name!r}.")
    gl = build_gltf(poses, name, parameters)
    with atomic_path(path) as tmp:
        if path.suffix.lower() == ".glb":
            gl.save_binary(str(tmp))
        else:
            gl.convert_buffers(g.BufferFormat.DATAURI)  # the buffer inside the JSON, base64
            gl.save_json(str(tmp))
    return path
