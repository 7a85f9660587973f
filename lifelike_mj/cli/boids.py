"""``lifelike-mj boids ...`` and the boids' part of ``view``, ``render``, ``reproduce``, ``bench``."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from lifelike_mj.cli.common import (
    add_executor,
    add_json,
    add_overwrite,
    add_seed,
    check_executor,
    check_outputs,
    count,
    emit,
    seeds,
)
from lifelike_mj.errors import UserError

NAME = "boids"
#: Bounds of the command line: agents, steps, and values of a sweep axis (agents x steps:
#: :data:`~lifelike_mj.checks.MAX_AGENT_STEPS` per run, :data:`~lifelike_mj.checks.MAX_SWEEP_AGENT_STEPS` per sweep).
MAX_AGENTS = 1_000_000  # boids.sim.MAX_FLOCK, written out so that --help imports no engine (a test holds them equal)
MAX_STEPS = 1_000_000
MAX_AXIS_VALUES = 1_000
RUN_FILES = ("trajectories.npz", "trajectories.csv", "measures.json")
HELP = "the heterogeneous boids of Nakamura 2013"
VIEW_HELP = "a flock, live, whose weights you can change while it flies"
#: What the viewer's flock shows after each pattern's key (measured over 20 seeds: benchmarks/viewer_patterns.py).
VIEW_PATTERNS_NOTE = ("From the flock the viewer starts with, 4c, 5a, 5c and 5d form in 20 of 20 runs, but 4a and 4b "
                      "in 8, 4d and 5b in none: press Enter after their key (then 4a forms in 18 of 20, 4b in 14, 4d in "
                      "8, 5b in 16; within about a minute of viewing).")


def view_keys() -> str:
    """The flock's keys, for ``view boids --help``."""
    from lifelike_mj.boids.render import KEYS
    from lifelike_mj.render.viewer import keys_text

    return ("keys in the window: " + keys_text(KEYS) + " (the web viewer with --web has a button per pattern). "
            + VIEW_PATTERNS_NOTE)


def _add_boids(p) -> None:
    p.add_argument("--preset", default=None, help="pattern preset 4a ... 5d (default 5a), or a JSON file")
    p.add_argument("--wa", help="alignment matrix 'a,b;c,d' (rows: own type), with --wc instead of a preset")
    p.add_argument("--wc", help="cohesion matrix 'a,b;c,d'")
    p.add_argument("--n", type=count(2, MAX_AGENTS), default=300,
                   help=f"number of agents, 2 to {MAX_AGENTS:,} (a run is also bounded by its neighbour visits: in the "
                        "paper's 20-unit box about 14,000 agents for 10,000 steps; a preset with a wider \"box\" holds "
                        "more)")
    add_seed(p)
    p.add_argument("--dims", type=int, default=3, choices=(3, 2), help="3 or 2 (section 4.3)")


def _check_size(n: int, steps: int | None, params=None) -> int:
    """The agent-steps of one run of ``n`` agents for ``steps`` (default the paper's), refused above
    :data:`~lifelike_mj.checks.MAX_AGENT_STEPS`, and with ``params`` its neighbour visits, refused above
    :data:`~lifelike_mj.boids.engine.MAX_NEIGHBOUR_VISITS` (:func:`~lifelike_mj.boids.engine.check_cost`)."""
    from lifelike_mj import checks
    from lifelike_mj.boids.metrics import RUN_STEPS

    steps = steps or RUN_STEPS
    out = checks.work(f"--n {n:,} for {steps:,} steps", n * steps, checks.MAX_AGENT_STEPS, "agent-steps",
                      "fewer agents or steps")
    if params is not None:
        from lifelike_mj.boids.engine import check_cost

        check_cost(params, n, steps, f"--n {n:,} for {steps:,} steps")
    return out


def _params(args):
    from lifelike_mj.boids.engine import parse_matrix
    from lifelike_mj.boids.presets import load_preset

    if args.dims not in (2, 3):
        raise UserError(f"--dims must be 3 or 2, got {args.dims}.")
    if (args.wa is None) != (args.wc is None):
        raise UserError("give both --wa and --wc (or neither, and a --preset).")
    if args.wa is not None:
        from lifelike_mj.boids.engine import BoidParams

        return BoidParams(wa=parse_matrix(args.wa, "--wa"), wc=parse_matrix(args.wc, "--wc"), dims=args.dims,
                          name="custom")
    return load_preset("5a" if args.preset in (None, "default") else args.preset, dims=args.dims)


def _axis(spec: str) -> tuple[str, list[float]]:
    import numpy as np

    from lifelike_mj import checks

    try:
        name, rng = spec.split("=")
        a, b, k = rng.split(":")
        lo, hi, n = float(a), float(b), int(k)
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ValueError
    except ValueError:
        raise UserError(f"a sweep axis looks like wa_cross=-0.3:0.5:9 (name=start:stop:count, finite numbers and a "
                        f"whole count), got {spec!r}.") from None
    if n < 1:
        raise UserError(f"a sweep axis needs at least one value, got {spec!r}.")
    checks.work(f"sweep axis {spec!r}", n, MAX_AXIS_VALUES, "values")
    return name, [float(x) for x in np.linspace(lo, hi, n)]


