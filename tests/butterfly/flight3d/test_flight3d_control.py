"""3D controllers: observations, networks, commands, files, tasks, and the evolution's numbers."""

import json
import math

import numpy as np
import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.flight import Flight3D, euler_from_quat
from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
from lifelike_mj.errors import UserError


def _quat(roll, pitch, yaw):
    """w, x, y, z of yaw (about z), then pitch nose up (about -y), then roll (about x)."""
    def q(axis, a):
        return np.concatenate([[math.cos(a / 2)], math.sin(a / 2) * np.asarray(axis, float)])

    def mul(a, b):
        w1, x1, y1, z1 = a
        w2, x2, y2, z2 = b
        return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                         w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])

    return mul(mul(q([0, 0, 1], yaw), q([0, -1, 0], pitch)), q([1, 0, 0], roll))


@pytest.mark.parametrize("angles", [(0.3, 0.2, 1.0), (-0.5, -0.4, -2.5), (0.0, 0.7, 3.0)])
def test_attitude_reads_roll_pitch_yaw_back(angles):
    q = _quat(*angles)
    np.testing.assert_allclose(flight3d.loop.attitude(q), angles, atol=1e-12)
    np.testing.assert_allclose(euler_from_quat(q), angles, atol=1e-12)


def test_the_observation_is_relative_to_the_reference():
    qpos = np.zeros(12)
    qpos[3:7] = _quat(0.1, 0.2, math.radians(30))
    qpos[2] = 0.4
    qvel = np.zeros(11)
    qvel[0:3] = (2.0 * math.cos(math.radians(30)), 2.0 * math.sin(math.radians(30)), -0.3)
    qvel[3:6] = (1.0, -2.0, 3.0)
    obs = np.empty(flight3d.N_OBS)
    flight3d.loop.observe(qpos, qvel, math.radians(90), 0.1, 1.5, np.zeros(3), obs)
    want = [0.1, 0.2, math.radians(60), 1.0, 2.0, 3.0, 0.5, 0.0, -0.3, 0.3, 1.5]
    np.testing.assert_allclose(obs, want, atol=1e-12)
    flight3d.loop.observe(qpos, qvel, math.radians(90), -5.0, 1.5, np.zeros(3), obs)
    assert obs[9] == flight3d.controllers.ALTITUDE_CLIP_M
    # through the air: a wind of 1 m/s from behind and 0.5 m/s from the right (heading 30 deg), and a rising
    # gust the climb rate ignores (the altitude is the ground's)
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    wind = np.array([1.0 * c - 0.5 * -s, 1.0 * s - 0.5 * c, 0.4])
    flight3d.loop.observe(qpos, qvel, math.radians(90), 0.1, 1.5, wind, obs)
    np.testing.assert_allclose(obs, [0.1, 0.2, math.radians(60), 1.0, 2.0, 3.0, -0.5, 0.5, -0.3, 0.3, 1.5], atol=1e-12)


def test_air_inputs_fly_as_ground_inputs_in_still_air_and_differently_in_wind():
    ctl = flight3d.load_controller(flight3d.withdrawn_file("steer"))
    air = ctl.with_weights(ctl.weights, inputs="air")
    assert air.air_inputs and not ctl.air_inputs and air.to_dict()["inputs"] == "air"
    calm, windy = flight3d.course(100), flight3d.course(100).with_weather((0.0, 1.0, 0.0))
    f = [Flight3D(controller=c, task=t, n_strips=4, n_chord=1) for t in (calm, windy) for c in (ctl, air)]
    for x in f:
        x.step(600)
    np.testing.assert_array_equal(f[0].data.qpos, f[1].data.qpos)
    assert np.abs(f[2].data.qpos[:3] - f[3].data.qpos[:3]).max() > 0.01


