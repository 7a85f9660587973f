"""Animated glTF 2.0 (``.glb`` or ``.gltf``) of recorded body poses (:class:`~lifelike_mj.export.poses.Poses`).

Layout of the file:

* one root node, ``lifelike-mj``, turning MuJoCo's Z-up world into glTF's Y-up (-90 deg about X); metres;
* under it, one node per exported body, animated (translation and rotation, linear, each channel at its own
  keys: the samples of the simulation's steps that interpolation needs to stay within the key tolerance,
  :mod:`lifelike_mj.export.keys`; rotations as normalized 16-bit integers by default, within 6e-5 rad), and
  one still node per drawn geom of the world body (ground, tank, flowers);
* under each body node, one still node per drawn geom, at the geom's place in the body, holding its mesh;
* under it too, the cameras of :mod:`lifelike_mj.export.cameras`: ``camera overview`` (still, seeing the
  whole run) and, for a single creature, ``camera follow`` (moving with it);
* one mesh per distinct shape (type, size, mesh) and one material per distinct look, shared by every geom
  that has them, so a flock of hundreds stores one bird's mesh; a material is named as the MJCF's (``wing``,
  ``body``), or after the first geom that wears it where the geom has none.

Shapes are triangulated from the MJCF geoms (:mod:`lifelike_mj.export.shapes`). The colour is the
geom's (or its material's) RGBA as the base colour, not metallic; translucent ones blend.

The whole buffer is written in the file: binary in a ``.glb``, base64 in a ``.gltf`` (one file either
way), atomically.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import mujoco
import numpy as np
import pygltflib as g

from lifelike_mj import __version__
from lifelike_mj.errors import UserError
from lifelike_mj.export.cameras import FOV_DEG, framing
from lifelike_mj.export.keys import DEFAULT_TOLERANCE, Track, body_tracks, key_counts, tolerance_of
from lifelike_mj.export.poses import Poses, drawn_geoms, geom_looks, geom_rgba
from lifelike_mj.export.rig import Cycle, Look, Mesh, Rig
from lifelike_mj.export.shapes import geom_shape, geom_texture, geom_uv, shape_key
from lifelike_mj.io import atomic_path, strict
from lifelike_mj.provenance import provenance

#: The root's rotation (glTF x, y, z, w): -90 deg about X takes MuJoCo's Z-up to glTF's Y-up; and as a matrix.
Z_UP_TO_Y_UP = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))
Z_UP_TO_Y_UP_MATRIX = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


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
                 np.dtype(np.uint16): g.UNSIGNED_SHORT, np.dtype(np.int16): g.SHORT}[arr.dtype]
        acc = g.Accessor(bufferView=len(self.gltf.bufferViews) - 1, componentType=ctype, count=len(arr), type=kind,
                         normalized=bool(arr.dtype == np.int16))
        if minmax:
            flat = arr.reshape(len(arr), -1)
            acc.min = [float(v) for v in flat.min(axis=0)]
            acc.max = [float(v) for v in flat.max(axis=0)]
        self.gltf.accessors.append(acc)
        return len(self.gltf.accessors) - 1


def _xyzw(q_wxyz) -> list[float]:
    return [float(q_wxyz[1]), float(q_wxyz[2]), float(q_wxyz[3]), float(q_wxyz[0])]


def quantize_rotations(q_xyzw: np.ndarray) -> np.ndarray:
    """Unit quaternions as glTF's normalized signed shorts (``round(32767 q)``; a reader divides by 32767):
    each component within 1.5e-5, the rotation within about 6e-5 rad."""
    return np.round(np.clip(q_xyzw, -1.0, 1.0) * 32767.0).astype(np.int16)


def build_gltf(poses: Poses, name: str = "lifelike-mj run", parameters: dict | None = None,
               rotations: str = "short", tolerance=DEFAULT_TOLERANCE, rigs: list[Rig] | None = None) -> g.GLTF2:
    """The glTF document (module docstring) of ``poses``; :func:`write_gltf` writes it. The asset's
    ``extras`` hold the provenance: the versions, the command, the time and ``parameters`` (what made the
    run), with the frames' count, rate and times, the samples' and the keys kept per body.

    Keys: each body's translation and rotation keys are the samples that interpolation needs to stay within
    ``tolerance`` (m, deg) of every sample (:mod:`lifelike_mj.export.keys`), at their own times.
    ``rotations``: ``"short"`` stores the quaternions as normalized 16-bit integers (:func:`quantize_rotations`,
    half the bytes; core glTF 2.0), ``"float"`` as 32-bit floats. Positions are always 32-bit floats (glTF
    allows nothing else for translation keys). A body that does not move or turn over the whole run gets no
    channel for it: its node holds the still pose.

    ``rigs``: the creatures as skinned meshes on skeletons (:mod:`lifelike_mj.export.rig`), in place of their
    bodies' MJCF geoms: each an armature node (the creature's name) holding its bones (MuJoCo bodies named as in
    the MJCF, and the extra bones), a skin, and a skinned mesh node at the scene's root."""
    tolerance = tolerance_of(tolerance)
    prov = provenance(**(parameters or {}))
    prov["frames"] = frames_record(poses, rotations)
    doc = Doc(name, rotations)
    part = add_poses(doc, doc.root, poses, rigs, tolerance)
    prov["keys"] = {"tolerance_m": tolerance[0], "tolerance_deg": tolerance[1], **part["keys"]}
    if rigs:
        prov["rigs"] = part["rigs"]
    _add_cameras(doc, poses, part["tracks"], tolerance)
    return doc.finish(prov)


