"""Offscreen video, single frames and the viewer of the heterogeneous boids (Nakamura 2013).

The agents are the real run of :mod:`lifelike_mj.boids.engine`, streamed: the state ``(x, v)`` of
:func:`~lifelike_mj.boids.engine.initial_state` (same ``params``, ``n``, ``seed``) is advanced in
place with :func:`~lifelike_mj.boids.engine.step_grid` between frames, so no trajectory is kept in
memory and a rendered run is the run :func:`~lifelike_mj.boids.engine.simulate` computes with the
same arguments. MuJoCo only draws: the agents are mocap bodies of :mod:`lifelike_mj.boids.scene`
(ellipsoids along their velocities; A red, B yellow-green), placed by
:func:`~lifelike_mj.boids.scene.update` before each frame.

Time: the engine's step (``dt = 1``) has no unit of seconds, so a video plays ``steps_per_frame``
engine steps per frame: frame ``j`` shows step ``warmup_steps + j * steps_per_frame``, for
``j = 0 .. n_steps // steps_per_frame`` (the first frame is the state after the warm-up). At the
defaults (5 steps per frame, 30 frames/s) a flock at the typical 0.05-0.15 box units per step
crosses the 20-unit box in 1.5 to 4.5 s of video.

Cameras (``camera=``, :data:`~lifelike_mj.boids.scene.CAMERAS`): ``overview`` (perspective, the
whole box from above one corner), ``top`` (orthographic x-y projection, the plane of the paper-style
figures; the natural view of a 2D run) and ``side`` (orthographic x-z projection; 3D only).

Rendering reuses the offscreen machinery of :mod:`lifelike_mj.viz.video` (OpenGL backend choice,
context, frame writers for ``.mp4`` and ``.gif``, size checks, atomic writes); the scene keeps its
own lighting (shadows and multisampling off for speed). As there, ``mujoco`` is imported only inside
functions, so that :func:`~lifelike_mj.viz.video.ensure_gl_backend` can run first.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path
from lifelike_mj.viz.video import _check_size, _Offscreen, _positive, _video_report, _video_target, _write_frames
from lifelike_mj.viz.viewer import FRAME_S, MAX_CATCH_UP_S, launch_viewer, require_display

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.boids.engine import BoidParams

#: The cameras of a 3D run (a 2D run has the first two); see :mod:`lifelike_mj.boids.scene`.
CAMERAS = ("overview", "top", "side")
#: Engine steps per video frame by default.
DEFAULT_STEPS_PER_FRAME = 5
#: Engine steps of a video by default (after the warm-up): 601 frames, 20 s at 30 frames/s.
DEFAULT_STEPS = 3000
#: Engine steps per wall-clock second in the viewer by default (5 per refresh at 30 Hz).
VIEW_STEPS_PER_S = 150.0


def _count(name: str, v: Any, low: int) -> int:
    if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
        raise UserError(f"{name} must be a whole number of at least {low}, got {v!r}.")
    return int(v)


def _check_camera(camera: str, dims: int) -> None:
    names = CAMERAS if dims == 3 else CAMERAS[:2]
    if camera not in names:
        extra = " (a 2D run has no side view)" if camera in CAMERAS else ""
        raise UserError(f"unknown camera {camera!r}{extra}; choose one of {', '.join(names)}.")


class _Run:
    """A streamed boids run in a mocap scene: the engine's state ``(x, v)`` at step ``step``."""

    def __init__(self, params: BoidParams, n: int, seed: int) -> None:
        import mujoco

        from lifelike_mj.boids.engine import initial_state
        from lifelike_mj.boids.scene import build_scene

        self.params = params
        self.x, self.v, self.types = initial_state(params, n, seed)
        self.seed = int(seed)
        self.step = 0
        self.model, self.layout = build_scene(n, self.types, box=params.box, dims=params.dims)
        self.data = mujoco.MjData(self.model)
        self.refresh()

    @property
    def n(self) -> int:
        return self.layout.n

    def advance(self, step: int) -> None:
        """Run the engine to step ``step`` (no-op if there) and place the bodies;
        :class:`UserError` if the run diverges."""
        from lifelike_mj.boids.engine import step_grid

        k = int(step) - self.step
        if k < 0:
            raise ValueError("a boids run cannot be stepped backwards")
        if k:
            step_grid(self.x, self.v, self.types, self.params, k)
            self.step = int(step)
            self.refresh()

    def refresh(self) -> None:
        from lifelike_mj.boids.scene import update

        update(self.model, self.data, self.layout, self.x, self.v)

    def camera(self, name: str):
        import mujoco

        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
        cam.fixedcamid = self.model.camera(name).id
        return cam


