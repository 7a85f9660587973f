"""A shipped controller flown through the vector environment scores what `butterfly assess` reports.

The network chooses each copy's pitch from the env's observation (action mode "phi"); the numbers
(E6 drop, settled band and speed; E7 from +10 m; the 2 m/s tail wind; the wind map's passed cells) are
computed here from the observations alone and compared with ``assess``, which flies the controller on
the library's batch path."""

import numpy as np
import pytest

pytest.importorskip("gymnasium")

from lifelike_mj.butterfly import controllers  # noqa: E402
from lifelike_mj.butterfly.ann_experiments import PAPER_WINDS, assess  # noqa: E402
from lifelike_mj.envs.policies import FILE_WORD, controller_policy  # noqa: E402
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv  # noqa: E402

SETTLE_FROM = 12000  # steps: the last 10 s of 20 s at 1/1200 s
STEP = 1.5  # m/s, the wind map's grid step here (5 x 5 cells)


def _fly(ctrl, inputs, conditions):
    """Altitude (m) and ground forward speed (m/s) after every step, one column per condition."""
    n = len(conditions)
    env = ButterflyPitchVectorEnv(n, action_mode="phi", inputs=inputs, duration_s=20.0)
    policy = controller_policy(ctrl.with_inputs(FILE_WORD[inputs]), env)
    obs, _ = env.reset(seed=0, options={"conditions": conditions})
    air_fwd = np.array([(-a if inputs == "air" else 0.0) for _, (a, _b) in conditions])
    ys, vzs = [obs[:, 4].copy()], [obs[:, 5] + air_fwd]
    for _ in range(24000):
        obs, _, term, trunc, _ = env.step(policy(obs))
        assert not term.any()
        ys.append(obs[:, 4].copy())
        vzs.append(obs[:, 5] + air_fwd)
    assert trunc.all()
    return np.array(ys), np.array(vzs)


def test_the_shipped_network_through_the_env_scores_what_assess_reports():
    ctrl = controllers.load("ann_paper")
    report = assess(ctrl, windmap_step_m_s=STEP)
    grid = np.arange(-2, 3) * STEP
    cells = [(0.0, (a, b)) for b in grid for a in grid]
    flights = [(0.0, (0.0, 0.0)), (10.0, (0.0, 0.0)), (0.0, PAPER_WINDS["behind (-2,0)"])]
    y, vz = _fly(ctrl, "air", flights + cells)
    settled = slice(SETTLE_FROM, None)

    def numbers(j, y0):
        lo, hi = y[settled, j].min(), y[settled, j].max()
        return max(0.0, y0 - y[:, j].min()), lo, hi, 100.0 * vz[settled, j].mean()

    drop, lo, hi, speed = numbers(0, 0.0)
    still = report["still_air"]
    assert (drop, lo, hi, speed) == pytest.approx(
        (still["initial_drop_m"], still["settled_altitude_min_m"], still["settled_altitude_max_m"],
         still["settled_forward_speed_cm_s"]), rel=1e-9, abs=1e-12)
    assert still["holds_level"] == (max(abs(lo), abs(hi)) <= 0.25)
    _, lo10, hi10, _ = numbers(1, 10.0)
    assert [lo10, hi10] == pytest.approx(report["from_+10m_settled"], rel=1e-9)
    drop_t, lo_t, hi_t, _ = numbers(2, 0.0)
    assert [drop_t, lo_t, hi_t] == pytest.approx([report["tail_wind_2m_s"]["initial_drop_m"],
                                                  *report["tail_wind_2m_s"]["settled"]], rel=1e-9)

    def passed(y, vz):  # the wind map's test: 100 Hz samples of the last 10 s within +-1 m, moving forward
        s = slice(SETTLE_FROM, None, 12)
        return (y[s].min(axis=0) >= -1.0) & (y[s].max(axis=0) <= 1.0) & (vz[s].mean(axis=0) >= 0.0)

    ours = {"relative": int(passed(y[:, 3:], vz[:, 3:]).sum()), "ground": int(passed(*_fly(ctrl, "ground", cells)).sum())}
    assert ours == report["windmap_pass_cells"]
    assert 0 < ours["relative"] < len(cells)  # the grid has cells both ways: the count is a real test
