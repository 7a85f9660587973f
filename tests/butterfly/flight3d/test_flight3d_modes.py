"""Behaviour networks: a controller's ``land`` and ``take_off`` networks fly only within their reach (the last metres of
a landing, the first second of a take-off), its flight network everywhere else; the controller file keeps them; an
evolution of one behaviour changes only its network."""

import json
import math

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import controllers as c3
from lifelike_mj.butterfly.flight3d import tasks as t3
from lifelike_mj.butterfly.flight3d.evolution import TASK_SETS, FlightProblem3D
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.loop import behaviour
from lifelike_mj.errors import UserError

FLOWERS = [(0.0, 0.0, -0.2), (0.9, 0.3, -0.25)]


def _flight_only():
    """The shipped monarch's flight network alone (no behaviour networks)."""
    return c3.load_controller("monarch").replace(modes={})


def _monarch(**modes):
    ctl = _flight_only()
    for name, (weights, reach) in modes.items():
        ctl = ctl.with_mode(name, weights, reach)
    return ctl


def _path(ctl, take_off=False, seconds=1.5):
    """Positions (every step) of ``ctl`` flying to flower 1: from flower 0 with a take-off, else from the air 0.6 m
    before it."""
    f = Flight3D(controller=ctl, flowers=FLOWERS, ground_m=-1.0, start_m=(0.3, 0.1, -0.1))
    f.reset()
    if take_off:
        f.perch_on(0)
        f.take_off(f.land_on(1))
    else:
        f2 = Flight3D(controller=ctl, flowers=FLOWERS, ground_m=-1.0, start_m=(0.3, 0.1, -0.1), task=f.land_on(1),
                      _model=f.model)
        f = f2
    t0 = f.time
    rows = []
    while f.time < t0 + seconds and not f.perched:
        f.step()
        rows.append([f.time - t0, *f.data.qpos[0:3]])
    return np.array(rows)


def test_a_controller_without_behaviours_flies_its_flight_network_everywhere():
    ctl = _flight_only()
    assert ctl.modes == {} and "modes" not in ctl.to_dict()
    assert np.array_equal(ctl.all_weights(), np.tile(ctl.weights, 1 + len(c3.MODES)))
    assert np.array_equal(ctl.mode_reach(), np.zeros(len(c3.MODES)))


def test_which_network_flies_is_picked_by_the_reach():
    """land within reach[0] m of a landing flower's axis, take_off within reach[1] s of the last take-off, else the
    flight network; a flight that began in the air has no take-off."""
    task = t3.land((1.0, 0.0, 0.0), 0.008).as_array(2)
    rec = t3.new_record(1, 2)[0]
    reach = np.array([0.6, 1.0])
    assert behaviour(task, np.array([0.0, 0.0, 0.0]), 0.0, rec, reach) == 0
    assert behaviour(task, np.array([0.5, 0.0, 0.0]), 0.0, rec, reach) == 1
    assert behaviour(task, np.array([0.5, 0.0, 0.0]), 0.0, rec, np.zeros(2)) == 0
    t3.start_take_off(rec, 2.0)
    assert rec[t3.R_CLAP_UNTIL] == pytest.approx(2.0 + t3.CLAP_S)
    assert behaviour(task, np.array([0.0, 0.0, 0.0]), 2.9, rec, reach) == 2
    assert behaviour(task, np.array([0.0, 0.0, 0.0]), 3.1, rec, reach) == 0
    level = t3.level(1.0).as_array(2)
    assert behaviour(level, np.array([0.9, 0.0, 0.0]), 2.5, rec, reach) == 2  # only a landing has a flower


def test_a_landing_network_takes_over_only_within_its_reach():
    """A land network that differs from the flight network leaves the path untouched until the butterfly comes within
    its reach of the flower, and changes it after; one that repeats the flight network changes nothing at all."""
    base = _path(_flight_only())
    same = _path(_monarch(land=(_flight_only().weights, 0.3)))
    assert np.array_equal(base, same)
    other = _path(_monarch(land=(np.zeros(c3.n_weights([10, 9])), 0.3)))
    n = min(len(base), len(other))
    dh = np.hypot(*(np.array(FLOWERS[1][:2]) - base[:n, 1:3]).T)
    first = int(np.argmax(dh < 0.3))
    assert 0 < first < n - 20, "the flight should come within the reach"
    differs = np.flatnonzero(np.any(base[:n, 1:] != other[:n, 1:], axis=1))
    assert len(differs) and differs[0] >= first - 1 and differs[0] <= first + 10


