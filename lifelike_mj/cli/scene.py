"""``lifelike-mj export scene SCENE.json --out FILE``: several creatures' runs composed into one file (one scale,
metres; one root; one ground; named cameras), as :mod:`lifelike_mj.export.scene` lays it out.

A scene file is strict JSON (``docs/schemas/scene.schema.json``)::

    {"format": "lifelike-mj/scene", "version": 1, "name": "garden",
     "duration_s": 8, "fps": 30, "ground_half_m": 20,
     "parts": [
       {"name": "garden", "creature": "butterfly3d", "at_m": [0, 0, 1], "options": {"garden": 6, "seed": 3},
        "follow": ["b0_butterfly"]},
       {"name": "pond", "creature": "fish", "at_m": [-3, -4, 0], "options": {"n": 10}, "follow": ["s0/f0/fish"]},
       {"name": "flock", "creature": "boids", "at_m": [-3, -3, 5], "bird_length_m": 0.2, "still": false}]}

Each part runs one creature as ``lifelike-mj export CREATURE`` would, with ``options`` being that command's
options (``"garden": 6`` is ``--garden 6``; ``true`` a flag; a list of numbers is comma-joined): the same
names, checks and defaults. The scene sets the time: every part is recorded for ``duration_s`` seconds of
playback at ``fps`` frames per second (a flock: ``duration_s x fps x steps_per_frame`` steps). ``at_m`` is where
the part's own origin goes (m; a flock's box spans 0 to its size along each axis from there, in bird-scaled
metres), ``yaw_deg`` its turn about the vertical; a flock's box units are scaled so that a bird is
``bird_length_m`` long (default :data:`BIRD_LENGTH_M`). ``still: false`` leaves out the part's still geoms (a
flock's box edges); no part's own ground plane is drawn where the scene has a ground. ``follow``: the creatures
that get a follow camera, named after their root body (``b0_butterfly`` in a garden, ``s0/f3/fish`` in a tank,
``boid12`` in a flock).

Every part's options, every window and the output are checked before any creature is simulated. From Python:
:func:`scene_parts` (the runs, as :class:`~lifelike_mj.export.scene.Part`) and :func:`export_scene`.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from lifelike_mj.errors import UserError

#: The scene file's format name.
FORMAT = "lifelike-mj/scene"
#: A bird's length (m) when a scene does not give one: about a common starling's (20-22 cm).
BIRD_LENGTH_M = 0.2
#: The options a scene sets itself, which a part may not give.
SET_BY_SCENE = ("duration", "fps", "steps", "out", "format", "overwrite", "json", "looks", "loop", "loop_blend",
                "key_tolerance", "rotations")
MAX_PARTS = 16
MAX_DURATION_S = 600.0


def json_schema() -> dict:
    """The JSON Schema of a scene file (``docs/schemas/scene.schema.json``)."""
    from lifelike_mj.cli.common import SIMULATED
    from lifelike_mj.schema import document_schema, number

    option = {"anyOf": [{"type": "string"}, {"type": "number"}, {"type": "boolean"},
                        {"type": "array", "items": {"type": "number"}, "maxItems": 16}]}
    part = {"type": "object", "additionalProperties": False, "required": ["name", "creature"], "properties": {
        "name": {"type": "string", "pattern": "^[A-Za-z0-9_.-]{1,40}$",
                 "description": "the part's name, unique in the scene (letters, digits, _ . -)"},
        "creature": {"enum": list(SIMULATED), "description": "what runs: as lifelike-mj export CREATURE"},
        "options": {"type": "object", "maxProperties": 40, "additionalProperties": option,
                    "description": "the options of lifelike-mj export CREATURE, without their dashes"},
        "at_m": {"type": "array", "items": number("", -10_000, 10_000), "minItems": 3, "maxItems": 3,
                 "description": "where the part's own origin goes in the scene, m (z up)"},
        "yaw_deg": number("the part's turn about the vertical, deg", -360, 360),
        "bird_length_m": number("a flock only: a bird's length in the scene, m", exclusive_minimum=0, maximum=10),
        "still": {"type": "boolean", "description": "draw the part's still geoms (tank, flowers; default true)"},
        "follow": {"type": "array", "items": {"type": "string", "maxLength": 100}, "maxItems": 16, "uniqueItems": True,
                   "description": "the creatures (rig names) that get a follow camera"}}}
    props = {"duration_s": number("seconds of playback every part is recorded for (and at most 36,000 frames of fps)",
                                  exclusive_minimum=0, maximum=MAX_DURATION_S),
             "fps": {"type": "integer", "minimum": 1, "maximum": 240, "description": "playback frames per second"},
             "ground_half_m": {"anyOf": [number("", exclusive_minimum=0, maximum=10_000), {"type": "null"}],
                               "description": "the ground's half size, m (null: no scene ground)"},
             "looks": {"enum": ["rig", "mjcf"], "description": "rigs (default) or the MJCF's geoms"},
             "parts": {"type": "array", "items": part, "minItems": 1, "maxItems": MAX_PARTS}}
    return document_schema(FORMAT, "lifelike-mj scene", props, ["duration_s", "parts"],
                           "Creatures' runs composed into one file: lifelike-mj export scene SCENE.json.")


def load_scene(path: str | Path) -> dict:
    """The scene file ``path``, checked against :func:`json_schema` (one sentence if it is not one)."""
    from lifelike_mj.paths import read_json
    from lifelike_mj.schema import check_header, validate

    where = f"scene file {path}"
    data = check_header(read_json(path, "scene"), FORMAT, where, kind="scene file")
    validate(data, json_schema(), where)
    return data


def _tokens(options: dict, parser: argparse.ArgumentParser, creature: str, where: str) -> list[str]:
    """A part's ``options`` as the command line's words for ``parser`` (``lifelike-mj export CREATURE``): each as
    ``--name=value``, so that a value starting with a minus sign (``"wind_from": [-0.5, 0, 0]``) is read as the
    command line reads ``--wind-from -0.5,0,0``; an unknown name gets the nearest known one, a flag takes only
    ``true`` or ``false``, and a number or a list is written as it reads back (``repr`` of a float)."""
    from lifelike_mj.errors import unknown_name

    actions = {a.dest: a for a in parser._actions if a.option_strings and a.dest != "help"}
    by_flag = parser._option_string_actions
    known = sorted({o[2:].replace("-", "_") for o in by_flag if o.startswith("--") and o != "--help"}
                   - set(SET_BY_SCENE))
    out = []
    for key, value in options.items():
        name = key.replace("-", "_")
        if name in SET_BY_SCENE:
            raise UserError(f"{where}: the scene sets {key!r} itself (its duration_s, fps and the command's "
                            "output options); leave it out of the part's options.")
        flag = "--" + name.replace("_", "-")
        action = by_flag.get(flag)
        if action is None or action.dest not in actions:
            raise unknown_name(f"{where}: lifelike-mj export {creature} has no option", key, known)
        if isinstance(action, argparse._StoreTrueAction):
            if not isinstance(value, bool):
                raise UserError(f"{where}: option {key!r} is a flag: give true or false, got {value!r}.")
            if value:
                out.append(flag)
            continue
        if isinstance(value, bool):
            raise UserError(f"{where}: option {key!r} takes a value ({action.metavar or action.dest.upper()}), "
                            f"not {str(value).lower()}.")
        if isinstance(value, list):
            text = ",".join(repr(float(v)) if isinstance(v, float) else str(v) for v in value)
        else:
            text = repr(float(value)) if isinstance(value, float) else str(value)
        out.append(f"{flag}={text}")
    return out


def _parse_part(part: dict, scene: dict, where: str) -> argparse.Namespace:
    from lifelike_mj.cli.common import Parser
    from lifelike_mj.cli.common import creature as _module

    creature = part["creature"]
    mod = _module(creature)
    p = Parser(prog=f"lifelike-mj export {creature}", add_help=False)
    mod.add_export_args(p)
    tokens = _tokens(part.get("options", {}), p, creature, where)
    try:
        args = p.parse_args(tokens)
    except UserError as exc:
        raise UserError(f"{where}: {exc}") from None
    fps = int(scene.get("fps", 30))
    args.fps = fps
    if creature == "boids":
        args.steps = int(round(float(scene["duration_s"]) * fps * args.steps_per_frame))
    else:
        args.duration = float(scene["duration_s"])
    if "bird_length_m" in part and creature != "boids":
        raise UserError(f"{where}: bird_length_m sizes a flock's birds; a {creature} lives in metres already.")
    return args


def _check_follow(part: dict, model, where: str) -> None:
    """The creatures a part follows are among its model's drawn bodies (a rig is named after its root body)."""
    import mujoco

    from lifelike_mj.export.poses import animated_bodies

    bodies = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(b)) for b in animated_bodies(model)]
    roots = [n for b, n in zip(animated_bodies(model), bodies) if model.body_parentid[b] == 0]
    for who in part.get("follow", ()):
        if who not in bodies:
            raise UserError(f"{where} has no creature {who!r} to follow; its creatures are "
                            f"{', '.join(roots[:4])}{' ...' if len(roots) > 4 else ''}.")


