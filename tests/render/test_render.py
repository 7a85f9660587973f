"""The generic rendering package: the one recorder films live steppers and recorded runs of every
creature; plot helpers; the viewer loop."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import gif_frames

from lifelike_mj import boids, butterfly, fish
from lifelike_mj.errors import UserError
from lifelike_mj.render import plot
from lifelike_mj.stepper import Playback


def test_film_a_recorded_flight_equals_filming_it_live(tmp_path, gl_backend):
    tr = butterfly.Flight("simple_rule").record(duration_s=0.2)
    pb = butterfly.playback(tr)
    a = butterfly.film_flight(tmp_path / "rec.gif", pb, duration_s=0.2, fps=30, width=64, height=48)
    b = butterfly.film_flight(tmp_path / "live.gif", butterfly.Flight("simple_rule"), duration_s=0.2, fps=30,
                              width=64, height=48)
    assert a["frames"] == b["frames"] == 6
    fa, fb = gif_frames(tmp_path / "rec.gif"), gif_frames(tmp_path / "live.gif")
    assert all(np.array_equal(x, y) for x, y in zip(fa, fb))  # the paper backend is drawn by the same posed model
    assert max(np.abs(fa[i + 1] - fa[i]).max() for i in range(5)) > 30  # the wings move


def test_film_a_recorded_swim_and_flock(tmp_path, gl_backend):
    swim = fish.Tank(fish.load_preset("B-D"), 3, seed=0, size=(1.0, 0.3, 0.5)).record(duration_s=0.5)
    info = fish.film_tank(tmp_path / "swim.gif", fish.playback(swim), duration_s=0.5, fps=30, width=64, height=48)
    assert info["frames"] == 15 and len(gif_frames(tmp_path / "swim.gif")) >= 2  # GIF merges repeated frames
    run = boids.simulate(boids.load_preset("4c"), n=40, n_steps=30, seed=0)
    pb = boids.playback(run)
    info = boids.film_flock(tmp_path / "flock.gif", pb, n_frames=7, steps_per_frame=5, width=64, height=48)
    frames = gif_frames(tmp_path / "flock.gif")
    assert info["frames"] == 7 and not np.array_equal(frames[0], frames[-1])


def test_render_frame_of_a_run_you_have(gl_backend):
    run = boids.simulate(boids.load_preset("4c"), n=40, n_steps=30, seed=0)
    pb = boids.playback(run)
    pb.step(30)
    last = boids.render_frame(pb, width=64, height=48)
    live = boids.Flock(boids.load_preset("4c"), 40, 0)
    live.step(30)
    np.testing.assert_array_equal(last, boids.render_frame(live, width=64, height=48))


def test_playback_holds_its_last_frame():
    shown = []
    pb = Playback(None, None, 3, shown.append, 0.5)
    pb.step(10)
    pb.sync()
    assert shown == [2] and pb.time == 5.0
    with pytest.raises(ValueError):
        Playback(None, None, 0, shown.append, 0.5)


def test_plot_finish_saves_only_when_asked(tmp_path):
    fig = plot.new_figure(3, 2)
    fig.subplots().plot([0, 1], [1, 0])
    assert plot.finish(fig, None) is fig and not list(tmp_path.iterdir())
    plot.finish(fig, tmp_path / "a.png")
    assert (tmp_path / "a.png").stat().st_size > 1000
    with pytest.raises(UserError, match=r"\.png"):
        plot.finish(fig, tmp_path / "a.jpg")


def test_view_drives_any_stepper(stand_in_viewer):
    from lifelike_mj.render.viewer import view

    flock = boids.Flock(boids.load_preset("4c"), 20, 0)
    view(flock, steps_per_s=5000.0, end_step=30)
    assert flock.steps == 30 and stand_in_viewer[-1].syncs >= 1
