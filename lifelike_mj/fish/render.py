"""Offscreen video, single frames, a render benchmark and the viewer of the fish tank (Satoi 2015).

The fish are the real simulation of :mod:`lifelike_mj.fish.sim`: a :class:`~lifelike_mj.fish.sim.Swimmer`
advanced by whole control steps (``params.control_hz``, 60 per second, as in Satoi, Nakadai,
Hoshino 2015), so a rendered swim is the swim that :func:`~lifelike_mj.fish.sim.swim` computes with
the same preset, fish count, seed and tank (the swimmer draws its random numbers per control step,
in any chunking). Frame ``j`` of a video shows the state at the control step nearest to its time
``j / fps`` (s), rounding halves up: at 30 frames per second every 2nd control step, at 24 the
steps 0, 3, 5, 8, 10, ... (the frame times 0, 0.042, 0.083, ... s fall between control steps).

Cameras (``camera=``):

* ``side``: the model's side camera, the paper's view: the whole tank, seen through the front glass
  (in the filmed 5 m tank a 7 cm fish is about 8 pixels long at 640 x 480);
* ``oblique``: the model's camera above and in front of the tank;
* ``follow``: a closer side view for watching one fish swim: a free camera looking along +y (into
  the tank), :data:`FOLLOW_ELEVATION_DEG` from the horizontal, at the distance that shows
  :data:`FOLLOW_VIEW_M` (1 m) of tank length at mid-depth (a fish is then about 45 pixels long at
  640 x 480). It aims at fish ``follow_fish`` (default 0), its aim low-pass filtered with the time
  constant :data:`FOLLOW_SMOOTH_S` so that a burst shows as the fish darting across the frame, and
  clamped so that the view never leaves the tank (the camera stops at the end walls and lets the
  fish turn in view). The fish of this model do not school (each swims on its own, spread over the
  whole tank), so the centroid of the tank's fish is usually empty water: one fish is followed.

Rendering reuses the butterfly's offscreen machinery of :mod:`lifelike_mj.viz.video` (OpenGL
backend choice, context, frame writers for ``.mp4`` and ``.gif``, size checks, atomic writes); the
tank keeps its own lighting (``models/tank.xml``; shadows and multisampling are off for speed).
As there, ``mujoco`` is imported only inside functions, so that :func:`~lifelike_mj.viz.video.ensure_gl_backend`
can run first.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.viz.video import _check_size, _Offscreen, _positive, _video_report, _video_target, _write_frames
from lifelike_mj.viz.viewer import FRAME_S, MAX_CATCH_UP_S, launch_viewer, require_display

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.fish.params import FishParams
    from lifelike_mj.fish.sim import Swimmer

#: The cameras of :func:`render_fish`: two of the tank model, and the closer following view.
CAMERAS = ("side", "oblique", "follow")
#: Tank length (m) that the ``follow`` camera shows across the frame, at mid-depth (y = 0).
FOLLOW_VIEW_M = 1.0
#: Elevation of the ``follow`` camera (deg; negative: looking slightly down, the sand floor shows).
FOLLOW_ELEVATION_DEG = -5.0
#: Time constant (s) of the low-pass filter on the ``follow`` camera's aim.
FOLLOW_SMOOTH_S = 0.5
#: Closest the ``follow`` camera comes to the tank's mid-plane beyond the front glass (m).
FOLLOW_GLASS_CLEARANCE_M = 0.1


def _check_camera(camera: str) -> None:
    if camera not in CAMERAS:
        raise UserError(f"unknown camera {camera!r}; choose one of {', '.join(CAMERAS)}.")


def _refresh(m, d) -> None:
    """Recompute the drawing quantities (body poses, cameras, lights) of the current state.

    ``mj_step`` leaves them at the start of its last step; they are derived quantities that the
    next step recomputes, so this does not change the swim."""
    import mujoco

    mujoco.mj_kinematics(m, d)
    mujoco.mj_comPos(m, d)
    mujoco.mj_camlight(m, d)


def _swimmer(params: FishParams, n_fish: int, seed: int, size) -> Swimmer:
    from lifelike_mj.fish.sim import Swimmer

    sw = Swimmer(params, n_fish, seed, size)
    _refresh(sw.scene.model, sw.data)
    return sw


def _advance(sw: Swimmer, step: int) -> None:
    """Run the swimmer to control step ``step`` (no-op if there) and refresh its drawing state."""
    n = int(step) - sw.step
    if n < 0:
        raise ValueError("a swim cannot be stepped backwards")
    if n:
        sw.run(n, record=False)
        _refresh(sw.scene.model, sw.data)


def frame_steps(n_frames: int, fps: float, control_hz: float) -> np.ndarray:
    """Control step shown by each of ``n_frames`` frames at ``fps`` frames/s: the step nearest to
    the frame time ``j / fps`` s (halves rounded up), for a control rate of ``control_hz`` steps/s."""
    j = np.arange(int(n_frames), dtype=float)
    return np.floor(j * float(control_hz) / float(fps) + 0.5 + 1e-9).astype(np.int64)


class _Camera:
    """An ``MjvCamera`` for one of :data:`CAMERAS`; :meth:`aim` moves the ``follow`` camera."""

    def __init__(self, sw: Swimmer, camera: str, width: int, height: int, follow_fish: int = 0) -> None:
        import mujoco

        _check_camera(camera)
        m = sw.scene.model
        self.kind = camera
        self.cam = mujoco.MjvCamera()
        self._aim: np.ndarray | None = None
        if camera != "follow":
            self.cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
            self.cam.fixedcamid = m.camera(camera).id
            return
        n = sw.scene.n
        if isinstance(follow_fish, bool) or not isinstance(follow_fish, (int, np.integer)) or not 0 <= follow_fish < n:
            raise UserError(f"the fish to follow must be a whole number from 0 to {n - 1}, got {follow_fish!r}.")
        self.qadr = int(sw.scene.qadr[follow_fish])
        L, D, H = sw.scene.size
        half_v = math.radians(float(m.vis.global_.fovy)) / 2.0  # a free camera's vertical field of view
        tan_h = math.tan(half_v) * width / height
        dist = max(0.5 * FOLLOW_VIEW_M / tan_h, D / 2 + FOLLOW_GLASS_CLEARANCE_M)
        self.half_w = dist * tan_h  # half the view (m) at mid-depth
        self.half_h = dist * math.tan(half_v)
        self.size = (L, D, H)
        self.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.cam.distance = dist
        self.cam.azimuth = 90.0  # looking along +y, into the tank from the front glass
        self.cam.elevation = FOLLOW_ELEVATION_DEG

    def aim(self, d, dt_s: float | None = None) -> None:
        """Point the ``follow`` camera at its fish: directly when ``dt_s`` is None (the first frame,
        a snapshot), else low-pass filtered over ``dt_s`` s of swim since the last aim."""
        if self.kind != "follow":
            return
        target = np.array(d.qpos[self.qadr : self.qadr + 3], dtype=float)
        if self._aim is None or dt_s is None:
            self._aim = target
        else:
            self._aim = self._aim + (target - self._aim) * (1.0 - math.exp(-dt_s / FOLLOW_SMOOTH_S))
        L, _D, H = self.size
        x = float(np.clip(self._aim[0], -L / 2 + self.half_w, L / 2 - self.half_w)) if L > 2 * self.half_w else 0.0
        z = float(np.clip(self._aim[2], self.half_h, H - self.half_h)) if H > 2 * self.half_h else H / 2
        self.cam.lookat[:] = (x, 0.0, z)


def _renderer(sw: Swimmer, width: int, height: int) -> _Offscreen:
    # five visible geoms per fish, plus the tank
    return _Offscreen(sw.scene.model, width, height, maxgeom=100 + 8 * sw.scene.n, dress=False)


def render_fish(out_path: str | Path, params: FishParams, n_fish: int = 10, duration_s: float = 10.0, seed: int = 0,
                size=None, fps: float = 30.0, width: int = 640, height: int = 480, camera: str = "side",
                follow_fish: int = 0, progress: bool = False, start_s: float = 0.0) -> dict:
    """Render a swim of ``n_fish`` fish offscreen to an ``.mp4`` or ``.gif`` file (Satoi 2015 model).

    ``params``: a preset (:func:`~lifelike_mj.fish.params.load_preset`); ``seed``: the swim's seed;
    ``size``: the water volume ``(L, D, H)`` in m (default the filmed tank, 5 x 0.5 x 1 m).
    ``round(duration_s * fps)`` frames (``duration_s`` in s) are played at ``fps`` frames/s, at real
    speed; frame ``j`` shows control step ``round(start_s * control_hz) + round(j * control_hz / fps)``
    (module docstring), so ``fps`` may be at most the control rate (60). ``start_s`` (s, default 0): the swim runs that
    long unrendered first (the fish start at rest and wait for their first *accelerate* MU, about
    0.5 s on average with the B-D preset). ``camera``: ``side`` (the whole tank, the paper's view),
    ``oblique``, or ``follow`` (a 1 m wide side view following fish ``follow_fish``; module
    docstring). ``width``/``height`` in pixels (8-4096; even for MP4). ``progress``: a tqdm bar.
    The file is written atomically (nothing is left behind on an error, e.g. a runaway swim).

    Returns ``{"path", "frames", "fps", "width", "height", "camera", "seconds" (video length, s =
    simulated time shown), "n_fish", "seed", "preset", "gl_backend", "sim_s", "render_s", "encode_s",
    "wall_s" (wall-clock s of the swim, of drawing and reading the frames, of encoding, and in all),
    "render_fps" (frames drawn per wall second of drawing alone, swim and encoding excluded),
    "start_s"}``.
    """
    out, suffix = _video_target(out_path, width, height)
    _check_camera(camera)
    duration_s = _positive("duration", duration_s)
    fps = _positive("fps", fps)
    if fps > params.control_hz * (1.0 + 1e-9):
        raise UserError(f"{fps:g} frames per second is more than the {params.control_hz:g} control steps per second "
                        "of the swim (frames would repeat); choose fps <= the control rate.")
    if isinstance(start_s, bool) or not isinstance(start_s, (int, float)) or not (math.isfinite(start_s) and start_s >= 0):
        raise UserError(f"the start time must be a number of seconds >= 0, got {start_s!r}.")
    n_frames = max(1, int(round(duration_s * fps)))
    first = int(math.floor(start_s * params.control_hz + 0.5))
    steps = first + frame_steps(n_frames, fps, params.control_hz)

    t_start = time.perf_counter()
    sw = _swimmer(params, n_fish, seed, size)
    cam = _Camera(sw, camera, width, height, follow_fish)
    renderer = _renderer(sw, width, height)
    m, d = sw.scene.model, sw.data

    def advance(j: int) -> None:
        _advance(sw, int(steps[j]))

    def draw(j: int) -> np.ndarray:
        cam.aim(d, None if j == 0 else int(steps[j] - steps[j - 1]) * params.control_dt_s)
        renderer.update(m, d, cam.cam)
        return renderer.draw()

    try:
        t = _write_frames(out, suffix, fps, n_frames, advance, draw, "render fish", progress)
    finally:
        renderer.close()
    return {
        **_video_report(out, n_frames, fps, width, height, camera, renderer.backend, t, t_start),
        "n_fish": int(sw.scene.n),
        "seed": int(sw.seed),
        "preset": params.name,
        "start_s": first * params.control_dt_s,
    }

def render_frame(params: FishParams, t_s: float = 5.0, n_fish: int = 10, seed: int = 0, size=None,
                 camera: str = "side", width: int = 640, height: int = 480, follow_fish: int = 0) -> np.ndarray:
    """One rendered frame of the swim at time ``t_s`` (s; the nearest control step): an
    ``(height, width, 3)`` uint8 RGB image, top row first. Arguments as :func:`render_fish`; the
    ``follow`` camera aims straight at its fish (no filter history)."""
    _check_size(width, height, "image")
    _check_camera(camera)
    if isinstance(t_s, bool) or not isinstance(t_s, (int, float)) or not (math.isfinite(t_s) and t_s >= 0):
        raise UserError(f"the snapshot time must be a number of seconds >= 0, got {t_s!r}.")
    sw = _swimmer(params, n_fish, seed, size)
    cam = _Camera(sw, camera, width, height, follow_fish)
    _advance(sw, int(math.floor(t_s * params.control_hz + 0.5)))
    cam.aim(sw.data)
    renderer = _renderer(sw, width, height)
    try:
        renderer.update(sw.scene.model, sw.data, cam.cam)
        return renderer.draw()
    finally:
        renderer.close()


def _gl_renderer_name() -> str:
    """The OpenGL renderer's name (e.g. ``llvmpipe`` = software, or the GPU's) of the current context."""
    with contextlib.suppress(Exception):
        from OpenGL import GL

        name = GL.glGetString(GL.GL_RENDERER)
        if name:
            return name.decode(errors="replace") if isinstance(name, bytes) else str(name)
    return "unknown"


def render_benchmark(n_frames: int = 120, width: int = 640, height: int = 480, n_fish: int = 10,
                     camera: str = "side", repeats: int = 5, seed: int = 0) -> dict:
    """Frames per second of pure rendering of the fish tank (the default, filmed tank; preset B-D).

    The swim is run 2 s (so the fish have spread and turned), then the same state is drawn
    ``n_frames`` times, ``repeats`` times over: each frame is ``mjv_updateScene``, ``mjr_render`` and
    reading the pixels back (what a video needs), no physics and no encoding. After 5 warm-up
    frames. Returns ``{"fps" (median over the repeats, frames/s), "fps_runs", "ms_per_frame"
    (median, ms), "n_frames", "repeats", "width", "height", "n_fish", "camera", "gl_backend",
    "gl_renderer"}``. The goal for the performance doc: at least 60 frames/s at 640 x 480.
    """
    from lifelike_mj.fish.params import load_preset

    _check_size(width, height, "benchmark")
    _check_camera(camera)
    for name, v in (("frame count", n_frames), ("repeats", repeats)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 1:
            raise UserError(f"{name} must be a whole number of at least 1, got {v!r}.")
    params = load_preset("B-D")
    sw = _swimmer(params, n_fish, seed, None)
    _advance(sw, int(round(2.0 * params.control_hz)))
    cam = _Camera(sw, camera, width, height)
    cam.aim(sw.data)
    m, d = sw.scene.model, sw.data
    renderer = _renderer(sw, width, height)
    runs = []
    try:
        for _ in range(5):
            renderer.update(m, d, cam.cam)
            renderer.draw()
        gl_name = _gl_renderer_name()
        for _ in range(repeats):
            t0 = time.perf_counter()
            for _ in range(n_frames):
                renderer.update(m, d, cam.cam)
                renderer.draw()
            runs.append(n_frames / (time.perf_counter() - t0))
    finally:
        renderer.close()
    fps = statistics.median(runs)
    return {
        "fps": fps,
        "fps_runs": runs,
        "ms_per_frame": 1000.0 / fps,
        "n_frames": int(n_frames),
        "repeats": int(repeats),
        "width": width,
        "height": height,
        "n_fish": int(n_fish),
        "camera": camera,
        "gl_backend": renderer.backend,
        "gl_renderer": gl_name,
    }


def view_fish(params: FishParams, n_fish: int = 10, seed: int = 0, size=None, duration_s: float | None = None,
              camera: str = "side", follow_fish: int = 0) -> None:
    """Swim the fish in the MuJoCo viewer in about real time, until the window is closed or
    ``duration_s`` seconds of simulated swim have passed (``None``: until closed).

    Control steps at ``params.control_hz`` (60 per second). ``camera``: ``side`` (a free camera
    placed as the tank's side camera: the whole tank; drag to orbit, scroll to zoom) or ``follow``
    (MuJoCo's tracking camera on fish ``follow_fish``, from the side at the distance of the
    ``follow`` video camera). Raises :class:`UserError` when there is no display (use
    :func:`render_fish` instead); on macOS run it under ``mjpython``.
    """
    require_display("fish")
    if duration_s is not None:
        duration_s = _positive("duration", duration_s)
    if camera not in ("side", "follow"):
        raise UserError(f"unknown viewer camera {camera!r}; choose side or follow.")

    import mujoco

    sw = _swimmer(params, n_fish, seed, size)
    m, d = sw.scene.model, sw.data
    sw.run(1, record=False)  # compiles the swim loop (a few s, once per process) before the window opens
    _refresh(m, d)
    follow = _Camera(sw, "follow", 640, 480, follow_fish) if camera == "follow" else None
    dt = params.control_dt_s
    with launch_viewer(m, d) as viewer:
        with viewer.lock():
            side = m.camera("side")
            L, D, H = sw.scene.size
            if follow is None:
                viewer.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
                viewer.cam.lookat[:] = (0.0, 0.0, H / 2)
                viewer.cam.distance = float(np.linalg.norm(side.pos - np.array([0.0, 0.0, H / 2])))
                viewer.cam.elevation = 0.0
            else:
                viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
                viewer.cam.trackbodyid = int(sw.scene.body[follow_fish])
                viewer.cam.distance = follow.cam.distance
                viewer.cam.elevation = FOLLOW_ELEVATION_DEG
            viewer.cam.azimuth = 90.0
            viewer.opt.sitegroup[:] = 0
        end_step = None if duration_s is None else int(round(duration_s / dt))
        max_chunk = max(1, int(round(MAX_CATCH_UP_S / dt)))
        start = time.perf_counter()
        sim_at_start = sw.step
        while viewer.is_running():
            target = sim_at_start + int((time.perf_counter() - start) / dt)
            if target - sw.step > max_chunk:  # fell behind: re-anchor the clock, run slower than real time
                target = sw.step + max_chunk
                sim_at_start, start = target, time.perf_counter()
            if end_step is not None:
                target = min(target, end_step)
            with viewer.lock():
                _advance(sw, max(target, sw.step))
            viewer.sync()
            if end_step is not None and sw.step >= end_step:
                break
            time.sleep(FRAME_S)


__all__ = ["CAMERAS", "FOLLOW_VIEW_M", "frame_steps", "render_benchmark", "render_fish", "render_frame", "view_fish"]