def frames_record(poses: Poses, rotations: str) -> dict:
    """The frames' count, rate and span of ``poses``, for the provenance."""
    return {"count": poses.n_frames, "per_s": float(poses.fps), "start_s": float(poses.t_s[0]),
            "end_s": float(poses.t_s[-1]), "bodies": len(poses.body_ids), "rotations": rotations}


class Doc:
    """A glTF document being built: its root node ``lifelike-mj`` (MuJoCo's Z-up world turned to glTF's Y-up),
    one binary buffer, one animation whose channels share key times where their keys are the same."""

    def __init__(self, name: str, rotations: str = "short") -> None:
        if rotations not in ("short", "float"):
            raise UserError(f"rotations are stored as 'short' or 'float', got {rotations!r}.")
        self.rotations = rotations
        self.gl = g.GLTF2(asset=g.Asset(version="2.0", generator=f"lifelike-mj {__version__}"))
        self.gl.scenes = [g.Scene(name=name, nodes=[0])]
        self.gl.scene = 0
        self.root = g.Node(name="lifelike-mj", rotation=list(Z_UP_TO_Y_UP), children=[])
        self.gl.nodes.append(self.root)
        self.buf = _Buffer(self.gl)
        self.anim = g.Animation(name=name, samplers=[], channels=[])
        self._cycles: dict[str, dict] = {}  # a shared cycle's animation, its key times and its values per phase
        self._inputs: dict[tuple, int] = {}
        self._times: dict[int, tuple] = {}  # the sample times seen (kept alive), by id, with their digest

    def node(self, node: g.Node, parent: g.Node | None) -> int:
        """Add ``node`` as a child of ``parent`` (or at the scene's root, for None); its index."""
        self.gl.nodes.append(node)
        idx = len(self.gl.nodes) - 1
        if parent is None:
            self.gl.scenes[0].nodes.append(idx)
        else:
            parent.children.append(idx)
        return idx

    def channel(self, t: np.ndarray, node: int, path: str, keys: np.ndarray, values: np.ndarray) -> None:
        """Animate ``node``'s ``path`` (translation: ``values`` (n, 3) m; rotation: (n, 4) x, y, z, w) at the
        samples ``keys`` of the times ``t`` (s; the file's time 0 is ``t[0]``), linearly."""
        if id(t) not in self._times:
            self._times[id(t)] = (t, hashlib.sha1(np.ascontiguousarray(t).tobytes()).hexdigest())
        key = (self._times[id(t)][1], keys.tobytes())
        if key not in self._inputs:
            self._inputs[key] = self.buf.add((t[keys] - t[0]).astype(np.float32), g.SCALAR, minmax=True)
        if path == "rotation":
            out = self.buf.add(quantize_rotations(values) if self.rotations == "short" else values.astype(np.float32),
                               g.VEC4)
        else:
            out = self.buf.add(values.astype(np.float32), g.VEC3)
        self.anim.samplers.append(g.AnimationSampler(input=self._inputs[key], output=out, interpolation="LINEAR"))
        self.anim.channels.append(g.AnimationChannel(sampler=len(self.anim.samplers) - 1,
                                                     target=g.AnimationChannelTarget(node=node, path=path)))

    def cycle_channel(self, cycle: Cycle, part: str, group: int, node: int) -> None:
        """Animate ``node``'s rotation by ``part`` of the shared ``cycle`` in phase ``group``: a channel of the
        cycle's own animation (named as the cycle, one period long, to be looped), whose key times are stored once
        and whose values once per part and phase, however many nodes play them."""
        c = self._cycles.get(cycle.name)
        if c is None:
            m = cycle.samples
            times = (np.arange(m + 1) * (cycle.period_s / m)).astype(np.float32)
            c = {"anim": g.Animation(name=cycle.name, samplers=[], channels=[], extras={
                     "lifelike_mj_cycle": {"period_s": cycle.period_s, "phases": cycle.groups, "loop": True}}),
                 "input": self.buf.add(times, g.SCALAR, minmax=True), "outputs": {}}
            self._cycles[cycle.name] = c
        if (part, group) not in c["outputs"]:
            q = cycle.shifted(part, group)[:, [1, 2, 3, 0]]
            c["outputs"][part, group] = self.buf.add(
                quantize_rotations(q) if self.rotations == "short" else q.astype(np.float32), g.VEC4)
        anim = c["anim"]
        anim.samplers.append(g.AnimationSampler(input=c["input"], output=c["outputs"][part, group],
                                                interpolation="LINEAR"))
        anim.channels.append(g.AnimationChannel(sampler=len(anim.samplers) - 1,
                                                target=g.AnimationChannelTarget(node=node, path="rotation")))

    def finish(self, provenance_record: dict) -> g.GLTF2:
        """The document, with ``provenance_record`` as the asset's extras (strict JSON)."""
        gl = self.gl
        gl.asset.extras = strict(provenance_record)
        gl.animations = ([self.anim] if self.anim.channels else []) + [c["anim"] for c in self._cycles.values()]
        gl.buffers = [g.Buffer(byteLength=len(self.buf.data))]
        gl.set_binary_blob(bytes(self.buf.data))
        return gl