def _renderer(run: _Run, width: int, height: int) -> _Offscreen:
    from lifelike_mj.boids.scene import EDGE_RADIUS, set_edge_radius

    # the box's edges at least about a pixel wide (the overview shows some 1.8 box sides over the height)
    set_edge_radius(run.model, run.layout, max(EDGE_RADIUS, 1.0 * run.params.box / height))
    return _Offscreen(run.model, width, height, maxgeom=run.model.ngeom + 100, dress=False)


def _check_run(params: BoidParams, n: int, seed: int, camera: str) -> None:
    _count("the number of agents", n, 2)
    _count("seed", seed, 0)
    _check_camera(camera, params.dims)


def render_boids(out_path: str | Path, params: BoidParams, n: int = 300, n_steps: int = DEFAULT_STEPS, seed: int = 0,
                 fps: float = 30.0, steps_per_frame: int = DEFAULT_STEPS_PER_FRAME, width: int = 640, height: int = 480,
                 camera: str = "overview", warmup_steps: int = 0, progress: bool = False) -> dict:
    """Render a boids run of ``n`` agents offscreen to an ``.mp4`` or ``.gif`` file (Nakamura 2013).

    ``params``: :class:`~lifelike_mj.boids.engine.BoidParams` (e.g.
    :func:`~lifelike_mj.boids.presets.load_preset`; 3D or 2D); ``seed``: the run's seed (initial
    positions, velocities and types, as :func:`~lifelike_mj.boids.engine.simulate`). The run is
    streamed (module docstring): ``warmup_steps`` engine steps unrendered first (the patterns form
    within about 1,000-3,000 steps), then ``n_steps // steps_per_frame + 1`` frames, frame ``j``
    showing step ``warmup_steps + j * steps_per_frame``, played at ``fps`` frames/s. ``camera``:
    ``overview``, ``top`` or ``side`` (3D only). ``width``/``height`` in pixels (8-4096; even for
    MP4). ``progress``: a tqdm bar over the frames (the warm-up is not shown). The file is written
    atomically: nothing is left behind on an error, e.g. a diverging run (:class:`UserError` naming
    the step).

    Returns ``{"path", "frames", "fps", "width", "height", "camera", "seconds" (video length, s),
    "n", "seed", "preset", "dims", "first_step", "last_step", "steps_per_frame", "gl_backend",
    "sim_s", "render_s", "encode_s", "wall_s" (wall-clock s of the engine with the body updates, of
    drawing and reading the frames, of encoding, and in all), "render_fps" (frames drawn per wall
    second of drawing alone)}``.
    """
    out, suffix = _video_target(out_path, width, height)
    _check_run(params, n, seed, camera)
    fps = _positive("fps", fps)
    n_steps = _count("the number of steps", n_steps, 0)
    spf = _count("steps per frame", steps_per_frame, 1)
    warmup = _count("the warm-up", warmup_steps, 0)
    n_frames = n_steps // spf + 1

    t_start = time.perf_counter()
    run = _Run(params, n, seed)
    cam = run.camera(camera)
    m, d = run.model, run.data
    t0 = time.perf_counter()
    run.advance(warmup)
    warm_s = time.perf_counter() - t0
    renderer = _renderer(run, width, height)

    def draw(j: int) -> np.ndarray:
        renderer.update(m, d, cam)
        return renderer.draw()

    try:
        t = _write_frames(out, suffix, fps, n_frames, lambda j: run.advance(warmup + j * spf), draw,
                          f"render boids {params.name or ''}".rstrip(), progress)
    finally:
        renderer.close()
    return {
        **_video_report(out, n_frames, fps, width, height, camera, renderer.backend, t, t_start, warm_s),
        "n": run.n,
        "seed": run.seed,
        "preset": params.name,
        "dims": params.dims,
        "first_step": warmup,
        "last_step": run.step,
        "steps_per_frame": spf,
    }

