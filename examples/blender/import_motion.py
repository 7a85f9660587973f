"""Run by Blender: import an exported run (glTF) into a fresh scene, ready to play, save it as a .blend and
render a still.

    lifelike-mj export butterfly3d --task course --seed 101 --duration 6 --out flight.glb
    blender -b --python examples/blender/import_motion.py -- flight.glb flight.blend --render flight.png

Arguments after ``--``: the ``.glb``/``.gltf`` file, then optionally the ``.blend`` to save, and:

* ``--render PNG``: render a still there (``--frame N``, default the middle frame; ``--engine cycles`` on the
  CPU, the default, or ``eevee``, which needs a display: run Blender under ``xvfb-run`` where there is none;
  ``--samples``, ``--size WxH``);
* ``--camera NAME``: the camera to look through (default the run's ``camera follow``, else ``camera
  overview``);
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
    if not 1 <= args.samples <= 4096:
        fail(f"--samples is 1 to 4096, got {args.samples}.")
    return args


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
