"""The boids' mocap scene, offscreen video, paper-style figures and viewer guard (Nakamura 2013)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from conftest import gif_frames, saved
from PIL import Image

from lifelike_mj.boids import figures as boids_figures
from lifelike_mj.boids import render as boids_video
from lifelike_mj.boids import scene
from lifelike_mj.boids.engine import BoidParams, BoidRun
from lifelike_mj.boids.presets import PATTERNS, homogeneous, load_preset
from lifelike_mj.boids.sim import Flock, simulate
from lifelike_mj.errors import UserError
from lifelike_mj.render.video import advance_to


def _x_axes(model, data, layout) -> np.ndarray:
    """The bodies' x axes in the world frame (n, 3): the first column of ``xmat``."""
    return data.xmat[layout.body].reshape(-1, 3, 3)[:, :, 0]


def test_scene_has_one_mocap_body_per_agent_and_no_collisions():
    types = np.arange(50) % 2
    m, layout = scene.build_scene(50, types)
    assert m.nmocap == 50 and layout.n == 50 and m.nbody == 51
    assert np.array_equal(m.body_mocapid[layout.body], np.arange(50))
    assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)
    assert m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    geoms = [m.body_geomadr[b] for b in layout.body]
    assert np.all(m.geom_type[geoms] == mujoco.mjtGeom.mjGEOM_ELLIPSOID)
    np.testing.assert_allclose(m.geom_size[geoms[0]], scene.BODY_SEMI_AXES)
    rgba = m.mat_rgba[m.geom_matid[geoms]]
    np.testing.assert_allclose(rgba[0], scene.type_rgba(0), atol=1e-6)  # A blue (colour-blind palette)
    np.testing.assert_allclose(rgba[1], scene.type_rgba(1), atol=1e-6)  # B orange
    assert [m.camera(i).name for i in range(m.ncam)] == list(scene.CAMERAS)
    assert m.narena == scene.scene_memory_bytes(50)
    m2, layout2 = scene.build_scene(10, dims=2)
    assert [m2.camera(i).name for i in range(m2.ncam)] == ["overview", "top"] and layout2.dims == 2
    assert scene.scene_memory_bytes(3000) > 2 * 3000**2  # room for the broadphase of 3,000 bodies
    with pytest.raises(UserError, match="types"):
        scene.build_scene(3, [0, 1])


def test_update_points_each_body_along_its_velocity():
    m, layout = scene.build_scene(4, [0, 1, 0, 1])
    d = mujoco.MjData(m)
    x = np.array([[1.0, 2.0, 3.0], [5.0, 5.0, 5.0], [10.0, 10.0, 10.0], [19.0, 1.0, 7.0]])
    v = np.array([[1.0, 2.0, -2.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 0.3], [-0.2, -1e-3, 0.1]])
    scene.update(m, d, layout, x, v)
    np.testing.assert_allclose(d.xpos[layout.body], x, atol=1e-12)
    np.testing.assert_allclose(_x_axes(m, d, layout), v / np.linalg.norm(v, axis=1, keepdims=True), atol=1e-12)
    y_axes = d.xmat[layout.body].reshape(-1, 3, 3)[:, :, 1]
    np.testing.assert_allclose(y_axes[:, 2], 0.0, atol=1e-12)  # no roll: the body's y axis stays horizontal
    before = d.xmat[layout.body].copy()
    v2 = v.copy()
    v2[0] = 0.0  # at rest: keeps its orientation
    scene.update(m, d, layout, x + 1.0, v2)
    np.testing.assert_allclose(d.xmat[layout.body[0]], before[0], atol=1e-12)
    np.testing.assert_allclose(d.xpos[layout.body[0]], x[0] + 1.0)


def test_update_in_2d_puts_agents_on_the_plane():
    m, layout = scene.build_scene(3, dims=2)
    d = mujoco.MjData(m)
    x = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    v = np.array([[0.0, 1.0], [-1.0, -1.0], [2.0, 0.0]])
    scene.update(m, d, layout, x, v)
    np.testing.assert_allclose(d.xpos[layout.body][:, :2], x)
    np.testing.assert_allclose(d.xpos[layout.body][:, 2], scene.PLANE_Z_2D)
    u = np.column_stack([v, np.zeros(3)])
    np.testing.assert_allclose(_x_axes(m, d, layout), u / np.linalg.norm(u, axis=1, keepdims=True), atol=1e-12)
    with pytest.raises(ValueError):
        scene.update(m, d, layout, np.zeros((3, 3)), np.zeros((3, 3)))


def test_velocity_quat_is_a_unit_quaternion_in_every_direction():
    rng = np.random.default_rng(3)
    v = np.concatenate([rng.normal(size=(200, 3)), [[-1, 0, 0], [-1, 1e-14, 0], [-1, -1e-14, 0], [0, 0, 1],
                                                     [0, 0, -2], [0, -1, 0], [-3, 0, 1e-12]]])
    q = scene.velocity_quat(v)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-14)
    mats = np.empty((len(q), 9))
    for i in range(len(q)):
        mujoco.mju_quat2Mat(mats[i], q[i])
    np.testing.assert_allclose(mats.reshape(-1, 3, 3)[:, :, 0], v / np.linalg.norm(v, axis=1, keepdims=True), atol=1e-12)


