"""``lifelike-mj butterfly fly3d | evolve3d | assess3d | measure3d | strobe3d | land3d``: the butterfly in three
dimensions."""

from __future__ import annotations

import argparse
from pathlib import Path

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
from lifelike_mj.paths import shipped_names
from lifelike_mj.progress import stage

#: The files of ``fly3d --out``.
FLY3D_FILES = ("path.npz", "path.csv", "paths.png", "summary.json")
MAX_DURATION_S = 3600.0
#: The settling time of assess3d's level flight (s), and the most courses it flies.
LEVEL_SETTLE_S = 5.0
MAX_COURSES = 1000
#: The --controller option's help: the shipped 3D controllers' names.
CONTROLLER_HELP = f"a shipped 3D controller's name ({', '.join(shipped_names('butterfly3d'))}) or a file"
#: The 3D controller flown unless another is named: the one designed from the averaged model (``design3d``); the
#: command that evolves networks (``evolve3d``) and ``export`` (whose animation tests hold its flights) keep the
#: evolved ``monarch``.
DEFAULT_CONTROLLER = "designed"


def _flown(name: str):
    """The 3D controller ``name`` (a shipped name or a file) as it flies (``designed_kernel.load_compiled``)."""
    from lifelike_mj.butterfly.flight3d.designed_kernel import load_compiled

    return load_compiled(name)


def _fastest_beat_hz(ctrl) -> float:
    """The fastest wing beat (Hz) ``ctrl`` flies at first: a network's base gait's, a designed controller's top of
    the natural envelope (the time step must resolve it)."""
    from lifelike_mj.butterfly.flight3d.averaged import ENVELOPE

    base = getattr(ctrl, "base", None)
    return float(base.frequency_hz) if base is not None else float(ENVELOPE["frequency_hz"][1])


def _add_level_flight(p: argparse.ArgumentParser, settle_s: float, settle_help: str) -> None:
    """The options of a level flight that is flown, then looked at: the controller, its speed, the settling time."""
    p.add_argument("--controller", default=DEFAULT_CONTROLLER, help=CONTROLLER_HELP + f" (default: {DEFAULT_CONTROLLER})")
    p.add_argument("--speed", type=num(0.1, 5.0, unit="m/s"), default=1.5, help="commanded speed, m/s")
    p.add_argument("--settle", type=num(0, 600, unit="s"), default=settle_s, help=settle_help)


def _views(text: str) -> str:
    from lifelike_mj.butterfly.flight3d.strobe import VIEWS

    parts = [v.strip() for v in text.split(",")]
    bad = [v for v in parts if v not in VIEWS]
    if bad or not parts:
        raise argparse.ArgumentTypeError(f"views are some of {', '.join(VIEWS)}, comma-separated; got {text!r}")
    return ",".join(parts)


def _task(args):
    from lifelike_mj.butterfly import flight3d

    if args.task == "level":
        task = flight3d.level(args.speed)
    elif args.task == "turn":
        task = flight3d.turn(args.angle, 2.0, args.speed)
    else:
        task = flight3d.course(args.seed, speed_m_s=args.speed)
    return task.with_weather(args.wind, gust_m_s=args.gusts, flutter=args.flutter, seed=args.seed,
                             gust_vertical_m_s=args.vertical_gusts)


def cmd_fly3d(args) -> None:
    import numpy as np

    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    ctrl = _flown(args.controller)
    if args.predictive and (args.task != "course" or getattr(ctrl, "start_command", None) is None):
        raise UserError("--predictive flies a designed controller (design3d, or the shipped 'designed') on a course "
                        "(--task course).")
    check_outputs(args, folders={"--out": FLY3D_FILES})
    flight = Flight3D(controller=ctrl, task=_task(args), dt_s=args.dt)
    if args.predictive:
        from lifelike_mj.butterfly.flight3d.predictive import Planner

        planner = Planner(flight, seed=args.seed)
        with stage(f"3D flight with predictive sampling, {args.duration:g} s (about 12 s of compute a second)"):
            rec = planner.record(args.duration)
    else:
        with stage(f"3D flight, {args.duration:g} s"):
            rec = flight.record(duration_s=args.duration, every=max(1, round(0.01 / args.dt)))  # every 10 ms
    pos, att = rec["position_m"], rec["attitude_rad"]
    s = {"controller": ctrl.name or args.controller, "task": flight.task.name, "duration_s": float(rec["t_s"][-1]),
         "end_m": [float(v) for v in pos[-1]], "distance_m": float(np.linalg.norm(pos[-1, :2] - pos[0, :2])),
         "path_length_m": float(np.linalg.norm(np.diff(pos[:, :2], axis=0), axis=1).sum()),
         "altitude_min_m": float(pos[:, 2].min()), "altitude_max_m": float(pos[:, 2].max()),
         "roll_max_deg": float(np.degrees(np.abs(att[:, 0]).max())),
         "pitch_range_deg": [float(np.degrees(att[:, 1].min())), float(np.degrees(att[:, 1].max()))],
         "mean_reward": flight.reward / max(flight.time, 1e-12), "waypoints_passed": flight.waypoints_passed,
         "predictive": bool(args.predictive)}
    if args.out:
        from lifelike_mj.butterfly.flight3d.figures import write_flight

        write_flight(args.out, rec, s, flight.task)
    human = (f"{s['task']}: {s['path_length_m']:.1f} m flown over ground in {s['duration_s']:.1f} s, ending "
             f"{s['distance_m']:.1f} m from the start, altitude in "
             f"[{s['altitude_min_m']:+.2f}, {s['altitude_max_m']:+.2f}] m, roll within {s['roll_max_deg']:.0f} deg, "
             f"pitch in [{round(s['pitch_range_deg'][0])}, {round(s['pitch_range_deg'][1])}] deg")
    if flight.task.kind == "waypoints":
        human += f"; {s['waypoints_passed']} of {len(flight.task.rows)} waypoints passed"
    emit(args, s, human)


