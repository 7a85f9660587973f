"""Offscreen rendering of the MuJoCo butterfly: videos (MP4/GIF) and a snapshot figure (Oe 2010 Fig. 10).

The physics is the real simulation of :mod:`lifelike_mj.butterfly.mjbackend`: the model built by
``build_model``, its data from ``setup_data``, stepped with the compiled passive callback
installed and the controller's pitch command applied once per step, exactly as the compiled
``_run`` loop does. ``_run`` always starts its clock at step 0, so it cannot be resumed between
frames; :func:`_advance` below is the same loop with a start step (same ``t = k dt``, same
``pitch_command``, same divergence test), and a flight rendered in chunks is bit-for-bit the
flight ``fly_one`` computes (``tests/test_viz.py`` checks this).

OpenGL backend. MuJoCo's Python package picks its OpenGL backend from ``MUJOCO_GL`` once, when
``mujoco`` is first imported. On a headless Linux machine call :func:`ensure_gl_backend` before
anything imports ``mujoco`` (the command-line entry point should do this first thing): it sets
``MUJOCO_GL`` to the first of ``egl``, ``osmesa`` that can create a context (probed in a
subprocess, since a failed backend cannot be unloaded). The renderer here opens its context from
the backend's own module (``mujoco.egl``, ``mujoco.osmesa``, ``mujoco.glfw``), so it also works
when ``mujoco`` was imported before ``MUJOCO_GL`` was set.

This module imports ``mujoco`` only inside functions, so importing it to call
:func:`ensure_gl_backend` does not load MuJoCo.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path

if TYPE_CHECKING:  # pragma: no cover
    from lifelike_mj.butterfly.controllers import ButterflyController
    from lifelike_mj.butterfly.paper import Condition
    from lifelike_mj.butterfly.params import ButterflyParams

#: Offscreen backends tried, in order, when ``MUJOCO_GL`` is unset (Linux).
GL_CANDIDATES = ("egl", "osmesa")
#: ``MUJOCO_GL`` values that mean "glfw" to MuJoCo.
_GLFW_ALIASES = ("glfw", "glx", "enable", "enabled", "on", "true", "1")
_GL_DISABLED = ("disable", "disabled", "off", "false", "0")

#: Default camera of the videos: tracking the butterfly from the side, slightly behind and above.
FOLLOW_DISTANCE_M = 0.20
FOLLOW_AZIMUTH_DEG = 62.0  # 90 = looking along +y (pure side view); less = from behind
FOLLOW_ELEVATION_DEG = -14.0
#: Close-up camera of the snapshot figure: pure side view (the pitch reads directly).
SNAP_DISTANCE_M = 0.16
SNAP_AZIMUTH_DEG = 90.0
SNAP_ELEVATION_DEG = -8.0
#: Default start of the snapshots: settled flight (s).
SNAP_START_S = 15.0
#: Repeats of the ground checker texture per metre when rendering (the models' 40 blurs into
#: moire at the butterfly's scale; 0.5 gives 1 m squares whose motion shows the flight speed).
GROUND_TEXREPEAT = 0.5

_probe_cache: dict[str, bool] = {}
_PROBE_CODE = (
    "import mujoco\n"
    "c = mujoco.GLContext(16, 16)\n"
    "c.make_current()\n"
    "m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><geom size=\"1\"/></worldbody></mujoco>')\n"
    "r = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)\n"
    "r.free()\n"
    "c.free()\n"
)


def _probe(backend: str) -> bool:
    """Whether ``MUJOCO_GL=backend`` can create an OpenGL context (tried in a subprocess)."""
    if backend not in _probe_cache:
        env = dict(os.environ, MUJOCO_GL=backend)
        try:
            res = subprocess.run([sys.executable, "-c", _PROBE_CODE], env=env, capture_output=True, timeout=120)
            _probe_cache[backend] = res.returncode == 0
        except (OSError, subprocess.SubprocessError):
            _probe_cache[backend] = False
    return _probe_cache[backend]


def ensure_gl_backend() -> str | None:
    """Set ``os.environ["MUJOCO_GL"]`` to a working offscreen backend if it is unset; return it.

    Call it before the first ``import mujoco`` of the process (MuJoCo reads ``MUJOCO_GL`` at import
    time). A value the user already set is respected and returned unchanged. On Linux the first of
    ``egl``, ``osmesa`` that can create a context is chosen (each probe is a short subprocess,
    about 1 s, done once per process); elsewhere (macOS, Windows) MuJoCo's default is kept and
    ``None`` returned. ``None`` also when no backend works; :func:`render_butterfly` then raises
    :class:`~lifelike_mj.errors.UserError`.
    """
    current = os.environ.get("MUJOCO_GL", "").strip()
    if current:
        return current.lower()
    if not sys.platform.startswith("linux"):
        return None
    for backend in GL_CANDIDATES:
        if _probe(backend):
            os.environ["MUJOCO_GL"] = backend
            return backend
    return None


def _gl_context(width: int, height: int) -> tuple[Any, str]:
    """An OpenGL context made current, and the backend's name; :class:`UserError` if none works."""
    requested = os.environ.get("MUJOCO_GL", "").strip().lower()
    if requested in _GL_DISABLED:
        raise UserError(f"rendering is disabled by MUJOCO_GL={requested}; unset it or set it to egl or osmesa.")
    if not requested:
        requested = ensure_gl_backend() or ""
    if not requested:
        if sys.platform.startswith("linux"):
            raise UserError("no offscreen OpenGL backend works on this machine (tried EGL and OSMesa); install "
                            "libegl1 or libosmesa6 (e.g. `apt-get install libosmesa6`) or set MUJOCO_GL.")
        requested = "cgl" if sys.platform == "darwin" else "glfw"
    name = "glfw" if requested in _GLFW_ALIASES else requested
    try:
        module = importlib.import_module(f"mujoco.{name}")
        ctx = module.GLContext(width, height)
        ctx.make_current()
    except Exception as exc:  # noqa: BLE001 - any failure of the GL stack means "no backend"
        raise UserError(f"cannot create an offscreen OpenGL context with MUJOCO_GL={requested} "
                        f"({exc.__class__.__name__}: {str(exc).strip()[:160] or 'no detail'}); "
                        "try MUJOCO_GL=egl or MUJOCO_GL=osmesa.") from None
    return ctx, name


