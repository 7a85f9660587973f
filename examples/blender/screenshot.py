"""Run by Blender with a window: a screenshot of a saved flight at one frame, seen through its camera
(the README's picture, docs/figures/blender_flight.png)::

    xvfb-run -s "-screen 0 1280x720x24" blender flight.blend --python examples/blender/screenshot.py -- 75 out.png
"""

import sys

import bpy

frame, out = sys.argv[sys.argv.index("--") + 1:][:2]
scene = bpy.context.scene
scene.frame_set(int(frame))
for o in bpy.data.objects:
    o.select_set(o.get("mujoco_body") == "butterfly")


def shot():
    window = bpy.context.window_manager.windows[0]
    for area in window.screen.areas:
        if area.type == "VIEW_3D":
            space = area.spaces[0]
            space.region_3d.view_perspective = "CAMERA"
            space.shading.type, space.shading.color_type = "SOLID", "MATERIAL"
            region = next(r for r in area.regions if r.type == "WINDOW")
            with bpy.context.temp_override(window=window, area=area, region=region):
                bpy.ops.view3d.view_center_camera()
    bpy.app.timers.register(save, first_interval=1.0)


def save():
    bpy.ops.screen.screenshot(filepath=out)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(shot, first_interval=3.0)
