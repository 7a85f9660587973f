"""Scenes: several runs, of any creatures, composed into one file in one scale (metres), with one root, one
ground and named cameras.

A scene is a list of :class:`Part`: a run's recorded poses (:class:`~lifelike_mj.export.poses.Poses`), its
rigs where it has them (:mod:`lifelike_mj.export.rig`), and where it stands: its model's origin is placed at
``at_m`` (m, the scene's Z-up world), turned ``yaw_deg`` about the vertical and scaled by ``scale`` (scene
metres per unit of the run: 1 for the creatures that live in metres; a flock's box units are scaled to a
stated bird size). All parts play from the scene's time 0 at their own playback times.

Layout of the glTF file (beside what :mod:`lifelike_mj.export.gltf` writes for one run):

* the root ``lifelike-mj`` (Z up to Y up), under it the ground (a textured plane, :func:`ground_poses`, a
  MuJoCo model of its own) and one node per part, named as the part, holding its placement (translation,
  rotation, uniform scale) and, beneath it, the part's still geoms (not its own ground plane: the scene has
  one), plain bodies and armatures (``<part>/<creature> rig``; bones named as in the MJCF, as in a single run);
* cameras: ``camera overview`` (still, every part at every sample in view) and ``camera follow <part>/<name>``
  for each creature a part asks to follow, moving with it at 8 of its sizes.

Each part's keys stay within the tolerance *in scene metres*: a part scaled by ``s`` is keyed within
``tolerance / s`` of its own units.

This module composes recorded runs; running the creatures from a scene description (``lifelike-mj export
scene SCENE.json``) is the command line's (:mod:`lifelike_mj.cli.scene`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.cameras import FOLLOW_MIN_M, FOLLOW_SIZES, bounds, look_quat_wxyz, overview, view_direction
from lifelike_mj.export.keys import DEFAULT_TOLERANCE, lerp_keys, tolerance_of
from lifelike_mj.export.poses import Poses
from lifelike_mj.export.rig import Rig, qaxis, qrot
from lifelike_mj.io import atomic_path
from lifelike_mj.provenance import provenance

#: The ground's texture (a MuJoCo builtin: grass-green with lighter blades at random) and its repeats per metre.
GROUND_XML = """<mujoco model="scene ground">
  <asset>
    <texture name="grass" type="2d" builtin="flat" width="512" height="512" rgb1="0.23 0.42 0.16"
             mark="random" random="0.35" markrgb="0.42 0.58 0.25"/>
    <material name="ground" texture="grass" texrepeat="{repeat} {repeat}" texuniform="false"/>
  </asset>
  <worldbody>
    <geom name="ground" type="plane" size="{half} {half} 0.1" material="ground"/>
  </worldbody>
