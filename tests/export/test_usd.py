"""Animated USD of a run, read back with usd-core: every body and geom where the simulation had it."""

import json

import mujoco
import numpy as np
import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.errors import UserError
from lifelike_mj.export.poses import drawn_geoms, record_poses
from lifelike_mj.export.rig import qconj, qmul, qrot
from lifelike_mj.export.usd import write_usd

pxr = pytest.importorskip("pxr", reason="usd-core is not installed (the usd extra)")
from pxr import Usd, UsdGeom  # noqa: E402


def _rotation_error(R, q_wxyz):
    m = np.empty(9)
    mujoco.mju_quat2Mat(m, np.asarray(q_wxyz, dtype=float))
    c = (np.trace(np.asarray(R) @ m.reshape(3, 3).T) - 1.0) / 2.0
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_the_stage_read_back_puts_every_body_and_geom_where_the_simulation_had_it(tmp_path, suffix):
    f = Flight3D(controller=flight3d.withdrawn_file("steer"), task=flight3d.course(100))
    poses = record_poses(f, 1.0, fps=30.0)
    path = write_usd(poses, tmp_path / f"run{suffix}", parameters={"controller": "steer"})
    stage = Usd.Stage.Open(str(path))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z and UsdGeom.GetStageMetersPerUnit(stage) == 1.0
    assert stage.GetTimeCodesPerSecond() == pytest.approx(30.0, rel=1e-3) and stage.GetEndTimeCode() == 30
    prov = json.loads(stage.GetRootLayer().customLayerData["lifelike_mj"])
    assert prov["versions"]["lifelike-mj"] and prov["command"] and prov["parameters"] == {"controller": "steer"}
    prims = {p.GetCustomDataByKey("mujoco_body"): p for p in stage.Traverse() if p.GetCustomDataByKey("mujoco_body")}
    assert sorted(prims) == sorted(poses.body_names)
    cache = UsdGeom.XformCache()
    for k in range(poses.n_samples):  # every body at every sample (1,200/s), between frames too: within 0.5 mm and
        cache.SetTime(Usd.TimeCode(float((poses.t_s[k] - poses.t_s[0]) * poses.fps)))  # 0.5 deg, USD interpolating
        for b, name in enumerate(poses.body_names):
            M = np.array(cache.GetLocalToWorldTransform(prims[name]))  # USD: row vectors, translation in row 3
            assert np.linalg.norm(M[3, :3] - poses.position_m[k, b]) <= 0.0005
            assert _rotation_error(M[:3, :3].T, poses.quat_wxyz[k, b]) <= np.radians(0.5)
    counts = prov["keys"]["per_body"]
    assert all(1 < c["rotation"] < poses.n_samples for c in counts.values())
    for name in poses.body_names:  # the keys are few, and where the file says
        orient = [a for a in prims[name].GetAttributes() if a.GetName() == "xformOp:orient"][0]
        assert len(orient.GetTimeSamples()) == counts[name]["rotation"]
    cache.SetTime(Usd.TimeCode(30))
    m, d = f.model, f.data  # the last frame: every drawn geom of a body, through its reference and place
    seen = 0
    for prim in prims.values():
        for child in prim.GetChildren():
            geom = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, child.GetCustomDataByKey("mujoco_geom"))
            M = np.array(cache.GetLocalToWorldTransform(child))
            np.testing.assert_allclose(M[3, :3], d.geom_xpos[geom], atol=1e-4)
            assert UsdGeom.Mesh(child).GetPointsAttr().Get()  # the referenced shape's triangles
            seen += 1
    drawn = drawn_geoms(m)
    assert seen == int(np.sum(m.geom_bodyid[drawn] > 0))


