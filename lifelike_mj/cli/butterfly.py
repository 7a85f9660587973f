"""``lifelike-mj butterfly ...`` and the butterfly's part of ``view``, ``render``, ``reproduce``, ``bench``."""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from lifelike_mj.checks import positive
from lifelike_mj.cli.common import (
    add_executor,
    add_json,
    add_overwrite,
    add_run_files,
    add_seed,
    add_wind,
    check_executor,
    check_outputs,
    count,
    emit,
    num,
)
from lifelike_mj.errors import UserError
from lifelike_mj.progress import stage

NAME = "butterfly"
#: Longest flight (s) of fly and compare; longest video (s) of render.
MAX_DURATION_S = 3600.0
MAX_VIDEO_S = 600.0
#: Largest wind map (cells), and the files of ``fly --out``.
MAX_WIND_CELLS = 40_000
FLY_FILES = ("trajectory.npz", "trajectory.csv", "flight.png", "summary.json")
HELP = "the butterfly of Oe et al. 2010"


def add_physics(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("physical constants (defaults: Oe 2010, A_b = 1.0 cm^2)")
    g.add_argument("--body-area-cm2", type=num(0, 100, lo_open=True, unit="cm^2"),
                   help="body projected area A_b (eq. 10), cm^2, in (0, 100] (default 1.0)")
    g.add_argument("--mass-g", type=num(0, 100, lo_open=True, unit="g"), help="butterfly mass m, g, in (0, 100] (paper: 0.319)")
    g.add_argument("--span-cm", type=num(0, 100, lo_open=True, unit="cm"), help="wing length L, cm, in (0, 100] (paper: 5.5)")
    g.add_argument("--width-cm", type=num(0, 100, lo_open=True, unit="cm"), help="wing width W, cm, in (0, 100] (paper: 5.0)")
    g.add_argument("--rho", type=num(0, 2000, lo_open=True, unit="kg/m^3"),
                   help="air density, kg/m^3, in (0, 2000] (paper: 1.28)")
    g.add_argument("--cd", type=num(0, 10, lo_open=True), help="drag coefficient C_d, in (0, 10] (paper: 2.2)")


def params(args):
    from lifelike_mj.butterfly.params import ButterflyParams

    return ButterflyParams().with_overrides(
        body_area_cm2=args.body_area_cm2, mass_g=args.mass_g, span_cm=args.span_cm, width_cm=args.width_cm,
        rho=args.rho, cd=args.cd)


def _inputs(words: tuple[str, ...]):
    """An argparse ``type`` for ``--inputs``: the words the 3D flight also uses (``air``, ``ground``; ``both``
    where given), returned as the planar model's own (``air`` is its ``relative``); ``relative``, the spelling of
    before 0.3, is taken one more release with a note."""

    def parse(text: str) -> str:
        from lifelike_mj.cli.common import note

        if text == "relative":
            note("--inputs relative is now --inputs air (velocities through the air); 'relative' goes in the next "
                 "release.")
            return "relative"
        if text not in words:
            raise argparse.ArgumentTypeError(f"expected {', '.join(words[:-1])} or {words[-1]}, got {text!r}")
        return "relative" if text == "air" else text

    return parse


def _add_controller(p: argparse.ArgumentParser, required: bool = True) -> None:
    p.add_argument("--controller", required=required, default=None if required else "simple_rule",
                   help="shipped controller name (e.g. simple_rule) or path to a controller JSON file")
    p.add_argument("--phi-up-deg", type=num(-90, 90, unit="deg"), help="override simple_rule's upstroke pitch, deg")
    p.add_argument("--phi-down-deg", type=num(-90, 90, unit="deg"), help="override simple_rule's downstroke pitch, deg")
    p.add_argument("--phi-deg", type=num(-90, 90, unit="deg"), help="override a constant controller's pitch, deg")
    p.add_argument("--inputs", type=_inputs(("air", "ground")), default=None, metavar="{air,ground}",
                   help="network controllers: feed velocities through the air or over the ground (section 7.2)")


def _controller(args):
    from lifelike_mj.butterfly import controllers

    ctrl = controllers.load(args.controller)
    overrides = {"phi_up_deg": args.phi_up_deg, "phi_down_deg": args.phi_down_deg, "phi_deg": args.phi_deg}
    ctrl = ctrl.with_parameters(**overrides)
    if getattr(args, "inputs", None):
        ctrl = ctrl.with_inputs(args.inputs)
    return ctrl


def _add_backend(p: argparse.ArgumentParser) -> None:
    p.add_argument("--backend", default="paper", choices=("paper", "mujoco"),
                   help="paper (eq. 7-11, compiled) or mujoco (models/butterfly/)")
    p.add_argument("--config", default=None, choices=("paper", "rich"),
                   help="MuJoCo configuration: paper (equivalent, the default) or rich; only with --backend mujoco")
    p.add_argument("--force-mode", default=None, choices=("tip", "strip"),
                   help="MuJoCo wing force: tip (paper formula) or strip (default: the configuration's); "
                        "only with --backend mujoco")


def _backend_options(args) -> dict:
    from lifelike_mj.butterfly.backends import check_backend, mujoco_options

    check_backend(args.backend)
    if args.backend != "mujoco":
        given = [o for o, v in (("--config", args.config), ("--force-mode", args.force_mode)) if v is not None]
        if given:
            raise UserError(f"{' and '.join(given)} only apply to --backend mujoco.")
        return {}
    return mujoco_options(args.config or "paper", args.force_mode)


def _condition(args):
    from lifelike_mj.butterfly.flight import Condition

    return Condition(args.y0, args.wind)


# ---- commands ---------------------------------------------------------------------------------


def cmd_speed_limit(args) -> None:
    from lifelike_mj.butterfly import aero

    r = aero.speed_limit(params(args))
    emit(args, r.to_dict(), f"speed limit: {r.speed_limit_cm_s} cm/s at A_b = {r.body_area_cm2:g} cm^2 "
         f"(continuous solution {100 * r.closed_form_m_s:.1f} cm/s; paper: 380 cm/s)")


def cmd_forces(args) -> None:
    from lifelike_mj.butterfly import aero

    r = aero.check_closed_forms(params(args))
    lines = [f"{q:6s} planform {k}: closed form {c:.6e}, strips {s:.6e}, rel. error {e:.1e}" for q, k, c, s, e in r.rows]
    lines.append(f"largest relative error: {r.closed_form_max_rel_error:.2e}")
    emit(args, r.to_dict(), "\n".join(lines))


def cmd_trim(args) -> None:
    from lifelike_mj.butterfly import experiments

    opts = _backend_options(args)
    experiments.check_trim_work(args.backend, positive("--dt", args.dt))
    with stage("E4: bisection on phi_up for level flight (20 s flights)"):
        r = experiments.e4_trim(params(args), backend=args.backend, dt_s=positive("--dt", args.dt), **opts)
    d = r.to_dict()
    emit(args, d, f"level flight at phi_up = {d['phi_up_level_deg']:.3f} deg (paper 12.77); settled forward speed "
         f"{d['mean_forward_speed_cm_s']:.1f} cm/s (paper 340); ripple {d['ripple_cm']:.2f} cm (paper 5.3); "
         f"initial drop {d['initial_drop_m']:.2f} m (paper about 3)")


def cmd_timestep(args) -> None:
    from lifelike_mj.butterfly import experiments

    opts = _backend_options(args)
    with stage("E5: 20 s flights at four time steps"):
        r = experiments.e5_timestep(params(args), backend=args.backend, **opts)
    d = r.to_dict()
    rows = [f"dt {k:>8s}: altitude at 20 s {d['altitude_20s_m'][k]:8.3f} m, rel. error {d['rel_error'][k]:.2e}"
            for k in d["altitude_20s_m"]]
    emit(args, d, "\n".join(rows))


def cmd_fly(args) -> None:
    from lifelike_mj.butterfly.experiments import fly

    check_outputs(args, folders={"--out": FLY_FILES})
    ctrl = _controller(args)
    opts = _backend_options(args)
    r = fly(ctrl, params(args), _condition(args), args.duration, args.dt, args.backend, **opts, name=args.controller)
    s = r.summary
    if args.out:
        r.write(args.out, f"{s['controller']} on the {args.backend} backend")
    human = (f"final altitude {s['final_altitude_m']:.3f} m, min {s['min_altitude_m']:.3f} m, "
             f"mean forward speed {s['mean_forward_speed_cm_s']:.1f} cm/s; last 10 s: altitude in "
             f"[{s['settled_altitude_min_m']:.3f}, {s['settled_altitude_max_m']:.3f}] m, "
             f"speed {s['settled_forward_speed_cm_s']:.1f} cm/s")
    emit(args, s, human)


def cmd_evolve(args) -> None:
    from lifelike_mj.butterfly.evolution import evolve_controller, make_problem

    if args.generations is not None and args.evaluations is not None:
        raise UserError("give either --generations or --evaluations, not both.")
    check_executor(args)
    gens = args.generations
    if gens is None and args.evaluations is None:
        gens = 1000  # the paper's budget (section 6.3)
    problem = make_problem(args.task, args.backend, args.inputs, params(args), hidden=args.hidden)
    out = Path(args.out or f"butterfly_{args.optimizer}_{args.task}_s{args.seed}.json")
    res, ctrl = evolve_controller(problem, args.optimizer, args.seed, out, population=args.population,
                                  generations=gens, evaluations=args.evaluations, executor=args.executor,
                                  workers=args.workers, ray_address=args.ray_address, checkpoint=args.checkpoint,
                                  resume=args.resume, progress=not args.quiet, task=args.task,
                                  command="lifelike-mj " + " ".join(sys.argv[1:]), overwrite=args.overwrite)
    if ctrl is None:
        raise KeyboardInterrupt("stopped before the first generation was evaluated; nothing was written")
    d = {"out": str(out), **{k: v for k, v in ctrl.provenance.items() if k not in ("fitness_history", "problem")}}
    state = "stopped early (Ctrl-C); best so far" if res.interrupted else "done"
    emit(args, d, f"{state}: best fitness H = {res.best_f:.1f} after {res.evaluations} evaluations "
         f"({res.wall_time_s:.1f} s); controller written to {out}")
    if res.interrupted:
        raise KeyboardInterrupt


def cmd_windmap(args) -> None:
    from lifelike_mj.butterfly.ann_experiments import e11_windmap

    check_outputs(args, files={"--plot": (".png",)})
    cells = (2 * math.floor(args.max / args.step + 1e-9) + 1) ** 2
    if cells > MAX_WIND_CELLS:
        raise UserError(f"--max {args.max:g} with --step {args.step:g} makes {cells:,} wind cells; at most "
                        f"{MAX_WIND_CELLS:,} (a larger --step or a smaller --max).")
    ctrl = _controller(args)
    if ctrl.type != "ann":
        raise UserError(f"the wind map needs a network (ann) controller; {args.controller!r} is {ctrl.type!r}.")
    m = e11_windmap(ctrl, args.inputs, positive("--step", args.step), positive("--max", args.max), params(args),
                    progress=True)
    d = {"controller": ctrl.name or args.controller, **m.to_dict()}
    if args.plot:
        from lifelike_mj.butterfly.ann_figures import fig_windmap

        fig_windmap(m, args.plot, titles=[f"{d['controller']} ({m.inputs} inputs)"])
        d["plot"] = args.plot
    emit(args, d, f"{m.pass_cells} of {m.total_cells} wind cells pass ({m.inputs} velocity inputs)")


def cmd_assess(args) -> None:
    from lifelike_mj.butterfly.ann_experiments import assess

    ctrl = _controller(args)
    if ctrl.type != "ann":
        raise UserError(f"assess needs a network (ann) controller; {args.controller!r} is {ctrl.type!r}.")
    with stage("assess: still air, from +10 m and from below, tail wind, the wind map"):
        d = {"controller": ctrl.name or args.controller, **assess(ctrl, params(args))}
    s = d["still_air"]
    human = (f"still air: drop {s['initial_drop_m']:.2f} m, settled [{s['settled_altitude_min_m']:+.3f}, "
             f"{s['settled_altitude_max_m']:+.3f}] m at {s['settled_forward_speed_cm_s']:.0f} cm/s; from +10 m holds: "
             f"{d['from_+10m_holds']}; from below reaches 0 m: {d['from_below_reaches_target']}; 2 m/s tail wind "
             f"holds +-0.5 m: {d['tail_wind_2m_s']['holds_0_5m']}; wind map passes {d['windmap_pass_cells']} of "
             f"{d['windmap_total_cells']}")
    emit(args, d, human)


def cmd_compare(args) -> None:
    from lifelike_mj.butterfly.compare import compare
    from lifelike_mj.butterfly.flight import check_timing

    ctrl = _controller(args)
    check_timing(args.duration, args.dt)
    with stage("the same flight on both backends"):
        r = compare(ctrl, args.config, params(args), duration_s=positive("--duration", args.duration),
                    dt_s=positive("--dt", args.dt), force_mode=args.force_mode)
    d = r.to_dict()
    emit(args, d, f"{args.config} configuration ({r.force_mode} force): largest altitude difference "
         f"{r.max_altitude_diff_m * 100:.2f} cm ({100 * r.altitude_diff_fraction:.2f} % of the "
         f"{r.max_altitude_excursion_m:.2f} m excursion), largest forward difference {r.max_forward_diff_m * 100:.2f} cm")


def add_commands(sub) -> None:
    """The ``lifelike-mj butterfly ...`` subcommands."""
    from lifelike_mj.cli.common import Parser

    bf = sub.add_parser(NAME, help=HELP).add_subparsers(dest="sub", required=True, parser_class=Parser)
    p = bf.add_parser("speed-limit", help="E3: quasi-static forward-speed limit (section 4.3)")
    add_physics(p)
    add_json(p)
    p.set_defaults(func=cmd_speed_limit)
    p = bf.add_parser("forces", help="E1: closed forms (eq. 4, 6) against strip integration")
    add_physics(p)
    add_json(p)
    p.set_defaults(func=cmd_forces)
    p = bf.add_parser("trim", help="E4: level-flight upstroke pitch of the simple rule (section 5.1)")
    add_physics(p)
    _add_backend(p)
    p.add_argument("--dt", type=num(0, 0.01, lo_open=True, unit="s"), default=1.0 / 12000.0,
                   help="time step, s, in (0, 0.01] (paper: 1/12000)")
    add_json(p)
    p.set_defaults(func=cmd_trim)
    p = bf.add_parser("timestep", help="E5: time-step study at phi_up = 14 deg (section 5.2)")
    add_physics(p)
    _add_backend(p)
    add_json(p)
    p.set_defaults(func=cmd_timestep)
    p = bf.add_parser("fly", help="fly a controller")
    _add_controller(p)
    add_physics(p)
    _add_backend(p)
    p.add_argument("--y0", type=num(-1000, 1000, unit="m"), default=0.0, help="start altitude, m, within +-1000")
    add_wind(p, 2, "from", "forward, up")
    p.add_argument("--duration", type=num(0, MAX_DURATION_S, lo_open=True, unit="s"), default=20.0,
                   help=f"seconds of flight, at most {MAX_DURATION_S:g}")
    p.add_argument("--dt", type=num(0, 0.0125, lo_open=True, unit="s"), default=1.0 / 1200.0,
                   help="time step, s, at most 1/8 of the wing beat")
    p.add_argument("--out", help="folder for trajectory.npz/.csv, flight.png, summary.json")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_fly)
    p = bf.add_parser("evolve", help="evolve the network pitch controller (section 6) with an optimiser")
    p.add_argument("--optimizer", required=True, choices=("rcga", "cmaes", "crs2", "esch", "isres"),
                   help="rcga (the paper's GA), cmaes, crs2, esch or isres")
    p.add_argument("--task", default="paper",
                   help="paper (still air from 0 m, section 6.3); robust, robust_wide or robust_map (varied starts and winds)")
    p.add_argument("--hidden", default=None,
                   help="hidden layer sizes of the network, e.g. 8,8 (default 6: the paper's 6-6-1 network)")
    p.add_argument("--population", type=count(1, 100_000), default=None,
                   help="population size, up to 100,000 (default: rcga 40, cmaes 4 + 3 ln(genes), nlopt's own)")
    p.add_argument("--generations", type=count(1, 1_000_000), default=None,
                   help="generations, up to 1,000,000 (default 1000, the paper's)")
    p.add_argument("--evaluations", type=count(1, 10**9), default=None,
                   help="budget in evaluations instead of generations, up to 10^9")
    add_seed(p)
    p.add_argument("--backend", default="paper", choices=("paper", "mujoco"), help="paper (compiled eq. 7-11) or mujoco")
    p.add_argument("--inputs", default=None, type=_inputs(("air", "ground", "both")), metavar="{air,ground,both}",
                   help="velocity inputs: through the air, over the ground, or both (default: air; robust task: both)")
    add_executor(p)
    add_run_files(p, "controller file to write (.json; default butterfly_OPT_TASK_sSEED.json)")
    add_json(p)
    add_physics(p)
    p.set_defaults(func=cmd_evolve)
    p = bf.add_parser("windmap", help="E11: pass/fail map over uniform winds (section 7.2)")
    _add_controller(p)
    add_physics(p)
    p.add_argument("--step", type=num(0.01, 10, unit="m/s"), default=0.1, help="grid step, m/s, at least 0.01")
    p.add_argument("--max", type=num(0, 10, lo_open=True, unit="m/s"), default=3.0,
                   help="largest wind component, m/s, at most 10")
    p.add_argument("--plot", default=None, help="write the map as a PNG")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_windmap)
    p = bf.add_parser("assess", help="a network controller's acceptance numbers (E6, E7, E9, tail wind, E11)")
    _add_controller(p)
    add_physics(p)
    add_json(p)
    p.set_defaults(func=cmd_assess)
    p = bf.add_parser("compare", help="the same flight on both backends")
    _add_controller(p)
    add_physics(p)
    p.add_argument("--config", default="paper", choices=("paper", "rich"),
                   help="paper (equivalent) or rich (free body, heavy wings, strips)")
    p.add_argument("--force-mode", default=None, choices=("tip", "strip"),
                   help="tip or strip (default: tip for paper, strip for rich)")
    p.add_argument("--duration", type=num(0, MAX_DURATION_S, lo_open=True, unit="s"), default=20.0,
                   help="seconds of flight")
    p.add_argument("--dt", type=num(0, 0.0125, lo_open=True, unit="s"), default=1.0 / 1200.0, help="time step, s")
    add_json(p)
    p.set_defaults(func=cmd_compare)
    from lifelike_mj.cli import butterfly3d

    butterfly3d.add_commands(bf)