</mujoco>
"""
#: The ground texture's size on the ground (m per repeat).
GROUND_TILE_M = 2.0


def ground_poses(half_m: float) -> Poses:
    """The scene's ground as a run of no bodies: a square plane ``2 half_m`` metres wide at z = 0, textured
    (:data:`GROUND_XML`, a MuJoCo model compiled here, so its texture is exported as any model's)."""
    if not (math.isfinite(half_m) and 0.0 < half_m <= 10_000.0):
        raise UserError(f"the ground's half size is a number of metres in (0, 10000], got {half_m!r}.")
    m = mujoco.MjModel.from_xml_string(GROUND_XML.format(half=half_m, repeat=max(1.0, 2 * half_m / GROUND_TILE_M)))
    empty = np.zeros((1, 0, 3))
    return Poses(m, np.zeros(0, dtype=int), [], np.zeros(1), empty, np.zeros((1, 0, 4)))


@dataclass
class Part:
    """One run in a scene (module docstring): ``name`` (unique in the scene), ``poses``, ``rigs`` (or None: the
    MJCF's geoms), placement ``at_m``, ``yaw_deg``, ``scale``; ``still``: draw the run's still world geoms (a
    tank, flowers; never its ground plane); ``follow``: the creatures (rig names, or body names where there is
    no rig) that get a follow camera; ``parameters``: what made the run, for the provenance."""

    name: str
    poses: Poses
    rigs: list[Rig] | None = None
    at_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    yaw_deg: float = 0.0
    scale: float = 1.0
    still: bool = True
    follow: tuple[str, ...] = ()
    parameters: dict = field(default_factory=dict)

    @property
    def turn_wxyz(self) -> np.ndarray:
        """The part's turn about the vertical, as a quaternion."""
        return qaxis((0.0, 0.0, 1.0), math.radians(self.yaw_deg))

    def to_scene(self, points_m: np.ndarray) -> np.ndarray:
        """Points of the run (its units) in the scene (m)."""
        return np.asarray(self.at_m, dtype=float) + self.scale * qrot(self.turn_wxyz, np.asarray(points_m, float))

    def check(self) -> None:
        if not (math.isfinite(self.scale) and self.scale > 0.0):
            raise UserError(f"part {self.name!r}: its scale is a positive number, got {self.scale!r}.")
        if not all(math.isfinite(float(v)) for v in (*self.at_m, self.yaw_deg)):
            raise UserError(f"part {self.name!r}: its place and turn are finite numbers.")
        known = {r.name for r in self.rigs or []} | set(self.poses.body_names)
        for f in self.follow:
            if f not in known:
                near = sorted(known)[:6]
                raise UserError(f"part {self.name!r} has no creature {f!r} to follow (it has "
                                f"{', '.join(near)}{' ...' if len(known) > 6 else ''}).")


def _follow_path(part: Part, who: str) -> tuple[np.ndarray, float]:
    """The scene path (m) of the creature ``who`` of ``part`` (a rig's root bone, or a body) and its size (m)."""
    rig = next((r for r in part.rigs or [] if r.name == who), None)
    if rig is not None:
        root = rig.bones[0]
        reach = float(np.linalg.norm(rig.mesh.positions, axis=1).max())
        return part.to_scene(root.position_m), reach * part.scale
    b = part.poses.body_names.index(who)
    m = part.poses.model
    body = int(part.poses.body_ids[b])
    geoms = np.nonzero(m.geom_bodyid == body)[0]
    reach = max([float(np.linalg.norm(m.geom_pos[g]) + m.geom_rbound[g]) for g in geoms] or [0.0])
    return part.to_scene(part.poses.position_m[:, b]), reach * part.scale


def scene_box(parts: list[Part]) -> tuple[np.ndarray, np.ndarray]:
    """The box (m, the scene's world) around every part's bodies at every sample and their still geoms."""
    lows, highs = [], []
    for part in parts:
        lo, hi, _ = bounds(part.poses)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        c = part.to_scene(corners)
        lows.append(c.min(axis=0))
        highs.append(c.max(axis=0))
    return np.min(lows, axis=0), np.max(highs, axis=0)


def _check(parts: list[Part]) -> None:
    if not parts:
        raise UserError("a scene holds at least one part.")
    names = [p.name for p in parts]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UserError(f"each part of a scene has its own name; {', '.join(repr(n) for n in twice)} is used twice.")
    for p in parts:
        p.check()


def build_scene_gltf(parts: list[Part], name: str = "lifelike-mj scene", parameters: dict | None = None,
                     rotations: str = "short", tolerance=DEFAULT_TOLERANCE, ground_half_m: float | None = 20.0):
    """The glTF document of the scene (module docstring); ``ground_half_m``: the ground's half size (m), or None
    for no ground (each part then keeps its own). The asset's extras hold the provenance: ``parameters``, and per
    part its placement, its own ``parameters``, its frames and keys."""
    import pygltflib as g

    from lifelike_mj.export.gltf import Doc, _xyzw, add_camera, add_poses, frames_record

    _check(parts)
    tolerance = tolerance_of(tolerance)
    doc = Doc(name, rotations)
    prov = provenance(**(parameters or {}))
    span = max(float(p.poses.t_s[-1] - p.poses.t_s[0]) for p in parts)
    fps = float(parts[0].poses.fps)
    prov["frames"] = {"count": int(math.floor(span * fps + 1e-9)) + 1, "per_s": fps, "start_s": 0.0, "end_s": span,
                      "bodies": sum(len(p.poses.body_ids) for p in parts), "rotations": rotations}
    prov["keys"] = {"tolerance_m": tolerance[0], "tolerance_deg": tolerance[1]}
    prov["scene"] = {"units": "m", "ground_half_m": ground_half_m, "parts": {}}
    if ground_half_m is not None:
        add_poses(doc, doc.root, ground_poses(ground_half_m), None, tolerance)
    for part in parts:
        s = float(part.scale)
        node = g.Node(name=part.name, translation=[float(v) for v in part.at_m], rotation=_xyzw(part.turn_wxyz),
                      scale=[s, s, s] if s != 1.0 else None, children=[],
                      extras={"lifelike_mj_part": part.name, "scale": s})
        doc.node(node, doc.root)
        done = add_poses(doc, node, part.poses, part.rigs, (tolerance[0] / s, tolerance[1]),
                         ground=ground_half_m is None, still=part.still, prefix=f"{part.name}/")
        prov["scene"]["parts"][part.name] = {
            "at_m": [float(v) for v in part.at_m], "yaw_deg": float(part.yaw_deg), "scale": s, "still": part.still,
            "follow": list(part.follow), "parameters": part.parameters,
            "frames": frames_record(part.poses, rotations), "keys": done["keys"], "rigs": done["rigs"]}
    direction = view_direction()
    look = look_quat_wxyz(direction)
    centre, distance = overview(*scene_box(parts), direction)
    add_camera(doc, doc.root, "overview", look, centre + direction * distance, distance)
    for part in parts:
        t = part.poses.t_s
        for who in part.follow:
            path, size = _follow_path(part, who)
            dist = max(FOLLOW_SIZES * size, FOLLOW_MIN_M)
            path = path + direction * dist
            keys = lerp_keys(t, path, tolerance[0]) if len(t) > 1 else np.zeros(1, dtype=np.int64)
            add_camera(doc, doc.root, f"follow {part.name}/{who}", look, path, dist, t, keys)
    return doc.finish(prov)


def scene_view(parts: list[Part]) -> dict:
    """What the web page needs to frame the scene: the overview's centre, direction and distance (MuJoCo's
    world), the span (s) and the first follow camera's path and distance, if any."""
    direction = view_direction()
    centre, distance = overview(*scene_box(parts), direction)
    view = {"centre_m": centre, "direction": direction, "overview_m": distance,
            "span_s": max(float(p.poses.t_s[-1] - p.poses.t_s[0]) for p in parts), "follow": None}
    for part in parts:
        for who in part.follow:
            path, size = _follow_path(part, who)
            frames = part.poses.frame_samples
            view["follow"] = {"path_m": path[frames], "distance_m": max(FOLLOW_SIZES * size, FOLLOW_MIN_M)}
            return view
    return view


def scene_format(path: str | Path, fmt: str | None = None) -> str:
    """The format a scene is written in, from ``path``'s ending (checked against ``fmt``): glb, gltf or html."""
    from lifelike_mj.export import format_of

    fmt = format_of(path, fmt)
    if fmt == "usd":
        raise UserError("a scene is written as glTF (.glb, .gltf) or a web page (.html); USD takes one run "
                        "(lifelike-mj export CREATURE --out FILE.usd).")
    return fmt


def write_scene(parts: list[Part], path: str | Path, fmt: str | None = None, name: str = "lifelike-mj scene",
                parameters: dict | None = None, rotations: str = "short", tolerance=DEFAULT_TOLERANCE,
                ground_half_m: float | None = 20.0) -> Path:
    """Write the scene of ``parts`` (module docstring) as glTF (``.glb``, ``.gltf``) or a web page (``.html``),
    atomically. Returns the path."""
    path = Path(path)
    fmt = scene_format(path, fmt)
    gl = build_scene_gltf(parts, name, parameters, rotations, tolerance, ground_half_m)
    if fmt == "html":
        from lifelike_mj.export.html import page

        text = page(gl, name, scene_view(parts))
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
        return path
    from lifelike_mj.export.gltf import save

    return save(gl, path)


__all__ = ["GROUND_XML", "Part", "build_scene_gltf", "ground_poses", "scene_box", "scene_format", "scene_view",
           "write_scene"]
