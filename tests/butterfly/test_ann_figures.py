"""Figures of the evolved controller's experiments (Oe 2010 Fig. 7-9, 11-15), drawn from small
synthetic inputs: no network is evolved or flown here."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import saved
from PIL import Image

from lifelike_mj.butterfly import ann_figures as af
from lifelike_mj.butterfly.ann_experiments import (
    PAPER_WINDS,
    GlideResult,
    LevelResult,
    StartsResult,
    WindMap,
    WindsResult,
    flight_numbers,
)
from lifelike_mj.butterfly.flight import Trajectory

DT = 0.01  # s
DURATION = 4.0  # s


def _traj(y0: float = 0.0, y_end: float = 0.0, speed: float = 3.0, duration: float = DURATION) -> Trajectory:
    """A synthetic flight: altitude relaxing from ``y0`` to ``y_end`` (m) with a 10 Hz ripple,
    forward speed ``speed`` (m/s), pitch switching between 30 and -14 deg with the flap."""
    t = np.arange(0.0, duration + DT / 2, DT)
    y = y_end + (y0 - y_end) * np.exp(-t) + 0.01 * np.sin(2 * np.pi * 10 * t)
    vy = np.gradient(y, t)
    z = speed * t
    theta = np.radians(7.5 + 67.5 * np.cos(2 * np.pi * 10 * t))
    phi = np.where(np.sin(2 * np.pi * 10 * t) > 0, np.radians(30.0), np.radians(-14.0))
    return Trajectory(t, y, z, vy, np.full_like(t, speed), phi, theta, y0=y0)


def _check_png(path: Path, min_width: int = 500) -> None:
    assert path.is_file()
    assert path.stat().st_size > 10_000
    with Image.open(path) as im:
        assert im.format == "PNG"
        assert im.width >= min_width and im.height >= 300
        rgb = np.asarray(im.convert("RGB"))
    assert rgb.std() > 10.0  # not a blank canvas
    packed = (rgb[..., 0].astype(np.int32) << 16) | (rgb[..., 1].astype(np.int32) << 8) | rgb[..., 2]
    assert len(np.unique(packed)) > 20  # lines, text and fills, not a flat image
    assert not list(path.parent.glob(f".{path.stem}.*"))  # the atomic write left no temporary file


def _level() -> LevelResult:
    tr = _traj(0.0, 0.0)
    n_cyc = int(DURATION / 0.1)
    rng = np.random.default_rng(0)
    pmin = list(-14.0 + rng.normal(0.0, 1.0, n_cyc))
    alt = list(0.01 * rng.normal(size=n_cyc))
    return LevelResult(flight_numbers(tr), 6.7, [30.0] * n_cyc, pmin, alt, -0.4, [], tr)


def _history(n: int = 30, pop: int = 40, seed: int = 0) -> list[dict]:
    rng = np.random.default_rng(seed)
    best = np.maximum.accumulate(20000.0 * (1 - np.exp(-np.arange(1, n + 1) / 8)) + rng.normal(0, 300, n))
    return [{"generation": g + 1, "best": float(best[g]), "mean": float(0.3 * best[g] + rng.normal(0, 500)),
             "evaluations": (g + 1) * pop, "elapsed_s": 0.1 * g} for g in range(n)]


def _windmap(inputs: str = "relative") -> WindMap:
    grid = np.arange(-2.0, 2.01, 1.0)
    A, B = np.meshgrid(grid, grid)
    smin = -0.1 - 0.6 * B
    smax = 0.1 - 0.6 * B
    v = 3.0 - A
    smin[0, 0] = -np.inf  # a diverged cell
    smax[0, 0] = np.inf
    v[0, 0] = -np.inf
    v[2, 4] = -0.5  # a backwards cell inside the band
    passed = (smin >= -1) & (smax <= 1) & (v >= 0)
    return WindMap(inputs, grid, grid, passed, smin, smax, v)


def test_fig7_fitness(tmp_path):
    fig = af.fig7_fitness(_history(), tmp_path / "fig7.png", label="synthetic")
    _check_png(saved(fig, tmp_path / "fig7.png"))
    assert af.fig7_fitness(_history()).axes  # without a path: the figure alone, nothing written
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fig7.png"]
    with pytest.raises(ValueError):
        af.fig7_fitness([], tmp_path / "empty.png")


def test_fig8_and_fig9(tmp_path):
    level = _level()
    _check_png(saved(af.fig8_flight(level, tmp_path / "fig8.png"), tmp_path / "fig8.png"))
    _check_png(saved(af.fig9_phi(level, tmp_path / "sub" / "fig9.png"), tmp_path / "sub" / "fig9.png"))  # creates the folder
    bare = LevelResult({}, None, [], [], [], float("nan"))
    with pytest.raises(ValueError):
        af.fig8_flight(bare, tmp_path / "none.png")


def test_fig11_and_fig13(tmp_path):
    above = StartsResult({"+10 m": flight_numbers(_traj(10.0))}, {"+10 m": _traj(10.0)})
    _check_png(saved(af.fig11_from_above(above, tmp_path / "fig11.png"), tmp_path / "fig11.png"))
    trs = {"-10 m": _traj(-10.0, -100.0, speed=0.02), "-2 m": _traj(-2.0), "-1 m": _traj(-1.0, -1.2)}
    below = StartsResult({k: flight_numbers(t) for k, t in trs.items()}, trs)
    _check_png(saved(af.fig13_from_below(below, tmp_path / "fig13.png"), tmp_path / "fig13.png"))


def test_fig12_sink(tmp_path):
    flap = _traj(10.0)
    t = flap.t
    vy = -4.7 * (1 - np.exp(-2 * t))
    glide = Trajectory(t, 10.0 + np.cumsum(vy) * DT, 1.5 * t, vy, np.full_like(t, 1.5), 0 * t, np.full_like(t, np.radians(75)),
                       y0=10.0)
    g = GlideResult(float(-flap.vy.min()), 4.7, 4.7 / float(-flap.vy.min()), flap, glide)
    _check_png(saved(af.fig12_sink(g, tmp_path / "fig12.png"), tmp_path / "fig12.png"))


def test_fig14_15_winds(tmp_path):
    trajs, flights = {}, {}
    for kind, offset in (("relative", 1.5), ("ground", 0.3)):
        trajs[kind] = {w: _traj(0.0, offset * (i - 1.5), speed=3.0 - a) for i, (w, (a, _)) in enumerate(PAPER_WINDS.items())}
        trajs[kind]["behind (-2,0)"] = _traj(0.0, -50.0)  # a crash leaving the plot
        flights[kind] = {w: flight_numbers(t, 1.0) for w, t in trajs[kind].items()}
    out = tmp_path / "fig14_15.png"
    _check_png(saved(af.fig14_15_winds(WindsResult(flights, trajs), out), out), min_width=900)


def test_fig_windmap(tmp_path):
    m = _windmap()
    _check_png(saved(af.fig_windmap(m, tmp_path / "map1.png"), tmp_path / "map1.png"))
    out = tmp_path / "map2.png"
    _check_png(saved(af.fig_windmap([m, _windmap("ground")], out, titles=["paper", "robust"]), out), min_width=900)
    with pytest.raises(ValueError):
        af.fig_windmap([m], tmp_path / "bad.png", titles=["a", "b"])


def test_fig_compare_starts(tmp_path):
    trajs = {"ann_paper": _traj(-10.0, -60.0, speed=0.1), "ann_robust": _traj(-10.0, 0.0)}
    out = tmp_path / "cmp.png"
    _check_png(saved(af.fig_compare_starts(trajs, out, "cf. Oe 2010 Fig. 13 — from -10 m"), out))


def test_fig_optimizer_convergence(tmp_path):
    runs = {"rcga": [_history(30, 40, s) for s in range(3)], "cmaes": [_history(60, 16, s) for s in range(2)]}
    _check_png(saved(af.fig_optimizer_convergence(runs, tmp_path / "conv.png"), tmp_path / "conv.png"))
    _check_png(saved(af.fig_optimizer_convergence(runs, tmp_path / "conv_lin.png", log_x=False), tmp_path / "conv_lin.png"))
    with pytest.raises(ValueError):
        af.fig_optimizer_convergence({"rcga": []}, tmp_path / "none.png")


def test_altitude_window_clips_a_crash():
    lo, hi = af._altitude_window([-10.0, 0.0], [np.linspace(-10, -100, 50), np.linspace(-2, 0, 50)])
    assert -14.0 < lo < -12.0 and 0.0 < hi < 1.0
    lo, hi = af._altitude_window([-1.0, 1.0], [np.array([-0.1, 0.1])], min_pad_m=1.5)
    assert lo < -1.0 and hi > 1.0  # the anchors (a band) always stay in view


def test_map_codes_and_best_on_grid():
    m = _windmap()
    codes = af._map_codes(m)
    assert codes.shape == m.passed.shape
    assert np.array_equal(codes == 0, m.passed)
    assert codes[0, 0] == 4 and codes[2, 4] == 3
    assert (codes[-1] == 1).all() and (codes[0, 1:] == 2).all()  # from above: below the band; from below: above it
    run = [{"evaluations": 40, "best": 1.0}, {"evaluations": 80, "best": 3.0}]
    got = af._best_on_grid(run, np.array([20.0, 40.0, 60.0, 80.0, 100.0]))
    assert np.isnan(got[0]) and np.isnan(got[-1]) and list(got[1:4]) == [1.0, 1.0, 3.0]
