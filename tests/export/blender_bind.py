"""Run by Blender: ``blender -b --python blender_bind.py -- FILE OUT.json RIG BONE FPS T1 T2 ...``.

Imports FILE (glTF) at FPS frames/s, makes a new mesh of its own (a small cube at the bone's rest place), binds
it to the bone BONE of armature RIG the way an artist replaces a creature's mesh (a vertex group named as the
bone and an Armature modifier), and writes, for each time T (s), the bound mesh's centre as Blender deforms it
and the bone's head: ``{"cube": {T: xyz}, "head": {T: xyz}}``."""

import json
import sys
import warnings

import bpy
import numpy

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    if not hasattr(numpy, "bool"):
        numpy.bool = bool

argv = sys.argv[sys.argv.index("--") + 1:]
path, out, rig, bone, fps, ts = argv[0], argv[1], argv[2], argv[3], float(argv[4]), argv[5:]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = round(fps)
scene.render.fps_base = round(fps) / fps
bpy.ops.import_scene.gltf(filepath=path)
arm = bpy.data.objects[rig]
head = arm.matrix_world @ arm.data.bones[bone].head_local  # where the bone rests
size = 0.002
verts = [(head.x + sx * size, head.y + sy * size, head.z + sz * size) for sx in (-1, 1) for sy in (-1, 1)
         for sz in (-1, 1)]
faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
mesh = bpy.data.meshes.new("my mesh")
mesh.from_pydata(verts, [], faces)
cube = bpy.data.objects.new("my mesh", mesh)
scene.collection.objects.link(cube)
group = cube.vertex_groups.new(name=bone)
group.add(list(range(8)), 1.0, "REPLACE")
mod = cube.modifiers.new("armature", "ARMATURE")
mod.object = arm
result = {"cube": {}, "head": {}}
for t in ts:
    frame = float(t) * fps
    scene.frame_set(int(frame // 1), subframe=frame - int(frame // 1))
    dg = bpy.context.evaluated_depsgraph_get()
    ev = cube.evaluated_get(dg)
    pts = [ev.matrix_world @ v.co for v in ev.data.vertices]
    result["cube"][t] = [sum(p[i] for p in pts) / len(pts) for i in range(3)]
    pb = arm.evaluated_get(dg).pose.bones[bone]
    result["head"][t] = list(arm.matrix_world @ pb.head)
with open(out, "w") as fh:
    json.dump(result, fh)
