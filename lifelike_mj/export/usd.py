"""Animated USD (``.usda`` text, ``.usdc``/``.usd`` binary, ``.usdz`` a package with the textures) of recorded
body poses, written with ``usd-core`` (the ``usd`` extra: ``pip install "lifelike-mj[usd]"``).

Layout of the stage (Z up, metres, as MuJoCo's world; ``timeCodesPerSecond`` is the frame rate and time code
``k`` is frame ``k``):

* ``/World``: one ``Xform`` per exported body (its MuJoCo name in ``customData["mujoco_body"]`` and in the
  attribute ``userProperties:mujoco_body``, which Blender shows as a custom property), animated
  (``xformOp:translate`` and ``xformOp:orient`` time samples at each channel's keys, which may fall between
  frames, 32-bit floats; a body that never moves holds one still value), and the world body's drawn geoms as
  still meshes;
* under each body, one ``Mesh`` per drawn geom at its place in the body;
* ``/Shapes`` (a class, not drawn): one mesh per distinct shape, which the geoms reference, so a flock of
  hundreds stores one bird; ``/Looks``: one ``UsdPreviewSurface`` material per look,
  named as the MJCF's material (or after the first geom that wears it).

The provenance (versions, command, time, parameters, the frames' count, rate and span) is the root layer's
``customLayerData["lifelike_mj"]``, as strict JSON text.

MuJoCo ships its own exporter (``mujoco.usd``). It is not used here: it writes a folder (``frames/frame_N``
and ``assets/``) rather than the file asked for, animates every geom of the rendering scene rather than
the bodies, and updates them one by one in Python; on this project's 2-core machine it took 1.5 s per
frame for a flock of 300 (50 min for 2,001 frames), where this writer takes seconds.
"""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.keys import DEFAULT_TOLERANCE, body_tracks, key_counts, tolerance_of
from lifelike_mj.export.poses import Poses, drawn_geoms, geom_looks, geom_rgba
from lifelike_mj.export.shapes import geom_shape, shape_key
from lifelike_mj.io import atomic_path, strict
from lifelike_mj.provenance import provenance


def require_usd():
    """usd-core's modules, or a :class:`UserError` saying how to install them."""
    try:
        from pxr import Gf, Sdf, Usd, UsdGeom, UsdShade, Vt
    except ImportError:
        raise UserError('USD export needs usd-core: pip install "lifelike-mj[usd]" (or pip install usd-core).') from None
    return Gf, Sdf, Usd, UsdGeom, UsdShade, Vt


def _ident(text: str, used: set[str]) -> str:
    """A valid, unused prim name for ``text`` (MJCF names may hold ``/`` and other characters USD refuses)."""
    from pxr import Tf

    base = Tf.MakeValidIdentifier(text) or "_"
    name, k = base, 1
    while name in used:
        k += 1
        name = f"{base}_{k}"
    used.add(name)
    return name