# ---- the shared verbs -----------------------------------------------------------------------------


def _add_scene(p: argparse.ArgumentParser) -> None:
    _add_controller(p, required=False)
    add_physics(p)
    p.add_argument("--config", default="paper", choices=("paper", "rich"), help="MuJoCo configuration: paper or rich")
    p.add_argument("--force-mode", default=None, choices=("tip", "strip"), help="tip or strip (default: the configuration's)")
    p.add_argument("--y0", type=num(-1000, 1000, unit="m"), default=0.0, help="start altitude, m")
    add_wind(p, 2, "from", "forward, up")


def add_view_args(p: argparse.ArgumentParser) -> None:
    _add_scene(p)
    p.add_argument("--duration", type=num(0, None, lo_open=True, unit="s"), default=None,
                   help="stop after this many seconds (default: run until the window is closed)")


def view(args) -> None:
    from lifelike_mj.butterfly.render import view_butterfly
    from lifelike_mj.cli import web_options

    web = web_options(args)
    view_butterfly(_controller(args), params(args), _condition(args), config=args.config, force_mode=args.force_mode,
                   duration_s=args.duration, web=web)


def add_render_args(p: argparse.ArgumentParser) -> None:
    _add_scene(p)
    p.add_argument("--duration", type=num(0, MAX_VIDEO_S, lo_open=True, unit="s"), default=3.0,
                   help=f"seconds of flight, at most {MAX_VIDEO_S:g}")
    p.add_argument("--camera", default="follow", choices=("follow", "side", "chase"), help="follow, side or chase")