def cmd_run(args) -> None:
    from lifelike_mj.boids.experiments import measured_run, write_run

    params = _params(args)
    _check_size(args.n, args.steps, params)
    if args.record_every is not None and not args.out:
        raise UserError("--record-every only applies with --out (it chooses what the trajectory files keep).")
    check_outputs(args, files={"--plot": (".png",)}, folders={"--out": RUN_FILES})
    run, out = measured_run(params, args.n, args.seed, args.steps, progress=True, record_every=args.record_every)
    if args.plot:
        from lifelike_mj.boids.figures import pattern_figure

        pattern_figure(run, args.plot, title=f"{params.name}: classified {out['label']}")
    if args.out:
        out["files"] = write_run(run, dict(out), args.out)
    seg = out.get("segregation_index")
    seg_text = "n/a (one type)" if seg is None else f"{seg:.2f}"
    emit(args, out, f"{params.name}, n = {args.n}, seed {args.seed}, {out['steps']} steps: classified {out['label']} "
         f"(segregation index {seg_text}, groups {out.get('n_groups')})")


def cmd_sweep(args) -> None:
    import numpy as np

    from lifelike_mj import checks
    from lifelike_mj.boids.experiments import Sweep, run_sweep, write_sweep
    from lifelike_mj.boids.presets import homogeneous, load_grid

    check_executor(args)
    per_run = _check_size(args.n, args.steps, homogeneous(1.0, 0.0, dims=args.dims) if args.grid else _params(args))
    seed_list = seeds(args.seeds)
    if args.grid:
        g = load_grid(args.grid)
        sweep = Sweep(homogeneous(1.0, 0.0, dims=args.dims), ("wa", "wc"), args.n, args.steps)
        values = [g["w_a"], g["w_c"]]
    else:
        if not args.x:
            raise UserError("give --grid fig2_grid, or at least --x AXIS=START:STOP:COUNT.")
        axes, values = [], []
        for spec in [args.x] + ([args.y] if args.y else []):
            name, rng = _axis(spec)
            axes.append(name)
            values.append(rng)
        sweep = Sweep(_params(args), tuple(axes), args.n, args.steps)
    from lifelike_mj.progress import stage

    n_runs = len(seed_list) * int(np.prod([len(v) for v in values]))
    checks.work(f"a sweep of {n_runs:,} runs of --n {args.n:,}", n_runs * per_run, checks.MAX_SWEEP_AGENT_STEPS,
                "agent-steps", "fewer cells, seeds, agents or steps")
    sweep.check_cells(values)  # bad axes or weights: one sentence before the progress bar starts
    check_outputs(args, folders={"--out": ("sweep.json", "phase_diagram.png")})
    with stage(f"sweep: {n_runs} runs on {args.executor}", total=n_runs, unit="run") as b:
        res = run_sweep(sweep, values, seed_list, executor=args.executor, workers=args.workers,
                        ray_address=args.ray_address, bar=b)
    if args.out:
        write_sweep(res, sweep, values, args.out)
    counts: dict[str, int] = {}
    for v in res["majority"].values():
        counts[v] = counts.get(v, 0) + 1
    emit(args, res, f"{len(res['rows'])} runs over {len(res['majority'])} cells: "
         + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))


def add_commands(sub) -> None:
    from lifelike_mj.cli.common import Parser

    boids = sub.add_parser(NAME, help=HELP).add_subparsers(dest="sub", required=True, parser_class=Parser)
    p = boids.add_parser("run", help="one run: classified pattern and its measures")
    _add_boids(p)
    p.add_argument("--steps", type=count(10, MAX_STEPS), default=None,
                   help=f"steps, 10 to {MAX_STEPS:,} (default: the classifier's run length)")
    add_json(p)
    p.add_argument("--plot", help="PNG of the last 5 steps in the paper's style")
    p.add_argument("--out", help="folder for trajectories (npz, CSV) and measures")
    p.add_argument("--record-every", type=count(1, 100_000), default=None,
                   help="keep every K-th step of the whole run in --out (default: the classifier's frames, every "
                        "20th step of the last 2,000, and the last 5 steps)")
    add_overwrite(p)
    p.set_defaults(func=cmd_run)
    p = boids.add_parser("sweep", help="a grid of runs, classified: the phase diagram")
    _add_boids(p)
    p.add_argument("--grid", help="a homogeneous grid preset (fig2_grid: the paper's Fig. 2)")
    p.add_argument("--x", help="axis NAME=START:STOP:COUNT: wa_cross, wc_cross, wa_IJ, wc_IJ, wa, wc")
    p.add_argument("--y", help="second axis, same form")
    p.add_argument("--seeds", default="0-2", help="seeds, e.g. 0-4 or 0,3,7")
    p.add_argument("--steps", type=count(10, MAX_STEPS), default=None,
                   help="steps of each run (default: the classifier's run length)")
    add_executor(p)
    p.add_argument("--out", help="folder for sweep.json and phase_diagram.png")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_sweep)