def add_poses(doc: Doc, parent: g.Node, poses: Poses, rigs: list[Rig] | None, tolerance, ground: bool = True,
              still: bool = True, prefix: str = "") -> dict:
    """Add a run to ``doc`` under ``parent``: the world's still geoms (``still``; a ground plane only with
    ``ground``), a node per plain body with its geoms, a rig per creature in ``rigs`` (keyed within
    ``tolerance``, m and deg, in the run's own units; its armature, skin and mesh named with ``prefix``).
    Returns ``{"tracks"}`` (the plain bodies' keys, by body index), ``{"keys"}`` (samples and keys per body)
    and ``{"rigs"}`` (each rig's keys per bone)."""
    rigged = {bone.body for r in rigs or [] for bone in r.bones if bone.body is not None}
    plain = [b for b, n in enumerate(poses.body_names) if n not in rigged]  # bodies written with their geoms
    rotations = doc.rotations
    tracks = dict(zip(plain, body_tracks(poses.t_s, poses.position_m[:, plain], poses.quat_wxyz[:, plain], tolerance,
                                         rotations))) if plain else {}
    span = float(poses.t_s[-1] - poses.t_s[0])
    keys = {"samples": poses.n_samples, "samples_per_s": (poses.n_samples - 1) / span if span > 0 else 0.0,
            "per_body": key_counts([tracks[b] for b in plain], [poses.body_names[b] for b in plain])}
    gl, buf = doc.gl, doc.buf
    m = poses.model
    meshes: dict[tuple, int] = {}
    materials: dict[int, int] = {}
    rgba = geom_rgba(m)
    look, look_names = geom_looks(m)

    def mesh_of(geom: int) -> int:
        key = shape_key(m, geom)
        colour = tuple(np.round(rgba[geom], 6).tolist())
        full = (key, int(look[geom]))
        if full not in meshes:
            image = geom_texture(m, geom)
            if look[geom] not in materials:
                mat = g.Material(name=look_names[look[geom]], doubleSided=True,
                                 pbrMetallicRoughness=g.PbrMetallicRoughness(
                                     baseColorFactor=[float(c) for c in colour], metallicFactor=0.0,
                                     roughnessFactor=0.8))
                if image is not None:  # the model's own texture (a ground's checker), repeated
                    mat.pbrMetallicRoughness.baseColorTexture = g.TextureInfo(index=_texture(
                        gl, buf, image, look_names[look[geom]], repeat=True))
                if colour[3] < 1.0:
                    mat.alphaMode = g.BLEND
                gl.materials.append(mat)
                materials[int(look[geom])] = len(gl.materials) - 1
            pos, nrm, tri = geom_shape(m, geom)
            a_pos = buf.add(pos.astype(np.float32), g.VEC3, g.ARRAY_BUFFER, minmax=True)
            a_nrm = buf.add(nrm.astype(np.float32), g.VEC3, g.ARRAY_BUFFER)
            a_uv = buf.add(geom_uv(m, geom, pos).astype(np.float32), g.VEC2, g.ARRAY_BUFFER) if image is not None \
                else None
            idx = tri.reshape(-1).astype(np.uint16 if len(pos) < 65536 else np.uint32)
            a_idx = buf.add(idx, g.SCALAR, g.ELEMENT_ARRAY_BUFFER)
            gl.meshes.append(g.Mesh(primitives=[g.Primitive(attributes=g.Attributes(POSITION=a_pos, NORMAL=a_nrm,
                                                                                    TEXCOORD_0=a_uv),
                                                            indices=a_idx, material=materials[int(look[geom])])]))
            meshes[full] = len(gl.meshes) - 1
        return meshes[full]

    def geom_node(geom: int, parent_node: g.Node) -> None:
        gname = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, geom) or f"geom{geom}"
        doc.node(g.Node(name=gname, mesh=mesh_of(geom), translation=[float(v) for v in m.geom_pos[geom]],
                        rotation=_xyzw(m.geom_quat[geom])), parent_node)

    drawn = drawn_geoms(m)
    for geom in drawn[m.geom_bodyid[drawn] == 0] if still else ():  # the world's still geoms
        if ground or m.geom_type[geom] != mujoco.mjtGeom.mjGEOM_PLANE:
            geom_node(int(geom), parent)
    t = poses.t_s
    for b, (body, bname) in enumerate(zip(poses.body_ids, poses.body_names)):
        if bname in rigged:
            continue
        node = g.Node(name=bname, translation=[float(v) for v in poses.position_m[0, b]],
                      rotation=_xyzw(poses.quat_wxyz[0, b]), children=[], extras={"mujoco_body": bname})
        idx = doc.node(node, parent)
        for geom in drawn[m.geom_bodyid[drawn] == body]:
            geom_node(int(geom), node)
        track = tracks[b]
        if track.translation is not None:
            doc.channel(t, idx, "translation", track.translation, poses.position_m[track.translation, b])
        if track.rotation is not None:
            doc.channel(t, idx, "rotation", track.rotation, poses.quat_wxyz[track.rotation, b][:, [1, 2, 3, 0]])
    return {"tracks": tracks, "keys": keys, "rigs": _add_rigs(doc, parent, poses, rigs, tolerance, prefix) if rigs else {}}


