"""The butterfly on screen: offscreen videos (MP4/GIF), single frames, the snapshot figure of
Oe 2010 Fig. 10, and the MuJoCo viewer, of a live :class:`~lifelike_mj.butterfly.sim.Flight` or of a
trajectory you already have.

Everything here drives the stepper shape (:mod:`lifelike_mj.stepper`) through the generic
:mod:`lifelike_mj.render` package; this module adds only what is the butterfly's own: its cameras and
the dressing of its model for the eye (ground squares of 1 m, softer light). A live flight on the
MuJoCo backend is drawn as simulated; a flight on the paper backend, or a recorded
:class:`~lifelike_mj.butterfly.flight.Trajectory`, is drawn by posing the paper-equivalent MuJoCo
model at each frame.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.controllers import ButterflyController
from lifelike_mj.butterfly.flight import Condition, Trajectory
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.butterfly.sim import Flight, pose_paper_model
from lifelike_mj.errors import UserError
from lifelike_mj.render import camera
from lifelike_mj.render.offscreen import Offscreen
from lifelike_mj.render.plot import new_figure, save
from lifelike_mj.render.video import advance_to, check_size, film, video_target, write_png
from lifelike_mj.render.viewer import require_display, view
from lifelike_mj.stepper import Playback

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
#: Cameras: ``follow`` (tracking, the default) or one of the model's own.
CAMERAS = ("follow", "side", "chase")


def dress(m):
    """Rendering-only touches to a compiled model (in place; returned): ground squares of 1 m, and
    more ambient light so that a wing seen edge-on to the overhead sun is not black."""
    for i in range(m.nmat):
        if m.mat(i).name == "grid":
            m.mat_texrepeat[i] = (GROUND_TEXREPEAT, GROUND_TEXREPEAT)
    m.vis.headlight.ambient[:] = 0.35
    m.vis.headlight.diffuse[:] = 0.55
    return m


def flight_camera(stepper, name: str = "follow"):
    """``follow`` (tracks the butterfly from the side, slightly behind) or a camera of the model."""
    if name == "follow":
        return camera.tracking(int(stepper.model.body("butterfly").id), FOLLOW_DISTANCE_M, FOLLOW_AZIMUTH_DEG,
                               FOLLOW_ELEVATION_DEG)
    return camera.fixed(stepper.model, name, others=("follow",))


def playback(trajectory: Trajectory, params: ButterflyParams | None = None) -> Playback:
    """A recorded flight in the stepper shape (:class:`~lifelike_mj.stepper.Playback`): frame ``k`` poses
    the paper-equivalent model at the trajectory's row ``k`` (altitude, forward distance, pitch, flap)."""
    import mujoco

    from lifelike_mj.butterfly.model import build_model

    m = build_model(params, "paper")
    d = mujoco.MjData(m)
    tr = trajectory
    if len(tr.t) < 1 or not np.all(np.isfinite(tr.y)):
        raise UserError("the trajectory has no frames, or NaN rows (a diverged flight); nothing to draw.")
    dt = float(tr.t[1] - tr.t[0]) if len(tr.t) > 1 else 1.0

    def pose(k: int) -> None:
        pose_paper_model(m, d, float(tr.y[k]), float(tr.z[k]), float(tr.phi[k]), float(tr.theta[k]))

    def state(k: int) -> dict:
        return {"position_m": np.array([tr.z[k], tr.y[k]]), "velocity_m_s": np.array([tr.vz[k], tr.vy[k]]),
                "pitch_rad": np.array(tr.phi[k]), "flap_rad": np.array(tr.theta[k])}

    return Playback(m, d, len(tr.t), pose, dt, state)