def cmd_evolve3d(args) -> None:
    from lifelike_mj.butterfly.flight3d.controllers import load_controller
    from lifelike_mj.butterfly.flight3d.evolution import TASK_SETS, check_time_step, evolve

    check_executor(args)
    layers = [11 if args.speed_input else 10, *args.hidden, 9]
    start = load_controller(args.start) if args.start else None
    if start is not None:
        check_time_step(args.dt, start.base.frequency_hz, "--dt")
    if start is not None and args.hidden:
        raise UserError("--hidden does not apply with --start (the network is the start controller's).")
    if args.mode is not None and start is None:
        raise UserError("--mode evolves a behaviour of a controller: give the controller with --start.")
    if args.reach is not None and args.mode is None:
        raise UserError("--reach applies to the behaviour evolved with --mode.")
    out = Path(args.out or f"butterfly3d_{args.optimizer}_{args.tasks}_s{args.seed}.json")
    res, ctrl = evolve(TASK_SETS[args.tasks](), out, optimizer=args.optimizer, seed=args.seed, layers=layers,
                       population=args.population, generations=args.generations, duration_s=args.duration,
                       checkpoint=args.checkpoint, resume=args.resume, progress=not args.quiet,
                       overwrite=args.overwrite, task_set=args.tasks, start=start, gene_bound=args.gene_bound,
                       inputs=args.inputs, executor=args.executor, workers=args.workers, ray_address=args.ray_address,
                       dt_s=args.dt, animal=args.animal, natural=args.natural, force_law=args.force_law,
                       take_off=args.take_off, mode=args.mode, reach=args.reach, speed_input=args.speed_input)
    if ctrl is None:
        raise KeyboardInterrupt("stopped before the first generation was evaluated; nothing was written")
    state = "stopped early (Ctrl-C); best so far" if res.interrupted else "done"
    emit(args, {"out": str(out), "best_fitness": float(res.best_f), "generations": res.generations,
                "wall_time_s": float(res.wall_time_s), "interrupted": bool(res.interrupted)},
         f"{state}: best fitness {res.best_f:.3f} after {res.generations} generations ({res.wall_time_s:.0f} s); "
         f"controller written to {out}")
    if res.interrupted:
        raise KeyboardInterrupt


def cmd_assess3d(args) -> None:
    from lifelike_mj.butterfly.flight3d.flight import check_time_step
    from lifelike_mj.butterfly.flight3d.validate import check_window, course_check, level_check, turn_check

    check_window("the level flight (--duration)", args.duration, LEVEL_SETTLE_S, 1.0,
                 "it measures the speed each second after settling")
    ctrl = _flown(args.controller)
    check_time_step(args.dt, _fastest_beat_hz(ctrl), "--dt")
    with stage("level flight, turns of 90 and 180 deg, courses"):
        level = level_check(ctrl, args.speed, args.duration, LEVEL_SETTLE_S, dt_s=args.dt)
        turns = [turn_check(ctrl, a, speed_m_s=args.speed, dt_s=args.dt) for a in (90.0, -90.0, 180.0)]
        weather = {"wind_to_m_s": args.wind, "gust_m_s": args.gusts, "gust_vertical_m_s": args.vertical_gusts}
        courses = [course_check(ctrl, s, weather=weather, dt_s=args.dt) for s in args.courses]
    d = {"controller": ctrl.name or args.controller, "level": level, "turns": turns, "courses": courses,
         "course_weather": weather}
    human = (f"level {level['duration_s']:.0f} s at {args.speed:g} m/s: speed [{level['speed_min_m_s']:.2f}, "
             f"{level['speed_max_m_s']:.2f}] m/s, altitude [{level['altitude_min_m']:+.2f}, "
             f"{level['altitude_max_m']:+.2f}] m, roll within {level['roll_max_deg']:.0f} deg, pitch "
             f"[{round(level['pitch_min_deg'])}, {round(level['pitch_max_deg'])}] deg; "
             + "; ".join(f"turn {t['angle_deg']:+.0f} deg in {t['turn_time_s']:.1f} s, held within "
                         f"{t['held_error_max_deg']:.1f} deg" for t in turns)
             + "; courses: " + ", ".join(f"seed {c['seed']} {c['passed']}/{c['waypoints']}" for c in courses))
    emit(args, d, human)