def add_view_args(p: argparse.ArgumentParser) -> None:
    _add_boids(p)
    p.add_argument("--camera", default="overview", choices=("overview", "top"), help="viewer camera")
    p.add_argument("--steps", type=count(1, 10**9), default=None,
                   help="stop after this many steps (default: run until the window is closed)")


def view(args) -> None:
    from lifelike_mj.boids.render import view_boids
    from lifelike_mj.cli import web_options

    web = web_options(args)
    view_boids(_params(args), n=args.n, seed=args.seed, camera=args.camera, web=web, duration_steps=args.steps)


def add_render_args(p: argparse.ArgumentParser) -> None:
    _add_boids(p)
    p.add_argument("--steps", type=count(1, 100_000), default=None, help="steps to render (default 3000)")
    p.add_argument("--camera", default="overview", choices=("overview", "top", "side"), help="video camera")


def render(args) -> dict:
    from lifelike_mj.boids.render import render_boids

    params = _params(args)
    _check_size(args.n, args.steps or 3000, params)
    return render_boids(args.out, params, n=args.n, n_steps=args.steps or 3000, seed=args.seed, fps=args.fps,
                        width=args.width, height=args.height, camera=args.camera, progress=True)


def add_reproduce_args(p: argparse.ArgumentParser) -> None:
    pass


def reproduce(out: Path, args) -> None:
    from lifelike_mj.boids.report import reproduce_boids

    reproduce_boids(out)


def add_bench_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--repeats", type=count(1, 3), default=3, help="timed repeats, at most 3 (the median is reported)")
    p.add_argument("--max-n", type=count(1000, 10_000_000), default=1_000_000, help="largest n of the scaling run")
    p.add_argument("--mesa-python", default=None, help="a Python interpreter that has Mesa (for the peer)")


def bench(args) -> tuple[dict, str]:
    from lifelike_mj.boids import bench as b

    r = b.run(repeats=min(args.repeats, 3), max_n=args.max_n, mesa_python=args.mesa_python)
    return r, (f"n = 300: {r['agent_steps_per_s_n300']:.3g} agent-steps/s; scaling exponent "
               f"{r.get('scaling_exponent', float('nan')):.2f}; x{r.get('mesa_ratio', float('nan')):.0f} Mesa")


def add_export_args(p: argparse.ArgumentParser) -> None:
    from lifelike_mj.boids.render import DEFAULT_STEPS_PER_FRAME

    _add_boids(p)
    p.add_argument("--start", type=count(0, MAX_STEPS), default=0, help="steps run before the exported window starts")
    p.add_argument("--steps", type=count(1, MAX_STEPS), default=3000, help="steps exported")
    p.add_argument("--steps-per-frame", type=count(1, 1000), default=DEFAULT_STEPS_PER_FRAME,
                   help="steps per playback frame")
    p.add_argument("--fps", type=count(1, 240), default=30,
                   help="playback frames per second (keys fall where the motion needs them, --key-tolerance)")


def export_window(args):
    """The run to export, built and checked, not yet simulated (:class:`~lifelike_mj.cli.export.Window`), and the
    parameters that make it."""
    from lifelike_mj import checks
    from lifelike_mj.boids.sim import Flock
    from lifelike_mj.cli.export import Window, check_window, parameters_of

    _check_size(args.n, args.start + args.steps, _params(args))
    if args.steps < args.steps_per_frame:
        raise UserError(f"--steps {args.steps} is fewer than one frame of --steps-per-frame {args.steps_per_frame}.")
    check_window(args.start, args.steps, 1.0 / args.steps_per_frame, 1.0, unit="steps", bodies=args.n,
                 limit=checks.MAX_AGENT_STEPS, body_unit="agent-steps", drawn=args.n)
    flock = Flock(_params(args), args.n, args.seed)
    return (Window(flock, args.start, args.steps, 1.0 / args.steps_per_frame,
                   1.0 / (args.steps_per_frame * args.fps), unit="steps"), parameters_of(args))


def export_rigs(poses, metres_per_unit: float = 1.0) -> list:
    """The run's creatures as rigs (skinned, textured meshes on skeletons), for ``export --looks rig``;
    ``metres_per_unit``: the box unit's length where the flock is scaled to a bird size (a scene)."""
    from lifelike_mj.boids.look import rigs

    return rigs(poses, metres_per_unit=metres_per_unit)
