"""Offscreen video, single frames, a render benchmark and the viewer of the fish tank (Satoi 2015).

The fish are the real simulation of :mod:`lifelike_mj.fish.sim`: a :class:`~lifelike_mj.fish.sim.Tank`
advanced by whole control steps (``params.control_hz``, 60 per second, as in Satoi, Nakadai,
Hoshino 2015), so a rendered swim is the swim that :func:`~lifelike_mj.fish.sim.swim` computes with
the same preset, fish count, seed and tank (the tank draws its random numbers per control step,
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

A swim you already recorded (:class:`~lifelike_mj.fish.sim.SwimResult`) is drawn the same way
through :func:`playback`. Rendering uses the generic :mod:`lifelike_mj.render` package (OpenGL
backend choice, the recorder and its MP4/GIF writers, atomic writes); the tank keeps its own
lighting (``models/fish/tank.xml``; shadows and multisampling are off for speed). ``mujoco`` is
imported only inside functions, so that :func:`~lifelike_mj.render.gl.ensure_gl_backend` can run first.
"""

from __future__ import annotations

import math
import statistics
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.render.offscreen import Offscreen, gl_renderer_name
from lifelike_mj.render.video import advance_to, check_size, film, video_target, write_png
from lifelike_mj.render.viewer import require_display, view
from lifelike_mj.stepper import Playback

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.fish.params import FishParams
    from lifelike_mj.fish.sim import SwimResult, Tank

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


def _tank(params: FishParams, n_fish: int, seed: int, size) -> Tank:
    from lifelike_mj.fish.sim import Tank

    tank = Tank(params, n_fish, seed, size)
    tank.sync()
    return tank


def frame_steps(n_frames: int, fps: float, control_hz: float) -> np.ndarray:
    """Control step shown by each of ``n_frames`` frames at ``fps`` frames/s: the step nearest to
    the frame time ``j / fps`` s (halves rounded up), for a control rate of ``control_hz`` steps/s."""
    j = np.arange(int(n_frames), dtype=float)
    return np.floor(j * float(control_hz) / float(fps) + 0.5 + 1e-9).astype(np.int64)


class _Camera:
    """An ``MjvCamera`` for one of :data:`CAMERAS`; :meth:`aim` moves the ``follow`` camera."""

    def __init__(self, sw: Tank | Playback, camera: str, width: int, height: int, follow_fish: int = 0) -> None:
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
        checks.whole("the fish to follow", follow_fish, 0, n - 1)
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


def _renderer(sw: Tank | Playback, width: int, height: int) -> Offscreen:
    # five visible geoms per fish, plus the tank
    return Offscreen(sw.scene.model, width, height, maxgeom=100 + 8 * sw.scene.n)


def playback(result: SwimResult) -> Playback:
    """A recorded swim (:class:`~lifelike_mj.fish.sim.SwimResult`) in the stepper shape: step ``k`` poses
    the fish of a tank like the swim's at its control step ``k`` (positions and orientations)."""
    import mujoco

    from lifelike_mj.fish.scene import build_scene

    scene = build_scene(result.n_fish, result.tank_m)
    d = mujoco.MjData(scene.model)
    pos, quat = result.positions, result.quats

    def pose(k: int) -> None:
        for i, a in enumerate(scene.qadr):
            d.qpos[a : a + 3] = pos[k, i]
            d.qpos[a + 3 : a + 7] = quat[k, i]
        mujoco.mj_kinematics(scene.model, d)
        mujoco.mj_comPos(scene.model, d)
        mujoco.mj_camlight(scene.model, d)

    def state(k: int) -> dict:
        return {"position_m": pos[k], "quat": quat[k], "mu": result.mu[k] % 4, "avoiding": result.mu[k] >= 4}

    dt = float(result.times_s[1] - result.times_s[0]) if len(result.times_s) > 1 else result.params.control_dt_s
    pb = Playback(scene.model, d, len(result.times_s), pose, dt, state)
    pb.scene = scene  # the cameras need the tank's size and the fish's addresses
    pb.params = result.params
    return pb