def film_flight(out_path: str | Path, flight: Flight | Playback, duration_s: float = 3.0, fps: float = 30,
                width: int = 640, height: int = 480, camera_name: str = "follow", slowdown: float = 1.0,
                motion_blur: int = 1, progress: bool = False) -> dict:
    """Film a flight you made (a :class:`~lifelike_mj.butterfly.sim.Flight`, from its current state on,
    or a :func:`playback` of a trajectory) into an ``.mp4`` or ``.gif`` file.

    Frame ``j`` shows the state ``j / (fps * slowdown)`` s after the start, for
    ``round(duration_s * fps * slowdown)`` frames played at ``fps``: ``duration_s`` seconds of flight,
    at real speed by default (``slowdown`` > 1 plays it slower, e.g. 8 to see the 10 Hz wing beat).
    ``camera_name``: ``follow`` (default) or a camera of the model (``side``, ``chase``). ``motion_blur``
    > 1 averages that many renders spread over the half frame interval before each frame time (a
    180 degree shutter). Written atomically. Returns the keys of
    :func:`~lifelike_mj.render.video.video_report` and ``sim_duration_s``.
    """
    video_target(out_path, width, height)
    duration_s = checks.positive("duration", duration_s, "s")
    fps = checks.positive("fps", fps)
    slowdown = checks.positive("slowdown", slowdown)
    blur = checks.whole("motion blur (renders per frame)", motion_blur, 1, 32)
    n_frames = max(1, int(round(duration_s * fps * slowdown)))
    sim_per_frame = 1.0 / (fps * slowdown)
    dt = flight.dt
    if sim_per_frame < dt * (1.0 - 1e-9):
        raise UserError(f"{fps:g} frames per second at slowdown {slowdown:g} is finer than the time step {dt:g} s.")
    k0 = int(flight.steps)
    if blur == 1:
        frames: list = [k0 + int(round(j * sim_per_frame / dt)) for j in range(n_frames)]
    else:
        frames = [[k0 + max(0, int(round((j - 0.5 * (blur - 1 - s) / (blur - 1)) * sim_per_frame / dt)))
                   for s in range(blur)] for j in range(n_frames)]
    flight.sync()
    cam = flight_camera(flight, camera_name)
    with Offscreen(dress(flight.model), width, height) as renderer:
        info = film(out_path, flight, frames, renderer, cam, fps, camera_name, progress, "render butterfly")
    info["sim_duration_s"] = n_frames * sim_per_frame
    return info


def render_butterfly(out_path: str | Path, controller: ButterflyController | str = "simple_rule",
                     params: ButterflyParams | None = None, condition: Condition | None = None, config: str = "paper",
                     force_mode: str | None = None, duration_s: float = 3.0, fps: float = 30, width: int = 640,
                     height: int = 480, camera: str = "follow", dt_s: float = 1.0 / 1200.0, slowdown: float = 1.0,
                     motion_blur: int = 1, progress: bool = False) -> dict:
    """Render a new flight of the MuJoCo butterfly (``config``, ``force_mode``; compiled wing-force
    callback, controller once per step, time step ``dt_s``) offscreen: :func:`film_flight` of a fresh
    :class:`~lifelike_mj.butterfly.sim.Flight` on the MuJoCo backend."""
    video_target(out_path, width, height)
    flight = Flight(controller, params, condition, backend="mujoco", config=config, force_mode=force_mode, dt_s=dt_s)
    return film_flight(out_path, flight, duration_s, fps, width, height, camera, slowdown, motion_blur, progress)


def render_frame(flight: Flight | Playback, width: int = 640, height: int = 480, camera_name: str = "follow") -> np.ndarray:
    """The current state of a flight (or playback) drawn: an ``(height, width, 3)`` uint8 RGB image."""
    check_size(width, height, "image")
    flight.sync()
    with Offscreen(dress(flight.model), width, height) as r:
        r.update(flight.model, flight.data, flight_camera(flight, camera_name))
        return r.draw()


def frame_png(out_path: str | Path, flight: Flight | Playback, width: int = 640, height: int = 480,
              camera_name: str = "follow") -> Path:
    """:func:`render_frame` written as a PNG, atomically; returns the path."""
    return write_png(out_path, render_frame(flight, width, height, camera_name))


