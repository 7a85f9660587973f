"""Offscreen video, snapshot figure and viewer guard of the MuJoCo butterfly."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import gif_frames
from PIL import Image

from lifelike_mj.butterfly import batch, controllers
from lifelike_mj.butterfly import render as video
from lifelike_mj.butterfly.backends import mj as mjbackend
from lifelike_mj.butterfly.sim import Flight
from lifelike_mj.errors import UserError
from lifelike_mj.render import viewer
from lifelike_mj.render.video import advance_to


@pytest.fixture(scope="module")
def rule():
    return controllers.load("simple_rule")


def test_render_short_gif(tmp_path, rule, gl_backend):
    out = tmp_path / "fly.gif"
    info = video.render_butterfly(out, rule, duration_s=0.3, fps=30, width=64, height=48)
    assert info["frames"] == 9 and info["path"] == str(out)
    assert (info["width"], info["height"], info["fps"]) == (64, 48, 30)
    assert info["gl_backend"] in ("egl", "osmesa", "glfw", "cgl", "wgl", gl_backend)
    frames = gif_frames(out)
    assert len(frames) == 9 and frames[0].shape == (48, 64, 3)
    assert all(f.std() > 5.0 for f in frames)  # sky, ground and butterfly, not a blank image
    # the wings move between frames (10 Hz beat, 3 frames per cycle) while the camera follows the body
    assert max(np.abs(frames[i + 1] - frames[i]).max() for i in range(8)) > 50.0
    assert not list(tmp_path.glob(".fly.*"))  # the temporary file was renamed


def test_render_rejects_bad_requests(tmp_path, rule):
    with pytest.raises(UserError, match=r"\.mp4 or \.gif"):
        video.render_butterfly(tmp_path / "fly.avi", rule)
    with pytest.raises(UserError, match="even"):
        video.render_butterfly(tmp_path / "fly.mp4", rule, width=65, height=48)
    with pytest.raises(UserError, match="camera"):
        video.render_butterfly(tmp_path / "fly.gif", rule, duration_s=0.05, width=32, height=24, camera="nope")
    assert not list(tmp_path.iterdir())


def test_chunked_stepping_equals_fly_one(rule):
    """The flight stepped between frames (uneven chunks, drawing refreshes) is the recorded one, bit for bit."""
    for config, mode in (("paper", "tip"), ("rich", "strip")):
        m = mjbackend.build_model(None, config)
        m.opt.timestep = 1.0 / 1200.0
        ref = batch.fly_one(m, rule, duration_s=0.5, force_mode=mode)
        flight = Flight(rule, backend="mujoco", config=config, force_mode=mode)
        for k in (1, 37, 40, 41, 400, 600):  # uneven chunks, drawing-refresh between them
            advance_to(flight, k)
        lay = mjbackend.layout(flight.model)
        q, v = flight.data.qpos, flight.data.qvel
        got = (q[lay.q_height], q[lay.q_forward], v[lay.d_height], v[lay.d_forward], q[lay.q_flap_left])
        want = (ref.y[-1], ref.z[-1], ref.vy[-1], ref.vz[-1], ref.theta[-1])
        assert got == want, config


def test_snapshot_figure_writes_png(tmp_path, rule, gl_backend):
    out = tmp_path / "snap.png"
    path = video.snapshot_figure(out, rule, t_start_s=0.5, count=3, width=64, height=48)
    assert path == out and out.stat().st_size > 1000
    with Image.open(out) as im:
        assert im.format == "PNG"
        assert np.asarray(im.convert("L"), dtype=float).std() > 5.0


def test_viewer_without_display_raises_user_error(monkeypatch, rule):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(viewer.sys, "platform", "linux")
    assert viewer.has_display() is False
    with pytest.raises(UserError, match="no display"):
        video.view_butterfly(rule, duration_s=0.1)


def test_has_display_reads_environment(monkeypatch):
    monkeypatch.setattr(viewer.sys, "platform", "linux")
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setenv("DISPLAY", ":0")
    assert viewer.has_display() is True
