"""Run by Blender: import an exported flight and save it as a .blend, ready to play.

    lifelike-mj export butterfly3d --task course --seed 101 --duration 6 --out flight.glb
    blender -b --python examples/blender/import_flight.py -- flight.glb flight.blend

The scene's frame rate is set to the file's (30 frames/s), its frame range to the flight's, and the
flight's ``camera follow`` becomes the scene camera. Debian's Blender 3.4 with Debian's numpy 1.24 needs
the ``numpy.bool`` alias below; newer Blenders do not.
"""

import sys

import bpy
import numpy

if not hasattr(numpy, "bool"):
    numpy.bool = bool  # Blender 3.4's glTF importer still uses numpy.bool

glb, blend = sys.argv[sys.argv.index("--") + 1:][:2]
for o in list(bpy.data.objects):  # the default cube, light and camera
    bpy.data.objects.remove(o)
scene = bpy.context.scene
scene.render.fps = 30
bpy.ops.import_scene.gltf(filepath=glb)
ends = [kp.co[0] for a in bpy.data.actions for fc in a.fcurves for kp in fc.keyframe_points]
scene.frame_start, scene.frame_end = 0, int(max(ends)) if ends else 0
cameras = [o for o in bpy.data.objects if o.type == "CAMERA"]
scene.camera = next((o for o in cameras if "follow" in o.name), cameras[0] if cameras else None)
bpy.ops.wm.save_as_mainfile(filepath=blend)