def view_butterfly(controller: ButterflyController | str = "simple_rule", params: ButterflyParams | None = None,
                   condition: Condition | None = None, config: str = "paper", force_mode: str | None = None,
                   duration_s: float | None = None, flight: Flight | None = None, web=None) -> None:
    """Fly the butterfly in the MuJoCo viewer in about real time, until the window is closed or
    ``duration_s`` seconds of simulated flight have passed (``None``: until closed).

    A new flight on the MuJoCo backend, or the ``flight`` you give (either backend). The camera tracks
    the butterfly from the side, slightly behind (drag to orbit). Raises
    :class:`~lifelike_mj.errors.UserError` when there is no display; on macOS run it under ``mjpython``.
    ``web``: :class:`~lifelike_mj.render.web.WebOptions` to serve MuJoCo's web viewer instead (no display
    needed).
    """
    if web is None:
        require_display("butterfly")
    if duration_s is not None:
        duration_s = checks.positive("duration", duration_s, "s")
    if flight is None:
        flight = Flight(controller, params, condition, backend="mujoco", config=config, force_mode=force_mode)
    flight.step(1)  # compiles the stepping loop (about 1 s) before the window opens
    end = None if duration_s is None else flight.steps + int(round(duration_s / flight.dt))
    body = flight.body_id

    def setup(viewer) -> None:
        import mujoco

        viewer.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
        viewer.cam.trackbodyid = body
        viewer.cam.distance = FOLLOW_DISTANCE_M
        viewer.cam.azimuth = FOLLOW_AZIMUTH_DEG
        viewer.cam.elevation = FOLLOW_ELEVATION_DEG

    flight.sync()
    view(flight, 1.0 / flight.dt, end, setup, web=web)


def snapshot_figure(out_path: str | Path, controller: ButterflyController | str = "simple_rule",
                    params: ButterflyParams | None = None,
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

    out = Path(out_path)
    if out.suffix.lower() != ".png":
        raise UserError(f"cannot write {out.name}: the snapshot figure is a .png file.")
    check_size(width, height, "snapshot")
    checks.whole("count", count, 1, 64)
    t_start = checks.number("snapshot start time", SNAP_START_S if t_start_s is None else t_start_s, 0.0, unit="s")
    checks.number("snapshot interval", interval_s, 1e-9, unit="s")

    flight = Flight(controller, params, backend="mujoco", config=config, force_mode="tip")
    dt = flight.dt
    steps = [int(round((t_start + i * interval_s) / dt)) for i in range(count)]
    if len(set(steps)) < count:
        raise UserError(f"the snapshot interval {interval_s:g} s is shorter than the time step {dt:g} s.")
    states, coms, times = [], [], []
    body = flight.body_id
    for k in steps:
        advance_to(flight, k)
        states.append(flight.data.qpos.copy())
        coms.append(np.array(flight.data.subtree_com[body]))
        times.append(k * dt)
    coms_a = np.array(coms)

    m = dress(flight.model)
    d = mujoco.MjData(m)
    cols = min(count, 4)
    rows = int(math.ceil(count / cols))
    pano_w, pano_h = cols * width, max(height, int(round(cols * width * 0.3)))
    renderer = Offscreen(m, max(width, pano_w), max(height, pano_h), maxgeom=200 + 20 * count)

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
        cam = camera.free(0.5 * (lo + hi), 1.0, 90.0, -3.0, orthographic=True)
        m.vis.global_.fovy = view_h  # for an orthographic camera: the view's height (m)
        renderer.set_size(pano_w, pano_h)
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
        renderer.set_size(width, height)
        close = camera.tracking(body, SNAP_DISTANCE_M, SNAP_AZIMUTH_DEG, SNAP_ELEVATION_DEG)
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
    fig = new_figure(fig_w, fig_h, layout=None)
    fig.set_dpi(dpi)
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
    save(fig, out, dpi=dpi)
    return out