def test_a_flock_stores_one_shape_and_bad_names_are_refused(tmp_path):
    from lifelike_mj.boids import Flock

    poses = record_poses(Flock(n=300, seed=1), 20.0, fps=1.0)
    stage = Usd.Stage.Open(str(write_usd(poses, tmp_path / "flock.usdc")))
    shapes = stage.GetPrimAtPath("/Shapes").GetAllChildren()
    bodies = [p for p in stage.Traverse() if p.GetCustomDataByKey("mujoco_body")]
    assert len(bodies) == 300 and len(shapes) < 10
    last = UsdGeom.XformCache(Usd.TimeCode(poses.n_frames - 1))
    for b, prim in enumerate(bodies):
        assert prim.GetCustomDataByKey("mujoco_body") == poses.body_names[b]
        np.testing.assert_allclose(np.array(last.GetLocalToWorldTransform(prim))[3, :3], poses.position_m[-1, b],
                                   atol=1e-4)
    with pytest.raises(UserError, match=r"\.usda"):
        write_usd(poses, tmp_path / "flock.glb")


def _usd_validation(stage) -> list[str]:
    """Every error and warning of usd-core's own validators (UsdValidation, all registered ones)."""
    from pxr import UsdValidation

    context = UsdValidation.ValidationContext(UsdValidation.ValidationRegistry().GetOrLoadAllValidators())
    return [f"{e.GetType()} {e.GetName()}: {e.GetMessage()}" for e in context.Validate(stage)]


def test_usd_cores_validators_find_nothing_in_any_creatures_stage(runs, creature, tmp_path):
    from lifelike_mj.export.usd import build_stage

    _, poses = runs(creature)
    stage = build_stage(poses)
    assert _usd_validation(stage) == []
    # every mesh's topology holds together (the validators do not look; Blender 5.0's importer crashed on a
    # box given one face per corner)
    shapes = stage.GetPrimAtPath("/Shapes").GetAllChildren()  # a class prim: its children are abstract
    assert shapes
    for prim in shapes:
        mesh = UsdGeom.Mesh(prim)
        counts = np.array(mesh.GetFaceVertexCountsAttr().Get())
        indices = np.array(mesh.GetFaceVertexIndicesAttr().Get())
        points = mesh.GetPointsAttr().Get()
        assert np.all(counts == 3) and counts.sum() == len(indices) and indices.max() < len(points)
        assert len(mesh.GetNormalsAttr().Get()) == len(points)
    bare = Usd.Stage.CreateInMemory()  # the validators do speak: a stage without its metadata is refused
    UsdGeom.Xform.Define(bare, "/World")
    assert _usd_validation(bare)


