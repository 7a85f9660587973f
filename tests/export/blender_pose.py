"""Run by Blender: ``blender -b --python blender_pose.py -- FILE OUT.json FPS T1 T2 ...``, or by a Python that
has Blender as a module (PyPI's ``bpy``): ``python blender_pose.py -- FILE OUT.json FPS T1 T2 ...``.

Imports FILE (.glb/.gltf with Blender's glTF importer, .usd* with its USD importer) into an empty scene at FPS
frames per second and writes, for each time T (s from the start), every imported body's world matrix as
Blender evaluates it at frame ``T x FPS`` (a subframe where it falls between frames), and every armature's
bones' world matrices: ``{"frames": {T: {body: 4x4}}, "bones": {T: {bone: 4x4}}, "armatures": {armature:
[bones]}, "blender": version}`` (or ``{"error": ...}`` where it cannot import the format).
Bodies are found by their ``mujoco_body`` custom property (glTF: the node's extras; USD: the Xform's
``userProperties:mujoco_body``).
"""

import json
import sys

import bpy
import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Blender 3.4's glTF importer still uses numpy.bool, which numpy 1.24 lacks

argv = sys.argv[sys.argv.index("--") + 1:]
path, out, fps, ts = argv[0], argv[1], float(argv[2]), argv[3:]
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
frames = {t: float(t) * fps for t in ts}
if path.lower().endswith((".glb", ".gltf")):
    scene.render.fps = round(fps)  # the importer turns the keys' seconds into frames at the scene's rate
    scene.render.fps_base = round(fps) / fps
    bpy.ops.import_scene.gltf(filepath=path)
    bodies = {o.name: o["mujoco_body"] for o in bpy.data.objects if "mujoco_body" in o.keys()}
else:
    if "usd_import" not in dir(bpy.ops.wm):  # Debian's Blender is built without USD
        with open(out, "w") as fh:
            json.dump({"blender": bpy.app.version_string, "error": "this Blender has no USD importer"}, fh)
        sys.exit(0)
    # every Xform its own object (Blender merges a body with its only mesh by default: the object is then the
    # mesh, at the geom's place in the body)
    bpy.ops.wm.usd_import(filepath=path, merge_parent_xform=False)
    bodies = {o.name: o["mujoco_body"] for o in bpy.data.objects if "mujoco_body" in o.keys()}  # code k: frame k
arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
result = {"blender": bpy.app.version_string, "frames": {}, "bones": {},
          "armatures": {o.name: [b.name for b in o.data.bones] for o in arms}}
for k, frame in frames.items():
    whole = int(frame // 1)
    scene.frame_set(whole, subframe=frame - whole)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    result["frames"][str(k)] = {body: [list(r) for r in bpy.data.objects[name].evaluated_get(depsgraph).matrix_world]
                                for name, body in bodies.items()}
    result["bones"][str(k)] = {b.name: [list(r) for r in (o.matrix_world @ b.matrix)] for o in arms
                               for b in o.evaluated_get(depsgraph).pose.bones}
with open(out, "w") as fh:
    json.dump(result, fh)