def render_frame(params: BoidParams, step: int = 3000, n: int = 300, seed: int = 0, camera: str = "overview",
                 width: int = 640, height: int = 480) -> np.ndarray:
    """One rendered frame of the run at engine step ``step``: an ``(height, width, 3)`` uint8 RGB
    image, top row first. Arguments as :func:`render_boids`."""
    _check_size(width, height, "image")
    _check_run(params, n, seed, camera)
    step = _count("the step", step, 0)
    run = _Run(params, n, seed)
    run.advance(step)
    renderer = _renderer(run, width, height)
    try:
        renderer.update(run.model, run.data, run.camera(camera))
        return renderer.draw()
    finally:
        renderer.close()


def frame_png(out_path: str | Path, params: BoidParams, step: int = 3000, n: int = 300, seed: int = 0,
              camera: str = "overview", width: int = 640, height: int = 480) -> Path:
    """:func:`render_frame` written atomically as a PNG; returns the path."""
    from PIL import Image

    out = Path(out_path)
    if out.suffix.lower() != ".png":
        raise UserError(f"cannot write {out.name}: a frame is written as a .png file.")
    img = render_frame(params, step, n, seed, camera, width, height)
    with atomic_path(out) as tmp:
        Image.fromarray(img).save(tmp, format="PNG")
    return out


def view_boids(params: BoidParams, n: int = 300, seed: int = 0, steps_per_s: float = VIEW_STEPS_PER_S,
               duration_steps: int | None = None, camera: str = "overview", warmup_steps: int = 0) -> None:
    """Run the boids in the MuJoCo viewer, ``steps_per_s`` engine steps per wall-clock second, until
    the window is closed or ``duration_steps`` steps have been shown (``None``: until closed).

    ``warmup_steps`` are run before the window opens. ``camera``: ``overview`` (a free camera placed
    as the scene's overview camera: drag to orbit, scroll to zoom) or ``top`` (a free camera looking
    straight down: the x-y plane). The stepping slows down rather than freezes when the engine
    cannot keep up. Raises :class:`UserError` when there is no display (use :func:`render_boids`
    instead); on macOS run it under ``mjpython``.
    """
    require_display("boids")
    _count("the number of agents", n, 2)
    _count("seed", seed, 0)
    rate = _positive("steps per second", steps_per_s)
    if duration_steps is not None:
        duration_steps = _count("the number of steps", duration_steps, 1)
    warmup = _count("the warm-up", warmup_steps, 0)
    if camera not in ("overview", "top"):
        raise UserError(f"unknown viewer camera {camera!r}; choose overview or top.")

    import mujoco

    run = _Run(params, n, seed)
    run.advance(max(warmup, 1))  # compiles the engine (about 10 s the first time, then cached) before the window opens
    m, d = run.model, run.data
    with launch_viewer(m, d) as viewer:
        with viewer.lock():
            centre = run.layout.centre
            over = m.camera("overview")
            offset = np.asarray(over.pos) - centre
            viewer.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            viewer.cam.lookat[:] = centre
            viewer.cam.distance = float(np.linalg.norm(offset))
            if camera == "top":
                viewer.cam.azimuth, viewer.cam.elevation = 90.0, -90.0
            else:
                viewer.cam.azimuth = math.degrees(math.atan2(offset[1], offset[0])) + 180.0
                viewer.cam.elevation = -math.degrees(math.atan2(offset[2], math.hypot(offset[0], offset[1])))
        first = run.step
        end_step = None if duration_steps is None else first + duration_steps
        max_chunk = max(1, int(round(MAX_CATCH_UP_S * rate)))
        start = time.perf_counter()
        at_start = first
        while viewer.is_running():
            target = at_start + int((time.perf_counter() - start) * rate)
            if target - run.step > max_chunk:  # fell behind: re-anchor the clock, run slower than asked
                target = run.step + max_chunk
                at_start, start = target, time.perf_counter()
            if end_step is not None:
                target = min(target, end_step)
            with viewer.lock():
                run.advance(max(target, run.step))
            viewer.sync()
            if end_step is not None and run.step >= end_step:
                break
            time.sleep(FRAME_S)


__all__ = ["CAMERAS", "DEFAULT_STEPS", "DEFAULT_STEPS_PER_FRAME", "VIEW_STEPS_PER_S", "frame_png", "render_boids",
           "render_frame", "view_boids"]
