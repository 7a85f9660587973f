"""Offscreen video, frames, figures and viewer guard of the fish tank (Satoi 2015)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import gif_frames, saved
from PIL import Image

from lifelike_mj.errors import UserError
from lifelike_mj.fish import figures as fish_figures
from lifelike_mj.fish import render as fish_video
from lifelike_mj.fish.params import load_preset
from lifelike_mj.fish.sim import Tank, swim
from lifelike_mj.render import viewer
from lifelike_mj.render.video import advance_to


@pytest.fixture(scope="module")
def params():
    return load_preset("B-D")


@pytest.fixture(scope="module")
def short_swim(params):
    return swim(params, n_fish=3, duration_s=5.0, seed=0)


def _fish_pixels(img) -> int:
    """Pixels of the fish's blue (red low, blue high; the water, glass and sky are pale)."""
    a = np.asarray(img, dtype=float)
    return int(((a[..., 0] < 110) & (a[..., 2] > 150)).sum())


def test_render_tiny_gif(tmp_path, params, gl_backend):
    out = tmp_path / "fish.gif"
    # from 2 s: the fish start at rest and wait for their first accelerate MU (Pillow merges identical frames)
    info = fish_video.render_fish(out, params, n_fish=3, duration_s=0.5, seed=0, fps=30, width=160, height=120,
                                  camera="follow", start_s=2.0)
    assert info["path"] == str(out) and info["frames"] == 15 and info["start_s"] == pytest.approx(2.0)
    assert (info["width"], info["height"], info["fps"], info["camera"]) == (160, 120, 30, "follow")
    assert info["seconds"] == pytest.approx(0.5) and info["render_fps"] > 0
    frames = gif_frames(out)
    assert len(frames) == 15 and frames[0].shape == (120, 160, 3)
    assert all(f.std() > 3.0 for f in frames)  # water, glass, floor: not a blank image
    assert all(_fish_pixels(f) > 5 for f in frames)  # the followed fish is in view, blue
    assert max(np.abs(frames[i + 1] - frames[i]).max() for i in range(14)) > 30.0  # it moves
    assert not list(tmp_path.glob(".fish.*"))  # the temporary file was renamed


def test_side_frame_shows_fish(params, gl_backend):
    img = fish_video.render_frame(params, t_s=0.5, n_fish=3, seed=0, camera="side", width=320, height=240)
    assert img.shape == (240, 320, 3) and img.dtype == np.uint8
    assert _fish_pixels(img) >= 3


def test_frame_steps_for_rates_that_do_not_divide_the_control_rate():
    assert fish_video.frame_steps(4, 30.0, 60.0).tolist() == [0, 2, 4, 6]
    assert fish_video.frame_steps(6, 24.0, 60.0).tolist() == [0, 3, 5, 8, 10, 13]  # 2.5 steps per frame
    assert fish_video.frame_steps(3, 60.0, 60.0).tolist() == [0, 1, 2]


def test_render_rejects_bad_requests(tmp_path, params):
    with pytest.raises(UserError, match="camera"):
        fish_video.render_fish(tmp_path / "f.gif", params, camera="top")
    with pytest.raises(UserError, match="camera"):
        fish_video.render_frame(params, camera="nope")
    with pytest.raises(UserError, match="width"):
        fish_video.render_fish(tmp_path / "f.gif", params, width=4)
    with pytest.raises(UserError, match="height"):
        fish_video.render_fish(tmp_path / "f.gif", params, height=5000)
    with pytest.raises(UserError, match="even"):
        fish_video.render_fish(tmp_path / "f.mp4", params, width=161, height=120)
    with pytest.raises(UserError, match=r"\.mp4 or \.gif"):
        fish_video.render_fish(tmp_path / "f.avi", params)
    with pytest.raises(UserError, match="control"):
        fish_video.render_fish(tmp_path / "f.gif", params, fps=120)
    with pytest.raises(UserError, match="fps"):
        fish_video.render_fish(tmp_path / "f.gif", params, fps=0)
    with pytest.raises(UserError, match="start time"):
        fish_video.render_fish(tmp_path / "f.gif", params, start_s=-1.0)
    with pytest.raises(UserError, match="width"):
        fish_video.render_frame(params, width=0)
    with pytest.raises(UserError, match="width"):
        fish_video.frame_png(tmp_path / "s.png", params, width=3)
    with pytest.raises(UserError, match="camera"):
        fish_video.render_benchmark(n_frames=1, camera="nope")
    assert not list(tmp_path.iterdir())


def test_follow_fish_out_of_range(tmp_path, params):
    with pytest.raises(UserError, match="fish to follow"):
        fish_video.render_frame(params, n_fish=2, camera="follow", follow_fish=2, width=16, height=16)


def test_tank_snapshot_png(tmp_path, params, gl_backend):
    out = tmp_path / "snap.png"
    assert fish_video.frame_png(out, params, n_fish=3, t_s=0.2, camera="oblique", width=96, height=72) == out
    with Image.open(out) as im:
        assert im.format == "PNG" and im.size == (96, 72)
        assert np.asarray(im.convert("L"), dtype=float).std() > 3.0


