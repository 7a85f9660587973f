"""``lifelike-mj export CREATURE ... --format glb|gltf|usd|html --out FILE``: a run's motion as a file.

The creatures are ``butterfly`` (the planar flight of the paper), ``butterfly3d`` (one 3D butterfly on a
task, or a garden of them), ``fish`` (a tank) and ``boids`` (a flock). Each creature module gives
``add_export_args`` (its scene's options and its time window) and ``export_window(args)``, which checks them
and builds the simulation (a :class:`Window`, not yet run) with the parameters that made it; this module checks
the output before any work, records the window and writes the file (:mod:`lifelike_mj.export`). ``export scene
SCENE.json`` composes several such runs into one file (:mod:`lifelike_mj.cli.scene`).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import numpy as np

from lifelike_mj.cli.common import SIMULATED, Parser, add_json, add_overwrite, count, creature, emit, num
from lifelike_mj.errors import UserError


def add_export_verb(sub) -> None:
    """The ``export`` verb with one sub-command per creature."""
    from lifelike_mj.export import FORMATS

    p = sub.add_parser("export", help="write a run's motion as glTF (glb, gltf), USD or a web page")
    per = p.add_subparsers(dest="what", required=True, parser_class=Parser, metavar="CREATURE")
    for c in SIMULATED:
        mod = creature(c)
        q = per.add_parser(c, help=mod.HELP)
        mod.add_export_args(q)
        q.add_argument("--out", required=True, help="the file: " + ", ".join(s for v in FORMATS.values() for s in v))
        q.add_argument("--format", default=None, choices=tuple(FORMATS),
                       help="glb, gltf, usd or html (default: from the file's ending)")
        q.add_argument("--rotations", default="short", choices=("short", "float"),
                       help="glTF and web keyframes' rotations: 16-bit (within 6e-5 rad, half the bytes) or 32-bit")
        q.add_argument("--looks", default="rig", choices=("rig", "mjcf"),
                       help="rig: each creature a textured mesh on a skeleton of its MuJoCo bodies and the bones of "
                            "its secondary motion (glTF skins, UsdSkel); mjcf: the model's own geoms on each body")
        q.add_argument("--loop", action="store_true",
                       help="a clip whose last frame joins its first: a butterfly in level flight is cut at whole "
                            "wing beats (flying in place, its travel per loop recorded as root motion); anything "
                            "else is recorded --loop-blend longer and its end blended into its start")
        q.add_argument("--loop-blend", type=num(0.05, 60.0, unit="s"), default=1.0, metavar="S",
                       help="seconds of playback over which a looped clip's end fades into its start, recorded "
                            "before the clip (for a cut, the lead-in that the secondary motion starts from)")
        q.add_argument("--key-tolerance", default="0.5mm,0.5deg", metavar="DIST,ANGLE",
                       help="how far the interpolated keys may stray from the simulation, sampled at every step: a "
                            "distance (um, mm, cm, m) and an angle (deg, rad)")
        add_overwrite(q)
        add_json(q)
        q.set_defaults(func=cmd_export)
    from lifelike_mj.cli.scene import add_scene_command

    add_scene_command(per)


def add_window(p: argparse.ArgumentParser, max_s: float, default_s: float) -> None:
    """``--start``, ``--duration`` (s) and ``--fps`` of a creature that lives in seconds."""
    from lifelike_mj.cli.common import num

    p.add_argument("--start", type=num(0, max_s, unit="s"), default=0.0,
                   help="seconds simulated before the exported window starts")
    from lifelike_mj.checks import MAX_FRAMES

    p.add_argument("--duration", type=num(0, max_s, lo_open=True, unit="s"), default=default_s,
                   help=f"seconds exported, at most {max_s:g}, and at most {MAX_FRAMES:,} frames of --fps "
                        f"({MAX_FRAMES / 30:g} s at 30 frames/s)")
    p.add_argument("--fps", type=count(1, 240), default=30,
                   help="playback frames per second, 1 to 240: the scene's frame rate (keys fall where the motion "
                        "needs them, --key-tolerance)")


def cmd_export(args) -> None:
    from lifelike_mj.export import format_of, write_poses
    from lifelike_mj.export.keys import key_counts, tolerance_of
    from lifelike_mj.paths import check_output_file

    fmt = format_of(args.out, args.format)
    tolerance = tolerance_of(args.key_tolerance)
    check_output_file(args.out, "--out", overwrite=args.overwrite)
    if fmt == "usd":  # usd-core is an extra: say so before the simulation, not after
        from lifelike_mj.export.usd import require_usd

        require_usd()
    mod = creature(args.what)
    cut = args.loop and getattr(mod, "loop_cut_body", lambda a: None)(args)
    if args.loop:  # a lead-in recorded before the clip: the blend's, or the secondary motion's history for a cut
        clip_s = (args.steps / (args.fps * args.steps_per_frame) if hasattr(args, "steps_per_frame")
                  else args.duration)
        need = 0.5 if cut else args.loop_blend
        if clip_s <= need:
            raise UserError(f"a looped clip of {clip_s:g} s is too short to " + (
                "hold whole wing beats; give at least 0.5 s." if cut else
                f"blend {args.loop_blend:g} s of its end into its start; give a longer clip or a shorter --loop-blend."))
        _lengthen(args, args.loop_blend)
    t0 = time.perf_counter()
    window, parameters = mod.export_window(args)
    poses = window.record()
    t_sim = time.perf_counter() - t0
    loop = None
    looks = args.looks
    if args.loop:
        from lifelike_mj.export import loop as looping

        rigs = mod.export_rigs(poses) if looks == "rig" else None
        if cut:
            i = poses.body_names.index(cut)
            period = looping.beat_period(poses.t_s, poses.quat_wxyz[:, i], poses.quat_wxyz[:, 0])
            poses, rigs, loop = looping.loop_cut(poses, rigs, period, args.loop_blend)
        else:
            poses, rigs, loop = looping.loop_blend(poses, rigs, args.loop_blend)
    else:
        rigs = mod.export_rigs(poses) if looks == "rig" else None
    parameters = {"creature": args.what, **parameters, "format": fmt, "rotations": args.rotations, "looks": looks,
                  "key_tolerance": {"m": tolerance[0], "deg": tolerance[1]}, "loop": loop}
    path = write_poses(poses, args.out, fmt, name=f"lifelike-mj {args.what}", parameters=parameters,
                       rotations=args.rotations, tolerance=tolerance, rigs=rigs)
    t_write = time.perf_counter() - t0 - t_sim
    size = path.stat().st_size
    storage = "float" if fmt == "usd" else args.rotations
    if rigs:
        counts = {f"{r.name}:{b}": c for r in rigs for b, c in r.key_counts(poses.t_s, tolerance, storage).items()}
        what = f"{len(rigs)} {'rigs' if len(rigs) > 1 else 'rig'} ({sum(len(r.bones) for r in rigs)} bones)"
    else:
        counts = key_counts(poses.tracks(tolerance, storage), poses.body_names)
        what = f"{len(poses.body_ids)} bodies"
    info = {"out": str(path), "format": fmt, "looks": looks, "bytes": size, "frames": poses.n_frames, "fps": poses.fps,
            "samples": poses.n_samples, "bodies": len(poses.body_ids), "span_s": float(poses.t_s[-1] - poses.t_s[0]),
            "key_tolerance": {"m": tolerance[0], "deg": tolerance[1]}, "keys": counts, "loop": loop,
            "simulate_s": t_sim, "write_s": t_write}
    emit(args, info, f"wrote {what}, {poses.n_frames} frames at {poses.fps:g}/s ({size / 1e6:.2f} MB) to {path} "
         f"in {t_sim + t_write:.1f} s\n" + keys_text(counts, poses.n_samples) + _loop_text(loop))


def _loop_text(loop: dict | None) -> str:
    if not loop:
        return ""
    how = (f"cut at {loop['beats']} wing beats of {loop['period_s'] * 1000:.1f} ms, flying in place (root motion "
           f"{np.linalg.norm(loop['root_motion_m']):.3f} m per loop)" if loop["mode"] == "cut"
           else f"its last {loop['blend_s']:.2f} s blended into its start")
    hint = ("; the flight had not settled into a repeating beat: a later --start (after the take-off) closes it"
            if loop["mode"] == "cut" and loop["seam_deg"] > 2.0 else "")
    return (f"\nloop of {loop['span_s']:.2f} s, {how}; seam: {loop['seam_m'] * 1000:.2f} mm, "
            f"{loop['seam_deg']:.2f} deg{hint}")


def _lengthen(args, seconds: float) -> None:
    """Record ``seconds`` of playback more (a looped blend's lead-in): ``--duration`` or a flock's ``--steps``."""
    if hasattr(args, "steps_per_frame"):
        args.steps += int(round(seconds * args.fps * args.steps_per_frame))
    else:
        args.duration += seconds


def keys_text(counts: dict[str, dict[str, int]], samples: int) -> str:
    """The keys kept per body, in a few lines: each body for a few, a summary for a crowd."""
    rows = [(name, c["translation"], c["rotation"]) for name, c in counts.items()]
    head = f"keys kept of {samples:,} samples (translation, rotation):"
    if len(rows) <= 12:
        return head + "".join(f"\n  {n}: {t:,}, {r:,}" for n, t, r in rows)
    t = np.array([r[1] for r in rows])
    r = np.array([r[2] for r in rows])
    return (head + f"\n  {len(rows):,} bodies or bones: translation {t.min():,}-{t.max():,} (median {int(np.median(t)):,}), "
            f"rotation {r.min():,}-{r.max():,} (median {int(np.median(r)):,}); --json lists each")


def parameters_of(args: argparse.Namespace) -> dict:
    """The creature's options as given (what made the run), for the file's provenance."""
    skip = {"func", "out", "format", "overwrite", "json", "command", "what", "rotations", "key_tolerance", "looks",
            "loop", "loop_blend"}
    return {k: (list(v) if isinstance(v, tuple) else v) for k, v in vars(args).items() if k not in skip}


def check_window(start: float, duration: float, per_unit: float, dt: float, unit: str = "s", bodies: int = 1,
                 limit: int | None = None, body_unit: str = "body-steps", drawn: int = 1) -> None:
    """Before the simulation is built: the window's frames (:func:`~lifelike_mj.export.poses.frames_of`: at least
    2, at most :data:`~lifelike_mj.checks.MAX_FRAMES`), the poses recorded (every step of ``dt`` in ``duration``
    of at least ``drawn`` drawn bodies: at most :data:`~lifelike_mj.checks.MAX_RECORD_ROWS`, checked exactly once
    the model is built, by :meth:`Window.plan`) and the steps of ``dt`` of ``bodies`` simulated bodies over
    ``start + duration`` (at most ``limit``, :data:`~lifelike_mj.checks.MAX_BODY_STEPS` by default)."""
    from lifelike_mj import checks
    from lifelike_mj.export.poses import frames_of

    n_frames = frames_of(duration, per_unit, unit)
    total = checks.steps_of(start + duration, dt) * bodies
    checks.work(f"simulating {start + duration:g} {unit} of {bodies:,} {'bodies' if bodies > 1 else 'body'}",
                total, checks.MAX_BODY_STEPS if limit is None else limit, body_unit, "a shorter --start or --duration")
    steps = int(round((n_frames - 1) / per_unit / dt)) + 1  # as plan_recording counts them: every step to the last frame
    checks.work(f"recording {steps:,} poses of at least {drawn:,} {'bodies' if drawn > 1 else 'body'}",
                float(steps) * drawn, checks.MAX_RECORD_ROWS, "body poses",
                "a shorter window, fewer frames per second or fewer creatures")


@dataclass
class Window:
    """A run to export, built and checked but not yet simulated: ``stepper`` run ``start`` units of its time
    unrecorded, then ``duration`` recorded at ``per_unit`` frames per unit, ``time_scale`` seconds of playback
    per unit (:func:`run_window`)."""

    stepper: object
    start: float
    duration: float
    per_unit: float
    time_scale: float = 1.0
    unit: str = "s"

    def plan(self) -> int:
        """Check the recording before any simulation (:func:`~lifelike_mj.export.poses.plan_recording`): the body
        poses it will keep, or a :class:`~lifelike_mj.errors.UserError` if that is too many."""
        from lifelike_mj.export.poses import plan_recording

        bodies, _, targets = plan_recording(self.stepper, self.duration, self.per_unit)
        return len(bodies) * len(targets)

    def record(self):
        """Simulate and record the window: its :class:`~lifelike_mj.export.poses.Poses`."""
        return run_window(self.stepper, self.start, self.duration, self.per_unit, self.time_scale, self.unit)


def run_window(stepper, start: float, duration: float, per_unit: float, time_scale: float = 1.0, unit: str = "s"):
    """Simulate ``start`` units of the stepper's time unrecorded, then record ``duration`` of them with
    ``per_unit`` frames per unit (:func:`~lifelike_mj.export.poses.record_poses`; ``time_scale``: seconds
    of playback per unit). Each creature checks its window first (:func:`check_window`)."""
    from lifelike_mj.export.poses import plan_recording, record_poses
    from lifelike_mj.progress import stage

    plan_recording(stepper, duration, per_unit)
    skip = int(round(start / stepper.dt))
    with stage(f"simulating {start + duration:g} {unit}"):
        if skip:
            stepper.step(skip)
        return record_poses(stepper, duration, per_unit, time_scale)