def build_stage(poses: Poses, name: str = "lifelike-mj run", parameters: dict | None = None,
                tolerance=DEFAULT_TOLERANCE, rigs: list | None = None, images: dict | None = None):
    """The USD stage (module docstring) of ``poses``, in memory; :func:`write_usd` writes it. Each body's
    translation and orientation have their own time samples: the keys that keep interpolation (linear, and
    slerp, which USD uses for quaternions) within ``tolerance`` (m, deg) of every sample
    (:mod:`lifelike_mj.export.keys`), at fractional time codes where they fall between frames.

    ``images``: where a dict is given (a ``.usdz`` package), a rig's textured look reads its texture from
    ``textures/<look>.png`` (a ``UsdUVTexture`` on the mesh's ``st``) and the image is put in ``images`` under
    that path for the writer to package; otherwise it takes the texture's mean colour."""
    Gf, Sdf, Usd, UsdGeom, UsdShade, Vt = require_usd()
    m = poses.model
    n = poses.n_frames
    span = float(poses.t_s[-1] - poses.t_s[0])
    fps = poses.fps if poses.fps > 0 else 1.0
    tolerance = tolerance_of(tolerance)
    rigged = {bone.body for r in rigs or [] for bone in r.bones if bone.body is not None}
    plain = [b for b, n in enumerate(poses.body_names) if n not in rigged]  # bodies written with their geoms
    tracks = dict(zip(plain, body_tracks(poses.t_s, poses.position_m[:, plain], poses.quat_wxyz[:, plain], tolerance,
                                         "float"))) if plain else {}
    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetTimeCodesPerSecond(fps)
    stage.SetFramesPerSecond(fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(n - 1)
    prov = provenance(**(parameters or {}))
    prov["frames"] = {"count": n, "per_s": float(fps), "start_s": float(poses.t_s[0]), "end_s": float(poses.t_s[-1]),
                      "bodies": len(poses.body_ids)}
    prov["keys"] = {"tolerance_m": tolerance[0], "tolerance_deg": tolerance[1], "samples": poses.n_samples,
                    "samples_per_s": (poses.n_samples - 1) / span if span > 0 else 0.0,
                    "per_body": key_counts([tracks[b] for b in plain], [poses.body_names[b] for b in plain])}
    stage.GetRootLayer().customLayerData = {"lifelike_mj": json.dumps(strict(prov), allow_nan=False)}
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    world.GetPrim().SetDocumentation(name)
    shapes = stage.CreateClassPrim("/Shapes")
    UsdGeom.Scope.Define(stage, "/Looks")
    rgba = geom_rgba(m)
    meshes: dict[tuple, str] = {}
    looks: dict[int, UsdShade.Material] = {}

    def shape_of(geom: int) -> str:
        key = shape_key(m, geom)
        if key not in meshes:
            pos, nrm, tri = geom_shape(m, geom)
            path = shapes.GetPath().AppendChild(f"shape{len(meshes)}")
            mesh = UsdGeom.Mesh.Define(stage, path)
            mesh.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(pos.astype(np.float32)))
            mesh.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(nrm.astype(np.float32)))
            mesh.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
            mesh.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(tri), 3, dtype=np.int32)))
            mesh.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(tri.reshape(-1).astype(np.int32)))
            mesh.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
            mesh.CreateDoubleSidedAttr(True)
            meshes[key] = str(path)
        return meshes[key]

    look, look_names = geom_looks(m)
    look_used: set[str] = set()

    def material(name: str, rgb, opacity: float, roughness: float):
        mat = UsdShade.Material.Define(stage, f"/Looks/{_ident(name, look_used)}")
        shader = UsdShade.Shader.Define(stage, mat.GetPath().AppendChild("surface"))
        shader.CreateIdAttr("UsdPreviewSurface")
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*map(float, rgb)))
        shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(float(opacity))
        shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(float(roughness))
        mat.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        return mat

    def look_of(geom: int):
        colour = tuple(np.round(rgba[geom], 6).tolist())
        if look[geom] not in looks:
            looks[int(look[geom])] = material(look_names[look[geom]], colour[:3], colour[3], 0.8)
        return looks[int(look[geom])]

    rig_looks: dict[int, UsdShade.Material] = {}

    def look_of_rig(lk):
        """A rig's look: its texture where the file is a package (``images``), else its colour times its
        texture's mean (a .usda or .usdc file holds no image of its own)."""
        if id(lk) not in rig_looks:
            rgb = np.asarray(lk.rgba[:3], dtype=float)
            if lk.image is not None and images is None:
                rgb = rgb * lk.image[..., :3].reshape(-1, 3).mean(axis=0) / 255.0
            mat = material(lk.name, rgb, lk.rgba[3], lk.roughness)
            if lk.image is not None and images is not None:
                _texture(stage, mat, lk, images)
            rig_looks[id(lk)] = mat
        return rig_looks[id(lk)]

    def still(parent: Sdf.Path, geom: int, used: set[str]) -> None:
        gname = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, geom) or f"geom{geom}"
        prim = stage.DefinePrim(parent.AppendChild(_ident(gname, used)))
        prim.GetReferences().AddInternalReference(shape_of(geom))
        prim.SetCustomDataByKey("mujoco_geom", gname)
        xf = UsdGeom.Xformable(prim)
        xf.AddTranslateOp().Set(Gf.Vec3d(*map(float, m.geom_pos[geom])))
        w, x, y, z = map(float, m.geom_quat[geom])
        xf.AddOrientOp(UsdGeom.XformOp.PrecisionDouble).Set(Gf.Quatd(w, x, y, z))
        UsdShade.MaterialBindingAPI.Apply(prim).Bind(look_of(geom))

    drawn = drawn_geoms(m)
    used: set[str] = set()
    for geom in drawn[m.geom_bodyid[drawn] == 0]:
        still(world.GetPath(), int(geom), used)
    ops = []
    for body, bname in zip(poses.body_ids[plain], [poses.body_names[b] for b in plain]):
        xf = UsdGeom.Xform.Define(stage, world.GetPath().AppendChild(_ident(bname, used)))
        xf.GetPrim().SetCustomDataByKey("mujoco_body", bname)
        # and as a user property, which Blender's USD importer turns into the object's custom property
        xf.GetPrim().CreateAttribute("userProperties:mujoco_body", Sdf.ValueTypeNames.String).Set(bname)
        ops.append((xf.AddTranslateOp(UsdGeom.XformOp.PrecisionFloat), xf.AddOrientOp(UsdGeom.XformOp.PrecisionFloat)))
        inner: set[str] = set()
        for geom in drawn[m.geom_bodyid[drawn] == body]:
            still(xf.GetPath(), int(geom), inner)
    pos = poses.position_m.astype(np.float32).astype(float)  # the values the file holds
    quat = poses.quat_wxyz.astype(np.float32).astype(float)
    codes = (poses.t_s - poses.t_s[0]) * fps  # each sample's time code: frame k at code k
    with Sdf.ChangeBlock():  # the prims exist: only values change from here
        for b, (translate, orient) in zip(plain, ops):
            track = tracks[b]
            for op, keys, values, kind in ((translate, track.translation, pos[:, b], Gf.Vec3f),
                                           (orient, track.rotation, quat[:, b], Gf.Quatf)):
                # still over the whole run: one value, no samples
                _set_samples(op, kind, codes, keys, values if keys is None else values[keys], values[0])
    if rigs:  # prims are defined: outside the change block
        prov["rigs"] = _add_rigs(stage, world.GetPath(), rigs, poses.t_s, fps, tolerance, used, look_of_rig)
        stage.GetRootLayer().customLayerData = {"lifelike_mj": json.dumps(strict(prov), allow_nan=False)}
    return stage