def _colour_pixels(img) -> tuple[int, int]:
    """Pixels of the blue (A) and the orange (B) agents (the colour-blind palette)."""
    a = np.asarray(img, dtype=float)
    r, g, b = a[..., 0], a[..., 1], a[..., 2]
    blue = (b > 90) & (b > r + 60) & (b > g + 25)
    orange = (r > 120) & (r > b + 90) & (g > b + 50) & (r > g + 20)
    return int(blue.sum()), int(orange.sum())


def test_render_tiny_gif(tmp_path, gl_backend):
    out = tmp_path / "boids.gif"
    params = load_preset("5a")
    info = boids_video.render_boids(out, params, n=60, n_steps=90, seed=1, fps=15, steps_per_frame=10, width=160,
                                    height=120, warmup_steps=100)
    assert info["path"] == str(out) and info["frames"] == 10 and info["n"] == 60
    assert (info["first_step"], info["last_step"], info["steps_per_frame"]) == (100, 190, 10)
    assert (info["width"], info["height"], info["camera"], info["preset"]) == (160, 120, "overview", "5a")
    assert info["render_fps"] > 0 and info["seconds"] == pytest.approx(10 / 15)
    frames = gif_frames(out)
    assert len(frames) == 10 and frames[0].shape == (120, 160, 3)
    assert all(min(_colour_pixels(f)) > 10 for f in frames)  # red A and yellow-green B agents in every frame
    assert max(np.abs(frames[i + 1] - frames[i]).max() for i in range(9)) > 30.0  # they move
    assert not list(tmp_path.glob(".boids.*"))  # the temporary file was renamed


def test_top_frame_of_a_2d_run(gl_backend):
    params = BoidParams(dims=2)
    img = boids_video.render_frame(params, step=50, n=40, seed=0, camera="top", width=120, height=90)
    assert img.shape == (90, 120, 3) and img.dtype == np.uint8
    assert min(_colour_pixels(img)) > 5


def test_streamed_run_is_the_simulated_run():
    params = load_preset("4c")
    run = Flock(params, 30, 2)
    advance_to(run, 3)
    advance_to(run, 7)
    ref = simulate(params, n=30, n_steps=7, seed=2, record_from=7)
    np.testing.assert_array_equal(run.state()["position_box"], ref.positions[-1])
    np.testing.assert_array_equal(run.types, ref.types)
    np.testing.assert_allclose(run.data.xpos[run.layout.body], ref.positions[-1], atol=1e-12)


def test_render_rejects_bad_requests(tmp_path):
    params = load_preset("4a")
    with pytest.raises(UserError, match="camera"):
        boids_video.render_boids(tmp_path / "b.gif", params, camera="follow")
    with pytest.raises(UserError, match="2D"):
        boids_video.render_boids(tmp_path / "b.gif", BoidParams(dims=2), camera="side")
    with pytest.raises(UserError, match="camera"):
        boids_video.render_frame(params, camera="nope")
    with pytest.raises(UserError, match="width"):
        boids_video.render_boids(tmp_path / "b.gif", params, width=4)
    with pytest.raises(UserError, match="height"):
        boids_video.render_boids(tmp_path / "b.gif", params, height=5000)
    with pytest.raises(UserError, match="even"):
        boids_video.render_boids(tmp_path / "b.mp4", params, width=161, height=120)
    with pytest.raises(UserError, match=r"\.mp4 or \.gif"):
        boids_video.render_boids(tmp_path / "b.avi", params)
    with pytest.raises(UserError, match="steps per frame"):
        boids_video.render_boids(tmp_path / "b.gif", params, steps_per_frame=0)
    with pytest.raises(UserError, match="fps"):
        boids_video.render_boids(tmp_path / "b.gif", params, fps=0)
    with pytest.raises(UserError, match="warm-up"):
        boids_video.render_boids(tmp_path / "b.gif", params, warmup_steps=-1)
    with pytest.raises(UserError, match="agents"):
        boids_video.render_boids(tmp_path / "b.gif", params, n=1)
    with pytest.raises(UserError, match=r"\.png"):
        boids_video.frame_png(tmp_path / "b.jpg", params)
    assert not list(tmp_path.iterdir())


def test_diverging_run_leaves_no_file(tmp_path, gl_backend):
    params = BoidParams(wa=((50.0,),), wc=((5.0,),))
    with pytest.raises(UserError, match="diverged"):
        boids_video.render_boids(tmp_path / "b.gif", params, n=40, n_steps=400, width=32, height=24)
    assert not list(tmp_path.iterdir())


# ---- figures ----------------------------------------------------------------------------------


def _fake_run(params: BoidParams, n: int = 40, seed: int = 0, steps=range(95, 101)) -> BoidRun:
    """A run's last records without running the engine: a random cloud drifting along +x."""
    rng = np.random.default_rng(seed)
    steps = np.asarray(list(steps))
    x0 = rng.uniform(4, 16, size=(n, params.dims))
    v = np.zeros((n, params.dims))
    v[:, 0] = 0.3
    pos = np.stack([x0 + (s - steps[0]) * v for s in steps])
    types = (np.arange(n) % params.n_types).astype(np.int64)
    return BoidRun(params, seed, types, steps, pos, np.broadcast_to(v, pos.shape).copy())


