"""Run by Blender: import an exported run (glTF) into a fresh scene, ready to play, save it as a .blend and
render a still.

    lifelike-mj export butterfly3d --task course --seed 101 --duration 6 --out flight.glb
    blender -b --python examples/blender/import_motion.py -- flight.glb flight.blend --render flight.png

Arguments after ``--``: the ``.glb``/``.gltf`` file, then optionally the ``.blend`` to save, and:

* ``--render PNG``: render a still there (``--frame N``, default the middle frame; ``--engine cycles`` on the
  CPU, the default, or ``eevee``, which needs a display: run Blender under ``xvfb-run`` where there is none;
  ``--samples``, ``--size WxH``);
* ``--camera NAME``: the camera to look through (default the run's ``camera follow``, else ``camera
  overview``); ``--zoom Z`` narrows its field of view Z times (a longer lens); ``--follow BONE`` looks through
  a new camera that follows a bone (a creature: ``butterfly``, ``s0/f3/fish``) from ``--distance`` metres;
* ``--overwrite``: replace an existing ``.blend`` or image (without it the script refuses, and writes nothing).

Paths are taken from the folder Blender was started in. The scene's frame rate is the file's (its
``asset.extras.frames.per_s``, read before the import, as the importer turns the keys' seconds into frames at
the scene's rate), its frame range the run's. The glTF has no lights: a sun and a pale sky light the render.
On any failure the script prints one sentence and Blender exits with status 2; Debian's Blender 3.4 with
Debian's numpy 1.24 needs the ``numpy.bool`` alias below, newer Blenders do not.

Blender's importer turns glTF's Y-up into Z-up by turning the meshes: each imported body (an empty) keeps
the body's MuJoCo orientation followed by a constant -90 deg about its own X axis. Parent to the empties, or
read the bones of a rig, rather than copying an empty's rotation as it is.
"""

import argparse
import json
import math
import os
import re
import struct
import sys
import warnings

import bpy
import numpy

with warnings.catch_warnings():  # numpy 1.24 warns when asked for the alias it removed
    warnings.simplefilter("ignore")
    if not hasattr(numpy, "bool"):
        numpy.bool = bool  # Blender 3.4's glTF importer still uses numpy.bool


def fail(sentence: str) -> None:
    print(f"import_motion.py: {sentence}", file=sys.stderr)
    sys.stderr.flush()
    sys.exit(2)


def quietly(call):
    """``call()`` with the process's standard error held back (Blender's importer prints its own traceback
    there before it raises): ``(result, None)``, or ``(None, the exception)``."""
    import tempfile

    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    with tempfile.TemporaryFile() as hold:
        os.dup2(hold.fileno(), 1)
        os.dup2(hold.fileno(), 2)
        try:
            return call(), None
        except Exception as e:  # noqa: BLE001 - whatever the importer raises is reported as one sentence
            return None, e
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            for fd, was in zip((1, 2), saved):
                os.dup2(was, fd)
                os.close(was)