def test_the_speed_asked_is_an_input_only_to_networks_that_have_it(tmp_path):
    ctl = flight3d.load_controller("monarch")
    seen = ctl.with_speed_input()
    assert list(seen.layers) == [flight3d.N_OBS, flight3d.N_ACT] and seen.sees_speed_asked
    assert not ctl.sees_speed_asked and seen.with_speed_input() is seen
    # each neuron's weights gain a zero before the bias; the others stay where they were
    w10 = ctl.weights.reshape(flight3d.N_ACT, flight3d.N_OBS)
    w11 = seen.weights.reshape(flight3d.N_ACT, flight3d.N_OBS + 1)
    np.testing.assert_array_equal(w11[:, :-2], w10[:, :-1])
    np.testing.assert_array_equal(w11[:, -1], w10[:, -1])
    assert not w11[:, -2].any()
    path = tmp_path / "seen.json"
    path.write_text(json.dumps(seen.to_dict()))
    assert flight3d.load_controller(path).sees_speed_asked
    # with zero weight on it the flight is bit for bit the old one; a weight on it changes the flight, and only
    # through the speed asked (the same weight at another speed asked flies otherwise)
    w = w11.copy()
    w[flight3d.ACTION_NAMES.index("abdomen_mean"), -2] = 0.5
    leaning = seen.with_weights(w.reshape(-1))
    f = [Flight3D(controller=c, task=flight3d.level(v)) for c, v in ((ctl, 1.5), (seen, 1.5), (leaning, 1.5),
                                                                     (leaning, 1.0))]
    for x in f:
        x.step(400)
    np.testing.assert_array_equal(f[0].data.qpos, f[1].data.qpos)
    assert np.abs(f[2].data.qpos[3:7] - f[1].data.qpos[3:7]).max() > 1e-3
    assert np.abs(f[3].data.qpos[3:7] - f[2].data.qpos[3:7]).max() > 1e-3
    assert f[0].decide()[-1] == 1.5 and f[3].decide()[-1] == 1.0


def test_a_pitch_schedule_shows_the_network_its_pitch_higher_the_faster_it_is_asked_to_fly():
    from lifelike_mj.butterfly.flight3d.measures import level_measures

    ctl = flight3d.load_controller("monarch")
    sched = ctl.with_speed_input(10.0, about_m_s=1.0)
    out = [np.empty(flight3d.N_ACT) for _ in range(3)]
    scratch = np.empty(2 * flight3d.N_OBS)
    x = np.random.default_rng(1).normal(size=flight3d.N_OBS)
    for v, o, c, shift in ((1.0, out[0], sched, 0.0), (3.0, out[1], sched, 0.0), (3.0, out[2], ctl, math.radians(20))):
        y = x.copy()
        y[10] = v
        y[1] += shift
        flight3d.loop.network(c.layers, c.weights, y, o, scratch)
    plain = np.empty(flight3d.N_ACT)
    flight3d.loop.network(ctl.layers, ctl.weights, x, plain, scratch)
    np.testing.assert_allclose(out[0], plain, atol=1e-12)  # as before at the speed it is set about
    np.testing.assert_allclose(out[1], out[2], atol=1e-12)  # 2 m/s faster: the pitch seen 20 deg higher
    # and so the monarch, which holds its pitch, flies its body lower the faster it is asked to fly
    body = [level_measures(sched, v, settle_s=3.0, window_s=1.0)["body_angle_deg"] for v in (1.0, 2.5)]
    assert body[0] - body[1] > 5.0

def test_the_speed_boost_raises_the_speed_asked_in_a_head_wind_up_to_its_bound(tmp_path):
    seen = flight3d.load_controller("monarch").with_speed_input()
    with pytest.raises(UserError, match="needs a network that sees the speed asked"):
        flight3d.load_controller("monarch").replace(speed_gain_per_s=0.5)
    boosted = seen.replace(speed_gain_per_s=0.5, speed_boost_max_m_s=0.8)
    path = tmp_path / "boosted.json"
    path.write_text(json.dumps(boosted.to_dict()))
    again = flight3d.load_controller(path)
    assert (again.speed_gain_per_s, again.speed_boost_max_m_s) == (0.5, 0.8)
    assert "speed_gain_per_s" not in seen.to_dict()  # no boost: the file is as before
    head = flight3d.level(1.0).with_weather((-1.5, 0.0, 0.0))  # a 1.5 m/s head wind: no ground made at 1 m/s
    f = [Flight3D(controller=c, task=t) for c, t in ((seen, head), (boosted, head), (boosted, flight3d.level(1.0)))]
    asked = []
    for x in f:
        x.step(800)  # 1 s
        asked.append(x.decide()[-1])
    assert asked[0] == 1.0  # without a boost the network sees the task's speed
    # 0.5/s times a shortfall of about 1 m/s and more: past half its bound within the second, and never past it
    assert 1.4 < asked[1] <= 1.8
    for _ in range(3):
        f[1].step(800)
        assert f[1].decide()[-1] <= 1.8
    assert f[1].decide()[-1] == pytest.approx(1.8)
    assert asked[2] < asked[1]  # in still air the same butterfly needs less