def _texture(stage, mat, look, images: dict) -> None:
    """Feed ``look``'s texture (``textures/<material>.png``, put in ``images``) into ``mat``'s surface: a
    ``UsdUVTexture`` read at the mesh's ``st`` by a ``UsdPrimvarReader_float2``, its colour times the look's
    as the diffuse colour, its alpha times the look's as the opacity."""
    from pxr import Gf, Sdf, UsdShade

    # "./" marks the path as the layer's own: usd-core's packager keeps it as it is (a bare "textures/x.png" is
    # moved to "0/x.png" in the package, with a warning that it cannot resolve the moved path)
    file = f"./textures/{mat.GetPath().name}.png"
    images[file] = look.image
    reader = UsdShade.Shader.Define(stage, mat.GetPath().AppendChild("st"))
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.String).Set("st")
    tex = UsdShade.Shader.Define(stage, mat.GetPath().AppendChild("texture"))
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(file))
    tex.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    tex.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("clamp")
    tex.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("clamp")
    r, g, b, a = (float(v) for v in look.rgba)
    tex.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(r, g, b, a))
    tex.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    tex.CreateOutput("a", Sdf.ValueTypeNames.Float)
    surface = UsdShade.Shader(stage.GetPrimAtPath(mat.GetPath().AppendChild("surface")))
    surface.GetInput("diffuseColor").ConnectToSource(tex.ConnectableAPI(), "rgb")
    surface.GetInput("opacity").ConnectToSource(tex.ConnectableAPI(), "a")


