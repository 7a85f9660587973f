"""Offscreen video, single frames and the viewer of the heterogeneous boids (Nakamura 2013).

The agents are the real run of a :class:`~lifelike_mj.boids.sim.Flock`, streamed: it is stepped
between frames, so no trajectory is kept in memory and a rendered run is the run
:func:`~lifelike_mj.boids.sim.simulate` computes with the same arguments. MuJoCo only draws:
the agents are mocap bodies of :mod:`lifelike_mj.boids.scene`
(ellipsoids along their velocities; A blue, B orange: :mod:`lifelike_mj.boids.palette`), placed by
:func:`~lifelike_mj.boids.scene.update` before each frame.

Time: the engine's step (``dt = 1``) has no unit of seconds, so a video plays ``steps_per_frame``
engine steps per frame: frame ``j`` shows step ``warmup_steps + j * steps_per_frame``, for
``j = 0 .. n_steps // steps_per_frame`` (the first frame is the state after the warm-up). At the
defaults (5 steps per frame, 30 frames/s) a flock at the typical 0.05-0.15 box units per step
crosses the 20-unit box in 1.5 to 4.5 s of video.

Cameras (``camera=``, :data:`~lifelike_mj.boids.scene.CAMERAS`): ``overview`` (perspective, the
whole box from above one corner), ``top`` (orthographic x-y projection, the plane of the paper-style
figures; the natural view of a 2D run) and ``side`` (orthographic x-z projection; 3D only).

A run you already recorded is drawn the same way through :func:`playback`. Rendering uses the
generic :mod:`lifelike_mj.render` package (OpenGL backend choice, the recorder and its MP4/GIF
writers, atomic writes); the scene keeps its own lighting (shadows and multisampling off for speed).
``mujoco`` is imported only inside functions, so that
:func:`~lifelike_mj.render.gl.ensure_gl_backend` can run first.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.render import camera as cameras
from lifelike_mj.render.offscreen import Offscreen
from lifelike_mj.render.video import advance_to, check_size, film, video_target, write_png
from lifelike_mj.render.viewer import require_display, view
from lifelike_mj.stepper import Playback

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.boids.engine import BoidParams, BoidRun
    from lifelike_mj.boids.sim import Flock

#: The cameras of a 3D run (a 2D run has the first two); see :mod:`lifelike_mj.boids.scene`.
CAMERAS = ("overview", "top", "side")
#: Engine steps per video frame by default.
DEFAULT_STEPS_PER_FRAME = 5
#: Engine steps of a video by default (after the warm-up): 601 frames, 20 s at 30 frames/s.
DEFAULT_STEPS = 3000
#: Engine steps per wall-clock second in the viewer by default (5 per refresh at 30 Hz).
VIEW_STEPS_PER_S = 150.0


def _check_camera(camera: str, dims: int) -> None:
    names = CAMERAS if dims == 3 else CAMERAS[:2]
    if camera not in names:
        extra = " (a 2D run has no side view)" if camera in CAMERAS else ""
        raise UserError(f"unknown camera {camera!r}{extra}; choose one of {', '.join(names)}.")


def _flock(params: BoidParams, n: int, seed: int) -> Flock:
    from lifelike_mj.boids.sim import Flock

    flock = Flock(params, n, seed)
    flock.sync()
    return flock


def playback(run: BoidRun) -> Playback:
    """A recorded run (:class:`~lifelike_mj.boids.engine.BoidRun`) in the stepper shape: step ``k``
    places the agents at the run's ``k``-th recorded state (its step ``run.steps[k]``)."""
    import mujoco

    from lifelike_mj.boids.scene import build_scene, update

    m, layout = build_scene(run.n, run.types, box=run.params.box, dims=run.params.dims)
    d = mujoco.MjData(m)

    def pose(k: int) -> None:
        update(m, d, layout, run.positions[k], run.velocities[k])

    def state(k: int) -> dict:
        return {"position_box": run.positions[k], "velocity_box_per_step": run.velocities[k], "type": run.types}

    dt = float(run.steps[1] - run.steps[0]) if len(run.steps) > 1 else 1.0
    pb = Playback(m, d, len(run.steps), pose, dt, state)
    pb.params, pb.layout = run.params, layout
    return pb


def _renderer(flock, width: int, height: int) -> Offscreen:
    from lifelike_mj.boids.scene import EDGE_RADIUS, set_edge_radius

    # the box's edges at least about a pixel wide (the overview shows some 1.8 box sides over the height)
    set_edge_radius(flock.model, flock.layout, max(EDGE_RADIUS, 1.0 * flock.params.box / height))
    return Offscreen(flock.model, width, height, maxgeom=flock.model.ngeom + 100)