def test_a_linear_network_is_tanh_of_the_scaled_inputs_and_the_command_maps_each_action():
    layers = np.array([flight3d.N_OBS, flight3d.N_ACT])
    rng = np.random.default_rng(0)
    w = rng.normal(size=flight3d.n_weights(layers))
    x = rng.normal(size=flight3d.N_OBS)
    out = np.empty(flight3d.N_ACT)
    flight3d.loop.network(layers, w, x, out, np.empty(2 * flight3d.N_OBS))
    W = w.reshape(flight3d.N_ACT, flight3d.N_OBS + 1)
    np.testing.assert_allclose(out, np.tanh(W[:, :-1] @ (x / flight3d.controllers.INPUT_SCALE) + W[:, -1]), rtol=1e-14)
    base = KinematicsCommand().as_array()
    scale = np.arange(1.0, 10.0) / 10
    u = np.array([1.0, 0.5, -1.0, 0.25, 0.2, -0.4, 1.0, -1.0, 0.5])
    target = np.empty(13)
    flight3d.loop.command(base, scale, u, target)
    d = target - base
    np.testing.assert_allclose(d[[1, 2]], [0.1 + 0.1, 0.1 - 0.1])
    np.testing.assert_allclose(d[[3, 4]], [-0.3 + 0.1, -0.3 - 0.1])
    np.testing.assert_allclose(d[[5, 6]], [0.1 - 0.24, 0.1 + 0.24])
    np.testing.assert_allclose(d[[7, 8, 10, 0]], [0.7, 0.7, -0.8, 0.45])
    assert d[9] == d[11] == d[12] == 0.0


def test_a_controller_file_round_trips_and_bad_ones_are_one_sentence(tmp_path):
    ctl = flight3d.Controller3D([10, 4, 9], np.linspace(-1, 1, flight3d.n_weights([10, 4, 9])), provenance={"note": "test"})
    again = flight3d.controller_from_dict(json.loads(json.dumps(ctl.to_dict())))
    np.testing.assert_array_equal(again.weights, ctl.weights)
    assert again.to_dict() == ctl.to_dict()
    good = ctl.to_dict()
    with pytest.raises(UserError, match="layers must be whole numbers running from 10 or 11 inputs to 9 outputs"):
        flight3d.controller_from_dict(dict(good, layers=[6, 1]))
    with pytest.raises(UserError, match="need 89 finite weights"):
        flight3d.controller_from_dict(dict(good, weights=[0.0] * 84))
    with pytest.raises(UserError, match="unknown key 'wieghts'"):
        flight3d.controller_from_dict(dict(good, wieghts=good["weights"]))
    with pytest.raises(UserError, match="inputs must be 'ground' or 'air', got 'sky'"):
        flight3d.controller_from_dict(dict(good, inputs="sky"))
    assert flight3d.controller_from_dict({k: v for k, v in good.items() if k != "inputs"}).inputs == "ground"
    with pytest.raises(UserError, match="scale has an unknown key 'yaw'"):
        flight3d.controller_from_dict(dict(good, scale={"yaw": 0.1}))
    with pytest.raises(UserError, match="base has an unknown key 'flap_hz'"):
        flight3d.controller_from_dict(dict(good, base={"flap_hz": 10.0}))
    path = tmp_path / "c.json"
    path.write_text(json.dumps(dict(good, weights=[float("nan")] + good["weights"][1:])).replace("NaN", "NaN"))
    with pytest.raises(UserError, match="not strict JSON"):
        flight3d.load_controller(path)


def test_tasks_are_checked_and_courses_are_drawn_by_seed():
    a, b, c = flight3d.course(3), flight3d.course(3), flight3d.course(4)
    assert a == b and a != c and len(a.rows) == 10
    legs = np.diff(np.array([(0.0, 0.0)] + [r[:2] for r in a.rows]), axis=0)
    np.testing.assert_allclose(np.linalg.norm(legs, axis=1), 1.5)
    assert max(abs(r[2]) for r in a.rows) <= 0.3
    with pytest.raises(UserError, match="first row starts at 0 s"):
        flight3d.Task3D("schedule", ((1.0, 0.0, 0.0, 1.0),))
    with pytest.raises(UserError, match="rows of 3 numbers"):
        flight3d.Task3D("waypoints", ((1.0, 0.0),))