def _add_rigs(stage, world_path, rigs, t, fps, tolerance, used, looks_of):
    """Each rig as a UsdSkel SkelRoot under ``world_path`` (module docstring): a Skeleton whose joints are the
    rig's bones (their MJCF names in ``jointNames``), its SkelAnimation (joint-local translations and rotations
    sampled at every key time of any of its bones, between frames where they fall; each bone's value there is its
    keys' interpolation, so within the tolerance), and the skinned mesh (``skel:jointIndices``/``jointWeights``,
    ``primvars:st``) with one material per look. Returns each rig's keys per bone."""
    from pxr import Gf, Sdf, UsdGeom, UsdSkel, Vt

    from lifelike_mj.export.rig import bone_play

    report = {}
    shared: dict[str, Sdf.Path] = {}  # a crowd's cycle: its one SkelAnimation, which each agent's references
    for rig in rigs:
        rig.check()
        crowd = rig.cycle is not None
        keys = rig.keys(t, tolerance, "float")
        root = UsdSkel.Root.Define(stage, Sdf.Path(world_path).AppendChild(_ident(f"{rig.name} rig", used)))
        root.GetPrim().SetCustomDataByKey("lifelike_mj_rig", rig.name)
        if crowd:  # the agent's drawn motion moves its SkelRoot; its skeleton's root joint rests
            _key_xform(UsdGeom.Xformable(root), keys[0], t, fps)
        skel = UsdSkel.Skeleton.Define(stage, root.GetPath().AppendChild("Skeleton"))
        paths, inner = [], {}
        for b in rig.bones:
            seen = inner.setdefault(b.parent, set())
            own = _ident(b.name.rsplit("/", 1)[-1], seen)
            paths.append(own if b.parent < 0 else f"{paths[b.parent]}/{own}")
        skel.CreateJointsAttr(Vt.TokenArray(paths))
        skel.CreateJointNamesAttr(Vt.TokenArray([b.name for b in rig.bones]))

        def m4(M):
            return Gf.Matrix4d(*np.asarray(M, dtype=float).T.reshape(-1).tolist())  # USD: row vectors

        skel.CreateBindTransformsAttr(Vt.Matrix4dArray([m4(b.bind) for b in rig.bones]))
        rest = [b.bind if b.parent < 0 else np.linalg.inv(rig.bones[b.parent].bind) @ b.bind for b in rig.bones]
        skel.CreateRestTransformsAttr(Vt.Matrix4dArray([m4(M) for M in rest]))
        if crowd:
            anim = _crowd_animation(stage, world_path, rig, keys, paths, t, fps, shared, skel.GetPath())
        else:
            anim = UsdSkel.Animation.Define(stage, skel.GetPath().AppendChild("Animation"))
            anim.CreateJointsAttr(Vt.TokenArray(paths))
            codes = (t - t[0]) * fps
            tk = sorted({int(i) for k in keys if k.translation is not None for i in k.translation} | {0, len(t) - 1})
            rk = sorted({int(i) for k in keys if k.rotation is not None for i in k.rotation} | {0, len(t) - 1})
            played = bone_play(t, rig, keys)
            trans = np.stack([p for p, _ in played], axis=1)
            rots = np.stack([q for _, q in played], axis=1)
            ta, ra = anim.CreateTranslationsAttr(), anim.CreateRotationsAttr()
            for i in tk:
                ta.Set(Vt.Vec3fArray.FromNumpy(trans[i].astype(np.float32)), float(codes[i]))
            for i in rk:
                ra.Set(Vt.QuatfArray([Gf.Quatf(*map(float, q)) for q in rots[i]]), float(codes[i]))
            anim.CreateScalesAttr().Set(Vt.Vec3hArray([Gf.Vec3h(1.0, 1.0, 1.0)] * len(paths)))
        UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets([anim.GetPath()])
        _skinned_mesh(stage, root, skel, rig, looks_of)
        report[rig.name] = rig.key_counts(t, tolerance, "float")
    return report


def _set_samples(op, kind, codes, idx, values, still) -> None:
    """Set an xform op's time samples: ``values`` (each a ``kind``) at the time codes ``codes[idx]``; with ``idx``
    None, one value ``still`` and no samples."""
    from pxr import Usd

    if idx is None:
        op.Set(kind(*map(float, still)))
        return
    for i, v in zip(idx, values):
        op.Set(kind(*map(float, v)), Usd.TimeCode(float(codes[i])))