def render(args) -> dict:
    from lifelike_mj.butterfly.render import render_butterfly

    return render_butterfly(args.out, _controller(args), params(args), _condition(args), config=args.config,
                            force_mode=args.force_mode, duration_s=positive("--duration", args.duration), fps=args.fps,
                            width=args.width, height=args.height, camera=args.camera, progress=True)


def add_reproduce_args(p: argparse.ArgumentParser) -> None:
    add_physics(p)


def reproduce(out: Path, args) -> None:
    from lifelike_mj.butterfly.report import reproduce as run

    run(out, params(args))


def add_bench_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--repeats", type=count(1, 100), default=5, help="timed repeats (the median is reported)")


def bench(args) -> tuple[dict, str]:
    from lifelike_mj.butterfly import bench as b

    r = b.run(repeats=args.repeats)
    human = (f"paper backend {r['paper_ns_per_step']:.1f} ns/step (naive Python {r['naive_ns_per_step']:.0f} ns/step, "
             f"x{r['paper_speedup_vs_naive']:.0f}); MuJoCo bare {r['mujoco_bare_us_per_step']:.2f} us/step, with "
             f"callback+controller {r['mujoco_us_per_step']:.2f} us/step (+{100 * r['mujoco_callback_overhead']:.0f} %)")
    return r, human


def add_export_args(p: argparse.ArgumentParser) -> None:
    from lifelike_mj.cli.export import add_window

    _add_scene(p)
    add_window(p, MAX_VIDEO_S, 3.0)


def export_window(args):
    """The run to export, built and checked, not yet simulated (:class:`~lifelike_mj.cli.export.Window`), and the
    parameters that make it."""
    from lifelike_mj.butterfly import Flight
    from lifelike_mj.cli.export import Window, check_window, parameters_of

    check_window(args.start, args.duration, args.fps, 1.0 / 1200.0)
    flight = Flight(_controller(args), params(args), _condition(args), backend="mujoco", config=args.config,
                    force_mode=args.force_mode)
    return Window(flight, args.start, args.duration, args.fps), parameters_of(args)


def loop_cut_body(args) -> str | None:
    """The body whose beat a looped export is cut at (``export --loop``), or None to blend the loop."""
    return "wing_left"


def export_rigs(poses) -> list:
    """The run's creatures as rigs (skinned, textured meshes on skeletons), for ``export --looks rig``."""
    from lifelike_mj.butterfly.look import rigs

    return rigs(poses, ("swallowtail",))