def film_tank(out_path: str | Path, tank: Tank | Playback, duration_s: float = 10.0, fps: float = 30.0,
              width: int = 640, height: int = 480, camera: str = "side", follow_fish: int = 0,
              progress: bool = False) -> dict:
    """Film a tank you made (a :class:`~lifelike_mj.fish.sim.Tank`, from its current state on, or a
    :func:`playback` of a swim) into an ``.mp4`` or ``.gif`` file: ``round(duration_s * fps)`` frames
    at ``fps`` frames/s (real speed; at most the control rate), frame ``j`` showing the control step
    nearest to ``j / fps`` s after the start (module docstring). Returns the keys of
    :func:`~lifelike_mj.render.video.video_report`."""
    video_target(out_path, width, height)
    _check_camera(camera)
    duration_s = checks.positive("duration", duration_s, "s")
    fps = checks.positive("fps", fps)
    control_hz = 1.0 / tank.dt
    if fps > control_hz * (1.0 + 1e-9):
        raise UserError(f"{fps:g} frames per second is more than the {control_hz:g} control steps per second "
                        "of the swim (frames would repeat); choose fps <= the control rate.")
    n_frames = max(1, int(round(duration_s * fps)))
    steps = int(tank.steps) + frame_steps(n_frames, fps, control_hz)
    cam = _Camera(tank, camera, width, height, follow_fish)

    def aimed(j: int):
        cam.aim(tank.data, None if j == 0 else int(steps[j] - steps[j - 1]) * tank.dt)
        return cam.cam

    tank.sync()
    with _renderer(tank, width, height) as renderer:
        return film(out_path, tank, [int(k) for k in steps], renderer, aimed, fps, camera, progress, "render fish")


def render_fish(out_path: str | Path, params: FishParams, n_fish: int = 10, duration_s: float = 10.0, seed: int = 0,
                size=None, fps: float = 30.0, width: int = 640, height: int = 480, camera: str = "side",
                follow_fish: int = 0, progress: bool = False, start_s: float = 0.0) -> dict:
    """Render a new swim of ``n_fish`` fish offscreen to an ``.mp4`` or ``.gif`` file (Satoi 2015 model).

    ``params``: a preset (:func:`~lifelike_mj.fish.params.load_preset`); ``seed``: the swim's seed;
    ``size``: the water volume ``(L, D, H)`` in m (default the filmed tank, 5 x 0.5 x 1 m).
    ``start_s`` (s, default 0): the swim runs that long unrendered first (the fish start at rest and
    wait for their first *accelerate* MU, about 0.5 s on average with the B-D preset); then
    :func:`film_tank`. ``camera``: ``side`` (the whole tank, the paper's view), ``oblique``, or
    ``follow`` (a 1 m wide side view following fish ``follow_fish``; module docstring).
    ``width``/``height`` in pixels (8-4096; even for MP4). The file is written atomically (nothing is
    left behind on an error, e.g. a runaway swim).

    Returns the keys of :func:`~lifelike_mj.render.video.video_report` and ``"n_fish", "seed",
    "preset", "start_s"``.
    """
    video_target(out_path, width, height)
    _check_camera(camera)
    start_s = checks.number("the start time", start_s, 0.0, unit="s")
    tank = _tank(params, n_fish, seed, size)
    first = int(math.floor(start_s * params.control_hz + 0.5))
    advance_to(tank, first)
    info = film_tank(out_path, tank, duration_s, fps, width, height, camera, follow_fish, progress)
    return {**info, "n_fish": int(tank.scene.n), "seed": int(tank.seed), "preset": params.name,
            "start_s": first * params.control_dt_s}


def render_frame(params: FishParams | Tank | Playback, t_s: float = 5.0, n_fish: int = 10, seed: int = 0, size=None,
                 camera: str = "side", width: int = 640, height: int = 480, follow_fish: int = 0) -> np.ndarray:
    """One rendered frame: of a new swim with preset ``params`` at time ``t_s`` (s; the nearest control
    step), or of a tank or playback you pass (its current state; ``t_s``, ``n_fish``, ``seed`` and
    ``size`` unused). An ``(height, width, 3)`` uint8 RGB image, top row first. The ``follow`` camera
    aims straight at its fish (no filter history)."""
    check_size(width, height, "image")
    _check_camera(camera)
    if hasattr(params, "step"):
        tank = params
    else:
        t_s = checks.number("the snapshot time", t_s, 0.0, unit="s")
        tank = _tank(params, n_fish, seed, size)
        advance_to(tank, int(math.floor(t_s * params.control_hz + 0.5)))
    tank.sync()
    cam = _Camera(tank, camera, width, height, follow_fish)
    cam.aim(tank.data)
    with _renderer(tank, width, height) as renderer:
        renderer.update(tank.scene.model, tank.data, cam.cam)
        return renderer.draw()