def test_a_rigged_stage_is_a_usdskel_whose_joints_follow_every_sample(runs, creature):
    """Rigs as UsdSkel: a SkelRoot per creature, its Skeleton's joints named as the bones (MJCF names in
    ``jointNames``), the skinned mesh bound to it; usd-core's validators find nothing, and usd-core's own skeleton
    evaluation puts every joint of the first creature within the key tolerance of its bone at every sample."""
    import importlib

    from pxr import UsdSkel

    _, poses = runs(creature)
    looks = {"butterfly3d": "butterfly", "butterfly2d": "butterfly", "fish": "fish", "boids": "boids"}[creature]
    rigs = importlib.import_module(f"lifelike_mj.{looks}.look").rigs(poses)[:20]  # a flock: 20 birds are plenty
    stage = build_stage_rigged(poses, rigs)
    assert _usd_validation(stage) == []
    roots = [p for p in stage.Traverse() if p.GetTypeName() == "SkelRoot"]
    assert sorted(r.GetCustomDataByKey("lifelike_mj_rig") for r in roots) == sorted(r.name for r in rigs)
    rig = rigs[min(1, len(rigs) - 1)]  # a flock's second bird: the first plays the beat at phase 0
    root = next(r for r in roots if r.GetCustomDataByKey("lifelike_mj_rig") == rig.name)
    skel = UsdSkel.Skeleton(root.GetChild("Skeleton"))
    assert list(skel.GetJointNamesAttr().Get()) == [b.name for b in rig.bones]
    binding = UsdSkel.BindingAPI(root.GetChild("Mesh"))
    assert binding.GetSkeletonRel().GetTargets() == [skel.GetPath()]
    query = UsdSkel.Cache().GetSkelQuery(skel)
    crowd = rig.cycle is not None  # a flock: its SkelRoot carries the drawn bird, its wings the shared wing beat
    for k in range(0, poses.n_samples, max(1, poses.n_samples // 200)):
        code = Usd.TimeCode(float((poses.t_s[k] - poses.t_s[0]) * poses.fps))
        xf = query.ComputeJointSkelTransforms(code)
        place = np.array(UsdGeom.Xformable(root).ComputeLocalToWorldTransform(code)).T if crowd else np.eye(4)
        world = [place @ np.array(x).T for x in xf]  # USD: row vectors
        for j, b in enumerate(rig.bones):
            M, want_p, want_q = world[j], b.position_m[k], b.quat_wxyz[k]
            if crowd and b.parent >= 0:  # channel by channel: in its parent's frame, as drawn
                if rig.cycle_part(b) is None:
                    continue  # the tail rests in USD (its skeleton's one animation is the shared beat)
                pb = rig.bones[b.parent]
                M = np.linalg.inv(world[b.parent]) @ M
                want_p = qrot(qconj(pb.quat_wxyz[k]), b.position_m[k] - pb.position_m[k])
                want_q = qmul(qconj(pb.quat_wxyz[k]), b.quat_wxyz[k])
            assert np.linalg.norm(M[:3, 3] - want_p) <= 0.0005, (k, b.name)
            assert _rotation_error(M[:3, :3], want_q) <= np.radians(0.5), (k, b.name)
    if crowd:  # the wing beat is stored once: every bird's animation references it, offset by its phase
        base = [p for p in stage.Traverse() if p.GetTypeName() == "SkelAnimation" and p.GetParent().GetName() == "Cycles"]
        assert len(base) == 1
        offsets = {p.GetPrimStack()[0].referenceList.prependedItems[0].layerOffset.offset
                   for p in stage.Traverse() if p.GetTypeName() == "SkelAnimation" and p.GetName() == "Animation"}
        assert len(offsets) > 5


def build_stage_rigged(poses, rigs):
    from lifelike_mj.export.usd import build_stage

    return build_stage(poses, rigs=rigs)


def test_a_usdz_package_holds_the_rigs_textures_which_its_materials_read(runs, tmp_path):
    """``.usdz``: the stage and the rigs' texture images in one package; each textured look reads its own image
    (the same pixels) at the mesh's ``st``; usd-core's validators (the package's among them) find nothing. A
    ``.usdc`` of the same run holds no image (its looks take the mean colour)."""
    import io
    import posixpath
    import zipfile

    from PIL import Image
    from pxr import UsdShade

    from lifelike_mj.fish.look import rigs as fish_rigs

    _, poses = runs("fish")
    rigs = fish_rigs(poses)
    path = write_usd(poses, tmp_path / "tank.usdz", rigs=rigs)
    stage = Usd.Stage.Open(str(path))
    assert _usd_validation(stage) == []
    images = {lk.name: lk.image for r in rigs for lk, _ in r.mesh.parts if lk.image is not None}
    assert images
    read = {}
    with zipfile.ZipFile(path) as z:
        for prim in stage.Traverse():
            shader = UsdShade.Shader(prim)
            if prim.GetTypeName() == "Shader" and shader.GetIdAttr().Get() == "UsdUVTexture":
                file = posixpath.normpath(shader.GetInput("file").Get().path)  # relative to the stage, its root
                look = prim.GetParent().GetName()
                read[look] = np.asarray(Image.open(io.BytesIO(z.read(file))).convert("RGBA"))
                surface = UsdShade.Shader(prim.GetParent().GetChild("surface"))
                source = surface.GetInput("diffuseColor").GetConnectedSources()[0][0]
                assert source.source.GetPath() == prim.GetPath()
    assert set(read) == set(images)
    for name, image in images.items():
        np.testing.assert_array_equal(read[name], image)
    plain = Usd.Stage.Open(str(write_usd(poses, tmp_path / "tank.usdc", rigs=rigs)))
    assert not any(p.GetTypeName() == "Shader" and UsdShade.Shader(p).GetIdAttr().Get() == "UsdUVTexture"
                   for p in plain.Traverse())