def test_the_schedule_and_the_waypoints_give_the_references():
    rec = flight3d.new_record(1, 2)[0]
    task = flight3d.turn(90.0, at_s=2.0, speed_m_s=1.2, climb_m=0.3).as_array(2)
    assert flight3d.loop.reference(task, 1.9, np.zeros(3), rec) == (0.0, 0.0, 1.2)
    assert flight3d.loop.reference(task, 2.0, np.zeros(3), rec) == (pytest.approx(math.pi / 2), 0.3, 1.2)
    wp = flight3d.Task3D("waypoints", ((1.0, 1.0, 0.2), (2.0, 0.0, 0.0)), radius_m=0.3, speed_m_s=1.0).as_array(2)
    h, z, v = flight3d.loop.reference(wp, 0.0, np.zeros(3), rec)
    assert (h, z, v) == (pytest.approx(math.pi / 4), 0.2, 1.0) and rec[flight3d.tasks.R_PASSED] == 0
    flight3d.loop.reference(wp, 0.0, np.array([0.9, 0.9, 0.2]), rec)  # within 0.3 m: passed, aim at the next
    assert rec[flight3d.tasks.R_PASSED] == 1 and rec[flight3d.tasks.R_WP] == pytest.approx(math.sqrt(0.02))
    h, _, _ = flight3d.loop.reference(wp, 0.0, np.array([0.9, 0.9, 0.2]), rec)
    assert h == pytest.approx(math.atan2(-0.9, 1.1))


def test_the_evolution_scores_what_the_stepper_flies():
    """The fitness of a controller in the batch (threads, many copies) is the reward its Flight3D earns."""
    layers = [10, 9]
    w = np.random.default_rng(1).normal(0, 0.2, flight3d.n_weights(layers))
    w[4 * 11 + 1] += 1.0
    tmpl = flight3d.Controller3D(layers, np.zeros(len(w)))
    tasks = (flight3d.level(1.0), flight3d.turn(90.0, 0.2))
    prob = flight3d.FlightProblem3D(tasks, tmpl, duration_s=0.3)
    fit = prob.evaluate(np.stack([w, w * 0.5]))
    for task, rec in zip(tasks, prob.fly(w[None, :])[0]):
        f = Flight3D(controller=tmpl.with_weights(w), task=task, n_strips=8, n_chord=2)
        f.step(round(0.3 / f.dt))
        assert f.reward == rec[flight3d.tasks.R_FIT]
    assert fit[0] == pytest.approx(np.mean(prob.fly(w[None, :])[0][:, flight3d.tasks.R_FIT]) / 0.3, rel=1e-15)
    assert prob.evaluate(w[None, :])[0] == fit[0]  # the same row scores the same in another batch


def test_the_counter_based_numbers_are_uniform_normal_and_repeatable():
    u = np.array([flight3d.loop.uniform(7, k, 3) for k in range(20000)])
    n = np.array([flight3d.loop.normal(7, k, 1) for k in range(20000)])
    assert 0.0 < u.min() and u.max() < 1.0
    assert abs(u.mean() - 0.5) < 0.01 and abs(u.std() - math.sqrt(1 / 12)) < 0.01
    assert abs(n.mean()) < 0.03 and abs(n.std() - 1.0) < 0.03
    assert abs(np.corrcoef(n[:-1], n[1:])[0, 1]) < 0.03
    normal = flight3d.loop.normal
    assert normal(7, 5, 1) == n[5] and normal(8, 5, 1) != n[5] and normal(7, 5, 2) != n[5]


def test_gusts_are_a_gauss_markov_process_of_the_stated_deviation_and_time():
    sigma, tau, dt = 0.5, 1.0, 0.01
    x, xs = 0.0, []
    for k in range(200_000):
        x = flight3d.loop.ou_step(x, sigma, tau, dt, flight3d.loop.normal(3, k, 0))
        xs.append(x)
    xs = np.array(xs[1000:])
    assert xs.std() == pytest.approx(sigma, rel=0.1)
    lag = int(tau / dt)
    assert np.corrcoef(xs[:-lag], xs[lag:])[0, 1] == pytest.approx(math.exp(-1.0), abs=0.08)