def _dress(m) -> None:
    """Rendering-only touches to a (private) compiled model: ground squares of 1 m, and more
    ambient light so that a wing seen edge-on to the overhead sun is not black."""
    for i in range(m.nmat):
        if m.mat(i).name == "grid":
            m.mat_texrepeat[i] = (GROUND_TEXREPEAT, GROUND_TEXREPEAT)
    m.vis.headlight.ambient[:] = 0.35
    m.vis.headlight.diffuse[:] = 0.55


class _Offscreen:
    """A minimal offscreen renderer (context, scene, pixel buffer) of one model."""

    def __init__(self, m, width: int, height: int, maxgeom: int = 1000, dress: bool = True) -> None:
        import mujoco

        self.width, self.height = int(width), int(height)
        # the offscreen framebuffer is sized from the model when the MjrContext is made
        m.vis.global_.offwidth = max(int(m.vis.global_.offwidth), self.width)
        m.vis.global_.offheight = max(int(m.vis.global_.offheight), self.height)
        if dress:  # the butterfly's rendering touches; other scenes (the fish tank) keep their own lighting
            _dress(m)
        self.ctx, self.backend = _gl_context(self.width, self.height)
        try:
            self.con = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)
        except Exception as exc:  # noqa: BLE001 - e.g. glfw without a display leaves no current context
            with contextlib.suppress(Exception):
                self.ctx.free()
            raise UserError(f"the OpenGL backend {self.backend} created no usable context ({exc.__class__.__name__}); "
                            "try MUJOCO_GL=egl or MUJOCO_GL=osmesa.") from None
        mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.con)
        self.scn = mujoco.MjvScene(m, maxgeom)
        self.opt = mujoco.MjvOption()
        self.opt.sitegroup[:] = 0  # hide the centre-of-pressure and tip markers
        self.pert = mujoco.MjvPerturb()
        self.rect = mujoco.MjrRect(0, 0, self.width, self.height)
        self._rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)

    def update(self, m, d, cam, moving_only: bool = False) -> None:
        """Build the scene of ``d`` seen from ``cam`` (an ``MjvCamera``); ``moving_only``: no ground."""
        import mujoco

        cat = mujoco.mjtCatBit.mjCAT_DYNAMIC if moving_only else mujoco.mjtCatBit.mjCAT_ALL
        mujoco.mjv_updateScene(m, d, self.opt, self.pert, cam, cat, self.scn)

    def add(self, m, d) -> None:
        """Add the moving geoms of ``d`` to the current scene (for overlays)."""
        import mujoco

        mujoco.mjv_addGeoms(m, d, self.opt, self.pert, mujoco.mjtCatBit.mjCAT_DYNAMIC, self.scn)

    def draw(self) -> np.ndarray:
        """Render the current scene; an ``(height, width, 3)`` uint8 image, top row first."""
        import mujoco

        self.ctx.make_current()
        mujoco.mjr_render(self.rect, self.scn, self.con)
        mujoco.mjr_readPixels(self._rgb, None, self.rect, self.con)
        return np.flipud(self._rgb).copy()

    def project(self, points: np.ndarray) -> np.ndarray:
        """Pixel coordinates ``(u, v)`` (from the top-left) of world points (m) in the last scene."""
        import mujoco

        cam = mujoco.mjv_averageCamera(self.scn.camera[0], self.scn.camera[1])  # mono view: between the eyes
        pos, fwd, up = np.array(cam.pos), np.array(cam.forward), np.array(cam.up)
        right = np.cross(fwd, up)
        rel = np.atleast_2d(points) - pos
        x, y, z = rel @ right, rel @ up, rel @ fwd
        if not cam.orthographic:
            x, y = x * cam.frustum_near / z, y * cam.frustum_near / z
        top, bottom = cam.frustum_top, cam.frustum_bottom
        half_w = cam.frustum_width or 0.5 * (top - bottom) * self.width / self.height
        u = (x - (cam.frustum_center - half_w)) / (2.0 * half_w) * self.width
        v = (top - y) / (top - bottom) * self.height
        return np.stack([u, v], axis=1)

    def close(self) -> None:
        with contextlib.suppress(Exception):
            self.ctx.make_current()
            self.con.free()
        with contextlib.suppress(Exception):
            self.ctx.free()