def cmd_measure3d(args) -> None:
    from lifelike_mj.butterfly.flight3d.flight import check_time_step
    from lifelike_mj.butterfly.flight3d.measures import check_window, level_measures

    check_window("the measures", args.settle + args.window, args.settle, 0.5, "they measure whole wing beats")
    ctrl = _flown(args.controller)
    check_time_step(args.dt, _fastest_beat_hz(ctrl), "--dt")
    with stage(f"level flight at {args.speed:g} m/s, {args.settle + args.window:g} s"):
        m = level_measures(ctrl, args.speed, args.settle, args.window, dt_s=args.dt)
    d = {"controller": ctrl.name or args.controller, **m}
    human = (f"{d['controller']} ({m['animal']}) level at {args.speed:g} m/s over {m['beats']} beats: "
             f"{m['flap_frequency_hz']:.2f} Hz, strokes left {m['stroke_left_deg']:.0f} / right "
             f"{m['stroke_right_deg']:.0f} deg, dorsal gap {m['dorsal_gap_deg']:.0f} deg, mean roll "
             f"{m['roll_mean_deg']:+.1f} deg, body angle {m['body_angle_deg']:.1f} deg, bobbing {m['bobbing_mm']:.1f} mm, "
             f"abdomen {m['abdomen_mean_deg']:+.0f} +- {m['abdomen_swing_deg']:.0f} deg, power "
             f"{m['power_W_kg']:.1f} W/kg ({m['power_net_W_kg']:.1f} net), J {m['advance_ratio']:.2f} at "
             f"{m['air_speed_m_s']:.2f} m/s through the air")
    emit(args, d, human)


def cmd_model3d(args) -> None:
    from lifelike_mj.butterfly.flight3d import averaged, calibrate
    from lifelike_mj.butterfly.flight3d.figures import fig_averaged
    from lifelike_mj.io import write_json
    from lifelike_mj.provenance import provenance

    check_outputs(args, files={"--out": (".json",), "--figure": (".png",)})
    total = len(args.speeds) * len(args.climbs)
    with stage("the filmed flight with the calibrated law"):
        filmed = calibrate.filmed_flight()
    with stage(f"{total} trims, their linear models and their flights", total=total, unit="trim") as bar:
        model = averaged.build(args.speeds, args.climbs, progress=lambda done, _n: bar.update(1),
                               workers=_workers(args))
    model["filmed_flight"] = {"filmed": calibrate.FILMED, "calibrated": filmed}
    out = {"provenance": provenance(speeds_m_s=args.speeds, climbs_m_s=args.climbs, force_law=model["force_law"],
                                    animal=model["animal"], n_phases=model["n_phases"]), **model}
    write_json(args.out, out)
    if args.figure:
        fig_averaged(model, args.figure)
    level = sorted((p for p in model["points"] if p["climb_m_s"] == 0.0), key=lambda p: p["speed_m_s"])
    balanced = sum(p["trimmed"] for p in model["points"])
    human = (f"wrote {args.out}: {balanced} of {total} trims of the {model['animal']} balance inside the natural "
             f"envelope; the filmed stroke at the filmed body angle "
             f"flying {filmed['speed_m_s']:.2f} m/s forward and {filmed['climb_m_s']:+.2f} m/s up; level: "
             + "; ".join(f"{p['speed_m_s']:g} m/s at {p['body_angle_deg']:.0f} deg, {p['command']['frequency_hz']:.1f} Hz, "
                         f"{p['flown']['power_net_W_kg']:.0f} W/kg, "
                         + ", ".join(m["name"] for m in p["modes"]["longitudinal"] + p["modes"]["lateral"]
                                     if m["real_per_s"] > 1e-6 or m["name"] == "neutral") for p in level))
    emit(args, {"out": args.out, "figure": args.figure, "levels": level and [
        {"speed_m_s": p["speed_m_s"], "body_angle_deg": p["body_angle_deg"], "modes": p["modes"]} for p in level]}, human)


def cmd_design3d(args) -> None:
    import numpy as np

    from lifelike_mj.butterfly.flight3d import averaged, designed
    from lifelike_mj.io import write_json
    from lifelike_mj.paths import read_json
    from lifelike_mj.provenance import provenance

    check_outputs(args, files={"--out": (".json",)})
    if args.model:
        model = designed.check_model(read_json(args.model, "averaged model"), f"averaged model {args.model}")
    else:
        with stage(f"{len(args.speeds)} level trims and their linear models", total=len(args.speeds),
                   unit="trim") as bar:
            model = averaged.build(args.speeds, [0.0], progress=lambda done, _n: bar.update(1),
                                   workers=_workers(args))
    with stage("the gains (LQR at every level trim)"):
        spec = designed.design(model)
        lagged = designed.lagged_poles(model, spec, designed.CONTROL_LAG_S)
    speeds = [s["speed_m_s"] for s in spec["schedule"]]
    if not args.no_landing:
        from lifelike_mj.butterfly.flight3d import perching

        with stage(f"the landing: {perching.N_BINS} manoeuvres and the take-off shot, and their tracking", total=perching.N_BINS,
                   unit="manoeuvre") as bar:
            spec["landing"] = perching.design_landing(spec, workers=_workers(args),
                                                      progress=lambda done, _n: bar.update(done - bar.n))
    ctl = designed.DesignedController(spec, name=Path(args.out).stem, provenance=provenance(
        model=args.model, model_provenance=model.get("provenance"), speeds_m_s=speeds, q_scales=spec["q_scales"],
        r_scales=spec["r_scales"], landing=not args.no_landing))
    with stage("a check: 4 s of level flight at 1.5 m/s"):
        from lifelike_mj.butterfly.flight3d import tasks
        from lifelike_mj.butterfly.flight3d.flight import Flight3D

        fl = Flight3D(controller=ctl, task=tasks.level(1.5))  # the flight's state is not in the file
        fl.step(int(round(2.0 / fl.dt)))
        z = []
        while fl.time < 4.0:
            fl.step(8)
            z.append(fl.data.qpos[2])
    write_json(args.out, ctl.to_dict())
    alt_rms = float(np.sqrt(np.mean(np.square(z))))
    human = (f"wrote {args.out}: a controller designed for the {spec['animal']} at {len(speeds)} airspeeds "
             f"({speeds[0]:g}-{speeds[-1]:g} m/s), slowest closed-loop pole "
             f"{min(s['slowest_pole_per_s'] for s in spec['schedule']):.2f}/s; level at 1.5 m/s: altitude within "
             f"{100 * alt_rms:.1f} cm rms (2-4 s); seen {1000 * designed.CONTROL_LAG_S:.0f} ms late, as it flies, the "
             "loop is "
             + ", ".join(f"{r['speed_m_s']:g} m/s " + (f"unstable ({r['growth_per_s']:+.1f}/s)" if r["growth_per_s"] > 0
                                                       else f"damped {r['damping']:.2f}") for r in lagged)
             + f" (guidance flies {designed.MIN_AIRSPEED_M_S:g}-{designed.MAX_AIRSPEED_M_S:g} m/s). Fly it: "
             f"lifelike-mj butterfly fly3d --controller {args.out}")
    emit(args, {"out": args.out, "speeds_m_s": speeds, "level_altitude_rms_m": alt_rms,
                "slowest_pole_per_s": [s["slowest_pole_per_s"] for s in spec["schedule"]],
                "lagged_poles": lagged}, human)