def test_render_benchmark_reports_fps(gl_backend):
    info = fish_video.render_benchmark(n_frames=3, width=64, height=48, n_fish=2, repeats=2)
    assert info["fps"] > 0 and len(info["fps_runs"]) == 2
    assert (info["width"], info["height"], info["n_fish"]) == (64, 48, 2)


def _png(path):
    with Image.open(path) as im:
        assert im.format == "PNG"
        a = np.asarray(im.convert("L"), dtype=float)
    assert a.shape[0] > 200 and a.shape[1] > 200 and a.std() > 5.0


def test_tracks_and_histogram_figures(tmp_path, short_swim):
    tracks = fish_figures.tracks_figure(short_swim, tmp_path / "tracks.png", fish=1)
    hist = fish_figures.accel_histogram_figure(short_swim, tmp_path / "hist.png")
    _png(saved(tracks, tmp_path / "tracks.png"))
    _png(saved(hist, tmp_path / "hist.png"))
    with pytest.raises(UserError, match="fish"):
        fish_figures.tracks_figure(short_swim, tmp_path / "bad.png", fish=3)
    with pytest.raises(UserError, match=r"\.png"):
        fish_figures.accel_histogram_figure(short_swim, tmp_path / "hist.pdf")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["hist.png", "tracks.png"]


def test_side_accelerations_are_in_body_lengths(short_swim):
    a = fish_figures.side_accelerations_bl(short_swim, body_length_m=0.07)
    b = fish_figures.side_accelerations_bl(short_swim, body_length_m=0.14)
    assert a.shape == (5 * 24 - 1, 3)  # 121 frames at 24 fps over 5 s, two differences
    np.testing.assert_allclose(a, 2.0 * b)


def test_patterns_figure(tmp_path):
    rng = np.random.default_rng(0)
    rows = [{"preset": p, "seed": s, "burstiness": rng.uniform(-0.2, 0.5), "accel_kurtosis": rng.uniform(0, 8),
             "turn_entropy": rng.uniform(0, 3), "other": "ignored"}
            for p in ("B-D", "NB-ND", "B-ND", "NB-D") for s in range(3)]
    rows[0]["turn_entropy"] = float("nan")
    _png(saved(fish_figures.patterns_figure(rows, tmp_path / "patterns.png"), tmp_path / "patterns.png"))
    with pytest.raises(UserError, match="turn_entropy"):
        fish_figures.patterns_figure([{"preset": "B-D", "burstiness": 0.1, "accel_kurtosis": 1.0}], tmp_path / "x.png")
    with pytest.raises(UserError, match="at least one row"):
        fish_figures.patterns_figure([], tmp_path / "x.png")


def test_view_fish_without_display_raises_user_error(monkeypatch, params):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.sys, "platform", "linux")
    with pytest.raises(UserError, match="no display"):
        fish_video.view_fish(params, n_fish=2, duration_s=0.1)


def test_view_fish_loop_with_a_stand_in_viewer(monkeypatch, params, stand_in_viewer):
    """The viewer loop (camera set-up, real-time stepping, stop at ``duration_s``) on a fake window."""

    import mujoco
    import mujoco.viewer

    monkeypatch.setattr(viewer, "has_display", lambda: True)
    fish_video.view_fish(params, n_fish=2, seed=0, duration_s=0.1, camera="follow")
    (v,) = stand_in_viewer
    assert v.syncs >= 1 and v.cam.type == mujoco.mjtCamera.mjCAMERA_TRACKING and v.cam.azimuth == 90.0
    fish_video.view_fish(params, n_fish=2, seed=0, duration_s=0.05)
    assert stand_in_viewer[-1].cam.type == mujoco.mjtCamera.mjCAMERA_FREE and stand_in_viewer[-1].cam.distance > 5.0
    with pytest.raises(UserError, match="viewer camera"):
        fish_video.view_fish(params, camera="oblique")


def test_the_aquariums_keys_in_the_window(monkeypatch, params, stand_in_viewer, capsys):
    """Enter and Space pressed in the (stand-in) window reach the tank between two steps; the pellet is drawn."""
    monkeypatch.setattr(viewer, "has_display", lambda: True)
    codes = viewer.KEY_CODES
    monkeypatch.setattr(stand_in_viewer.viewer_class, "presses", {3: codes["Enter"], 4: codes["Space"], 5: ord("Q")})
    fish_video.view_fish(params, n_fish=3, seed=0, duration_s=0.3)
    (v,) = stand_in_viewer
    out = capsys.readouterr().out
    assert out.startswith("keys: Space tap the front glass; Enter drop a food pellet")
    assert "drop a food pellet\ntap the front glass" in out  # Q is no key of the scene: nothing happens
    assert v.user_scn.ngeom == 1 and v.user_scn.geoms[0].size[0] > 0  # the pellet, drawn


def test_chunked_stepping_is_the_swim(params):
    """Advancing by frames (control steps 0, 3, 5, 8) reaches the state ``swim`` records."""
    ref = swim(params, n_fish=3, duration_s=8 / 60, seed=4)
    sw = Tank(params, 3, 4)
    for k in fish_video.frame_steps(4, 24.0, 60.0):
        advance_to(sw, int(k))
    pos, _quat = sw.snapshot()
    np.testing.assert_array_equal(pos, ref.positions[8])