# ---- the stepping loop, resumable ------------------------------------------------------------



def _advance_fn():
    """The resumable stepping loop shared with ``fly_one``: ``mjbackend.advance``."""
    from lifelike_mj.butterfly.mjbackend import advance

    return advance


class _Flight:
    """One butterfly flight on the MuJoCo backend that can be stepped in chunks (for rendering).

    ``advance_to(k)`` runs steps up to step ``k`` (time ``k dt``) with the compiled passive
    callback installed, then refreshes the kinematics (positions, centres of mass, cameras) of
    the new state for drawing: ``mj_step`` with RK4 leaves them at the start of its step. The
    refresh writes only derived quantities that the next ``mj_step`` recomputes.
    """

    def __init__(self, controller: ButterflyController, params: ButterflyParams | None = None,
                 condition: Condition | None = None, config: str = "paper", force_mode: str = "tip",
                 dt_s: float = 1.0 / 1200.0) -> None:
        from lifelike_mj.butterfly import mjbackend as mb
        from lifelike_mj.butterfly.paper import Condition, check_timing

        mb.check_config(config, force_mode)
        check_timing(1.0, dt_s)
        self.cond = condition or Condition()
        self.m = mb.build_model(params, config)
        self.m.opt.timestep = float(dt_s)
        self.d = mb.setup_data(self.m, controller, params, self.cond, force_mode)
        self.dt = float(self.m.opt.timestep)
        self.lay = mb.layout(self.m).as_array()
        kind, cp = controller.compiled()
        self.kind = int(kind)
        self.cp = np.ascontiguousarray(cp, dtype=float)
        self.flap = controller.flap.as_array()
        self.k = 0
        self.phi = 0.0
        self.diverged = np.full(1, -1, dtype=np.int64)
        self._fit = np.zeros(1)
        self.body = self.m.body("butterfly").id
        self._fn = _advance_fn()
        self._call(0)  # compiles the loop on first use (about 1 s), steps nothing
        self.refresh()

    @property
    def time_s(self) -> float:
        """Simulated time of the current state, s."""
        return self.k * self.dt

    def advance_to(self, step: int) -> None:
        """Step the flight to step ``step`` (no-op if already there); :class:`UserError` on divergence."""
        from lifelike_mj.butterfly.mjbackend import COMPILED_PASSIVE
        from lifelike_mj.physics.callbacks import passive_callback

        n = int(step) - self.k
        if n < 0:
            raise ValueError("a flight cannot be stepped backwards")
        if n:
            with passive_callback(COMPILED_PASSIVE):
                self._call(n)
            if self.diverged[0] >= 0:
                raise UserError(f"the flight diverged at step {self.diverged[0]} (t = "
                                f"{self.diverged[0] * self.dt:.4f} s); nothing was rendered from there on.")
            self.k = int(step)
        self.refresh()

    def _call(self, n: int) -> None:
        d = self.d
        self.phi = self._fn(self.m._address, d._address, d.qpos, d.qvel, d.userdata, self.k, n, self.kind, self.cp,
                            self.flap, 0.0, self.lay, self.dt, self.phi, self.diverged, self._fit)

    def refresh(self) -> None:
        """Recompute the kinematics of the current state for drawing."""
        import mujoco

        mujoco.mj_kinematics(self.m, self.d)
        mujoco.mj_comPos(self.m, self.d)
        mujoco.mj_camlight(self.m, self.d)

    def com(self) -> np.ndarray:
        """Centre of mass of the whole butterfly, world frame (m)."""
        return np.array(self.d.subtree_com[self.body])