def _workers(args) -> int:
    """``--workers``, or every core."""
    import os

    return args.workers or os.cpu_count() or 1


def _add_workers(p: argparse.ArgumentParser) -> None:
    p.add_argument("--workers", type=count(1, 1024), default=None,
                   help="processes the trims' and the landing's work is shared among, 1 to 1024 (default: all cores); "
                        "the trims are the same to the bit with any number")


def _values(text: str, lo: float, hi: float) -> list[float]:
    """A comma-separated list of 1 to 50 different speeds (m/s) within ``[lo, hi]``, sorted."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected numbers separated by commas (m/s), got {text!r}") from None
    if not values or len(values) > 50 or any(not (lo <= v <= hi) for v in values) or len(set(values)) < len(values):
        raise argparse.ArgumentTypeError(f"expected 1 to 50 different speeds within {lo:g} to {hi:g} m/s, got {text!r}")
    return sorted(values)


def _speeds(text: str) -> list[float]:
    return _values(text, 0.25, 3.0)


def _climbs(text: str) -> list[float]:
    return sorted(set(_values(text, -1.0, 1.0)) | {0.0})


def cmd_strobe3d(args) -> None:
    from lifelike_mj.butterfly import flight3d
    from lifelike_mj.butterfly.flight3d.strobe import strobe
    from lifelike_mj.render.video import check_size, write_png

    check_outputs(args, files={"--out": (".png",)})
    check_size(args.width, args.height, "panel")
    ctrl = _flown(args.controller)
    f = flight3d.Flight3D(controller=ctrl, task=flight3d.level(args.speed), dt_s=args.dt)
    with stage(f"level flight at {args.speed:g} m/s, {args.settle:g} s, then one beat"):
        f.step(int(round(args.settle / f.dt)))
        img = strobe(f, args.n, tuple(args.views.split(",")), args.width, args.height)
    write_png(args.out, img)
    emit(args, {"out": str(args.out), "controller": ctrl.name or args.controller, "moments": args.n,
                "views": args.views.split(","), "at_s": args.settle},
         f"{args.n} moments of one wing beat after {args.settle:g} s, {args.views}: written to {args.out}")


def cmd_land3d(args) -> None:
    from lifelike_mj.butterfly.flight3d.flowers import check_room, place_flowers
    from lifelike_mj.butterfly.flight3d.landing import visit_flowers

    check_room(args.flowers, args.size, "--flowers", "--size")
    check_outputs(args, files={"--picture": (".png",)})
    if args.picture:
        from lifelike_mj.render.video import check_size

        check_size(args.width, args.height, "panel")
    from lifelike_mj import checks
    from lifelike_mj.butterfly.flight3d.flight import DT_S
    from lifelike_mj.butterfly.flight3d.landing import MAX_LANDING_S, STILL_M

    checks.work(f"visiting {args.flowers} flowers, perched {args.perch:g} s on each",
                (args.flowers - 1) * checks.steps_of(MAX_LANDING_S + args.perch, DT_S), checks.MAX_BODY_STEPS,
                "time steps", "fewer flowers or a shorter perch")
    ctrl = _flown(args.controller)
    blossoms = place_flowers(args.seed, args.flowers, args.size)
    with stage(f"visiting {args.flowers} flowers by landing, perched {args.perch:g} s on each"):
        res = visit_flowers(ctrl, blossoms, args.perch)
    out = {"controller": ctrl.name or args.controller, "seed": args.seed, "garden_size_m": args.size,
           "blossoms_m": blossoms.tolist(), **res}
    if args.picture:
        from lifelike_mj.butterfly.flight3d.strobe import landing_strobe
        from lifelike_mj.render.video import write_png

        landed = bool(res["visits"]) and res["visits"][0]["landed"]
        with stage("the landing and take-off picture" if landed else "the take-off picture (it did not land)"):
            img, what = landing_strobe(ctrl, blossoms[:2], width=args.width, height=args.height, land=landed)
        write_png(args.picture, img)
        out["picture"] = {"out": str(args.picture), **what}
    ok = sum(v["within_bound"] and v["stayed"] and v["upright"] for v in res["visits"])
    still = sum(v["within_bound"] and v["still"] for v in res["visits"])
    emit(args, out, f"landed on {res['landed']} of {args.flowers - 1} flowers, {ok} within "
                    f"{res['touchdown_bound_m_s']:g} m/s and still on the blossom, upright, after {args.perch:g} s "
                    f"({still} moving less than {STILL_M * 1000:g} mm)"
                    + (f"; picture written to {args.picture}" if args.picture else ""))


def cmd_garden(args) -> None:
    import numpy as np

    from lifelike_mj import checks
    from lifelike_mj.butterfly.flight3d.flight import check_time_step
    from lifelike_mj.butterfly.flight3d.garden import Garden, film_garden

    checks.work(f"a garden of {args.n} butterflies for {args.duration:g} s",
                args.n * checks.steps_of(args.duration, args.dt), checks.MAX_BODY_STEPS, "butterfly-steps")
    if args.out:
        checks.work(f"a video of {args.duration:g} s at {args.fps} frames/s", checks.steps_of(args.duration, 1 / args.fps),
                    checks.MAX_FRAMES, "frames", "a shorter garden or fewer frames per second")
    ctrl = _flown(args.controller)
    check_time_step(args.dt, _fastest_beat_hz(ctrl), "--dt")
    check_outputs(args, files={"--out": (".mp4", ".gif"), "--paths": (".png",)})
    garden = Garden(args.n, ctrl, seed=args.seed, flutter=args.flutter, gust_m_s=args.gusts, wind_to_m_s=args.wind,
                    gust_vertical_m_s=args.vertical_gusts, dt_s=args.dt)
    d: dict = {"butterflies": args.n, "seed": args.seed, "controller": ctrl.name or args.controller}
    if args.paths:
        garden.track = []  # the positions at every frame, or every 0.02 s without a video
    if args.out:
        info = film_garden(args.out, garden, args.duration, args.fps, args.width, args.height, args.camera,
                           progress=True)
        d["video"] = info
    else:
        every = max(1, int(round(0.02 / garden.dt))) if args.paths else int(round(args.duration / garden.dt))
        with stage(f"{args.n} butterflies, {args.duration:g} s"):
            garden.sync()
            for _ in range(int(round(args.duration / garden.dt)) // every):
                garden.step(every)
                garden.sync()
    passed = garden.state()["waypoints_passed"]
    d.update({"duration_s": garden.time, "flowers_visited_min": int(passed.min()),
              "flowers_visited_mean": float(passed.mean()), "flowers_visited_max": int(passed.max())})
    if args.paths:
        from lifelike_mj.butterfly.flight3d.figures import fig_paths

        track = np.array(garden.track)
        fig_paths([{"position_m": track[:, i]} for i in range(args.n)], waypoints=garden.blossoms,
                  path=args.paths, title=f"{args.n} butterflies, {args.duration:g} s", waypoint_label="flowers")
        d["paths"] = args.paths
    emit(args, d, f"{args.n} butterflies flew {garden.time:.1f} s and visited {passed.min():.0f} to {passed.max():.0f} "
         f"flowers each" + (f"; video {args.out}" if args.out else "") + (f"; paths {args.paths}" if args.paths else ""))


def _add_weather(p, what: str, seed: str) -> None:
    add_wind(p, 3, "to", "x, y, z", what + "mean ", bound=50.0)
    p.add_argument("--gusts", type=num(0, 10, unit="m/s"), default=0.0,
                   help=what + f"gusts' standard deviation, m/s (horizontal; correlation time 1 s; drawn from {seed})")
    p.add_argument("--vertical-gusts", type=num(0, 10, unit="m/s"), default=None,
                   help="the vertical gusts' standard deviation, m/s (default: as --gusts; near the ground the "
                        "Dryden model gives half)")


def _add_dt(p, fine: bool = False, hi_s: float = 1.0 / 80.0) -> None:
    """``--dt``: the 3D flight's time step, at most ``hi_s`` (``fine``: default 1/1200 s, for exports, whose keys sample
    every step and whose loops end on a step)."""
    from lifelike_mj.butterfly.flight3d.timing import DT_FINE_S, DT_S

    p.add_argument("--dt", type=num(1e-5, hi_s, unit="s"), default=DT_FINE_S if fine else DT_S,
                   help="time step, s (1/1200 is the step the shipped controllers were evolved at; at most 1/8 of a "
                        "wing beat)" + ("; an export keeps 1/1200 by default, so that its keys and a loop's seam "
                                        "follow the wings closely" if fine else ""))


def _seeds(text: str) -> list[int]:
    from lifelike_mj.cli.common import seeds

    try:
        return seeds(text, "the range", MAX_COURSES)
    except UserError as exc:
        raise argparse.ArgumentTypeError(str(exc).rstrip(".")) from None


def _hidden(text: str) -> list[int]:
    if text in ("", "0", "none"):
        return []
    try:
        sizes = [int(v) for v in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected sizes like 8 or 8,8, got {text!r}") from None
    if not sizes or min(sizes) < 1 or max(sizes) > 256:
        raise argparse.ArgumentTypeError(f"hidden layer sizes are 1 to 256, got {text!r}")
    return sizes


def add_commands(bf) -> None:
    """``fly3d``, ``evolve3d`` and ``assess3d`` under ``lifelike-mj butterfly``."""
    p = bf.add_parser("fly3d", help="fly the 3D butterfly with a 3D controller")
    p.add_argument("--controller", default=DEFAULT_CONTROLLER,
                   help=CONTROLLER_HELP + f", a network or one designed (design3d; default: {DEFAULT_CONTROLLER})")
    p.add_argument("--task", default="level", choices=("level", "turn", "course"),
                   help="level flight, a turn (--angle) or a course of 10 waypoints drawn by --seed")
    p.add_argument("--speed", type=num(0.1, 5.0, unit="m/s"), default=1.5, help="commanded speed, m/s, 0.1 to 5")
    p.add_argument("--angle", type=num(-180, 180, unit="deg"), default=90.0, help="turn angle, deg, left > 0")
    add_seed(p)
    _add_weather(p, "", "--seed")
    p.add_argument("--flutter", type=num(0, 1), default=0.0, help="the butterfly's flutter, 0 to 1 (drawn from --seed)")
    p.add_argument("--duration", type=num(0, MAX_DURATION_S, lo_open=True, unit="s"), default=20.0,
                   help=f"seconds of flight, at most {MAX_DURATION_S:g}")
    p.add_argument("--predictive", action="store_true",
                   help="a designed controller on a course looks ahead: predictive sampling in copies of the flight, "
                        "in the air its antennae sense (holds courses in gusts on every axis; about 12 s of compute "
                        "per second flown)")
    _add_dt(p)
    p.add_argument("--out", help="folder for path.npz/.csv, paths.png (top and side views), summary.json")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_fly3d)
    p = bf.add_parser("evolve3d", help="evolve a 3D controller (CMA-ES or the paper's GA) on the MuJoCo batch")
    p.add_argument("--optimizer", default="cmaes", choices=("cmaes", "rcga", "crs2", "esch", "isres"),
                   help="cmaes, rcga (the paper's GA) or an nlopt method")
    p.add_argument("--tasks", default="steer", choices=("steer", "cruise", "wind", "natural", "garden", "agile", "fast",
                                                         "landings", "landings12"),
                   help="the task set: steer (level at 1 and 2 m/s, turns of 90 and -180 deg), cruise (level at 1.5 "
                        "and 2 m/s, the turns, and two flights in 1 m/s wind with 0.5 m/s gusts) or wind (courses "
                        "1-4 in 1 m/s wind from four sides with gusts of 0.5 m/s, 0.25 m/s vertically, course 5 and "
                        "the -180 deg turn in still air, level flight in wind) or natural (level at 1, 1.5 and 2 m/s, "
                        "the turns, course 5, and course 1 in 1 m/s wind with gusts of 0.5 m/s on every axis) or garden "
                        "(the monarch's: level at 1, 2 and 2.5 m/s, the turns, course 5, course 1 in 1 m/s wind "
                        "with gusts on every axis, course 3 in a 1.5 m/s wind, and three landings on flowers) or agile "
                        "(the steer set and calm courses 1-3) or fast (level at 1 to 3 m/s, the 90 deg turn, course 5, "
                        "course 1 in gusty 1 m/s wind, course 3 in 1.5 m/s wind) or landings (six flowers all round, "
                        "0.9-3.5 m away: for --mode land, or with --take-off for --mode take_off) or landings12 (those and "
                        "six more)")
    p.add_argument("--inputs", default=None, choices=("ground", "air"),
                   help="the network's speeds over the ground or through the air (default: the start's, else ground)")
    p.add_argument("--start", default=None, help="a 3D controller to start from (its network; genes are its changes)")
    p.add_argument("--animal", default=None, choices=("swallowtail", "monarch"),
                   help="the butterfly: swallowtail (the paper's triangular wings) or monarch (measured wings, masses "
                        "and stroke plane); default: the start's, else swallowtail")
    p.add_argument("--force-law", default=None, choices=("exact", "strip", "quasi_steady", "calibrated"),
                   help="the wing-force law of the training flights, kept in the controller: exact (eq. 1 over the "
                        "outline), strip (eq. 1 on panels) or quasi_steady (blade elements with a revolving fruit-fly "
                        "wing's coefficients) or calibrated (the same, scaled to a filmed monarch's flight); "
                        "default: the start's, else exact")
    p.add_argument("--natural", action="store_true",
                   help="also ask the flight to look like a butterfly's: level wings and even strokes in straight "
                        "flight, a dorsal gap of 35-50 deg, at most 20.2 W/kg, the body angle falling with speed")
    p.add_argument("--speed-input", action="store_true",
                   help="the network also sees the forward speed asked, so that it can trim for it (with --start: the "
                        "start's networks gain that input, its weights starting at zero)")
    p.add_argument("--take-off", action="store_true",
                   help="every training flight starts perched on a flower, its wings closed, and takes off clapping")
    p.add_argument("--mode", default=None, choices=("land", "take_off"),
                   help="evolve the --start controller's behaviour network of that name (a landing's last metres, a "
                        "take-off's first second), starting from its own, else from its flight network; the rest "
                        "is flown by its other networks as they are")
    p.add_argument("--reach", type=num(0, 100, lo_open=True), default=None,
                   help="where the --mode network flies: land, within this many m of the flower; take_off, for this "
                        "many s after a take-off (unless given: the start's, else 0.6 m and 1 s)")
    p.add_argument("--gene-bound", type=num(0, 10, lo_open=True), default=0.4,
                   help="bound of each gene (a weight's change from the start)")
    p.add_argument("--hidden", type=_hidden, default=[],
                   help="hidden layer sizes, e.g. 16 or 16,8 (default, 0 or none: no hidden layer, a linear network)")
    p.add_argument("--population", type=count(2, 100_000), default=16, help="population size")
    p.add_argument("--generations", type=count(1, 1_000_000), default=300, help="generations")
    p.add_argument("--duration", type=num(0, 60, lo_open=True, unit="s"), default=4.0,
                   help="seconds of each training flight")
    _add_dt(p, hi_s=0.01)  # an evolution's training flights: FlightProblem3D's bound
    add_executor(p, "serial", "this process, which flies a generation on every core")
    add_seed(p)
    add_run_files(p, "controller file to write (.json)")
    add_json(p)
    p.set_defaults(func=cmd_evolve3d)
    p = bf.add_parser("garden", help="a garden of 3D butterflies visiting flowers, filmed")
    p.add_argument("--n", type=count(1, 500), default=20, help="butterflies, 1 to 500")
    p.add_argument("--controller", default=DEFAULT_CONTROLLER, help=CONTROLLER_HELP + f" (default: {DEFAULT_CONTROLLER}; "
                   "designed lands on the flowers, as does a network with a landing; the others pass them by)")
    add_seed(p)
    p.add_argument("--flutter", type=num(0, 1), default=0.1, help="each butterfly's flutter, 0 to 1")
    _add_weather(p, "", "each butterfly's seed")
    p.add_argument("--duration", type=num(0, 600, lo_open=True, unit="s"), default=10.0, help="seconds of flight")
    _add_dt(p)
    p.add_argument("--out", default=None, help="video file (.mp4 or .gif)")
    p.add_argument("--camera", default="overview", choices=("overview", "chase"), help="overview (fixed) or chase")
    p.add_argument("--fps", type=count(1, 240), default=30, help="frames per second")
    p.add_argument("--width", type=count(16, 1920), default=960, help="frame width, pixels")
    p.add_argument("--height", type=count(16, 1080), default=540, help="frame height, pixels")
    p.add_argument("--paths", default=None, help="also a PNG of the paths from above and from the side")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_garden)
    p = bf.add_parser("assess3d", help="a 3D controller's acceptance numbers: level flight, turns, courses")
    p.add_argument("--controller", default=DEFAULT_CONTROLLER, help=CONTROLLER_HELP + f" (default: {DEFAULT_CONTROLLER})")
    p.add_argument("--speed", type=num(0.1, 5.0, unit="m/s"), default=1.5, help="commanded speed, m/s")
    p.add_argument("--duration", type=num(0, MAX_DURATION_S, lo_open=True, unit="s"), default=60.0,
                   help="seconds of level flight")
    p.add_argument("--courses", type=_seeds, default=[100, 101, 102], help="course seeds, e.g. 100-104")
    _add_weather(p, "the courses' ", "each course's seed")
    _add_dt(p)
    add_json(p)
    p.set_defaults(func=cmd_assess3d)
    p = bf.add_parser("measure3d", help="how natural a 3D controller's level flight is: roll, strokes, dorsal gap, "
                                        "body angle, bobbing, abdomen, power, advance ratio")
    _add_level_flight(p, 5.0, "seconds of settling first")
    p.add_argument("--window", type=num(0, 600, lo_open=True, unit="s"), default=5.0,
                   help="seconds measured after settling (whole wing beats)")
    _add_dt(p)
    add_json(p)
    p.set_defaults(func=cmd_measure3d)
    p = bf.add_parser("model3d", help="the monarch averaged over its wing beat: trims over the flight envelope, each "
                                      "flown, its linear model and modes (minutes)")
    p.add_argument("--out", required=True, help="the model file to write (.json)")
    p.add_argument("--figure", default=None, help="also draw the trims and modes (.png)")
    p.add_argument("--speeds", type=_speeds, default=[0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5],
                   help="forward speeds of the trims, m/s, comma-separated (default 0.5 to 2.5 by 0.25)")
    p.add_argument("--climbs", type=_climbs, default=[-0.5, 0.0, 0.5],
                   help="climb rates of the trims, m/s, comma-separated; 0 is always among them (default -0.5,0,0.5)")
    _add_workers(p)
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_model3d)
    p = bf.add_parser("design3d", help="design the flight controller from the averaged model: LQR at every level "
                                       "trim, with integral action and a wind estimate, and its landing and take-off "
                                       "(about 6-7 minutes on 2 cores with --model, seconds with --no-landing; 13-16 minutes "
                                       "from nothing)")
    p.add_argument("--out", required=True, help="the controller file to write (.json)")
    p.add_argument("--model", default=None, help="an averaged model file (lifelike-mj butterfly model3d); without it "
                                                 "the level trims are built first")
    p.add_argument("--speeds", type=_speeds, default=[0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5],
                   help="without --model: forward speeds of the level trims, m/s, comma-separated "
                        "(default 0.5 to 2.5 by 0.25)")
    p.add_argument("--no-landing", action="store_true", help="leave the landing out (its manoeuvres take most of "
                   "the design's time); the controller then passes flowers by")
    _add_workers(p)
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_design3d)
    p = bf.add_parser("strobe3d", help="a stroboscopic picture of one wing beat in level flight, from the side and "
                                       "from ahead")
    _add_level_flight(p, 3.0, "seconds of flight before the beat")
    p.add_argument("--n", type=count(2, 64), default=8, help="moments of the beat drawn, 2 to 64")
    p.add_argument("--views", default="side,front", type=_views, help="side, front and/or top, comma-separated")
    p.add_argument("--width", type=count(16, 1920), default=480, help="width of each view, pixels")
    p.add_argument("--height", type=count(16, 1080), default=360, help="height, pixels")
    p.add_argument("--out", required=True, help="the picture (.png)")
    _add_dt(p)
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_strobe3d)
    p = bf.add_parser("land3d", help="one butterfly visits flowers by landing on each in turn (touchdown speed, perch, "
                                     "take-off), with a picture of a landing and a take-off")
    p.add_argument("--controller", default=DEFAULT_CONTROLLER, help=CONTROLLER_HELP + f" (default: {DEFAULT_CONTROLLER}, "
                   "which lands by a manoeuvre shot in advance and tracked; the report counts each visit)")
    p.add_argument("--flowers", type=count(2, 200), default=11, help="flowers, 2 to 200: perched on the first, it "
                   "visits each other once")
    add_seed(p)
    p.add_argument("--size", type=num(2.0, 100.0), default=6.0, help="the flowers' square, m")
    p.add_argument("--perch", type=num(0.0, 600.0), default=2.0, help="seconds perched on each flower")
    p.add_argument("--picture", default=None, help="a picture (.png) of the landing on the second flower and the "
                   "take-off from it (of the take-off from the first, if it did not land)")
    p.add_argument("--width", type=count(16, 1920), default=640, help="width of each panel, pixels")
    p.add_argument("--height", type=count(16, 1080), default=420, help="height, pixels")
    add_overwrite(p)
    add_json(p)
    p.set_defaults(func=cmd_land3d)


HELP = "the butterfly in three dimensions: one on a task, or a garden of them"
VIEW_HELP = ("one 3D butterfly flying level at --speed with --controller, the camera following it; steer it and "
             "change the wind with the keys below")


def view_keys() -> str:
    """The 3D scene's keys, for ``view butterfly3d --help``."""
    from lifelike_mj.butterfly.flight3d.view import FLIGHT3D_KEYS
    from lifelike_mj.render.viewer import keys_text

    return "keys in the window (buttons in the web viewer with --web): " + keys_text(FLIGHT3D_KEYS) + "."