def check_scene(scene: dict | str | Path, where: str = "the scene") -> list[tuple[dict, argparse.Namespace]]:
    """``scene`` (a scene file's path, or its content as a dict) checked as a file is, and each part's options
    parsed by its command's own parser: ``(part, its options)`` per part, nothing built or run; one sentence for
    the first thing wrong."""
    from lifelike_mj.schema import check_header, validate

    if not isinstance(scene, dict):
        where = f"scene file {scene}"
        scene = load_scene(scene)
    else:
        check_header(scene, FORMAT, where, kind="scene")
        validate(scene, json_schema(), where)
    names = [p["name"] for p in scene["parts"]]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UserError(f"{where}: each part has its own name; {', '.join(map(repr, twice))} is used twice.")
    return [(part, _parse_part(part, scene, f"{where}, part {part['name']!r}")) for part in scene["parts"]]


def scene_parts(scene: dict | str | Path, where: str = "the scene", quiet: bool = False) -> list:
    """Run every part of ``scene`` (a scene file's path, or its content as a dict, checked as a file's) and
    return them as :class:`~lifelike_mj.export.scene.Part`, each recorded and rigged; every part is checked
    before any is simulated."""
    from lifelike_mj import checks
    from lifelike_mj.cli.common import creature as _module
    from lifelike_mj.export.scene import Part

    if not isinstance(scene, dict):
        where = f"scene file {scene}"
        scene = load_scene(scene)
    looks = scene.get("looks", "rig")
    planned, rows = [], 0
    for part, args in check_scene(scene, where):  # every part checked, built and its recording planned before any runs
        at = f"{where}, part {part['name']!r}"
        try:
            window, parameters = _module(part["creature"]).export_window(args)
        except UserError as exc:
            raise UserError(f"{at}: {exc}") from None
        _check_follow(part, window.stepper.model, at)
        try:
            rows += window.plan()
        except UserError as exc:
            raise UserError(f"{at}: {exc}") from None
        planned.append((part, window, parameters))
    checks.work(f"{where}: recording its {len(planned)} parts", rows, checks.MAX_RECORD_ROWS, "body poses",
                "fewer parts, a shorter duration_s or a lower fps")
    parts = []
    for part, window, parameters in planned:
        t0 = time.perf_counter()
        poses = window.record()
        mod = _module(part["creature"])
        scale = 1.0
        rigs = None
        if part["creature"] == "boids":
            from lifelike_mj.boids.look import agent_length

            scale = float(part.get("bird_length_m", BIRD_LENGTH_M)) / agent_length(poses)
            rigs = mod.export_rigs(poses, metres_per_unit=scale) if looks == "rig" else None
        elif looks == "rig":
            rigs = mod.export_rigs(poses)
        made = {"creature": part["creature"], **parameters}
        if part["creature"] == "boids":
            made["bird_length_m"] = part.get("bird_length_m")
        parts.append(Part(part["name"], poses, rigs, tuple(part.get("at_m", (0.0, 0.0, 0.0))),
                          float(part.get("yaw_deg", 0.0)), scale, bool(part.get("still", True)),
                          tuple(part.get("follow", ())), made))
        if not quiet:
            import sys

            print(f"part {part['name']}: {part['creature']}, {len(poses.body_ids)} bodies, {poses.n_samples:,} "
                  f"samples in {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
    return parts


def export_scene(scene: dict | str | Path, out: str | Path, fmt: str | None = None, rotations: str = "short",
                 tolerance="0.5mm,0.5deg", overwrite: bool = False, quiet: bool = True,
                 where: str = "the scene") -> Path:
    """Run ``scene`` (:func:`scene_parts`: a scene file's path, or its content, named ``where`` in messages) and
    write it to ``out`` (glb, gltf or html; :func:`~lifelike_mj.export.scene.write_scene`), the output checked
    first. Returns the path."""
    from lifelike_mj.export.keys import tolerance_of
    from lifelike_mj.export.scene import scene_format, write_scene
    from lifelike_mj.paths import check_output_file

    fmt = scene_format(out, fmt)
    tol = tolerance_of(tolerance)
    check_output_file(out, "--out", overwrite=overwrite)
    if not isinstance(scene, dict):
        scene, where = load_scene(scene), f"scene file {scene}"
    parts = scene_parts(scene, where, quiet=quiet)
    return write_scene(parts, out, fmt, name=f"lifelike-mj scene {scene.get('name', '')}".strip(),
                       parameters={"scene": scene}, rotations=rotations, tolerance=tol,
                       ground_half_m=scene.get("ground_half_m", 20.0))


def add_scene_command(per) -> None:
    """``export scene SCENE.json`` (module docstring)."""
    from lifelike_mj.cli.common import add_json, add_overwrite

    q = per.add_parser("scene", help="several creatures' runs composed into one file, from a scene file (JSON)")
    q.add_argument("scene", metavar="SCENE.json", help="the scene file: its parts, their places and options")
    q.add_argument("--out", required=True, help="the file: .glb, .gltf or .html")
    q.add_argument("--format", default=None, choices=("glb", "gltf", "html"),
                   help="glb, gltf or html (default: from the file's ending)")
    q.add_argument("--rotations", default="short", choices=("short", "float"),
                   help="keyframes' rotations: 16-bit (within 6e-5 rad, half the bytes) or 32-bit")
    q.add_argument("--key-tolerance", default="0.5mm,0.5deg", metavar="DIST,ANGLE",
                   help="how far the interpolated keys may stray from the simulation, in scene metres")
    add_overwrite(q)
    add_json(q)
    q.set_defaults(func=cmd_scene)


def cmd_scene(args) -> None:
    from lifelike_mj.cli.common import emit

    t0 = time.perf_counter()
    data = load_scene(args.scene)
    from lifelike_mj.progress import enabled

    path = export_scene(data, args.out, args.format, args.rotations, args.key_tolerance, args.overwrite,
                        quiet=args.json or not enabled(), where=f"scene file {args.scene}")
    size = path.stat().st_size
    info = {"out": str(path), "bytes": size, "parts": [p["name"] for p in data["parts"]],
            "duration_s": data["duration_s"], "seconds": time.perf_counter() - t0}
    emit(args, info, f"wrote the scene {data.get('name', args.scene)!r} ({len(data['parts'])} parts, "
         f"{data['duration_s']:g} s, {size / 1e6:.2f} MB) to {path} in {info['seconds']:.1f} s")