def test_a_take_off_network_flies_only_the_first_of_a_take_off():
    """A take-off network flies from the take-off on, for its reach: the path differs from the take-off on; a flight
    that begins in the air never uses it."""
    ctl = _flight_only()
    zero = np.zeros(c3.n_weights([10, 9]))
    base, other = _path(ctl, take_off=True, seconds=0.5), _path(_monarch(take_off=(zero, 1.0)), take_off=True,
                                                               seconds=0.5)
    f = Flight3D(controller=_monarch(take_off=(zero, 0.5)), flowers=FLOWERS, ground_m=-1.0)
    assert f.behaviour == "flight"
    f.perch_on(0)
    assert f.behaviour == "perched"
    f.take_off(f.land_on(1))
    assert f.behaviour == "take_off"
    f.step(round(0.6 / f.dt))
    assert f.behaviour in ("flight", "land")
    assert Flight3D(animal="monarch").behaviour == "none"
    assert not np.array_equal(base[: len(other)], other[: len(base)])
    assert np.array_equal(_path(ctl), _path(_monarch(take_off=(zero, 1.0))))


def test_behaviours_go_through_the_controller_file_and_bad_ones_are_refused():
    w = np.linspace(-0.5, 0.5, c3.n_weights([10, 9]))
    ctl = _monarch(land=(w, 0.4), take_off=(-w, 0.8))
    again = c3.controller_from_dict(json.loads(json.dumps(ctl.to_dict())))
    assert np.array_equal(again.mode_weights("land"), w) and np.array_equal(again.mode_weights("take_off"), -w)
    assert np.array_equal(again.mode_reach(), [0.4, 0.8])
    assert again.replace(name="x").modes.keys() == ctl.modes.keys()
    d = ctl.to_dict()
    for bad, words in (({"hover": {"weights": list(w)}}, "hover"),
                       ({"land": {"weights": [1.0, 2.0]}}, "weights"),
                       ({"land": {"weights": list(w), "from_m": -1.0}}, "from_m"),
                       ({"take_off": {"weights": list(w), "from_m": 1.0}}, "take_off"),
                       ({"land": {"weights": [math.nan] * len(w)}}, "must be a number")):
        with pytest.raises(UserError, match=words):
            c3.controller_from_dict({**d, "modes": bad})


def test_a_behaviour_evolution_changes_only_that_behaviours_network():
    """The genes of a land evolution land in the land network's part of the loop's weights; the controller it makes
    keeps the flight network; a behaviour the template lacks is refused."""
    ctl = _monarch(land=(_flight_only().weights, 0.6))
    prob = FlightProblem3D(TASK_SETS["landings"](), ctl, duration_s=0.1, mode="land")
    n = prob.dim
    x = np.full(n, 0.01)
    rows = prob.all_weights(prob.weights(x)[None, :])
    assert np.array_equal(rows[0, :n], ctl.weights) and np.array_equal(rows[0, 2 * n :], ctl.weights)
    assert np.allclose(rows[0, n : 2 * n], ctl.weights + 0.01)
    out = prob.controller(x)
    assert np.array_equal(out.weights, ctl.weights) and np.allclose(out.mode_weights("land"), ctl.weights + 0.01)
    assert prob.describe()["mode"] == "land" and prob.fingerprint() != FlightProblem3D(
        TASK_SETS["landings"](), ctl, duration_s=0.1).fingerprint()
    with pytest.raises(UserError, match="not in the controller"):
        FlightProblem3D(TASK_SETS["landings"](), _flight_only(), duration_s=0.1, mode="take_off")


def _take_off_tilts(ctl, seeds=range(1, 9)):
    """The largest roll or pitch (deg) and the height (m, from the perch) after 1 s, of ``ctl`` taking off from the
    first flower of each garden ``seeds`` (two flowers, 6 m square) towards the second."""
    from lifelike_mj.butterfly.flight3d.flowers import place_flowers

    out = []
    for seed in seeds:
        f = Flight3D(controller=ctl, flowers=place_flowers(seed, 2, 6.0))
        f.perch_on(0)
        z0 = f.state()["position_m"][2]
        f.take_off(f.land_on(1))
        tilt = 0.0
        while f.time < 1.0:
            f.step(5)
            tilt = max(tilt, float(np.degrees(np.abs(f.state()["attitude_rad"][:2]).max())))
        out.append((tilt, f.state()["position_m"][2] - z0))
    return np.array(out)


def test_the_shipped_monarch_takes_off_upright_with_its_take_off_network():
    """Gardens 1-8 (never flown in training): with its take_off network the shipped monarch stays within 85 deg of
    upright and ends its first second within 0.4 m of its perch's height; its flight network alone tumbles on most."""
    ctl = c3.load_controller("monarch")
    assert set(ctl.modes) == {"take_off"}
    r = _take_off_tilts(ctl)
    assert r[:, 0].max() < 85.0 and np.abs(r[:, 1]).max() < 0.4, r
    assert (_take_off_tilts(_flight_only())[:, 0] > 90.0).sum() >= 4