def frame_png(out_path: str | Path, params: FishParams | Tank | Playback, **kw) -> Path:
    """:func:`render_frame` written as a PNG, atomically; returns the path."""
    return write_png(out_path, render_frame(params, **kw))


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

    check_size(width, height, "benchmark")
    _check_camera(camera)
    checks.whole("frame count", n_frames, 1)
    checks.whole("repeats", repeats, 1)
    params = load_preset("B-D")
    tank = _tank(params, n_fish, seed, None)
    advance_to(tank, int(round(2.0 * params.control_hz)))
    cam = _Camera(tank, camera, width, height)
    cam.aim(tank.data)
    m, d = tank.scene.model, tank.data
    runs = []
    with _renderer(tank, width, height) as renderer:
        for _ in range(5):
            renderer.update(m, d, cam.cam)
            renderer.draw()
        gl_name = gl_renderer_name()
        for _ in range(repeats):
            t0 = time.perf_counter()
            for _ in range(n_frames):
                renderer.update(m, d, cam.cam)
                renderer.draw()
            runs.append(n_frames / (time.perf_counter() - t0))
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
              camera: str = "side", follow_fish: int = 0, tank: Tank | None = None, web=None) -> None:
    """Swim the fish in the MuJoCo viewer in about real time, until the window is closed or
    ``duration_s`` seconds of simulated swim have passed (``None``: until closed).

    A new tank, or the ``tank`` you give. ``camera``: ``side`` (a free camera placed as the tank's side
    camera: the whole tank; drag to orbit, scroll to zoom) or ``follow`` (MuJoCo's tracking camera on
    fish ``follow_fish``, from the side at the distance of the ``follow`` video camera). Raises
    :class:`UserError` when there is no display (use :func:`render_fish` instead); on macOS run it
    under ``mjpython``. ``web``: :class:`~lifelike_mj.render.web.WebOptions` to serve MuJoCo's web viewer
    instead of opening a window (no display needed). The tank is a virtual aquarium
    (:mod:`lifelike_mj.fish.aquarium`, unless it has policies of its own): Space taps the front glass, Enter
    drops a food pellet (keys in the window, buttons in the web viewer); fish that heed each other (a preset's
    social terms, as in ``school`` and ``shoal``) pass a startle on (the aquarium's cascade).
    """
    if web is None:
        require_display("fish")
    if duration_s is not None:
        duration_s = checks.positive("duration", duration_s, "s")
    if camera not in ("side", "follow"):
        raise UserError(f"unknown viewer camera {camera!r}; choose side or follow.")
    if tank is None:
        tank = _tank(params, n_fish, seed, size)
    tank.step(1)  # compiles the swim loop (a few s, once per process) before the window opens
    tank.sync()
    m = tank.scene.model
    follow = _Camera(tank, "follow", 640, 480, follow_fish) if camera == "follow" else None
    end = None if duration_s is None else int(round(duration_s / tank.dt))

    def setup(viewer) -> None:
        import mujoco

        side = m.camera("side")
        _L, _D, H = tank.scene.size
        if follow is None:
            viewer.cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            viewer.cam.lookat[:] = (0.0, 0.0, H / 2)
            viewer.cam.distance = float(np.linalg.norm(side.pos - np.array([0.0, 0.0, H / 2])))
            viewer.cam.elevation = 0.0
        else:
            viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
            viewer.cam.trackbodyid = int(tank.scene.body[follow_fish])
            viewer.cam.distance = follow.cam.distance
            viewer.cam.elevation = FOLLOW_ELEVATION_DEG
        viewer.cam.azimuth = 90.0

    from lifelike_mj.fish.aquarium import Aquarium, controls

    if tank.mu_policy is None and tank.push_policy is None:  # the virtual aquarium: Space taps, Enter feeds, Right looms
        # fish that heed each other pass a startle on and compete for food
        aquarium = Aquarium(tank, cascade=tank.params.social, compete=tank.params.social)
        view(aquarium, 1.0 / tank.dt, end, setup, web=web, controls=controls(aquarium, seed))
    else:
        view(tank, 1.0 / tank.dt, end, setup, web=web)


__all__ = ["CAMERAS", "FOLLOW_VIEW_M", "film_tank", "frame_png", "frame_steps", "playback", "render_benchmark",
           "render_fish", "render_frame", "view_fish"]