def _png(image: np.ndarray) -> bytes:
    import io

    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8), "RGBA").save(out, "PNG", optimize=True)
    return out.getvalue()


def _texture(gl: g.GLTF2, buf: _Buffer, image: np.ndarray, name: str, repeat: bool = False) -> int:
    """An embedded PNG texture of ``image``: its index (a clamped or a repeating sampler)."""
    png = _png(image)
    while len(buf.data) % 4:
        buf.data.append(0)
    gl.bufferViews.append(g.BufferView(buffer=0, byteOffset=len(buf.data), byteLength=len(png)))
    buf.data += png
    gl.images.append(g.Image(name=name, mimeType="image/png", bufferView=len(gl.bufferViews) - 1))
    wrap = g.REPEAT if repeat else g.CLAMP_TO_EDGE
    sampler = next((i for i, sm in enumerate(gl.samplers) if sm.wrapS == wrap), None)
    if sampler is None:
        gl.samplers.append(g.Sampler(magFilter=g.LINEAR, minFilter=g.LINEAR_MIPMAP_LINEAR, wrapS=wrap, wrapT=wrap))
        sampler = len(gl.samplers) - 1
    gl.textures.append(g.Texture(sampler=sampler, source=len(gl.images) - 1, name=name))
    return len(gl.textures) - 1