# ---- cameras -----------------------------------------------------------------------------------


def _follow_camera(m, body: int, distance: float, azimuth_deg: float, elevation_deg: float):
    import mujoco

    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    cam.trackbodyid = body
    cam.fixedcamid = -1
    cam.distance = distance
    cam.azimuth = azimuth_deg
    cam.elevation = elevation_deg
    return cam


def _camera(m, body: int, camera: str):
    """``follow`` (tracking, default view) or the name of a camera of the model (``side``, ``chase``)."""
    import mujoco

    if camera == "follow":
        return _follow_camera(m, body, FOLLOW_DISTANCE_M, FOLLOW_AZIMUTH_DEG, FOLLOW_ELEVATION_DEG)
    names = [m.camera(i).name for i in range(m.ncam)]
    if camera not in names:
        raise UserError(f"unknown camera {camera!r}; choose follow or one of the model's cameras: {', '.join(names)}.")
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FIXED
    cam.fixedcamid = m.camera(camera).id
    return cam


# ---- writing files atomically -------------------------------------------------------------------


class _MP4Writer:
    def __init__(self, path: Path, fps: float) -> None:
        import imageio.v2 as iio

        try:
            self._w = iio.get_writer(str(path), format="FFMPEG", mode="I", fps=fps, codec="libx264", quality=8,
                                     pixelformat="yuv420p", macro_block_size=2, ffmpeg_log_level="error")
        except (ImportError, RuntimeError, ValueError) as exc:
            raise UserError(f"cannot write MP4 ({exc.__class__.__name__}); install imageio-ffmpeg or write a "
                            ".gif.") from None

    def add(self, frame: np.ndarray) -> None:
        self._w.append_data(frame)

    def close(self) -> None:
        self._w.close()


class _GIFWriter:
    def __init__(self, path: Path, fps: float) -> None:
        self.path, self.fps, self.frames = path, fps, []

    def add(self, frame: np.ndarray) -> None:
        from PIL import Image

        self.frames.append(Image.fromarray(frame).quantize(colors=255, method=Image.Quantize.MEDIANCUT))

    def close(self) -> None:
        if self.frames:
            ms = max(20, int(round(1000.0 / self.fps)))  # browsers treat < 20 ms as 100 ms
            self.frames[0].save(self.path, format="GIF", save_all=True, append_images=self.frames[1:], duration=ms,
                                loop=0, disposal=1, optimize=False)


_WRITERS = {".mp4": _MP4Writer, ".gif": _GIFWriter}


# ---- public functions ---------------------------------------------------------------------------


