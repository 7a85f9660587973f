"""``lifelike-mj fish ...`` and the fish's part of ``view``, ``render``, ``reproduce``, ``bench``."""

from __future__ import annotations

import argparse
from pathlib import Path

from lifelike_mj.checks import positive
from lifelike_mj.cli.common import add_json, add_overwrite, add_seed, check_outputs, count, emit, num
from lifelike_mj.errors import UserError

NAME = "fish"
#: Bounds of the command line: fish in a tank, simulated seconds, the smallest tank (2.5 body lengths a side).
MAX_DURATION_S = 3600.0
MIN_TANK_SCALE = 0.35
#: The longest side ``--tank`` takes (m): twice the longest of ``--tank-scale``'s largest tank (the Python API takes the
#: same, ``fish.scene.MAX_TANK_SIDE_M``; tests/fish/test_fish_trust.py holds them equal).
MAX_TANK_SIDE_M = 100.0
SWIM_FILES = ("tracks.npz", "tracks.csv", "tracks.png", "accel_histogram.png", "measures.json")
HELP = "the tropical fish of Satoi et al. 2015"
VIEW_HELP = "a tank of fish, live: a virtual aquarium whose fish flee a tap on the glass and go for food"


def view_keys() -> str:
    """The aquarium's keys, for ``view fish --help``."""
    from lifelike_mj.fish.aquarium import KEYS
    from lifelike_mj.render.viewer import keys_text

    return "keys in the window (buttons in the web viewer with --web): " + keys_text(KEYS) + "."


def _preset(args):
    from lifelike_mj.fish.params import load_preset

    return load_preset(args.preset)


def _tank_type(text: str) -> tuple[float, float, float]:
    """An argparse ``type``: a tank's ``length,depth,height`` in m, each side at least 2.5 body lengths and at most
    :data:`MAX_TANK_SIDE_M` (:func:`lifelike_mj.fish.scene.tank_problem`, as the Python API checks it)."""
    from lifelike_mj.fish.scene import MIN_TANK_SIDE_M, tank_problem

    try:
        vals = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected three lengths L,D,H in m (length, depth, height: numbers, as 3,3,1), each "
            f"{MIN_TANK_SIDE_M:.3f} m (2.5 body lengths) to {MAX_TANK_SIDE_M:g} m, got {text!r}") from None
    sides, problem = tank_problem(vals, given=text)
    if sides is None:
        raise argparse.ArgumentTypeError(problem)
    return sides


_tank_type.__name__ = "tank size"


def _tank(args):
    from lifelike_mj.fish.scene import tank_size

    if getattr(args, "tank", None) is not None:
        if args.tank_scale != 1.0:
            raise UserError("give the tank either as --tank or as --tank-scale, not both.")
        return args.tank
    return tank_size(positive("--tank-scale", args.tank_scale))


class _Count(int):
    """A number given on the command line, with the spelling of the option that gave it (``flag``)."""

    flag = ""