def test_vertical_gusts_have_their_own_deviation():
    task = flight3d.level(1.5).with_weather((1.0, 0.0, 0.0), gust_m_s=0.5, seed=2,
                                      gust_vertical_m_s=0.5 * flight3d.DRYDEN_VERTICAL_RATIO)
    assert task.vertical_gust_m_s == 0.25 and flight3d.level(1.5).with_weather(gust_m_s=0.4).vertical_gust_m_s == 0.4
    f = Flight3D(controller=None, task=task.with_weather((1.0, 0.0, 0.0), 0.5, gust_tau_s=0.05, seed=2,
                                                        gust_vertical_m_s=0.25), n_strips=2, n_chord=1)
    airs = []
    for _ in range(2400):  # 20 s, sampled every 10 steps; the gusts decorrelate in 60 steps
        f.step(10)
        airs.append(f.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3].copy())
    airs = np.array(airs)
    sd = airs.std(axis=0)
    assert sd[0] == pytest.approx(0.5, rel=0.1) and sd[1] == pytest.approx(0.5, rel=0.1)
    assert sd[2] == pytest.approx(0.25, rel=0.1) and airs.mean(axis=0)[0] == pytest.approx(1.0, abs=0.1)  # 3 standard errors
    with pytest.raises(UserError, match="gust_vertical_m_s"):
        flight3d.level(1.5).with_weather(gust_m_s=0.5, gust_vertical_m_s=-1.0)


def test_a_gusty_flight_is_the_same_for_the_same_seed_and_feels_the_gusts():
    ctl = flight3d.Controller3D([10, 9], flight3d.pd_prior([10, 9]))
    task = flight3d.level(1.5).with_weather(wind_to_m_s=(1.0, 0.0, 0.0), gust_m_s=0.5, flutter=0.2, seed=4)
    runs = []
    for seed in (4, 4, 5):
        f = Flight3D(controller=ctl, task=task.with_weather((1.0, 0.0, 0.0), 0.5, flutter=0.2, seed=seed),
                     n_strips=8, n_chord=2)
        airs = []
        for _ in range(60):
            f.step(10)
            airs.append(f.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3].copy())
        runs.append((f.data.qpos.copy(), np.array(airs)))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    assert not np.array_equal(runs[0][0], runs[2][0])
    airs = runs[0][1]
    assert np.abs(airs.mean(axis=0)[0] - 1.0) < 0.5 and airs.std(axis=0).min() > 0.0


def test_a_moving_target_is_aimed_at_where_it_is_now():
    task = flight3d.moving_target(centre_m=(3.0, 0.0, 0.0), radius_m=2.0, speed_m_s=0.5, bob_m=0.0, cruise_m_s=1.5)
    arr = task.as_array(2)
    rec = flight3d.new_record(1, 2)[0]
    t = math.pi  # a quarter of the way round at 0.25 rad/s: the target is at (3 + 2 cos(pi/4), 2 sin(pi/4), 0)
    h, z, v = flight3d.loop.reference(arr, t, np.zeros(3), rec)
    tx, ty = 3.0 + 2.0 * math.cos(0.25 * t), 2.0 * math.sin(0.25 * t)
    assert h == pytest.approx(math.atan2(ty, tx)) and z == 0.0 and v == 1.5  # far: the cruise speed
    assert rec[flight3d.tasks.R_WP + 1] == pytest.approx(math.hypot(tx, ty)) and rec[flight3d.tasks.R_PASSED] == 0
    _, _, v = flight3d.loop.reference(arr, t, np.array([tx - 0.2, ty, 0.0]), rec)  # close: slower, and counted
    assert v == pytest.approx(1.0) and rec[flight3d.tasks.R_PASSED] == 1


def test_a_folder_named_like_a_shipped_controller_does_not_hide_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "monarch").mkdir()
    assert flight3d.load_controller("monarch").animal == "monarch"  # the shipped file, not the folder
    (tmp_path / "mine").mkdir()
    with pytest.raises(UserError, match="is a folder"):
        flight3d.load_controller("mine")