def _check_size(width: int, height: int, what: str) -> None:
    for name, v in (("width", width), ("height", height)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 8 <= v <= 4096:
            raise UserError(f"{what} {name} must be a whole number of pixels between 8 and 4096, got {v!r}.")


def _positive(name: str, v: Any) -> float:
    """``v`` as a float; :class:`UserError` unless it is a finite number > 0."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or not (math.isfinite(v) and v > 0):
        raise UserError(f"{name} must be a positive number, got {v!r}.")
    return float(v)


def _write_frames(out: Path, suffix: str, fps: float, n_frames: int, advance: Callable[[int], None],
                  draw: Callable[[int], np.ndarray], desc: str = "render", progress: bool = False) -> dict[str, float]:
    """Write ``n_frames`` frames to ``out`` (atomically; nothing left on an error): frame ``j`` is
    ``advance(j)`` (the simulation) then ``draw(j)`` (an RGB image), then encoding. Returns the wall
    seconds of each part: ``{"sim_s", "render_s", "encode_s"}``."""
    sim_s = render_s = encode_s = 0.0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_frames, unit="frame", desc=desc, leave=False)
    try:
        with atomic_path(out) as tmp:
            writer = _WRITERS[suffix](tmp, fps)
            try:
                for j in range(n_frames):
                    t0 = time.perf_counter()
                    advance(j)
                    t1 = time.perf_counter()
                    frame = draw(j)
                    t2 = time.perf_counter()
                    writer.add(frame)
                    sim_s += t1 - t0
                    render_s += t2 - t1
                    encode_s += time.perf_counter() - t2
                    if bar is not None:
                        bar.update(1)
            finally:
                t0 = time.perf_counter()
                writer.close()
                encode_s += time.perf_counter() - t0
    finally:
        if bar is not None:
            bar.close()
    return {"sim_s": sim_s, "render_s": render_s, "encode_s": encode_s}


def _video_report(out: Path, n_frames: int, fps: float, width: int, height: int, camera: str, gl_backend: str,
                  times: dict[str, float], t_start: float, warm_s: float = 0.0) -> dict:
    """The keys every rendered video reports: the file, frames, size, camera, and the wall seconds of
    simulation (``warm_s`` of warm-up added), rendering and encoding (``times``: from
    :func:`_write_frames`), the whole call since ``t_start`` (a ``time.perf_counter()``), and the
    rendering rate."""
    sim_s, render_s, encode_s = warm_s + times["sim_s"], times["render_s"], times["encode_s"]
    return {
        "path": str(out),
        "frames": n_frames,
        "fps": fps,
        "width": width,
        "height": height,
        "camera": camera,
        "seconds": n_frames / fps,
        "gl_backend": gl_backend,
        "sim_s": sim_s,
        "render_s": render_s,
        "encode_s": encode_s,
        "wall_s": time.perf_counter() - t_start,
        "render_fps": n_frames / render_s if render_s > 0 else float("inf"),
    }


def _video_target(out_path: str | Path, width: int, height: int) -> tuple[Path, str]:
    """The video's path and its lower-case suffix (a key of ``_WRITERS``); :class:`UserError` for another
    suffix, a size outside 8-4096 pixels, or an odd size for an MP4."""
    out = Path(out_path)
    suffix = out.suffix.lower()
    if suffix not in _WRITERS:
        raise UserError(f"cannot write {out.name}: the video file must end in .mp4 or .gif.")
    _check_size(width, height, "video")
    if suffix == ".mp4" and (width % 2 or height % 2):
        raise UserError(f"an MP4 video needs an even width and height, got {width}x{height}.")
    return out, suffix


def render_butterfly(out_path: str | Path, controller: ButterflyController, params: ButterflyParams | None = None,
                     condition: Condition | None = None, config: str = "paper", force_mode: str = "tip",
                     duration_s: float = 3.0, fps: float = 30, width: int = 640, height: int = 480,
                     camera: str = "follow", dt_s: float = 1.0 / 1200.0, slowdown: float = 1.0,
                     motion_blur: int = 1) -> dict:
    """Render a flight of the MuJoCo butterfly offscreen to an ``.mp4`` or ``.gif`` file.

    The flight is the real simulation (compiled wing-force callback, controller once per step,
    time step ``dt_s`` in s). Frame ``j`` shows the state at simulated time ``j / (fps * slowdown)``
    (s), for ``round(duration_s * fps * slowdown)`` frames played at ``fps``: ``duration_s`` seconds
    of flight, at real speed by default (``slowdown`` > 1 plays it slower, e.g. 8 to see the 10 Hz
    wing beat; the video then lasts ``duration_s * slowdown`` s). ``camera``: ``follow`` (tracks the
    butterfly from the side, slightly behind; default) or a camera of the model (``side``, ``chase``).
    ``width``/``height`` in pixels. ``motion_blur`` > 1 averages that many renders spread over the half
    frame interval before each frame time (a 180 degree shutter, as a film camera blurs the 10 Hz wing
    beat that 30 frames per second cannot resolve); it costs as many renders per frame. The file is
    written atomically (a temporary file beside it, then renamed).

    Returns ``{"path", "frames", "fps", "width", "height", "gl_backend", "sim_duration_s",
    "render_s", "render_fps"}`` (``render_fps``: frames made per wall-clock second, physics included).
    """
    out, suffix = _video_target(out_path, width, height)
    for name, v in (("duration", duration_s), ("fps", fps), ("slowdown", slowdown)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
            raise UserError(f"{name} must be a positive number, got {v!r}.")
    if isinstance(motion_blur, bool) or not isinstance(motion_blur, (int, np.integer)) or not 1 <= motion_blur <= 32:
        raise UserError(f"motion blur must be a whole number of renders per frame from 1 to 32, got {motion_blur!r}.")
    n_frames = max(1, int(round(duration_s * fps * slowdown)))
    sim_per_frame = 1.0 / (fps * slowdown)

    t0 = time.perf_counter()
    flight = _Flight(controller, params, condition, config, force_mode, dt_s)
    if sim_per_frame < flight.dt * (1.0 - 1e-9):
        raise UserError(f"{fps:g} frames per second at slowdown {slowdown:g} is finer than the time step "
                        f"{flight.dt:g} s.")
    cam = _camera(flight.m, flight.body, camera)
    renderer = _Offscreen(flight.m, width, height)
    try:
        with atomic_path(out) as tmp:
            writer = _WRITERS[suffix](tmp, fps)
            try:
                for j in range(n_frames):
                    if motion_blur == 1:
                        flight.advance_to(int(round(j * sim_per_frame / flight.dt)))
                        renderer.update(flight.m, flight.d, cam)
                        writer.add(renderer.draw())
                        continue
                    acc = np.zeros((height, width, 3), dtype=np.float32)
                    for s in range(motion_blur):
                        t = (j - 0.5 * (motion_blur - 1 - s) / (motion_blur - 1)) * sim_per_frame
                        flight.advance_to(max(flight.k, int(round(t / flight.dt))))
                        renderer.update(flight.m, flight.d, cam)
                        acc += renderer.draw()
                    writer.add(np.clip(acc / motion_blur + 0.5, 0, 255).astype(np.uint8))
            finally:
                writer.close()
    finally:
        renderer.close()
    elapsed = time.perf_counter() - t0
    return {
        "path": str(out),
        "frames": n_frames,
        "fps": fps,
        "width": width,
        "height": height,
        "gl_backend": renderer.backend,
        "sim_duration_s": n_frames * sim_per_frame,
        "render_s": elapsed,
        "render_fps": n_frames / elapsed if elapsed > 0 else float("inf"),
    }


def snapshot_figure(out_path: str | Path, controller: ButterflyController, params: ButterflyParams | None = None,
                    config: str = "paper", t_start_s: float | None = None, interval_s: float = 0.025,
                    count: int = 8, width: int = 320, height: int = 240) -> Path:
    """Snapshots of the flight every ``interval_s`` seconds, as in Oe 2010 Fig. 10; writes a PNG.

    The butterfly flies (real simulation, time step 1/1200 s) to ``t_start_s`` (s; default 15 s,
    settled flight), then ``count`` states ``interval_s`` apart are drawn (1) overlaid along the
    flight path in one side view with an orthographic camera (true lengths and heights, against the
    sky, with a 10 cm scale bar; flying left to right), and (2) each as a close-up from a side
    camera that follows the body (ground and sky behind), labelled with its time.
    ``width``/``height``: pixels of one close-up. Atomic write.
    Returns the path written.
    """
    import mujoco
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    out = Path(out_path)
    if out.suffix.lower() != ".png":
        raise UserError(f"cannot write {out.name}: the snapshot figure is a .png file.")
    _check_size(width, height, "snapshot")
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or not 1 <= count <= 64:
        raise UserError(f"count must be a whole number between 1 and 64, got {count!r}.")
    t_start = SNAP_START_S if t_start_s is None else t_start_s
    for name, v, lo in (("start time", t_start, 0.0), ("interval", interval_s, 1e-9)):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v >= lo):
            raise UserError(f"snapshot {name} must be a number of seconds >= {lo:g}, got {v!r}.")

    flight = _Flight(controller, params, None, config, "tip")
    dt = flight.dt
    steps = [int(round((t_start + i * interval_s) / dt)) for i in range(count)]
    if len(set(steps)) < count:
        raise UserError(f"the snapshot interval {interval_s:g} s is shorter than the time step {dt:g} s.")
    states, coms, times = [], [], []
    for k in steps:
        flight.advance_to(k)
        states.append(flight.d.qpos.copy())
        coms.append(flight.com())
        times.append(k * dt)
    coms_a = np.array(coms)

    m = flight.m
    d = mujoco.MjData(m)
    cols = min(count, 4)
    rows = int(math.ceil(count / cols))
    pano_w, pano_h = cols * width, max(height, int(round(cols * width * 0.3)))
    renderer = _Offscreen(m, max(width, pano_w), max(height, pano_h), maxgeom=200 + 20 * count)

    def pose(q):
        d.qpos[:] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_camlight(m, d)

    try:
        # (1) overlay along the path, orthographic side view
        span = params.span_m if params is not None else 0.055
        lo = coms_a.min(axis=0) - 1.3 * span
        hi = coms_a.max(axis=0) + 1.3 * span
        aspect = pano_w / pano_h
        view_h = max(hi[2] - lo[2], (hi[0] - lo[0]) / aspect)
        cam = mujoco.MjvCamera()
        cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        cam.lookat[:] = 0.5 * (lo + hi)
        cam.distance = 1.0
        cam.azimuth = 90.0
        cam.elevation = -3.0
        cam.orthographic = 1
        m.vis.global_.fovy = view_h  # for an orthographic camera: the view's height (m)
        renderer.width, renderer.height = pano_w, pano_h
        renderer.rect = mujoco.MjrRect(0, 0, pano_w, pano_h)
        renderer._rgb = np.empty((pano_h, pano_w, 3), dtype=np.uint8)
        pose(states[0])
        renderer.update(m, d, cam, moving_only=True)
        for q in states[1:]:
            pose(q)
            renderer.add(m, d)
        pano = renderer.draw()
        labels = renderer.project(coms_a)
        top_left = np.array([lo[0] + 0.02, 0.0, hi[2] - 0.015])
        bar = renderer.project(np.array([top_left, top_left + [0.10, 0.0, 0.0]]))

        # (2) close-ups, side camera following the body, perspective
        m.vis.global_.fovy = 45.0
        renderer.width, renderer.height = width, height
        renderer.rect = mujoco.MjrRect(0, 0, width, height)
        renderer._rgb = np.empty((height, width, 3), dtype=np.uint8)
        close = _follow_camera(m, flight.body, SNAP_DISTANCE_M, SNAP_AZIMUTH_DEG, SNAP_ELEVATION_DEG)
        closeups = []
        for q in states:
            pose(q)
            renderer.update(m, d, close)
            closeups.append(renderer.draw())
    finally:
        renderer.close()

    # compose: the overlay on top, the close-ups in a grid below
    dpi = 100
    fig_w = pano_w / dpi
    fig_h = (pano_h + rows * (height + 28)) / dpi + 0.5
    fig = Figure(figsize=(fig_w, fig_h), dpi=dpi)
    FigureCanvasAgg(fig)
    top_frac = (pano_h / dpi + 0.35) / fig_h
    ax = fig.add_axes((0.0, 1.0 - top_frac, 1.0, top_frac - 0.35 / fig_h))
    ax.imshow(pano)
    ax.set_axis_off()
    for i, (u, _v) in enumerate(labels):
        ax.text(u, pano_h - 6, f"{times[i]:.3f} s", ha="center", va="bottom", fontsize=8,
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})
    ax.plot(bar[:, 0], bar[:, 1], color="k", lw=2)
    ax.text(bar[:, 0].mean(), bar[0, 1] - 6, "10 cm", ha="center", va="bottom", fontsize=8)
    ax.set_xlim(0, pano_w)
    ax.set_ylim(pano_h, 0)
    fig.text(0.5, 1.0 - 0.3 / fig_h, f"Snapshots every {interval_s * 1000:g} ms of stable flight "
             f"(MuJoCo butterfly, {config} model; cf. Oe 2010 Fig. 10), flying left to right", ha="center",
             va="center", fontsize=10)
    grid_h = 1.0 - top_frac
    for i, img in enumerate(closeups):
        r, c = divmod(i, cols)
        cell_h = grid_h / rows
        a = fig.add_axes((c / cols, grid_h - (r + 1) * cell_h, 1.0 / cols, cell_h * height / (height + 28)))
        a.imshow(img)
        a.set_axis_off()
        a.set_title(f"t = {times[i]:.3f} s", fontsize=9, pad=2)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return out