def _key_xform(xf, k, t, fps) -> None:
    """Key a prim's translate and orient ops from a bone's world keys ``k`` (:class:`~lifelike_mj.export.rig.BoneKeys`)
    at their time codes (a still channel: one value)."""
    from pxr import Gf, UsdGeom

    codes = (t - t[0]) * fps
    _set_samples(xf.AddTranslateOp(UsdGeom.XformOp.PrecisionFloat), Gf.Vec3f, codes, k.translation,
                 k.translation_values, k.still_translation)
    _set_samples(xf.AddOrientOp(UsdGeom.XformOp.PrecisionFloat), Gf.Quatf, codes, k.rotation, k.rotation_values,
                 k.still_rotation)


def _crowd_animation(stage, world_path, rig, keys, paths, t, fps, shared: dict, skel_path):
    """A crowd agent's SkelAnimation: an internal reference to its cycle's one shared animation (made on first use,
    under ``/World/Cycles``: the cycle's bones over the whole run and a period either side, group 0), offset in
    time by the agent's phase, with the agent's own joint paths; the bones outside the cycle rest."""
    from pxr import Gf, Sdf, UsdSkel, Vt

    cyc = rig.cycle
    parts = [(j, rig.cycle_part(b)) for j, b in enumerate(rig.bones) if rig.cycle_part(b) is not None]
    if cyc.name not in shared:
        path = Sdf.Path(world_path).AppendChild("Cycles").AppendChild(_ident(cyc.name, set()))
        base = UsdSkel.Animation.Define(stage, path)
        base.GetPrim().SetCustomDataByKey("lifelike_mj_cycle", {"period_s": cyc.period_s, "phases": cyc.groups})
        base.CreateJointsAttr(Vt.TokenArray([paths[j].rsplit("/", 1)[-1] for j, _ in parts]))
        base.CreateTranslationsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(*map(float, keys[j].still_translation))
                                                         for j, _ in parts]))
        base.CreateScalesAttr().Set(Vt.Vec3hArray([Gf.Vec3h(1.0, 1.0, 1.0)] * len(parts)))
        rot = base.CreateRotationsAttr()
        m = cyc.samples
        span = float(t[-1] - t[0])
        for i in range(-m, int(np.ceil(span / cyc.period_s)) * m + 2 * m + 1):
            values = [cyc.quat_wxyz[part][i % m] for _, part in parts]
            rot.Set(Vt.QuatfArray([Gf.Quatf(*map(float, q)) for q in values]), i * cyc.period_s / m * fps)
        shared[cyc.name] = path
    anim = UsdSkel.Animation.Define(stage, skel_path.AppendChild("Animation"))
    offset = -rig.group / cyc.groups * cyc.period_s * fps  # the agent's phase, in time codes
    anim.GetPrim().GetReferences().AddInternalReference(shared[cyc.name], Sdf.LayerOffset(offset, 1.0))
    anim.CreateJointsAttr(Vt.TokenArray([paths[j] for j, _ in parts]))
    return anim


