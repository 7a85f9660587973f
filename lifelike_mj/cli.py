"""The ``lifelike-mj`` command.

Every error a user can cause ends in one sentence on stderr and exit status 2; imports are lazy so
that ``--help`` is instant and the GL backend can be chosen before MuJoCo is imported.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from lifelike_mj.errors import UserError


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one sentence, exit 2 (argparse prints usage otherwise)
        raise UserError(f"{message} (see '{self.prog} --help').")


def _wind(text: str) -> tuple[float, float]:
    parts = text.split(",")
    try:
        a, b = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--wind needs two numbers A,B in m/s, got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise argparse.ArgumentTypeError(f"--wind needs two finite numbers, got {text!r}")
    return a, b


def _add_physics(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("physical constants (defaults: Oe 2010, A_b = 1.0 cm^2)")
    g.add_argument("--body-area-cm2", type=float, help="body projected area A_b (eq. 10), cm^2")
    g.add_argument("--mass-g", type=float, help="butterfly mass m, g (paper: 0.319)")
    g.add_argument("--span-cm", type=float, help="wing length L, cm (paper: 5.5)")
    g.add_argument("--width-cm", type=float, help="wing width W, cm (paper: 5.0)")
    g.add_argument("--rho", type=float, help="air density, kg/m^3 (paper: 1.28)")
    g.add_argument("--cd", type=float, help="drag coefficient C_d (paper: 2.2)")


def _params(args):
    from lifelike_mj.butterfly.params import ButterflyParams

    return ButterflyParams().with_overrides(
        body_area_cm2=args.body_area_cm2, mass_g=args.mass_g, span_cm=args.span_cm, width_cm=args.width_cm,
        rho=args.rho, cd=args.cd)


def _add_controller(p: argparse.ArgumentParser, required: bool = True) -> None:
    p.add_argument("--controller", required=required, default=None if required else "simple_rule",
                   help="shipped controller name (e.g. simple_rule) or path to a controller JSON file")
    p.add_argument("--phi-up-deg", type=float, help="override simple_rule's upstroke pitch, deg")
    p.add_argument("--phi-down-deg", type=float, help="override simple_rule's downstroke pitch, deg")
    p.add_argument("--phi-deg", type=float, help="override a constant controller's pitch, deg")
    p.add_argument("--inputs", choices=None, default=None,
                   help="network controllers: feed relative (air) or ground velocities (section 7.2)")


def _controller(args):
    from lifelike_mj.butterfly import controllers

    ctrl = controllers.load(args.controller)
    overrides = {"phi_up_deg": args.phi_up_deg, "phi_down_deg": args.phi_down_deg, "phi_deg": args.phi_deg}
    ctrl = ctrl.with_parameters(**overrides)
    if getattr(args, "inputs", None):
        ctrl = ctrl.with_inputs(args.inputs)
    return ctrl


def _add_backend(p: argparse.ArgumentParser) -> None:
    p.add_argument("--backend", default="paper", help="paper (eq. 7-11, compiled) or mujoco (models/butterfly.xml)")
    p.add_argument("--config", default="paper", help="MuJoCo configuration: paper (equivalent) or rich")
    p.add_argument("--force-mode", default=None, help="MuJoCo wing force: tip (paper formula) or strip")


def _backend_options(args) -> dict:
    from lifelike_mj.butterfly.backends import DEFAULT_FORCE_MODE, check_backend

    check_backend(args.backend)
    if args.backend != "mujoco":
        return {}
    if args.config not in DEFAULT_FORCE_MODE:
        raise UserError(f"unknown configuration {args.config!r}; choose paper or rich.")
    return {"config": args.config, "force_mode": args.force_mode or DEFAULT_FORCE_MODE[args.config]}


def _positive(name: str, value: float) -> float:
    if not (math.isfinite(value) and value > 0):
        raise UserError(f"{name} must be a positive number, got {value}.")
    return value


def _emit(args, data: dict, human: str) -> None:
    print(json.dumps(data, indent=2) if getattr(args, "json", False) else human)


# ---- commands ---------------------------------------------------------------------------------


def cmd_speed_limit(args) -> None:
    from lifelike_mj.butterfly import aero

    r = aero.speed_limit(_params(args))
    _emit(args, r.to_dict(), f"speed limit: {r.speed_limit_cm_s} cm/s at A_b = {r.body_area_cm2:g} cm^2 "
          f"(continuous solution {100 * r.closed_form_m_s:.1f} cm/s; paper: 380 cm/s)")


def cmd_forces(args) -> None:
    from lifelike_mj.butterfly import aero

    r = aero.check_closed_forms(_params(args))
    lines = [f"{q:6s} planform {k}: closed form {c:.6e}, strips {s:.6e}, rel. error {e:.1e}" for q, k, c, s, e in r.rows]
    lines.append(f"largest relative error: {r.closed_form_max_rel_error:.2e}")
    _emit(args, r.to_dict(), "\n".join(lines))


def cmd_trim(args) -> None:
    from lifelike_mj.butterfly import experiments

    opts = _backend_options(args)
    r = experiments.e4_trim(_params(args), backend=args.backend, dt_s=_positive("--dt", args.dt), **opts)
    d = r.to_dict()
    _emit(args, d, f"level flight at phi_up = {d['phi_up_level_deg']:.3f} deg (paper 12.77); settled forward speed "
          f"{d['mean_forward_speed_cm_s']:.1f} cm/s (paper 340); ripple {d['ripple_cm']:.2f} cm (paper 5.3); "
          f"initial drop {d['initial_drop_m']:.2f} m (paper about 3)")


def cmd_timestep(args) -> None:
    from lifelike_mj.butterfly import experiments

    opts = _backend_options(args)
    r = experiments.e5_timestep(_params(args), backend=args.backend, **opts)
    d = r.to_dict()
    rows = [f"dt {k:>8s}: altitude at 20 s {d['altitude_20s_m'][k]:8.3f} m, rel. error {d['rel_error'][k]:.2e}"
            for k in d["altitude_20s_m"]]
    _emit(args, d, "\n".join(rows))


def cmd_fly(args) -> None:
    from lifelike_mj.butterfly import backends
    from lifelike_mj.butterfly.flight import Condition, check_timing

    ctrl = _controller(args)
    params = _params(args)
    opts = _backend_options(args)
    check_timing(args.duration, args.dt)
    cond = Condition(args.y0, args.wind)
    traj = backends.simulate(args.backend, ctrl, params, cond, args.duration, args.dt, 1, **opts)[0]
    summary = {"controller": ctrl.name or args.controller, **traj.summary(), **({"config": opts} if opts else {})}
    if traj.diverged_step >= 0:
        raise UserError(f"the flight diverged (runaway speed) at step {traj.diverged_step}.")
    if args.out:
        from lifelike_mj.io import write_json, write_npz, write_text
        from lifelike_mj.viz.flight import fig_flight

        out = Path(args.out)
        write_npz(out / "trajectory.npz", **traj.to_npz_dict())
        write_text(out / "trajectory.csv", traj.to_csv())
        fig_flight(traj, out / "flight.png", f"{summary['controller']} on the {args.backend} backend")
        write_json(out / "summary.json", summary)
    human = (f"final altitude {summary['final_altitude_m']:.3f} m, min {summary['min_altitude_m']:.3f} m, "
             f"mean forward speed {summary['mean_forward_speed_cm_s']:.1f} cm/s; last 10 s: altitude in "
             f"[{summary['settled_altitude_min_m']:.3f}, {summary['settled_altitude_max_m']:.3f}] m, "
             f"speed {summary['settled_forward_speed_cm_s']:.1f} cm/s")
    _emit(args, summary, human)


def cmd_evolve(args) -> None:
    from lifelike_mj.butterfly.evolution import evolve_controller, make_problem

    if args.generations is not None and args.evaluations is not None:
        raise UserError("give either --generations or --evaluations, not both.")
    gens = args.generations
    if gens is None and args.evaluations is None:
        gens = 1000  # the paper's budget (section 6.3)
    problem = make_problem(args.task, args.backend, args.inputs, _params(args))
    out = Path(args.out or f"butterfly_{args.optimizer}_{args.task}_s{args.seed}.json")
    if out.suffix != ".json":
        raise UserError(f"--out must be a .json file, got {str(out)!r}.")
    res, ctrl = evolve_controller(problem, args.optimizer, args.seed, out, population=args.population,
                                  generations=gens, evaluations=args.evaluations, executor=args.executor,
                                  workers=args.workers, ray_address=args.ray_address, checkpoint=args.checkpoint,
                                  resume=args.resume, progress=not args.quiet, task=args.task,
                                  command="lifelike-mj " + " ".join(sys.argv[1:]))
    d = {"out": str(out), **{k: v for k, v in ctrl.provenance.items() if k not in ("fitness_history", "problem")}}
    state = "stopped early (Ctrl-C); best so far" if res.interrupted else "done"
    _emit(args, d, f"{state}: best fitness H = {res.best_f:.1f} after {res.evaluations} evaluations "
          f"({res.wall_time_s:.1f} s); controller written to {out}")
    if res.interrupted:
        raise KeyboardInterrupt


def cmd_windmap(args) -> None:
    from lifelike_mj.butterfly.ann_experiments import e11_windmap

    ctrl = _controller(args)
    if ctrl.type != "ann":
        raise UserError(f"the wind map needs a network (ann) controller; {args.controller!r} is {ctrl.type!r}.")
    m = e11_windmap(ctrl, args.inputs, _positive("--step", args.step), _positive("--max", args.max), _params(args),
                    progress=not args.json)
    d = {"controller": ctrl.name or args.controller, **m.to_dict()}
    if args.plot:
        from lifelike_mj.viz.ann_figures import fig_windmap

        fig_windmap(m, args.plot, titles=[f"{d['controller']} ({m.inputs} inputs)"])
        d["plot"] = args.plot
    _emit(args, d, f"{m.pass_cells} of {m.total_cells} wind cells pass ({m.inputs} velocity inputs)")


def cmd_assess(args) -> None:
    from lifelike_mj.butterfly.ann_experiments import assess

    ctrl = _controller(args)
    if ctrl.type != "ann":
        raise UserError(f"assess needs a network (ann) controller; {args.controller!r} is {ctrl.type!r}.")
    d = {"controller": ctrl.name or args.controller, **assess(ctrl, _params(args))}
    s = d["still_air"]
    human = (f"still air: drop {s['initial_drop_m']:.2f} m, settled [{s['settled_altitude_min_m']:+.3f}, "
             f"{s['settled_altitude_max_m']:+.3f}] m at {s['settled_forward_speed_cm_s']:.0f} cm/s; from +10 m holds: "
             f"{d['from_+10m_holds']}; from below reaches 0 m: {d['from_below_reaches_target']}; 2 m/s tail wind "
             f"holds +-0.5 m: {d['tail_wind_2m_s']['holds_0_5m']}; wind map passes {d['windmap_pass_cells']} of "
             f"{d['windmap_total_cells']}")
    _emit(args, d, human)


def cmd_compare(args) -> None:
    from lifelike_mj.butterfly.compare import compare

    ctrl = _controller(args)
    r = compare(ctrl, args.config, _params(args), duration_s=_positive("--duration", args.duration),
                dt_s=_positive("--dt", args.dt), force_mode=args.force_mode)
    d = r.to_dict()
    _emit(args, d, f"{args.config} configuration ({r.force_mode} force): largest altitude difference "
          f"{r.max_altitude_diff_m * 100:.2f} cm ({100 * r.altitude_diff_fraction:.2f} % of the "
          f"{r.max_altitude_excursion_m:.2f} m excursion), largest forward difference {r.max_forward_diff_m * 100:.2f} cm")


def _fish_preset(args):
    from lifelike_mj.fish.params import load_preset

    return load_preset(args.preset)


def _fish_count(n) -> int:
    if n is None or n < 1:
        raise UserError(f"--fish must be at least 1, got {n}.")
    return int(n)


def _tank(args):
    from lifelike_mj.fish.scene import tank_size

    return tank_size(_positive("--tank-scale", args.tank_scale))


def cmd_fish_swim(args) -> None:
    from lifelike_mj.fish.experiments import swim_summary, write_tracks
    from lifelike_mj.fish.sim import swim

    params = _fish_preset(args)
    n = _fish_count(args.fish)
    if args.seed < 0:
        raise UserError(f"--seed must be a non-negative whole number, got {args.seed}.")
    if args.video and Path(args.video).suffix.lower() not in (".mp4", ".gif"):
        raise UserError(f"--video must end in .mp4 or .gif, got {args.video!r}.")
    if args.video:
        from lifelike_mj.viz.fish_video import CAMERAS

        if args.camera not in CAMERAS:
            raise UserError(f"unknown camera {args.camera!r}; choose one of {', '.join(CAMERAS)}.")
    r = swim(params, n, _positive("--duration", args.duration), args.seed, _tank(args), progress=not args.json)
    summary = swim_summary(r)
    if args.out:
        from lifelike_mj.io import write_json
        from lifelike_mj.viz.fish_figures import accel_histogram_figure, tracks_figure

        out = Path(args.out)
        files = write_tracks(r, out)
        tracks_figure(r, out / "tracks.png")
        accel_histogram_figure(r, out / "accel_histogram.png")
        write_json(out / "measures.json", summary)
        summary["files"] = [str(f) for f in (*files.values(), out / "tracks.png", out / "accel_histogram.png",
                                                out / "measures.json")]
    if args.video:
        from lifelike_mj.viz.fish_video import render_fish

        info = render_fish(args.video, params, n, min(args.duration, args.video_duration), args.seed, _tank(args),
                           camera=args.camera)
        summary["video"] = info
    _emit(args, summary, (f"{n} fish, {summary['duration_s']:.0f} s ({params.name}): a burst every "
                          f"{summary['burst_interval_mean_s']:.2f} s, burstiness {summary['burstiness']:.3f}, "
                          f"acceleration kurtosis {summary['accel_kurtosis']:.2f}, turning entropy "
                          f"{summary['turn_entropy']:.2f} bits, mean speed {summary['mean_speed_body_lengths_s']:.2f} "
                          f"body lengths/s, {summary['fish_outside_tank']} outside the tank "
                          f"({summary['realtime_factor']:.0f}x real time)"))


def cmd_fish_drag_check(args) -> None:
    from lifelike_mj.fish.experiments import drag_check

    r = drag_check()
    _emit(args, r, f"custom drag vs MuJoCo's inertia-box fluid model: max relative error {r['max_rel_error']:.2e} "
          f"over {r['trials']} random states")


def _boids_params(args):
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


def cmd_boids_run(args) -> None:
    from lifelike_mj.boids.experiments import classified_run, write_trajectories

    params = _boids_params(args)
    if args.n < 2:
        raise UserError(f"--n must be at least 2, got {args.n}.")
    if args.steps is not None and args.steps < 10:
        raise UserError(f"--steps must be at least 10, got {args.steps}.")
    run, m, label, reasons = classified_run(params, args.n, args.seed, args.steps, progress=not args.json)
    out = {"label": label, "reasons": reasons, **m, "preset": params.name, "n": args.n, "seed": args.seed,
           "steps": int(run.steps[-1]), "dims": params.dims, "wall_time_s": run.wall_time_s}
    if args.plot:
        from lifelike_mj.viz.boids_figures import pattern_figure

        pattern_figure(run, args.plot, title=f"{params.name}: classified {label}")
    if args.out:
        from lifelike_mj.io import write_json

        files = write_trajectories(run, args.out)
        write_json(Path(args.out) / "measures.json", out)
        out["files"] = [str(f) for f in files.values()]
    _emit(args, out, f"{params.name}, n = {args.n}, seed {args.seed}, {out['steps']} steps: classified {label} "
          f"(segregation index {m.get('segregation_index', float('nan')):.2f}, groups {m.get('n_groups')})")


def cmd_boids_sweep(args) -> None:
    from lifelike_mj.boids.experiments import Sweep, run_sweep
    from lifelike_mj.boids.presets import homogeneous, load_grid
    from lifelike_mj.io import write_json

    seeds = _seeds(args.seeds)
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
        sweep = Sweep(_boids_params(args), tuple(axes), args.n, args.steps)
    res = run_sweep(sweep, values, seeds, executor=args.executor, workers=args.workers, ray_address=args.ray_address)
    if args.out:
        out = Path(args.out)
        write_json(out / "sweep.json", res)
        if len(values) == 2:
            import numpy as np

            from lifelike_mj.viz.boids_figures import phase_diagram_figure

            labels = np.array([[res["majority"][f"{a:g},{b:g}"] for a in values[0]] for b in values[1]])
            phase_diagram_figure(labels, values[0], values[1], sweep.axes[0], sweep.axes[1], out / "phase_diagram.png")
    counts = {}
    for v in res["majority"].values():
        counts[v] = counts.get(v, 0) + 1
    _emit(args, res, f"{len(res['rows'])} runs over {len(res['majority'])} cells: "
          + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))


def _seeds(text: str) -> list[int]:
    try:
        if "-" in text:
            a, b = (int(x) for x in text.split("-"))
            seeds = list(range(a, b + 1))
        else:
            seeds = [int(x) for x in text.split(",")]
    except ValueError:
        raise UserError(f"--seeds must look like 0-4 or 0,1,2, got {text!r}.") from None
    if not seeds or min(seeds) < 0:
        raise UserError(f"--seeds must name non-negative seeds, got {text!r}.")
    return seeds


def _axis(spec: str) -> tuple[str, list[float]]:
    import numpy as np

    try:
        name, rng = spec.split("=")
        a, b, k = rng.split(":")
        values = [float(x) for x in np.linspace(float(a), float(b), int(k))]
    except ValueError:
        raise UserError(f"a sweep axis looks like wa_cross=-0.3:0.5:9 (name=start:stop:count), got {spec!r}.") from None
    if len(values) < 1:
        raise UserError(f"a sweep axis needs at least one value, got {spec!r}.")
    return name, values


REPRODUCIBLE = ("butterfly", "fish", "boids")


def cmd_reproduce(args) -> None:
    if args.what not in (*REPRODUCIBLE, "all"):
        raise UserError(f"nothing to reproduce for {args.what!r}; available: {', '.join(REPRODUCIBLE)} or all.")
    whats = REPRODUCIBLE if args.what == "all" else (args.what,)
    for what in whats:
        out = Path(args.out or "reports") / what if (args.what == "all" or not args.out) else Path(args.out)
        if what == "fish":
            from lifelike_mj.fish.reproduce import reproduce_fish

            reproduce_fish(out)
        elif what == "boids":
            from lifelike_mj.boids.reproduce import reproduce_boids

            reproduce_boids(out)
        else:
            from lifelike_mj.butterfly.reproduce import reproduce_all

            reproduce_all(out, _params(args))
        print(f"report written to {out / 'report.md'}")


def cmd_bench(args) -> None:
    if args.what not in ("butterfly", "fish", "boids"):
        raise UserError(f"no benchmark for {args.what!r} yet; available: butterfly, fish, boids.")
    if args.what == "boids":
        from lifelike_mj.boids import bench as boids_bench

        r = boids_bench.run(repeats=min(args.repeats, 3), max_n=args.max_n, mesa_python=args.mesa_python)
        if args.out:
            from lifelike_mj.io import write_json

            write_json(args.out, r)
        _emit(args, r, f"n = 300: {r['agent_steps_per_s_n300']:.3g} agent-steps/s; scaling exponent "
              f"{r.get('scaling_exponent', float('nan')):.2f}; x{r.get('mesa_ratio', float('nan')):.0f} Mesa")
        return
    if args.what == "fish":
        from lifelike_mj.fish import bench as fish_bench

        r = fish_bench.run(repeats=args.repeats, long_minutes=args.long_minutes)
        if args.out:
            from lifelike_mj.io import write_json

            write_json(args.out, r)
        rend = r.get("render", {})
        human = (f"10 fish x{r['ten']['realtime_factor']:.0f} real time, 1,000 fish "
                 f"x{r['thousand']['realtime_factor']:.2f}, render {rend.get('fps', float('nan')):.0f} fps "
                 f"at 640x480")
        _emit(args, r, human)
        return
    from lifelike_mj.butterfly import bench

    r = bench.run(repeats=args.repeats)
    if args.out:
        from lifelike_mj.io import write_json

        write_json(args.out, r)
    human = (f"paper backend {r['paper_ns_per_step']:.1f} ns/step (naive Python {r['naive_ns_per_step']:.0f} ns/step, "
             f"x{r['paper_speedup_vs_naive']:.0f}); MuJoCo bare {r['mujoco_bare_us_per_step']:.2f} us/step, with "
             f"callback+controller {r['mujoco_us_per_step']:.2f} us/step (+{100 * r['mujoco_callback_overhead']:.0f} %)")
    _emit(args, r, human)


def cmd_view(args) -> None:
    if args.what not in ("butterfly", "fish", "boids"):
        raise UserError(f"nothing to view for {args.what!r} yet; available: butterfly, fish, boids.")
    if args.what == "boids":
        from lifelike_mj.viz.boids_video import view_boids

        view_boids(_boids_params(args), n=args.n, seed=args.seed)
        return
    if args.what == "fish":
        from lifelike_mj.viz.fish_video import view_fish

        view_fish(_fish_preset(args), _fish_count(args.fish), args.seed, _tank(args), duration_s=args.duration)
        return
    from lifelike_mj.butterfly.flight import Condition
    from lifelike_mj.viz.viewer import view_butterfly

    view_butterfly(_controller(args), _params(args), Condition(args.y0, args.wind), config=args.config,
                   force_mode=args.force_mode or ("strip" if args.config == "rich" else "tip"),
                   duration_s=args.duration)


def cmd_render(args) -> None:
    if args.what not in ("butterfly", "fish", "boids"):
        raise UserError(f"nothing to render for {args.what!r} yet; available: butterfly, fish, boids.")
    if Path(args.out).suffix.lower() not in (".mp4", ".gif"):
        raise UserError(f"--out must end in .mp4 or .gif, got {args.out!r}.")
    if args.what == "boids":
        from lifelike_mj.viz.boids_video import render_boids

        info = render_boids(args.out, _boids_params(args), n=args.n, n_steps=args.steps or 3000, seed=args.seed,
                            fps=args.fps, width=args.width, height=args.height, camera=args.camera or "overview")
        _emit(args, info, f"wrote {info['frames']} frames to {args.out}")
        return
    if args.what == "fish":
        from lifelike_mj.viz.fish_video import render_fish

        info = render_fish(args.out, _fish_preset(args), _fish_count(args.fish),
                           _positive("--duration", args.duration), args.seed, _tank(args), fps=args.fps,
                           width=args.width, height=args.height, camera=args.camera or "side")
        _emit(args, info, f"wrote {info['frames']} frames to {args.out}")
        return
    from lifelike_mj.butterfly.flight import Condition
    from lifelike_mj.viz.video import render_butterfly

    info = render_butterfly(args.out, _controller(args), _params(args), Condition(args.y0, args.wind),
                            config=args.config, force_mode=args.force_mode or ("strip" if args.config == "rich" else "tip"),
                            duration_s=_positive("--duration", args.duration), fps=args.fps, width=args.width,
                            height=args.height)
    _emit(args, info, f"wrote {info['frames']} frames to {args.out}")


def _add_boids(p) -> None:
    p.add_argument("--preset", default=None, help="pattern preset 4a ... 5d (default 5a), or a JSON file")
    p.add_argument("--wa", help="alignment matrix 'a,b;c,d' (rows: own type), with --wc instead of a preset")
    p.add_argument("--wc", help="cohesion matrix 'a,b;c,d'")
    p.add_argument("--n", type=int, default=300, help="number of agents")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--dims", type=int, default=3, help="3 or 2 (section 4.3)")


def _add_fish(p) -> None:
    p.add_argument("--preset", default="default",
                   help="fish motion preset: NB-ND, NB-D, B-ND, B-D, default (= B-D), or a JSON file")
    p.add_argument("--fish", type=int, default=10, help="number of fish")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--tank-scale", type=float, default=1.0,
                   help="tank size as a fraction of the filmed 5 m x 0.5 m x 1 m tank")


def build_parser() -> argparse.ArgumentParser:
    from lifelike_mj import __version__

    top = _Parser(prog="lifelike-mj", description="Creatures that move like living things, by physics on MuJoCo.")
    top.add_argument("--version", action="version", version=f"lifelike-mj {__version__}")
    sub = top.add_subparsers(dest="command", required=True, parser_class=_Parser)

    bf = sub.add_parser("butterfly", help="the butterfly of Oe et al. 2010").add_subparsers(
        dest="sub", required=True, parser_class=_Parser)
    p = bf.add_parser("speed-limit", help="E3: quasi-static forward-speed limit (section 4.3)")
    _add_physics(p)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_speed_limit)
    p = bf.add_parser("forces", help="E1: closed forms (eq. 4, 6) against strip integration")
    _add_physics(p)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_forces)
    p = bf.add_parser("trim", help="E4: level-flight upstroke pitch of the simple rule (section 5.1)")
    _add_physics(p)
    _add_backend(p)
    p.add_argument("--dt", type=float, default=1.0 / 12000.0, help="time step, s (paper: 1/12000)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_trim)
    p = bf.add_parser("timestep", help="E5: time-step study at phi_up = 14 deg (section 5.2)")
    _add_physics(p)
    _add_backend(p)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_timestep)
    p = bf.add_parser("fly", help="fly a controller")
    _add_controller(p)
    _add_physics(p)
    _add_backend(p)
    p.add_argument("--y0", type=float, default=0.0, help="start altitude, m")
    p.add_argument("--wind", type=_wind, default=(0.0, 0.0), help="wind A,B in m/s: where it comes from (forward, up)")
    p.add_argument("--duration", type=float, default=20.0, help="seconds")
    p.add_argument("--dt", type=float, default=1.0 / 1200.0, help="time step, s")
    p.add_argument("--out", help="folder for trajectory.npz/.csv, flight.png, summary.json")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_fly)
    p = bf.add_parser("evolve", help="evolve the network pitch controller (section 6) with an optimiser")
    p.add_argument("--optimizer", required=True, help="rcga (the paper's GA), cmaes, crs2, esch or isres")
    p.add_argument("--task", default="paper",
                   help="paper (still air from 0 m, section 6.3); robust, robust_wide or robust_map (varied starts and winds)")
    p.add_argument("--population", type=int, default=None, help="population size (rcga default 40)")
    p.add_argument("--generations", type=int, default=None, help="generations (default 1000)")
    p.add_argument("--evaluations", type=int, default=None, help="budget in evaluations instead of generations")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--backend", default="paper", help="paper (compiled eq. 7-11) or mujoco")
    p.add_argument("--inputs", default=None,
                   help="velocity inputs: relative (air), ground, or both (default: relative; robust task: both)")
    p.add_argument("--executor", default="process", help="serial, process (default: all cores) or ray")
    p.add_argument("--workers", type=int, default=None, help="worker processes (default: all cores)")
    p.add_argument("--ray-address", default=None, help="Ray cluster address (default: start a local one)")
    p.add_argument("--checkpoint", default=None, help="checkpoint file (default: OUT.ckpt), written every generation")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoint")
    p.add_argument("--out", default=None, help="controller file to write (.json)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true")
    _add_physics(p)
    p.set_defaults(func=cmd_evolve)
    p = bf.add_parser("windmap", help="E11: pass/fail map over uniform winds (section 7.2)")
    _add_controller(p)
    _add_physics(p)
    p.add_argument("--step", type=float, default=0.1, help="grid step, m/s")
    p.add_argument("--max", type=float, default=3.0, help="largest wind component, m/s")
    p.add_argument("--plot", default=None, help="write the map as a PNG")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_windmap)
    p = bf.add_parser("assess", help="a network controller's acceptance numbers (E6, E7, E9, tail wind, E11)")
    _add_controller(p)
    _add_physics(p)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_assess)
    p = bf.add_parser("compare", help="the same flight on both backends")
    _add_controller(p)
    _add_physics(p)
    p.add_argument("--config", default="paper", help="paper (equivalent) or rich (free body, heavy wings, strips)")
    p.add_argument("--force-mode", default=None, help="tip or strip (default: tip for paper, strip for rich)")
    p.add_argument("--duration", type=float, default=20.0)
    p.add_argument("--dt", type=float, default=1.0 / 1200.0)
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_compare)

    fish = sub.add_parser("fish", help="the tropical fish of Satoi et al. 2015").add_subparsers(
        dest="command", required=True, parser_class=_Parser)
    p = fish.add_parser("swim", help="a tank of fish: tracks and life-likeness measures")
    _add_fish(p)
    p.add_argument("--duration", type=float, default=30.0, help="simulated seconds")
    p.add_argument("--out", help="folder for tracks (npz, CSV), measures and figures")
    p.add_argument("--video", help="also render FILE.mp4 or FILE.gif (same seed, same swim)")
    p.add_argument("--video-duration", type=float, default=10.0, help="seconds of video (at most --duration)")
    p.add_argument("--camera", default="side", help="video camera: side, oblique or follow")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_fish_swim)
    p = fish.add_parser("drag-check", help="custom drag (C_D = 1) against MuJoCo's inertia-box fluid model")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_fish_drag_check)

    boids = sub.add_parser("boids", help="the heterogeneous boids of Nakamura 2013").add_subparsers(
        dest="command", required=True, parser_class=_Parser)
    p = boids.add_parser("run", help="one run: classified pattern and its measures")
    _add_boids(p)
    p.add_argument("--steps", type=int, default=None, help="steps (default: the classifier's run length)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--plot", help="PNG of the last 5 steps in the paper's style")
    p.add_argument("--out", help="folder for trajectories (npz, CSV) and measures")
    p.set_defaults(func=cmd_boids_run)
    p = boids.add_parser("sweep", help="a grid of runs, classified: the phase diagram")
    _add_boids(p)
    p.add_argument("--grid", help="a homogeneous grid preset (fig2_grid: the paper's Fig. 2)")
    p.add_argument("--x", help="axis NAME=START:STOP:COUNT: wa_cross, wc_cross, wa_IJ, wc_IJ, wa, wc")
    p.add_argument("--y", help="second axis, same form")
    p.add_argument("--seeds", default="0-2", help="seeds, e.g. 0-4 or 0,3,7")
    p.add_argument("--steps", type=int, default=None)
    p.add_argument("--executor", default="process", help="serial, process (default) or ray")
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--ray-address", default=None)
    p.add_argument("--out", help="folder for sweep.json and phase_diagram.png")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_boids_sweep)

    p = sub.add_parser("reproduce", help="run a paper's experiments and write a report")
    p.add_argument("what", help="butterfly, fish, boids, or all")
    p.add_argument("--out", default=None, help="output folder (default reports/WHAT; with all: OUT/WHAT)")
    _add_physics(p)
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser("bench", help="speed benchmark")
    p.add_argument("what", help="butterfly or fish")
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--long-minutes", type=float, default=10.0, help="fish: simulated minutes of the no-escape run")
    p.add_argument("--max-n", type=int, default=1_000_000, help="boids: largest n of the scaling run")
    p.add_argument("--mesa-python", default=None, help="boids: a Python interpreter that has Mesa (for the peer)")
    p.add_argument("--out", help="also write the JSON here")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_bench)

    for name, func, helptext in (("view", cmd_view, "open the MuJoCo viewer"),
                                 ("render", cmd_render, "render a video offscreen")):
        p = sub.add_parser(name, help=helptext)
        p.add_argument("what", help="butterfly or fish")
        g = p.add_argument_group("fish")
        _add_fish(g)
        if name == "render":
            g.add_argument("--camera", default=None,
                           help="fish: side (default), oblique or follow; boids: overview (default), top or side")
        g = p.add_argument_group("boids")
        g.add_argument("--wa", help="boids: alignment matrix 'a,b;c,d' (with --wc, instead of a preset)")
        g.add_argument("--wc", help="boids: cohesion matrix")
        g.add_argument("--n", type=int, default=300, help="boids: number of agents")
        g.add_argument("--dims", type=int, default=3, help="boids: 3 or 2")
        if name == "render":
            g.add_argument("--steps", type=int, default=None, help="boids: steps to render (default 3000)")
        _add_controller(p, required=False)
        _add_physics(p)
        p.add_argument("--config", default="paper", help="paper or rich")
        p.add_argument("--force-mode", default=None, help="tip or strip")
        p.add_argument("--y0", type=float, default=0.0)
        p.add_argument("--wind", type=_wind, default=(0.0, 0.0))
        if name == "view":
            p.add_argument("--duration", type=float, default=None, help="stop after this many seconds")
        else:
            p.add_argument("--out", required=True, help="FILE.mp4 or FILE.gif")
            p.add_argument("--duration", type=float, default=3.0)
            p.add_argument("--fps", type=int, default=30)
            p.add_argument("--width", type=int, default=640)
            p.add_argument("--height", type=int, default=480)
            p.add_argument("--json", action="store_true")
        p.set_defaults(func=func)
    return top


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] in (["render"], ["reproduce"]) or (argv[:1] == ["fish"] and any(a.startswith("--video") for a in argv)):
        from lifelike_mj.viz.video import ensure_gl_backend

        ensure_gl_backend()  # before anything imports mujoco
    try:
        args = build_parser().parse_args(argv)
        args.func(args)
    except UserError as exc:
        print(f"lifelike-mj: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("lifelike-mj: interrupted.", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