def add_export_args(p: argparse.ArgumentParser) -> None:
    from lifelike_mj.cli.export import add_window

    p.add_argument("--controller", default="monarch", help=CONTROLLER_HELP + " (default: monarch, whose exports the "
                   "animation tests hold; designed flies too)")
    p.add_argument("--task", default="course", choices=("level", "turn", "course"),
                   help="level flight, a turn (--angle) or a course of 10 waypoints drawn by --seed")
    p.add_argument("--speed", type=num(0.1, 5.0, unit="m/s"), default=1.5, help="commanded speed, m/s, 0.1 to 5")
    p.add_argument("--angle", type=num(-180, 180, unit="deg"), default=90.0, help="turn angle, deg, left > 0")
    p.add_argument("--garden", type=count(0, 500), default=0,
                   help="a garden of this many butterflies visiting flowers instead of one on --task (0: one)")
    add_seed(p)
    _add_weather(p, "", "--seed")
    p.add_argument("--flutter", type=num(0, 1), default=0.0, help="the butterfly's flutter, 0 to 1 (drawn from --seed)")
    _add_dt(p, fine=True)
    add_window(p, MAX_DURATION_S, 5.0)


def export_window(args):
    """The run to export, built and checked, not yet simulated (:class:`~lifelike_mj.cli.export.Window`), and the
    parameters that make it."""
    from lifelike_mj.cli.export import Window, check_window, parameters_of

    check_window(args.start, args.duration, args.fps, args.dt, bodies=args.garden or 1, drawn=4 * (args.garden or 1))
    ctrl = _flown(args.controller)
    if args.garden:
        from lifelike_mj.butterfly.flight3d.garden import Garden

        sim = Garden(args.garden, ctrl, seed=args.seed, flutter=args.flutter, gust_m_s=args.gusts, wind_to_m_s=args.wind,
                     gust_vertical_m_s=args.vertical_gusts, dt_s=args.dt)
    else:
        from lifelike_mj.butterfly.flight3d.flight import Flight3D

        sim = Flight3D(controller=ctrl, task=_task(args), dt_s=args.dt)
    return Window(sim, args.start, args.duration, args.fps), parameters_of(args)


def loop_cut_body(args) -> str | None:
    """The body whose beat a looped export is cut at (``export --loop``), or None to blend the loop."""
    return "wing_left" if not args.garden and args.task == "level" else None


def export_rigs(poses) -> list:
    """The run's creatures as rigs (skinned, textured meshes on skeletons), for ``export --looks rig``."""
    from lifelike_mj.butterfly.look import rigs

    return rigs(poses)


def add_view_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--controller", default=DEFAULT_CONTROLLER, help=CONTROLLER_HELP + f" (default: {DEFAULT_CONTROLLER})")
    p.add_argument("--speed", type=num(0.1, 5.0, unit="m/s"), default=1.5, help="commanded speed, m/s, 0.1 to 5")
    p.add_argument("--duration", type=num(0, None, lo_open=True, unit="s"), default=None,
                   help="stop after this many seconds (default: run until the window is closed)")


def view(args) -> None:
    from lifelike_mj.butterfly.flight3d.view import view_flight3d
    from lifelike_mj.cli import web_options

    web = web_options(args)
    view_flight3d(_flown(args.controller), args.speed, args.duration, web=web)