def _skinned_mesh(stage, root, skel, rig, looks_of) -> None:
    """The rig's skinned mesh under its SkelRoot ``root``, bound to ``skel``, with one material per look."""
    from pxr import Gf, Sdf, UsdGeom, UsdShade, UsdSkel, Vt

    mesh = rig.mesh
    geom = UsdGeom.Mesh.Define(stage, root.GetPath().AppendChild("Mesh"))
    tris = np.concatenate([tr for _, tr in mesh.parts])
    geom.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(mesh.positions.astype(np.float32)))
    geom.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(mesh.normals.astype(np.float32)))
    geom.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
    geom.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(np.full(len(tris), 3, dtype=np.int32)))
    geom.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(tris.reshape(-1).astype(np.int32)))
    geom.CreateSubdivisionSchemeAttr(UsdGeom.Tokens.none)
    geom.CreateDoubleSidedAttr(True)
    lo, hi = mesh.positions.min(axis=0), mesh.positions.max(axis=0)
    geom.CreateExtentAttr(Vt.Vec3fArray([Gf.Vec3f(*map(float, lo)), Gf.Vec3f(*map(float, hi))]))
    st = UsdGeom.PrimvarsAPI(geom).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
    st.Set(Vt.Vec2fArray.FromNumpy(np.column_stack([mesh.uv[:, 0], 1.0 - mesh.uv[:, 1]]).astype(np.float32)))
    binding = UsdSkel.BindingAPI.Apply(geom.GetPrim())
    binding.CreateSkeletonRel().SetTargets([skel.GetPath()])
    binding.CreateJointIndicesPrimvar(False, 4).Set(Vt.IntArray.FromNumpy(mesh.joints.reshape(-1).astype(np.int32)))
    binding.CreateJointWeightsPrimvar(False, 4).Set(Vt.FloatArray.FromNumpy(mesh.weights.reshape(-1).astype(np.float32)))
    binding.CreateGeomBindTransformAttr(Gf.Matrix4d(1.0))
    start = 0
    if len(mesh.parts) == 1:
        UsdShade.MaterialBindingAPI.Apply(geom.GetPrim()).Bind(looks_of(mesh.parts[0][0]))
    else:
        for n, (look, tr) in enumerate(mesh.parts):
            subset = UsdGeom.Subset.CreateGeomSubset(geom, _ident(look.name, set()) + f"_{n}", UsdGeom.Tokens.face,
                                                     Vt.IntArray(list(range(start, start + len(tr)))),
                                                     UsdShade.Tokens.materialBind)
            UsdShade.MaterialBindingAPI.Apply(subset.GetPrim()).Bind(looks_of(look))
            start += len(tr)
        UsdShade.MaterialBindingAPI.Apply(geom.GetPrim())
        UsdGeom.Subset.SetFamilyType(geom, UsdShade.Tokens.materialBind, UsdGeom.Tokens.partition)


def write_usd(poses: Poses, path: str | Path, name: str = "lifelike-mj run", parameters: dict | None = None,
              tolerance=DEFAULT_TOLERANCE, rigs: list | None = None) -> Path:
    """Write ``poses`` as an animated USD stage (module docstring): ``.usda`` as text, ``.usdc`` or ``.usd``
    binary (crate), or ``.usdz``: a package (one zip file, as USD defines it) of the binary stage and the rigs'
    texture images, which its materials read; atomically, with the provenance. Returns the path."""
    path = Path(path)
    if path.suffix.lower() not in (".usda", ".usdc", ".usd", ".usdz"):
        raise UserError(f"a USD file ends in .usda, .usdc, .usd or .usdz, got {path.name!r}.")
    if path.suffix.lower() == ".usdz":
        return _write_usdz(poses, path, name, parameters, tolerance, rigs)
    stage = build_stage(poses, name, parameters, tolerance, rigs)
    with atomic_path(path) as tmp:  # the temporary file has the same ending, from which USD picks the format
        if not stage.GetRootLayer().Export(str(tmp)):
            raise UserError(f"USD could not write {path}.")
    return path


def _write_usdz(poses: Poses, path: Path, name: str, parameters: dict | None, tolerance, rigs: list | None) -> Path:
    """The ``.usdz`` package of :func:`write_usd`: the stage and its textures written into a temporary folder,
    then packaged by usd-core (``UsdUtils.CreateNewUsdzPackage``) into the file, atomically."""
    import tempfile

    from PIL import Image
    from pxr import Sdf, UsdUtils

    images: dict = {}
    stage = build_stage(poses, name, parameters, tolerance, rigs, images)
    with tempfile.TemporaryDirectory(prefix="lifelike-mj-usdz-") as folder:
        layer = Path(folder) / "stage.usdc"
        for file, image in images.items():
            (Path(folder) / file).parent.mkdir(parents=True, exist_ok=True)
            Image.fromarray(np.ascontiguousarray(image, dtype=np.uint8), "RGBA").save(Path(folder) / file, "PNG")
        if not stage.GetRootLayer().Export(str(layer)):
            raise UserError(f"USD could not write {path}.")
        with atomic_path(path) as tmp:
            if not UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(str(layer)), str(tmp)):
                raise UserError(f"USD could not package {path}.")
    return path