class _OneSpelling(argparse.Action):
    """Stores a number given under one of two spellings (``--n`` or ``--fish``); both at once are refused (else the
    last would win unseen). The same spelling twice keeps argparse's rule: the last wins."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        before = getattr(namespace, self.dest, None)
        if isinstance(before, _Count) and before.flag != option_string:
            raise argparse.ArgumentError(self, f"give the number of fish once, as {before.flag} or {option_string}, "
                                               f"not both (got {before.flag} {int(before)} and {option_string} {values})")
        v = _Count(values)
        v.flag = option_string or ""
        setattr(namespace, self.dest, v)


def _add_fish(p) -> None:
    p.add_argument("--preset", default="default",
                   help="fish motion preset: the paper's NB-ND, NB-D, B-ND, B-D; school, shoal or pair (fish that heed each "
                        "other); or a JSON file (default: B-D, also called 'default')")
    from lifelike_mj.fish.params import MAX_FISH

    p.add_argument("--n", "--fish", dest="fish", type=count(1, MAX_FISH), default=10, action=_OneSpelling,
                   help=f"number of fish, 1 to {MAX_FISH:,} (--n as for boids; --fish is the older spelling)")
    add_seed(p)
    p.add_argument("--tank-scale", type=num(MIN_TANK_SCALE, 10.0), default=1.0,
                   help=f"tank size as a fraction of the filmed 5 m x 0.5 m x 1 m tank, {MIN_TANK_SCALE} to 10 "
                        "(every side at least 2.5 body lengths)")
    p.add_argument("--tank", type=_tank_type, default=None, metavar="L,D,H",
                   help="tank size in m, length,depth,height (e.g. 3,3,1: the open tank the school and shoal presets "
                        "were measured in; 1.12,1.12,0.3 for pair), each side 2.5 body lengths to 100 m; in place of "
                        "--tank-scale")


def cmd_swim(args) -> None:
    from lifelike_mj.fish.experiments import swim_summary, write_swim
    from lifelike_mj.fish.sim import swim

    if args.video_duration != 10.0 and not args.video:
        raise UserError("--video-duration only applies with --video.")
    params = _preset(args)
    n = args.fish
    from lifelike_mj import checks
    from lifelike_mj.fish.sim import check_swim_work

    check_swim_work(params, n, checks.steps_of(args.duration, params.control_dt_s))  # the video: at most 600 s
    check_outputs(args, files={"--video": (".mp4", ".gif")}, folders={"--out": SWIM_FILES})
    r = swim(params, n, positive("--duration", args.duration), args.seed, _tank(args), progress=True)
    summary = swim_summary(r)
    if args.out:
        summary["files"] = write_swim(r, args.out, dict(summary))
    if args.video:
        from lifelike_mj.fish.render import render_fish

        summary["video"] = render_fish(args.video, params, n, min(args.duration, args.video_duration), args.seed,
                                       _tank(args), camera=args.camera, progress=True)
    emit(args, summary, (f"{n} fish, {summary['duration_s']:g} s ({params.name}): a burst every "
                         f"{summary['burst_interval_mean_s']:.2f} s, burstiness {summary['burstiness']:.3f}, "
                         f"acceleration kurtosis {summary['accel_kurtosis']:.2f}, turning entropy "
                         f"{summary['turn_entropy']:.2f} bits, mean speed {summary['mean_speed_body_lengths_s']:.2f} "
                         f"body lengths/s, {summary['fish_outside_tank']} outside the tank "
                         f"({summary['realtime_factor']:.0f}x real time); together: nearest neighbour "
                         f"{summary['group']['nn_distance_bl']['median']:.1f} body lengths (median), polarisation "
                         f"{summary['group']['polarisation']:.2f}, a kick every "
                         f"{summary['group']['kick_interval_s']['mean']:.2f} s (CV "
                         f"{summary['group']['kick_interval_s']['cv']:.2f})"))


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
    p.add_argument("--duration", type=num(0, MAX_DURATION_S, lo_open=True, unit="s"), default=30.0,
                   help=f"simulated seconds, at most {MAX_DURATION_S:g}")
    p.add_argument("--out", help="folder for tracks (npz, CSV), measures and figures")
    p.add_argument("--video", help="also render FILE.mp4 or FILE.gif (same seed, same swim)")
    p.add_argument("--video-duration", type=num(0, 600, lo_open=True, unit="s"), default=10.0,
                   help="seconds of video (at most --duration); only with --video")
    p.add_argument("--camera", default="side", choices=("side", "oblique", "follow"), help="video camera")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_swim)
    p = fish.add_parser("drag-check", help="custom drag (C_D = 1) against MuJoCo's inertia-box fluid model")
    add_json(p)
    p.set_defaults(func=cmd_drag_check)


def add_view_args(p: argparse.ArgumentParser) -> None:
    _add_fish(p)
    p.add_argument("--duration", type=num(0, None, lo_open=True, unit="s"), default=None,
                   help="stop after this many seconds (default: run until the window is closed)")
    p.add_argument("--camera", default="side", choices=("side", "follow"), help="viewer camera")


def view(args) -> None:
    from lifelike_mj.cli import web_options
    from lifelike_mj.fish.render import view_fish

    web = web_options(args)
    view_fish(_preset(args), args.fish, args.seed, _tank(args), duration_s=args.duration, camera=args.camera, web=web)


def add_render_args(p: argparse.ArgumentParser) -> None:
    _add_fish(p)
    p.add_argument("--duration", type=num(0, 600, lo_open=True, unit="s"), default=3.0, help="seconds of swim, at most 600")
    p.add_argument("--camera", default="side", choices=("side", "oblique", "follow"), help="video camera")


def render(args) -> dict:
    from lifelike_mj.fish.render import render_fish

    return render_fish(args.out, _preset(args), args.fish, positive("--duration", args.duration), args.seed,
                       _tank(args), fps=args.fps, width=args.width, height=args.height, camera=args.camera,
                       progress=True)


def add_reproduce_args(p: argparse.ArgumentParser) -> None:
    pass


def reproduce(out: Path, args) -> None:
    from lifelike_mj.fish.report import reproduce_fish

    reproduce_fish(out)


def add_bench_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--repeats", type=count(1, 100), default=5, help="timed repeats (the median is reported)")
    p.add_argument("--long-minutes", type=num(0, 600, lo_open=True, unit="min"), default=10.0,
                   help="simulated minutes of the no-escape run")


def bench(args) -> tuple[dict, str]:
    from lifelike_mj.fish import bench as b

    r = b.run(repeats=args.repeats, long_minutes=args.long_minutes)
    rend = r.get("render", {})
    human = (f"10 fish x{r['ten']['realtime_factor']:.0f} real time, 1,000 fish "
             f"x{r['thousand']['realtime_factor']:.2f}, render {rend.get('fps', float('nan')):.0f} fps at 640x480")
    return r, human


def add_export_args(p: argparse.ArgumentParser) -> None:
    from lifelike_mj.cli.export import add_window

    _add_fish(p)
    add_window(p, MAX_DURATION_S, 10.0)


def export_window(args):
    """The run to export, built and checked, not yet simulated (:class:`~lifelike_mj.cli.export.Window`), and the
    parameters that make it."""
    from lifelike_mj.cli.export import Window, check_window, parameters_of
    from lifelike_mj.fish.sim import Tank

    params = _preset(args)
    check_window(args.start, args.duration, args.fps, params.control_dt_s, bodies=args.fish * params.substeps,
                 body_unit="fish-steps (substeps included)", drawn=args.fish)
    tank = Tank(params, args.fish, args.seed, _tank(args))
    return Window(tank, args.start, args.duration, args.fps), parameters_of(args)


def export_rigs(poses) -> list:
    """The run's creatures as rigs (skinned, textured meshes on skeletons), for ``export --looks rig``."""
    from lifelike_mj.fish.look import rigs

    return rigs(poses)