def _png(path, min_side=200):
    with Image.open(path) as im:
        assert im.format == "PNG"
        a = np.asarray(im.convert("RGB"), dtype=float)
    assert min(a.shape[:2]) > min_side and a.std() > 5.0
    return a


def test_trails_are_the_last_five_steps_projected():
    run = _fake_run(load_preset("4c"), n=5)
    seg, depth = boids_figures.trails(run)
    assert seg.shape == (5, 6, 2)
    np.testing.assert_allclose(seg[:, :, 0], run.positions[:, :, 0].T)
    np.testing.assert_allclose(depth, run.positions[-1, :, 2])
    seg, depth = boids_figures.trails(run, plane="xz")
    np.testing.assert_allclose(seg[:, -1, 1], run.positions[-1, :, 2])
    np.testing.assert_allclose(depth, -run.positions[-1, :, 1])  # seen from -y: small y is near
    with pytest.raises(UserError, match="record_every=1"):
        boids_figures.trails(_fake_run(load_preset("4c"), steps=range(0, 60, 10)))
    with pytest.raises(UserError, match="plane"):
        boids_figures.trails(run, plane="zz")
    with pytest.raises(UserError, match="2D"):
        boids_figures.trails(_fake_run(BoidParams(dims=2)), plane="xz")


def test_pattern_figures_write_pngs(tmp_path):
    runs = {p: _fake_run(load_preset(p), seed=i) for i, p in enumerate(PATTERNS)}
    a = _png(saved(boids_figures.pattern_figure(runs["4c"], tmp_path / "one.png"), tmp_path / "one.png"))
    assert _colour_pixels(a)[0] > 20 and _colour_pixels(a)[1] > 20  # A red, B yellow-green trails
    _png(saved(boids_figures.patterns_grid_figure(runs, tmp_path / "grid.png"), tmp_path / "grid.png"))
    flat = tmp_path / "flat.png"
    _png(saved(boids_figures.pattern_figure(_fake_run(BoidParams(dims=2)), flat, title="2D"), flat))
    hom = {(a, c): _fake_run(homogeneous(a, c), seed=k) for k, (a, c) in
           enumerate((a, c) for a in (1.0, 0.1, 0.01, 0.001) for c in (0.1, 0.01, 0.001, 0.0))}
    hom[(1.0, 0.1)] = None  # diverged
    img = _png(saved(boids_figures.homogeneous_grid_figure(hom, tmp_path / "fig2.png"), tmp_path / "fig2.png"))
    assert _colour_pixels(img)[1] == 0  # one type: no yellow-green
    labels = np.array([["4a", "5a", "diverged"], ["5a", None, "unclassified"]], dtype=object)
    _png(saved(boids_figures.phase_diagram_figure(labels, [0.1, 0.01, 0.0], [0.5, -0.2], "w_c AB", "w_a AB",
                                            tmp_path / "phase.png"), tmp_path / "phase.png"), min_side=150)
    with pytest.raises(UserError, match="grid"):
        boids_figures.phase_diagram_figure(labels, [0.1, 0.01], [0.5, -0.2], "x", "y", tmp_path / "bad.png")
    with pytest.raises(UserError, match=r"\.png"):
        boids_figures.pattern_figure(runs["4a"], tmp_path / "one.pdf")
    with pytest.raises(UserError, match="at least one"):
        boids_figures.patterns_grid_figure({}, tmp_path / "bad.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig2.png", "flat.png", "grid.png", "one.png", "phase.png"]


# ---- viewer -----------------------------------------------------------------------------------


def test_view_boids_without_display_raises_user_error(monkeypatch):
    from lifelike_mj.render import viewer

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.sys, "platform", "linux")
    with pytest.raises(UserError, match="no display"):
        boids_video.view_boids(load_preset("4a"), n=20, duration_steps=5)


def test_view_boids_loop_with_a_stand_in_viewer(monkeypatch, stand_in_viewer):
    """The viewer loop (camera set-up, stepping by the clock, stop after ``duration_steps``) on a fake window."""
    import mujoco.viewer

    from lifelike_mj.render import viewer

    monkeypatch.setattr(viewer, "has_display", lambda: True)
    boids_video.view_boids(load_preset("4a"), n=20, seed=0, steps_per_s=2000.0, duration_steps=20, warmup_steps=10)
    (v,) = stand_in_viewer
    assert v.syncs >= 1 and v.cam.type == mujoco.mjtCamera.mjCAMERA_FREE and v.cam.distance > 20.0
    assert v.cam.elevation < -10.0  # from above
    boids_video.view_boids(BoidParams(dims=2), n=20, steps_per_s=2000.0, duration_steps=5, camera="top")
    assert stand_in_viewer[-1].cam.elevation == -90.0
    with pytest.raises(UserError, match="viewer camera"):
        boids_video.view_boids(load_preset("4a"), camera="side")
