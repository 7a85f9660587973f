"""Experiments E4-E5 of Oe 2010 section 5 (lifelike_mj/butterfly/experiments.py), their figures and
the report (lifelike_mj/butterfly/figures.py, lifelike_mj/butterfly/report.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import saved

from lifelike_mj.butterfly import controllers, experiments, figures, report
from lifelike_mj.butterfly.backends import paper
from lifelike_mj.errors import UserError

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def trim():
    # the paper's settings: RK4, dt = 1/12000 s, 20 s, from rest, flap [-90, 90] deg at 10 Hz
    return experiments.e4_trim()


@pytest.fixture(scope="module")
def timestep():
    return experiments.e5_timestep()


def test_e4_level_angle_and_flight_numbers_match_the_paper(trim):
    assert trim.backend == "paper" and trim.dt_s == 1.0 / 12000.0 and trim.duration_s == 20.0
    # Paper: 12.77 deg, 340 cm/s, ripple 5.3 cm, drop about 3 m. Ours, computed here: 12.769 deg (the
    # search's tolerance is 1e-3 deg, so 12.77 +- 0.005 is the paper's number as printed), 339.4 cm/s,
    # 5.34 cm; the drop is 1.84 m (docs/results.md: the paper's "about 3 m" is read off Fig. 4).
    assert trim.phi_up_level_deg == pytest.approx(12.77, abs=0.005)
    assert trim.mean_forward_speed_cm_s == pytest.approx(340.0, abs=1.0)
    assert trim.ripple_cm == pytest.approx(5.3, abs=0.1)
    assert trim.initial_drop_m == pytest.approx(1.84, abs=0.01)
    # the numbers are those of the level trajectory itself
    s = trim.level.summary()
    assert trim.ripple_cm == s["ripple_cm"] and trim.mean_forward_speed_cm_s == s["settled_forward_speed_cm_s"]
    assert trim.initial_drop_m == pytest.approx(-float(np.min(trim.level.y)), abs=1e-12)
    assert len(trim.level.t) == 240_001  # recorded at every step


def test_e4_root_is_level_to_the_tolerance(trim):
    # the climb rate changes by (above - below) per degree; at tol = 1e-3 deg the residual climb rate
    # must be below that slope times the tolerance
    slope = (trim.above["settled_climb_rate_cm_s"] - trim.below["settled_climb_rate_cm_s"]) / 1.0
    assert slope > 0
    assert abs(trim.settled_climb_rate_cm_s) <= slope * 1e-3
    lo, hi = trim.bracket_deg
    assert hi - lo < 1e-3 and lo <= trim.phi_up_level_deg <= hi
    # the search flights bracket the root: negative just below, positive just above
    below = [r for a, r in trim.search if a <= lo]
    above = [r for a, r in trim.search if a >= hi]
    assert below and above and max(below) <= 0.0 <= min(above)


def test_e4_below_descends_above_climbs(trim):
    assert trim.below["phi_up_deg"] == pytest.approx(trim.phi_up_level_deg - 0.5)
    assert trim.above["phi_up_deg"] == pytest.approx(trim.phi_up_level_deg + 0.5)
    assert trim.below["settled_climb_rate_cm_s"] < 0 and trim.below["final_altitude_m"] < 0
    assert trim.above["settled_climb_rate_cm_s"] > 0 and trim.above["final_altitude_m"] > 0
    assert trim.below["final_altitude_m"] < trim.final_altitude_m < trim.above["final_altitude_m"]


def test_e4_to_dict_is_json_with_the_papers_numbers(trim):
    d = json.loads(json.dumps(trim.to_dict(), allow_nan=False))
    for key in ("phi_up_level_deg", "mean_forward_speed_cm_s", "ripple_cm", "initial_drop_m", "final_altitude_m",
                "settled_climb_rate_cm_s", "backend", "dt_s", "body_area_cm2", "below", "above", "paper"):
        assert key in d
    assert d["paper"] == {"phi_up_level_deg": 12.77, "mean_forward_speed_cm_s": 340.0, "ripple_cm": 5.3,
                          "initial_drop_m": 3.0}
    assert d["n_flights"] == len(d["search"]) + 3


def test_e4_no_sign_change_is_a_user_error():
    with pytest.raises(UserError, match="no level-flight angle"):
        experiments.e4_trim(dt_s=1.0 / 1200.0, duration_s=12.0, lo_deg=20.0, hi_deg=25.0)


@pytest.mark.parametrize("batch", [16, 1])
def test_level_angle_search_grid_and_regula_falsi(batch):
    # the search alone on a cheap monotone stand-in for the climb rate (root at 12.3456789 deg)
    root = 12.3456789
    calls = []

    def rates(angles):
        calls.append(len(angles))
        return [math.tanh(a - root) + 0.2 * (a - root) ** 3 for a in angles]

    level, (lo, hi), flown = experiments._find_level_angle(rates, 10.0, 16.0, 1e-6, batch)
    assert abs(level - root) < 1e-6 and lo <= root <= hi
    assert all(n == (batch if batch > 2 else 1) for n in calls[1:])
    assert len(flown) == sum(calls)
    if batch == 1:
        assert calls[0] == 5 and len(calls) < 40


def test_e5_time_steps(timestep):
    keys = ["1/12000", "1/1200", "1/360", "1/120"]
    assert list(timestep.altitude_20s_m) == keys and list(timestep.rel_error) == keys
    alt = timestep.altitude_20s_m
    assert all(math.isfinite(alt[k]) for k in keys)
    assert all(v == -1 for v in timestep.diverged_step.values())
    # phi_up = 14 deg: descends, then climbs. Paper: 15-16 m at 20 s; ours 19.18 m (docs/results.md: the
    # paper's curve is read off Fig. 5 and its constants at phi_up = 14 deg are not all given).
    assert alt["1/12000"] == pytest.approx(19.176, abs=0.001)
    # the error ladder the code achieves: 1.07e-5 at 1/1200, 7.0e-4 at 1/360, 0.106 at 1/120 (RK4's fourth order
    # shows between 1/1200 and 1/360 as a factor 66 for a factor 3.3 in dt; the paper reports about x10 per x3)
    assert timestep.rel_error["1/1200"] == pytest.approx(1.07e-5, rel=0.02)
    assert timestep.rel_error["1/360"] == pytest.approx(7.01e-4, rel=0.02)
    assert timestep.rel_error["1/120"] == pytest.approx(0.106, rel=0.02)
    err = timestep.rel_error
    assert err["1/12000"] == 0.0
    assert 0.0 < err["1/1200"] < err["1/360"] < err["1/120"]
    for k in keys:
        assert err[k] == abs(alt[k] - alt["1/12000"]) / abs(alt["1/12000"])
    assert timestep.error_ratio_per_3x_dt == err["1/360"] / err["1/1200"]
    json.dumps(timestep.to_dict(), allow_nan=False)


def test_e5_samples_fall_on_whole_seconds(timestep):
    assert timestep.times_s == [float(s) for s in range(21)]
    ctrl = controllers.load("simple_rule").with_parameters(phi_up_deg=14.0)
    for label, per_s in experiments.E5_STEPS_PER_S.items():
        ys = timestep.altitude_every_1s_m[label]
        assert len(ys) == 21 and ys[0] == 0.0 and ys[-1] == timestep.altitude_20s_m[label]
        # the sample at t = 3 s is the end of a flight of exactly 3 s at the same step
        (short,) = paper.simulate(ctrl, None, None, 3.0, 1.0 / per_s, 1)
        assert ys[3] == float(short.y[-1])
        ref = np.array(timestep.altitude_every_1s_m["1/12000"])
        assert np.array_equal(np.array(timestep.altitude_diff_every_1s_m[label]), ref - np.array(ys))


def _is_png(path) -> bool:
    data = path.read_bytes()
    return len(data) > 10_000 and data.startswith(PNG_MAGIC)


def test_figures_write_pngs(tmp_path, trim, timestep):
    out = [
        saved(figures.fig3_forces(experiments.e2_fig3(), tmp_path / "f3.png"), tmp_path / "f3.png"),
        saved(figures.fig_speed_limit(experiments.e3_speed_limit_vs_area(), tmp_path / "sl.png"), tmp_path / "sl.png"),
        saved(figures.fig4_trim(trim, tmp_path / "sub" / "f4.png"), tmp_path / "sub" / "f4.png"),
        saved(figures.fig5_timestep(timestep, tmp_path / "f5.png"), tmp_path / "f5.png"),
    ]
    for path in out:
        assert path.exists() and _is_png(path), path
    assert sorted(p.name for p in tmp_path.rglob("*") if p.is_file()) == ["f3.png", "f4.png", "f5.png", "sl.png"]


def test_reproduce_writes_report_json_and_figures(tmp_path):
    res = report.report_e1_e5(tmp_path, extra_sections=[("Notes", "An extra *section*.")], progress=False)
    names = {p.name for p in tmp_path.iterdir()}
    assert names == {"fig3_forces.png", "fig_speed_limit.png", "fig4_trim.png", "fig5_timestep.png", "results.json",
                     "report.md"}
    for name in names - {"results.json", "report.md"}:
        assert _is_png(tmp_path / name)
    data = json.loads((tmp_path / "results.json").read_text())
    assert data["e4"]["phi_up_level_deg"] == res["e4"]["phi_up_level_deg"]
    assert set(data) >= {"e1", "e2", "e3", "e3_vs_area", "e4", "e5", "params"}
    md = (tmp_path / "report.md").read_text()
    assert "| experiment | paper | ours | note |" in md
    for name in ("fig3_forces.png", "fig_speed_limit.png", "fig4_trim.png", "fig5_timestep.png"):
        assert f"]({name})" in md
    assert "## Notes\n\nAn extra *section*." in md
    assert f"{res['e4']['phi_up_level_deg']:.6g}" in md and "| 12.77 |" in md
