"""Predictive sampling on the designed controller (``predictive.Planner``): it flies the designed controller when it
may not change anything, it senses only the air of now (delayed), never the gusts to come, and the same seed flies
the same flight."""

import json
from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import designed as D
from lifelike_mj.butterfly.flight3d import designed_kernel as DK
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.predictive import SENSE_DELAY_S, Planner
from lifelike_mj.butterfly.flight3d.tasks import R_GUST, T_GUST, T_GUST_W, T_WIND, course, turn
from lifelike_mj.errors import UserError

MODEL = Path(__file__).resolve().parents[3] / "benchmarks" / "results" / "monarch_model.json"
GUSTY = {"wind_to_m_s": (1.0, 0.0, 0.0), "gust_m_s": 0.5, "gust_vertical_m_s": 0.5}


@pytest.fixture(scope="module")
def designed():
    return DK.CompiledDesigned(D.design(json.loads(MODEL.read_text())))


def _gusty(designed, seed=201):
    return Flight3D(controller=designed, task=course(seed).with_weather(**GUSTY))


def _path(f) -> np.ndarray:
    return np.concatenate([f.data.qpos[:7], f.data.qvel[:6]])


def test_a_planner_that_may_change_nothing_flies_the_designed_controller_bit_for_bit(designed):
    """With no spread the candidates are the nominal and the designed controller alone, both zero: the flight is the
    designed controller's, step for step (``Flight3D.step``)."""
    alone = _gusty(designed)
    planned = _gusty(designed)
    p = Planner(planned, samples=2, iterations=1, horizon_s=0.05, replan_s=0.05, sigma=0.0)
    rows = []
    for _ in range(20):
        p.step()
        rows.append(_path(planned))
    for k in range(20):
        alone.step(40)
        np.testing.assert_array_equal(_path(alone), rows[k])
    assert np.ptp([r[0] for r in rows]) > 0.3


def test_the_copies_fly_in_the_air_sensed_a_moment_ago_and_never_in_the_gusts_to_come(designed):
    f = _gusty(designed)
    p = Planner(f, samples=3, iterations=1, horizon_s=0.02, replan_s=0.01, sigma=0.2)
    air = []
    for _ in range(12):
        p.step()
        air.append(np.array(f.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3]))
    lag = int(round(SENSE_DELAY_S / 0.01))
    assert lag >= 1
    np.testing.assert_array_equal(p.sensed_air_m_s, air[-1 - lag])
    assert np.linalg.norm(air[-1] - air[0]) > 0.0  # gusts blew
    p._load()
    assert np.all(p.batch.tasks[:, [T_GUST, T_GUST_W]] == 0.0)
    assert np.all(p.batch.records[:, R_GUST : R_GUST + 3] == 0.0)
    np.testing.assert_array_equal(p.batch.tasks[:, T_WIND : T_WIND + 3], np.tile(air[-1 - lag], (3, 1)))


def test_the_same_seed_flies_the_same_flight_and_another_seed_another(designed):
    def fly(seed):
        f = _gusty(designed)
        p = Planner(f, samples=4, iterations=1, horizon_s=0.3, replan_s=0.05, action_cost=0.0, seed=seed)
        plans = []
        for _ in range(6):
            p.step()
            plans.append(p.nominal.copy())
        return _path(f), np.array(plans)

    (a, pa), (b, pb), (c, pc) = fly(1), fly(1), fly(2)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(pa, pb)
    assert np.any(pa != 0.0) and np.any(pc != 0.0)  # a sampled correction beat the designed controller alone
    assert not np.array_equal(a, c)


def test_a_planner_needs_a_designed_controller_and_a_course(designed):
    with pytest.raises(UserError, match="designed controller"):
        Planner(Flight3D(controller="monarch", task=course(1)))
    with pytest.raises(UserError, match="courses"):
        Planner(Flight3D(controller=designed, task=turn(90.0)))
    with pytest.raises(UserError, match="samples"):
        Planner(_gusty(designed), samples=1)