def _add_rigs(doc: Doc, parent: g.Node, poses: Poses, rigs: list[Rig], tolerance, prefix: str = "") -> dict:
    """Each rig as an armature node under ``parent`` with its bones, a skin and a skinned mesh node at the scene's
    root (glTF ignores a skinned mesh node's own place: its joints place it, with whatever ``parent`` and the
    root add); meshes, textures and inverse bind matrices shared between the rigs that share them. Returns each
    rig's bones and keys, for the provenance."""
    gl, buf, rotations = doc.gl, doc.buf, doc.rotations
    R = np.eye(4)
    R[:3, :3] = Z_UP_TO_Y_UP_MATRIX  # the root's turn, which the joints' world transforms include
    looks: dict[int, int] = {}
    meshes: dict[int, int] = {}
    binds: dict[bytes, int] = {}
    report = {}

    def material(look: Look) -> int:
        if id(look) not in looks:
            pbr = g.PbrMetallicRoughness(baseColorFactor=[float(c) for c in look.rgba], metallicFactor=0.0,
                                         roughnessFactor=float(look.roughness))
            if look.image is not None:
                pbr.baseColorTexture = g.TextureInfo(index=_texture(gl, buf, look.image, look.name))
            mat = g.Material(name=look.name, doubleSided=look.double_sided, pbrMetallicRoughness=pbr)
            if look.rgba[3] < 1.0 or (look.image is not None and look.image[..., 3].min() < 255):
                mat.alphaMode = g.BLEND
            gl.materials.append(mat)
            looks[id(look)] = len(gl.materials) - 1
        return looks[id(look)]

    def mesh_of(mesh: Mesh) -> int:
        if id(mesh) not in meshes:
            pos = mesh.positions @ Z_UP_TO_Y_UP_MATRIX.T
            nrm = mesh.normals @ Z_UP_TO_Y_UP_MATRIX.T
            attrs = g.Attributes(
                POSITION=buf.add(pos.astype(np.float32), g.VEC3, g.ARRAY_BUFFER, minmax=True),
                NORMAL=buf.add(nrm.astype(np.float32), g.VEC3, g.ARRAY_BUFFER),
                TEXCOORD_0=buf.add(mesh.uv.astype(np.float32), g.VEC2, g.ARRAY_BUFFER),
                JOINTS_0=buf.add(mesh.joints.astype(np.uint16), g.VEC4, g.ARRAY_BUFFER),
                WEIGHTS_0=buf.add(mesh.weights.astype(np.float32), g.VEC4, g.ARRAY_BUFFER))
            prims = []
            for look, tris in mesh.parts:
                idx = tris.reshape(-1).astype(np.uint16 if len(pos) < 65536 else np.uint32)
                prims.append(g.Primitive(attributes=attrs, indices=buf.add(idx, g.SCALAR, g.ELEMENT_ARRAY_BUFFER),
                                         material=material(look)))
            gl.meshes.append(g.Mesh(name=mesh.name, primitives=prims))
            meshes[id(mesh)] = len(gl.meshes) - 1
        return meshes[id(mesh)]

    for rig in rigs:
        rig.check()
        keys = rig.keys(poses.t_s, tolerance, rotations)
        arm = g.Node(name=f"{prefix}{rig.name} rig", children=[], extras={"lifelike_mj_rig": rig.name, **rig.extras})
        doc.node(arm, parent)
        first = len(gl.nodes)
        for i, (bone, k) in enumerate(zip(rig.bones, keys)):
            extras = ({"secondary_motion": True} if bone.body is None else
                      {"drawn_from_body": bone.body} if bone.drawn else {"mujoco_body": bone.body})
            gl.nodes.append(g.Node(name=bone.name, translation=[float(v) for v in k.still_translation],
                                   rotation=_xyzw(k.still_rotation), children=[], extras=extras))
            (arm if bone.parent < 0 else gl.nodes[first + bone.parent]).children.append(first + i)
            if k.translation is not None:
                doc.channel(poses.t_s, first + i, "translation", k.translation, k.translation_values)
            if k.cycle is not None:
                doc.cycle_channel(rig.cycle, rig.cycle_part(bone), rig.group, first + i)
            elif k.rotation is not None:
                doc.channel(poses.t_s, first + i, "rotation", k.rotation, k.rotation_values[:, [1, 2, 3, 0]])
        ibm = np.stack([np.linalg.inv(R @ b.bind).T for b in rig.bones]).astype(np.float32)  # column-major
        if ibm.tobytes() not in binds:
            binds[ibm.tobytes()] = buf.add(ibm, g.MAT4)
        gl.skins.append(g.Skin(name=f"{prefix}{rig.name}", joints=list(range(first, first + len(rig.bones))),
                               inverseBindMatrices=binds[ibm.tobytes()]))
        doc.node(g.Node(name=f"{prefix}{rig.name} mesh", mesh=mesh_of(rig.mesh), skin=len(gl.skins) - 1), None)
        report[rig.name] = rig.key_counts(poses.t_s, tolerance, rotations)
    return report


