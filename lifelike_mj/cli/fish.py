"""``lifelike-mj fish ...`` and the fish's part of ``view``, ``render``, ``reproduce``, ``bench``."""

from __future__ import annotations

import argparse
from pathlib import Path

from lifelike_mj.checks import positive
from lifelike_mj.cli.common import add_json, emit
from lifelike_mj.errors import UserError

NAME = "fish"
HELP = "the tropical fish of Satoi et al. 2015"


def _preset(args):
    from lifelike_mj.fish.params import load_preset

    return load_preset(args.preset)


def _count(n) -> int:
    if n is None or n < 1:
        raise UserError(f"--fish must be at least 1, got {n}.")
    return int(n)


def _tank(args):
    from lifelike_mj.fish.scene import tank_size

    return tank_size(positive("--tank-scale", args.tank_scale))


def _add_fish(p) -> None:
    p.add_argument("--preset", default="default",
                   help="fish motion preset: NB-ND, NB-D, B-ND, B-D, default (= B-D), or a JSON file")
    p.add_argument("--fish", type=int, default=10, help="number of fish")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--tank-scale", type=float, default=1.0,
                   help="tank size as a fraction of the filmed 5 m x 0.5 m x 1 m tank")


def _check_camera(camera: str) -> None:
    from lifelike_mj.fish.render import CAMERAS

    if camera not in CAMERAS:
        raise UserError(f"unknown camera {camera!r}; choose one of {', '.join(CAMERAS)}.")


def cmd_swim(args) -> None:
    from lifelike_mj.fish.experiments import swim_summary, write_swim
    from lifelike_mj.fish.sim import swim

    params = _preset(args)
    n = _count(args.fish)
    if args.seed < 0:
        raise UserError(f"--seed must be a non-negative whole number, got {args.seed}.")
    if args.video and Path(args.video).suffix.lower() not in (".mp4", ".gif"):
        raise UserError(f"--video must end in .mp4 or .gif, got {args.video!r}.")
    if args.video:
        _check_camera(args.camera)
    r = swim(params, n, positive("--duration", args.duration), args.seed, _tank(args), progress=not args.json)
    summary = swim_summary(r)
    if args.out:
        summary["files"] = write_swim(r, args.out, dict(summary))
    if args.video:
        from lifelike_mj.fish.render import render_fish

        summary["video"] = render_fish(args.video, params, n, min(args.duration, args.video_duration), args.seed,
                                       _tank(args), camera=args.camera)
    emit(args, summary, (f"{n} fish, {summary['duration_s']:g} s ({params.name}): a burst every "
                         f"{summary['burst_interval_mean_s']:.2f} s, burstiness {summary['burstiness']:.3f}, "
                         f"acceleration kurtosis {summary['accel_kurtosis']:.2f}, turning entropy "
                         f"{summary['turn_entropy']:.2f} bits, mean speed {summary['mean_speed_body_lengths_s']:.2f} "
                         f"body lengths/s, {summary['fish_outside_tank']} outside the tank "
                         f"({summary['realtime_factor']:.0f}x real time)"))


def cmd_drag_check(args) -> None:
    from lifelike_mj.fish.experiments import drag_check

    r = drag_check()
    emit(args, r, f"custom drag vs MuJoCo's inertia-box fluid model: max relative error {r['max_rel_error']:.2e} "
         f"over {r['trials']} random states")


def add_commands(sub) -> None:
    from lifelike_mj.cli.common import Parser

    fish = sub.add_parser(NAME, help=HELP).add_subparsers(dest="sub", required=True, parser_class=Parser)
    p = fish.add_parser("swim", help="a tank of fish: tracks and life-likeness measures")
    _add_fish(p)
    p.add_argument("--duration", type=float, default=30.0, help="simulated seconds")
    p.add_argument("--out", help="folder for tracks (npz, CSV), measures and figures")
    p.add_argument("--video", help="also render FILE.mp4 or FILE.gif (same seed, same swim)")
    p.add_argument("--video-duration", type=float, default=10.0, help="seconds of video (at most --duration)")
    p.add_argument("--camera", default="side", help="video camera: side, oblique or follow")
    add_json(p)
    p.set_defaults(func=cmd_swim)
    p = fish.add_parser("drag-check", help="custom drag (C_D = 1) against MuJoCo's inertia-box fluid model")
    add_json(p)
    p.set_defaults(func=cmd_drag_check)


def add_view_args(p: argparse.ArgumentParser) -> None:
    _add_fish(p)
    p.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
    p.add_argument("--camera", default="side", help="side (default) or follow")


def view(args) -> None:
    from lifelike_mj.fish.render import view_fish

    view_fish(_preset(args), _count(args.fish), args.seed, _tank(args), duration_s=args.duration, camera=args.camera)


def add_render_args(p: argparse.ArgumentParser) -> None:
    _add_fish(p)
    p.add_argument("--duration", type=float, default=3.0, help="seconds of swim")
    p.add_argument("--camera", default="side", help="side (default), oblique or follow")


def render(args) -> dict:
    from lifelike_mj.fish.render import render_fish

    return render_fish(args.out, _preset(args), _count(args.fish), positive("--duration", args.duration), args.seed,
                       _tank(args), fps=args.fps, width=args.width, height=args.height, camera=args.camera)


def add_reproduce_args(p: argparse.ArgumentParser) -> None:
    pass


def reproduce(out: Path, args) -> None:
    from lifelike_mj.fish.report import reproduce_fish

    reproduce_fish(out)


def add_bench_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--long-minutes", type=float, default=10.0, help="simulated minutes of the no-escape run")


def bench(args) -> tuple[dict, str]:
    from lifelike_mj.fish import bench as b

    r = b.run(repeats=args.repeats, long_minutes=args.long_minutes)
    rend = r.get("render", {})
    human = (f"10 fish x{r['ten']['realtime_factor']:.0f} real time, 1,000 fish "
             f"x{r['thousand']['realtime_factor']:.2f}, render {rend.get('fps', float('nan')):.0f} fps at 640x480")
    return r, human