def read_extras(path: str) -> dict:
    """The file's ``asset.extras`` (what made the run), read as JSON: nothing in the file is run."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(20)
            if path.lower().endswith(".glb"):
                magic, _, _ = struct.unpack("<4sII", head[:12])
                size, kind = struct.unpack("<I4s", head[12:20])
                if magic != b"glTF" or kind != b"JSON":
                    fail(f"{path} is not a binary glTF (.glb) file.")
                text = fh.read(size)
            else:
                text = head + fh.read()
        doc = json.loads(text)
    except (OSError, ValueError, struct.error) as e:
        fail(f"could not read {path}: {e}.")
    extras = doc.get("asset", {}).get("extras") if isinstance(doc, dict) else None
    return extras if isinstance(extras, dict) else {}


def parse(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser(prog="import_motion.py", description="import a lifelike-mj glTF into Blender")
    p.add_argument("gltf")
    p.add_argument("blend", nargs="?")
    p.add_argument("--render")
    p.add_argument("--frame", type=int)
    p.add_argument("--engine", choices=("cycles", "eevee"), default="cycles")
    p.add_argument("--samples", type=int, default=32)
    p.add_argument("--size", default="960x540")
    p.add_argument("--camera")
    p.add_argument("--zoom", type=float, default=1.0)
    p.add_argument("--follow")
    p.add_argument("--distance", type=float, default=0.3)
    p.add_argument("--overwrite", action="store_true")
    try:
        args = p.parse_args(argv)
    except SystemExit as e:
        sys.exit(2 if e.code else 0)
    args.gltf = os.path.abspath(args.gltf)
    if not args.gltf.lower().endswith((".glb", ".gltf")):
        fail(f"the run must be a .glb or .gltf file, got {args.gltf}.")
    if not os.path.isfile(args.gltf):
        fail(f"{args.gltf} does not exist.")
    for attr, ends in (("blend", (".blend",)), ("render", (".png",))):
        out = getattr(args, attr)
        if out is None:
            continue
        out = os.path.abspath(out)
        setattr(args, attr, out)
        if not out.lower().endswith(ends):
            fail(f"the {attr} file must end in {ends[0]}, got {out}.")
        if not os.path.isdir(os.path.dirname(out)):
            fail(f"the folder of {out} does not exist.")
        if os.path.exists(out) and not args.overwrite:
            fail(f"{out} exists; give --overwrite to replace it.")
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
        assert 16 <= w <= 8192 and 16 <= h <= 8192
    except (ValueError, AssertionError):
        fail(f"--size is WIDTHxHEIGHT in pixels (16 to 8192), got {args.size!r}.")
    args.width, args.height = w, h
    if not 0.1 <= args.zoom <= 100:
        fail(f"--zoom is 0.1 to 100, got {args.zoom:g}.")
    if not 1 <= args.samples <= 4096:
        fail(f"--samples is 1 to 4096, got {args.samples}.")
    return args


def follow(scene, bone: str, distance: float):
    """A camera that keeps ``distance`` m from the bone ``bone`` of an imported armature (behind, to the left and
    above it, in the world's axes) and looks at it."""
    arm = next((o for o in bpy.data.objects if o.type == "ARMATURE" and bone in o.data.bones), None)
    if arm is None:
        names = sorted(b.name for o in bpy.data.objects if o.type == "ARMATURE" for b in o.data.bones)
        fail(f"no armature has a bone {bone!r}" + (f"; the bones include {', '.join(names[:6])}." if names else "."))
    if not 0.001 <= distance <= 1000:
        fail(f"--distance is 0.001 to 1000 m, got {distance:g}.")
    cam = bpy.data.objects.new(f"camera {bone}", bpy.data.cameras.new(f"camera {bone}"))
    cam.data.clip_start = distance / 100.0
    scene.collection.objects.link(cam)
    place = cam.constraints.new("COPY_LOCATION")
    place.target, place.subtarget = arm, bone
    cam.location = (-0.6 * distance, 0.55 * distance, 0.58 * distance)
    place.use_offset = True
    aim = cam.constraints.new("TRACK_TO")
    aim.target, aim.subtarget = arm, bone
    aim.track_axis, aim.up_axis = "TRACK_NEGATIVE_Z", "UP_Y"
    return cam


def main() -> None:
    args = parse(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    frames = read_extras(args.gltf).get("frames", {})
    fps = frames.get("per_s")
    if not isinstance(fps, (int, float)) or not 0 < fps <= 1000:
        fail(f"{args.gltf} does not say its frame rate (asset.extras.frames.per_s); was it written by lifelike-mj?")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = max(1, round(fps))  # before the import: it places keys at the scene's rate
    scene.render.fps_base = scene.render.fps / fps
    done, error = quietly(lambda: bpy.ops.import_scene.gltf(filepath=args.gltf))
    if error is not None or "FINISHED" not in done:
        lines = [x.strip() for x in str(error or "").splitlines()]
        why = next((x for x in reversed(lines) if re.match(r"^\w+(Error|Exception): ", x)), "")
        fail(f"Blender could not import {args.gltf}" + (f" ({why.rstrip('.')})." if why else "."))
    span = float(frames.get("end_s", 0.0)) - float(frames.get("start_s", 0.0))
    scene.frame_start, scene.frame_end = 0, max(0, round(span * fps))
    cameras = {o.name: o for o in bpy.data.objects if o.type == "CAMERA"}
    if args.camera is not None and args.camera not in cameras:
        fail(f"the run has no camera {args.camera!r}; it has {', '.join(sorted(cameras)) or 'none'}.")
    scene.camera = cameras.get(args.camera) or cameras.get("camera follow") or cameras.get("camera overview")
    if args.follow is not None:
        scene.camera = follow(scene, args.follow, args.distance)
    if scene.camera is not None and args.zoom != 1.0:
        scene.camera.data.lens *= args.zoom
    if not any(o.type == "LIGHT" for o in bpy.data.objects):
        sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
        sun.data.energy = 3.0
        sun.rotation_euler = (math.radians(35.0), 0.0, math.radians(30.0))
        scene.collection.objects.link(sun)
    world = scene.world or bpy.data.worlds.new("sky")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.75, 0.85, 0.95, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.8
    scene.frame_set(scene.frame_end // 2 if args.frame is None else args.frame)
    if args.blend:
        bpy.ops.wm.save_as_mainfile(filepath=args.blend, check_existing=False)
    if args.render:
        if scene.camera is None:
            fail("the run has no camera to render through.")
        scene.render.engine = "CYCLES" if args.engine == "cycles" else "BLENDER_EEVEE"
        if args.engine == "cycles":
            scene.cycles.device = "CPU"
            scene.cycles.samples = args.samples
            scene.cycles.use_denoising = False  # Debian's Blender is built without OpenImageDenoise
        else:
            scene.eevee.taa_render_samples = args.samples
        scene.render.resolution_x, scene.render.resolution_y = args.width, args.height
        scene.render.resolution_percentage = 100
        scene.render.image_settings.file_format = "PNG"
        scene.render.filepath = args.render
        bpy.ops.render.render(write_still=True)
        if not os.path.isfile(args.render):
            fail(f"Blender rendered no image to {args.render}.")
    print(f"import_motion.py: {os.path.basename(args.gltf)} at {fps:g} frames/s, frames 0-{scene.frame_end}"
          + (f", saved {args.blend}" if args.blend else "") + (f", rendered {args.render}" if args.render else ""))


try:
    main()
except SystemExit:
    raise
except Exception as e:  # noqa: BLE001 - anything else Blender raises: one sentence, status 2
    fail(f"Blender failed: {type(e).__name__}: {str(e).strip().splitlines()[-1] if str(e).strip() else ''}")