def film_flock(out_path: str | Path, flock: Flock | Playback, n_frames: int, fps: float = 30.0,
               steps_per_frame: int = DEFAULT_STEPS_PER_FRAME, width: int = 640, height: int = 480,
               camera: str = "overview", progress: bool = False) -> dict:
    """Film a flock you made (a :class:`~lifelike_mj.boids.sim.Flock`, from its current step on, or a
    :func:`playback` of a run, one recorded state per step) into an ``.mp4`` or ``.gif`` file:
    ``n_frames`` frames, frame ``j`` showing ``j * steps_per_frame`` steps later, at ``fps``."""
    video_target(out_path, width, height)
    _check_camera(camera, flock.params.dims)
    n_frames = checks.whole("the number of frames", n_frames, 1)
    spf = checks.whole("steps per frame", steps_per_frame, 1)
    k0 = int(flock.steps)
    flock.sync()
    cam = cameras.fixed(flock.model, camera)
    with _renderer(flock, width, height) as renderer:
        return film(out_path, flock, [k0 + j * spf for j in range(n_frames)], renderer, cam, fps, camera, progress,
                    f"render boids {flock.params.name or ''}".rstrip())


def render_boids(out_path: str | Path, params: BoidParams, n: int = 300, n_steps: int = DEFAULT_STEPS, seed: int = 0,
                 fps: float = 30.0, steps_per_frame: int = DEFAULT_STEPS_PER_FRAME, width: int = 640, height: int = 480,
                 camera: str = "overview", warmup_steps: int = 0, progress: bool = False) -> dict:
    """Render a new boids run of ``n`` agents offscreen to an ``.mp4`` or ``.gif`` file (Nakamura 2013).

    ``params``: :class:`~lifelike_mj.boids.engine.BoidParams` (e.g.
    :func:`~lifelike_mj.boids.presets.load_preset`; 3D or 2D); ``seed``: the run's seed (initial
    positions, velocities and types, as :func:`~lifelike_mj.boids.sim.simulate`). The run is
    streamed (module docstring): ``warmup_steps`` engine steps unrendered first (the patterns form
    within about 1,000-3,000 steps), then ``n_steps // steps_per_frame + 1`` frames, frame ``j``
    showing step ``warmup_steps + j * steps_per_frame``, played at ``fps`` frames/s. ``camera``:
    ``overview``, ``top`` or ``side`` (3D only). ``width``/``height`` in pixels (8-4096; even for
    MP4). ``progress``: a tqdm bar over the frames (the warm-up is not shown). The file is written
    atomically: nothing is left behind on an error, e.g. a diverging run (:class:`UserError` naming
    the step).

    Returns the keys of :func:`~lifelike_mj.render.video.video_report` (``sim_s`` includes the
    warm-up) and ``"n", "seed", "preset", "dims", "first_step", "last_step", "steps_per_frame"``.
    """
    video_target(out_path, width, height)
    _check_run(params, n, seed, camera)
    checks.positive("fps", fps)
    n_steps = checks.whole("the number of steps", n_steps, 0)
    spf = checks.whole("steps per frame", steps_per_frame, 1)
    warmup = checks.whole("the warm-up", warmup_steps, 0)
    t0 = time.perf_counter()
    flock = _flock(params, n, seed)
    advance_to(flock, warmup)
    warm_s = time.perf_counter() - t0
    info = film_flock(out_path, flock, n_steps // spf + 1, fps, spf, width, height, camera, progress)
    info["sim_s"] += warm_s
    return {**info, "n": flock.n, "seed": flock.seed, "preset": params.name, "dims": params.dims,
            "first_step": warmup, "last_step": flock.steps, "steps_per_frame": spf}


def _check_run(params: BoidParams, n: int, seed: int, camera: str) -> None:
    checks.whole("the number of agents", n, 2)
    checks.whole("seed", seed, 0)
    _check_camera(camera, params.dims)


def render_frame(params: BoidParams | Flock | Playback, step: int = 3000, n: int = 300, seed: int = 0,
                 camera: str = "overview", width: int = 640, height: int = 480) -> np.ndarray:
    """One rendered frame: of a new run at engine step ``step``, or of the flock or playback you pass
    (its current state; ``step``, ``n``, ``seed`` unused). An ``(height, width, 3)`` uint8 RGB image,
    top row first. Arguments as :func:`render_boids`."""
    check_size(width, height, "image")
    if hasattr(params, "step"):
        flock = params
        _check_camera(camera, flock.params.dims)
    else:
        _check_run(params, n, seed, camera)
        flock = _flock(params, n, seed)
        advance_to(flock, checks.whole("the step", step, 0))
    flock.sync()
    with _renderer(flock, width, height) as renderer:
        renderer.update(flock.model, flock.data, cameras.fixed(flock.model, camera))
        return renderer.draw()


def frame_png(out_path: str | Path, params: BoidParams | Flock | Playback, step: int = 3000, n: int = 300,
              seed: int = 0, camera: str = "overview", width: int = 640, height: int = 480) -> Path:
    """:func:`render_frame` written atomically as a PNG; returns the path."""
    out = Path(out_path)
    if out.suffix.lower() != ".png":
        raise UserError(f"cannot write {out.name}: a frame is written as a .png file.")
    return write_png(out, render_frame(params, step, n, seed, camera, width, height))


def view_boids(params: BoidParams, n: int = 300, seed: int = 0, steps_per_s: float = VIEW_STEPS_PER_S,
               duration_steps: int | None = None, camera: str = "overview", warmup_steps: int = 0,
               flock: Flock | None = None, web=None) -> None:
    """Run the boids in the MuJoCo viewer, ``steps_per_s`` engine steps per wall-clock second, until
    the window is closed or ``duration_steps`` steps have been shown (``None``: until closed).

    A new flock, or the ``flock`` you give. ``warmup_steps`` are run before the window opens.
    ``camera``: ``overview`` (a free camera placed as the scene's overview camera: drag to orbit,
    scroll to zoom) or ``top`` (a free camera looking straight down: the x-y plane). The stepping slows
    down rather than freezes when the engine cannot keep up. Raises :class:`UserError` when there is
    no display (use :func:`render_boids` instead); on macOS run it under ``mjpython``. ``web``:
    :class:`~lifelike_mj.render.web.WebOptions` to serve MuJoCo's web viewer instead (no display needed).
    Right and Left change the weights live (:func:`weight_controls`).
    """
    if web is None:
        require_display("boids")
    rate = checks.positive("steps per second", steps_per_s)
    if duration_steps is not None:
        duration_steps = checks.whole("the number of steps", duration_steps, 1)
    warmup = checks.whole("the warm-up", warmup_steps, 0)
    if camera not in ("overview", "top"):
        raise UserError(f"unknown viewer camera {camera!r}; choose overview or top.")
    if flock is None:
        checks.whole("the number of agents", n, 2)
        checks.whole("seed", seed, 0)
        flock = _flock(params, n, seed)
    # compiles the engine (about 10 s the first time, then cached) before the window opens
    advance_to(flock, max(warmup, 1, flock.steps))
    m = flock.model
    end = None if duration_steps is None else flock.steps + duration_steps

    def setup(viewer) -> None:
        import mujoco

        centre = flock.layout.centre
        offset = np.asarray(m.camera("overview").pos) - centre
        viewer.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        viewer.cam.lookat[:] = centre
        viewer.cam.distance = float(np.linalg.norm(offset))
        if camera == "top":
            viewer.cam.azimuth, viewer.cam.elevation = 90.0, -90.0
        else:
            viewer.cam.azimuth = math.degrees(math.atan2(offset[1], offset[0])) + 180.0
            viewer.cam.elevation = -math.degrees(math.atan2(offset[2], math.hypot(offset[0], offset[1])))

    view(flock, rate, end, setup, web=web, controls=weight_controls(flock))


#: The flock's keys in the desktop viewer and what each does (none of them is one of MuJoCo's viewer's own; the web
#: viewer also has a button per pattern).
KEYS = (("Right", "the next pattern's weights (4a, 4b, ... 5d)"), ("Left", "the previous pattern's weights"),
        ("Enter", "scatter the flock: a new mixed start under the weights flown now"))


def weight_controls(flock: Flock) -> list:
    """The flock's keys and buttons (:data:`KEYS`; :class:`~lifelike_mj.render.viewer.Control`): Right and Left step
    through patterns 4a, 4b, 4c, 4d, 5a, 5b, 5c and 5d (Nakamura 2013 Fig. 4-5), and the web viewer has one button
    per pattern; the flock takes that pattern's weight matrices ``W_a``, ``W_c`` from the next step on
    (:meth:`Flock.set_weights`), the agents where they are. Each press prints the pattern now flown. Enter
    scatters the agents afresh (:meth:`Flock.scatter`, a new seed each time): some patterns grow only from a
    mixed start, not from the groups another pattern has formed (measured: ``docs/models/boids.md``)."""
    from lifelike_mj.boids.presets import PATTERNS, load_preset
    from lifelike_mj.render.viewer import Control

    at = [-1]  # the pattern flown through these controls (none yet: the flock's own weights)

    def take(i: int) -> None:
        at[0] = i % len(PATTERNS)
        p = load_preset(PATTERNS[at[0]], flock.params.dims)
        flock.set_weights(wa=p.wa, wc=p.wc)
        print(f"now the weights of pattern {PATTERNS[at[0]]}", flush=True)

    def switch(i: int):
        return lambda: take(i)

    def back() -> None:
        take(at[0] - 1 if at[0] >= 0 else -1)

    scattered = [0]

    def scatter() -> None:
        scattered[0] += 1
        flock.scatter(flock.seed + scattered[0])

    return [Control("Right", KEYS[0][1], lambda: take(at[0] + 1)), Control("Left", KEYS[1][1], back),
            Control("Enter", KEYS[2][1], scatter),
            *(Control("", f"weights of pattern {name}", switch(i)) for i, name in enumerate(PATTERNS))]


__all__ = ["CAMERAS", "DEFAULT_STEPS", "DEFAULT_STEPS_PER_FRAME", "VIEW_STEPS_PER_S", "film_flock", "frame_png",
           "playback", "render_boids", "render_frame", "view_boids", "weight_controls"]
