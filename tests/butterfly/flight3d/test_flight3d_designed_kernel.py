"""The designed controller in the compiled loop (``designed_kernel``) against its Python twin
(``designed.DesignedController``): the same flight, sample by sample, on a course in gusts (waypoint guidance, the
wind observer at work) and in a turn (a schedule's references)."""

import json
from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import designed as D
from lifelike_mj.butterfly.flight3d import designed_kernel as DK
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.tasks import course, turn

MODEL = Path(__file__).resolve().parents[3] / "benchmarks" / "results" / "monarch_model.json"


@pytest.fixture(scope="module")
def spec():
    return D.design(json.loads(MODEL.read_text()))


def _flight(controller, task, seconds: float) -> np.ndarray:
    f = Flight3D(controller=controller, task=task)
    rows = []
    while f.time < seconds - 1e-9:
        f.step(40)
        rows.append(np.concatenate([f.data.qpos[:7], f.data.qvel[:6], [f.waypoints_passed]]))
    return np.array(rows)


@pytest.mark.parametrize("task,seconds", [
    (course(201).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5), 6.0),
    (turn(90.0, speed_m_s=1.2), 4.0)], ids=["gusty course", "turn"])
def test_the_compiled_controller_flies_as_its_python_twin(spec, task, seconds):
    python = _flight(D.DesignedController(spec), task, seconds)
    compiled = _flight(DK.CompiledDesigned(spec), task, seconds)
    assert np.ptp(python[:, 0]) > 1.0  # it flew somewhere
    np.testing.assert_allclose(compiled, python, rtol=0.0, atol=1e-9)


def test_the_ring_keeps_the_last_beat_as_the_twins_deque_does():
    st, buf, _ = DK.new_state()
    R = np.eye(3)
    for k in range(30):
        DK.sample(st, buf, np.full(7, float(k)), np.zeros(6), R, 0.0, 20 if k < 25 else 12)
    assert st[0] == 30 and st[1] == 12  # a shorter beat drops the oldest samples at once
    kept = [DK._row(buf, st, j)[0] for j in range(int(st[1]))]
    assert kept == [float(k) for k in range(18, 30)]


def test_a_batch_flies_each_butterfly_as_it_would_fly_alone(spec):
    """Two butterflies on two gusty courses in one compiled batch (threads over the copies, each with its own
    controller state): each flies as it does in a batch of one."""
    from lifelike_mj.butterfly.flight3d.loop import Batch
    from lifelike_mj.butterfly.flight3d.tasks import new_record

    ctl = DK.CompiledDesigned(spec)
    tasks = [course(s).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, gust_vertical_m_s=0.5)
             for s in (202, 203)]
    alone = [Flight3D(controller=ctl, task=t) for t in tasks]
    for f in alone:
        f.step(2400)
    pair = [Flight3D(controller=ctl, task=t, _model=alone[0].model) for t in tasks]
    rows = max(len(t.rows) for t in tasks)
    batch = Batch(pair[0].model, [f.data for f in pair], np.stack([t.as_array(rows) for t in tasks]), dt_s=pair[0].dt,
                  records=new_record(2, rows), base=pair[0].command.as_array(), designed=ctl)
    batch.advance(2400)
    for f, g in zip(alone, pair):
        np.testing.assert_allclose(g.data.qpos, f.data.qpos, rtol=0.0, atol=1e-9)
    assert np.linalg.norm(alone[0].data.qpos[:2] - alone[1].data.qpos[:2]) > 0.5  # two flights, not one twice


def test_a_designed_controller_converts_for_the_compiled_loop(spec):
    ctl = DK.CompiledDesigned.of(D.DesignedController(spec, name="d"))
    assert isinstance(ctl, DK.CompiledDesigned) and ctl.name == "d"
    f = Flight3D(controller=ctl, task=turn(90.0, speed_m_s=1.2))
    assert f.controller is None and f.designed is ctl  # no Python call per step
    from lifelike_mj.errors import UserError

    with pytest.raises(UserError, match="decide needs a 3D controller"):
        f.decide(np.zeros(9))