def add_camera(doc: Doc, parent: g.Node, name: str, quat_wxyz: np.ndarray, position_m: np.ndarray,
               distance_m: float, t: np.ndarray | None = None, keys: np.ndarray | None = None) -> int:
    """A perspective camera (field of view :data:`~lifelike_mj.export.cameras.FOV_DEG`) named ``name`` on a node
    ``camera <name>`` under ``parent``, turned by ``quat_wxyz`` (it looks along its own -Z, +Y up), at
    ``position_m`` (one place, or a path over the times ``t`` keyed at ``keys``); ``distance_m`` (from what it
    looks at) sets its near plane. Returns the node."""
    doc.gl.cameras.append(g.Camera(name=name, type="perspective", perspective=g.Perspective(
        yfov=math.radians(FOV_DEG), znear=max(distance_m / 1000.0, 1e-4))))
    position_m = np.asarray(position_m, dtype=float)
    first = position_m if position_m.ndim == 1 else position_m[0]
    idx = doc.node(g.Node(name=f"camera {name}", camera=len(doc.gl.cameras) - 1, rotation=_xyzw(quat_wxyz),
                          translation=[float(v) for v in first]), parent)
    if position_m.ndim == 2 and keys is not None:
        doc.channel(t, idx, "translation", keys, position_m[keys])
    return idx


def _add_cameras(doc: Doc, poses: Poses, tracks: dict[int, Track], tolerance=DEFAULT_TOLERANCE) -> None:
    """The overview camera and, for one creature, the follow camera (:mod:`lifelike_mj.export.cameras`), as
    nodes under the root (MuJoCo's world); the follow camera keeps its body's translation keys (it moves by
    the same path, shifted)."""
    f = framing(poses)
    look = f.look_quat_wxyz()
    add_camera(doc, doc.root, "overview", look, f.centre_m + f.direction * f.overview_m, f.overview_m)
    if f.follow is None:
        return
    path = poses.position_m[:, f.follow] + f.direction * f.follow_m
    track = tracks.get(f.follow) or body_tracks(poses.t_s, poses.position_m[:, [f.follow]],
                                                poses.quat_wxyz[:, [f.follow]], tolerance, doc.rotations)[0]
    add_camera(doc, doc.root, "follow", look, path, f.follow_m, poses.t_s, track.translation)


def write_gltf(poses: Poses, path: str | Path, name: str = "lifelike-mj run", parameters: dict | None = None,
               rotations: str = "short", tolerance=DEFAULT_TOLERANCE, rigs: list[Rig] | None = None) -> Path:
    """Write ``poses`` as animated glTF 2.0: binary (``.glb``) or JSON with the buffer inside (``.gltf``),
    atomically, with the provenance (:func:`build_gltf`; ``parameters``: what made the run; ``rotations``:
    ``"short"`` or ``"float"`` keys; ``tolerance``: the keys' (m, deg)). Returns the path."""
    path = Path(path)
    if path.suffix.lower() not in (".glb", ".gltf"):
        raise UserError(f"a glTF file ends in .glb or .gltf, got {path.name!r}.")
    return save(build_gltf(poses, name, parameters, rotations, tolerance, rigs), path)


def save(gl: g.GLTF2, path: str | Path) -> Path:
    """Write the document ``gl`` to ``path``, binary (``.glb``) or JSON with the buffer inside (``.gltf``),
    atomically. Returns the path."""
    path = Path(path)
    if path.suffix.lower() not in (".glb", ".gltf"):
        raise UserError(f"a glTF file ends in .glb or .gltf, got {path.name!r}.")
    with atomic_path(path) as tmp:
        if path.suffix.lower() == ".glb":
            gl.save_binary(str(tmp))
        else:
            gl.convert_buffers(g.BufferFormat.DATAURI)  # the buffer inside the JSON, base64
            gl.save_json(str(tmp))
    return path
