"""Landing, perching and take-off: the landing task's reference and touchdown, the perch on a flower's blossom (held
by the legs' contact alone), the take-off's clap, the score an evolution gives a landing, and the garden's visits."""

import math

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d import tasks as t3
from lifelike_mj.butterfly.flight3d.evolution import landing_score
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.flowers import BLOSSOM_SIZE_M, landing_surface
from lifelike_mj.butterfly.flight3d.loop import flare, lowest_foot, reference, touched_down
from lifelike_mj.errors import UserError

FLOWERS = [(0.0, 0.0, -0.2), (1.0, 0.5, -0.1)]


def _standing_on(flower, above_m=0.002):
    """A monarch flight whose thorax starts ``above_m`` above its standing height on flower 0, landing there."""
    h = mj3d.standing_height_m("monarch")
    top = landing_surface(FLOWERS[flower])
    f = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0, start_m=top + (0.0, 0.0, h + above_m))
    f2 = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0, start_m=top + (0.0, 0.0, h + above_m),
                  task=f.land_on(flower), _model=f.model)
    return f2


def test_the_standing_height_is_where_the_feet_touch_a_level_surface():
    """The legs reach 1.3 thorax widths below the thorax's axis (the monarch's thorax is 5.7 mm wide), plus the
    leg's radius: 7.7 mm."""
    h = mj3d.standing_height_m("monarch")
    width = 2.0 * float(mj3d.build_model(animal="monarch").geom("thorax").size[1])
    assert width == pytest.approx(0.0057, abs=0.0001)
    assert h == pytest.approx(mj3d.FOOT_DEPTH * width + mj3d.LEG_RADIUS_M, rel=1e-9)


def test_the_landing_reference_slows_and_lowers_the_butterfly_as_it_closes():
    """Far away: the task's speed, at most LAND_ABOVE_M above the standing point; closer: slow_per_s m/s per m and
    LAND_GLIDE m lower per m, ending sink_m below the standing point; right above the flower the heading aimed at last
    is kept. The flare raises the body by flare_deg over the flower, from flare_m out."""
    task = t3.land((2.0, 0.0, -0.1), 0.008, speed_m_s=1.0, sink_m=0.02, slow_per_s=1.5, flare_deg=40.0,
                   flare_m=0.5).as_array(2)
    rec = t3.new_record(1, 2)[0]
    aim_z = -0.1 + 0.008 - 0.02
    h, z, v = reference(task, 0.0, np.array([0.0, 0.0, 0.0]), rec)
    assert (h, z, v) == pytest.approx((0.0, aim_z + t3.LAND_ABOVE_M, 1.0))
    assert flare(task, np.zeros(3)) == 0.0
    h, z, v = reference(task, 0.0, np.array([1.8, -0.2, 0.0]), rec)
    dh = math.hypot(0.2, 0.2)
    assert h == pytest.approx(math.pi / 4)
    assert z == pytest.approx(aim_z + t3.LAND_GLIDE * dh)
    assert v == pytest.approx(1.5 * dh)
    assert math.degrees(flare(task, np.array([1.8, -0.2, 0.0]))) == pytest.approx(40.0 * (1 - dh / 0.5))
    h, z, v = reference(task, 0.0, np.array([2.0 + 0.01, 0.0, 0.0]), rec)  # over the flower: the heading kept
    assert h == pytest.approx(math.pi / 4) and v == pytest.approx(0.015)
    assert rec[t3.R_WP] == pytest.approx(0.092, abs=0.001)  # the closest approach so far, to the standing point


def test_touchdown_needs_the_thorax_over_the_blossom_and_a_foot_on_it():
    """Level, the feet are the standing height below the thorax; pitched nose up, the hind feet reach lower, so a
    butterfly landing with its body raised touches down with its thorax higher."""
    h = mj3d.standing_height_m("monarch")
    feet = mj3d.feet_m(mj3d.build_model(animal="monarch")).ravel()
    task = t3.land((0.0, 0.0, 0.0), h, radius_m=0.03).as_array(2)
    q = np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    for xyz, expected in (((0.0, 0.0, h + 0.002), True), ((0.029, 0.0, h), True), ((0.031, 0.0, h), False),
                          ((0.0, 0.0, h + 0.004), False), ((0.0, 0.0, h - 0.004), False)):
        q[0:3] = xyz
        assert touched_down(task, q, feet) is expected, xyz
    assert lowest_foot(q, feet) == pytest.approx(q[2] - h)
    pitch = math.radians(40.0)  # nose up: a rotation of -40 deg about the body's y axis (which points left)
    q[3:7] = (math.cos(pitch / 2), 0.0, -math.sin(pitch / 2), 0.0)
    q[0:3] = (0.0, 0.0, h + 0.005)
    assert lowest_foot(q, feet) < 0.0 + t3.TOUCH_MARGIN_M and touched_down(task, q, feet)


def test_a_butterfly_that_touches_down_perches_on_its_legs_with_its_wings_closed():
    """At touchdown the network stops, the wings close over the back (85 deg each) and stop; the four feet stand on
    the blossom, and the butterfly sits still for 2 s: the contact alone holds it, nothing else does. No reward is
    earned while perched."""
    f = _standing_on(0)
    f.step(1)
    assert f.perched and f.touchdown["time_s"] == 0.0
    f.step(round(0.3 / f.dt))
    start = f.state()["position_m"]
    reward = f.reward
    f.step(round(2.0 / f.dt))
    s = f.state()
    assert np.degrees(s["joints_rad"][:2]) == pytest.approx([85.0, 85.0], abs=0.5)
    assert np.abs(s["joint_rates_rad_s"][:2]).max() < 1e-3
    assert np.linalg.norm(s["position_m"] - start) < 0.003
    assert np.abs(np.degrees(s["attitude_rad"][:2])).max() < 10.0
    feet = {f.model.geom(int(g)).name for c in f.data.contact[: f.data.ncon] for g in (c.geom1, c.geom2)}
    assert {"blossom_0"} <= feet and sum(n.startswith("leg_") for n in feet) == 4
    assert f.reward == reward


def test_without_its_legs_touching_a_perched_butterfly_falls():
    """The perch is the contact's doing: the same start in the flight model without flowers falls through."""
    h = mj3d.standing_height_m("monarch")
    top = landing_surface(FLOWERS[0])
    f = Flight3D(controller="monarch", start_m=top + (0.0, 0.0, h + 0.002), task=t3.land(top, h))
    f.step(round(1.0 / f.dt))
    assert f.perched and f.state()["position_m"][2] < top[2] - 0.5


def test_a_butterfly_put_on_a_flower_perches_there_until_a_reset():
    f = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0)
    f.perch_on(1)
    assert f.perched and f.touchdown == {"time_s": 0.0, "speed_m_s": 0.0}
    f.step(round(1.0 / f.dt))
    top = landing_surface(FLOWERS[1])
    assert f.state()["position_m"] == pytest.approx(top + (0.0, 0.0, mj3d.standing_height_m("monarch")), abs=0.002)
    f.reset()  # back to the start, flying its landing task afresh
    assert not f.perched and f.touchdown is None and f.time == 0.0


def _pull_up(f, body_weights: float, s: float = 0.5) -> float:
    """Pull a perched butterfly straight up by ``body_weights`` times its weight for ``s`` s: how far it rose (m)."""
    m = f.model
    body = m.body("butterfly").id
    weight = float(m.body_subtreemass[body]) * float(np.linalg.norm(m.opt.gravity))
    z0 = f.state()["position_m"][2]
    f.data.xfrc_applied[body, 2] = body_weights * weight
    f.step(round(s / f.dt))
    f.data.xfrc_applied[body, 2] = 0.0
    return float(f.state()["position_m"][2] - z0)


def test_a_perched_butterfly_grips_the_blossom_and_lets_go_at_take_off():
    """While perched the feet hold on (MuJoCo's adhesion, GRIP_BODY_WEIGHTS times the weight, along the contact
    normal): pulled up by twice its weight it stays on the blossom; with the grip's force set to zero, or once it
    has taken off, the same pull lifts it away. A flight without legs has no grip at all."""
    assert mj3d.GRIP_BODY_WEIGHTS > 2.0
    f = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0)
    grip = f.model.actuator("grip").id
    f.perch_on(0)
    f.step(round(0.3 / f.dt))
    assert f.data.ctrl[grip] == 1.0
    assert abs(_pull_up(f, 2.0)) < 0.002 and f.data.ncon >= 4
    loose = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0)
    loose.model.actuator("grip").gainprm[0] = 0.0
    loose.perch_on(0)
    loose.step(round(0.3 / loose.dt))
    assert _pull_up(loose, 2.0) > 0.05
    f.take_off(f.land_on(1))
    f.step(1)
    assert f.data.ctrl[grip] == 0.0
    assert Flight3D(controller="monarch").model.nu == 0


def test_a_take_off_claps_and_leaves_the_flower():
    """take_off: the wings open to the top of the stroke and the network flies again; for CLAP_S each stroke is
    enlarged so that its top is CLAP_TOP_RAD: the wings meet over the back (flap angles near 90 deg) at the end of
    every upstroke; the butterfly leaves the blossom."""
    f = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0)
    f.perch_on(0)
    f.step(round(0.5 / f.dt))
    with pytest.raises(UserError, match="not perched"):
        Flight3D(controller="monarch").take_off(t3.level(1.0))
    f.take_off(f.land_on(1))
    assert not f.perched and f.touchdown is None
    flaps = []
    for _ in range(round(t3.CLAP_S / f.dt)):
        f.step(1)
        flaps.append(f.state()["joints_rad"][:2])
    flaps = np.degrees(flaps)
    beat = round(1.0 / f.command.frequency_hz / f.dt)
    tops = [flaps[k : k + beat].max(axis=0) for k in range(beat // 2, len(flaps) - beat, beat)]
    assert len(tops) >= 2 and np.min(tops) > 84.0  # every beat after the first half one claps, both wings
    start = landing_surface(FLOWERS[0]) + (0.0, 0.0, mj3d.standing_height_m("monarch"))
    assert np.linalg.norm(f.state()["position_m"] - start) > 0.03
    assert f.data.ncon == 0


def test_a_landing_is_scored_by_its_touchdown_speed_or_how_near_and_slow_it_came():
    """A touchdown scores at least 0.5, all of 1 within the bound (0.5 if it then tips over); short of one, at most
    0.5: by the closest approach, half of it by the speed there (none after a tumble)."""
    rec = t3.new_record(1, 2)[0]
    assert landing_score(rec) == 0.0  # never came near
    rec[t3.R_WP], rec[t3.R_NEAR_SPEED] = 0.05, 0.3
    hover = landing_score(rec)
    assert hover == pytest.approx(0.5 * math.exp(-0.5))
    rec[t3.R_NEAR_SPEED] = 0.5 + 0.5
    assert landing_score(rec) == pytest.approx(hover * (0.5 + 0.5 * math.exp(-1.0)))
    rec[t3.R_TUMBLED] = 100.0  # stopped dead by a tumble: no credit for the speed
    assert landing_score(rec) == pytest.approx(hover / 2)
    rec[t3.R_WP] = 0.2
    assert landing_score(rec) < hover / 2
    rec[t3.R_LANDED_AT], rec[t3.R_TOUCH_SPEED] = 1.0, t3.TOUCHDOWN_M_S
    assert landing_score(rec) == 0.5  # tipped over on the flower (the tumble above)
    rec[t3.R_TUMBLED] = -1.0
    assert landing_score(rec) == 1.0
    rec[t3.R_TOUCH_SPEED] = 2.0
    assert landing_score(rec) == pytest.approx(0.5 + 0.5 * math.exp(-3.0))


def test_a_thorax_is_on_the_blossom_within_its_radius_and_above_its_centre():
    from lifelike_mj.butterfly.flight3d.landing import on_blossom

    b = np.array(FLOWERS[1])
    r = BLOSSOM_SIZE_M[0]
    assert on_blossom(b + (0.0, 0.0, 0.02), b) and on_blossom(b + (0.99 * r, 0.0, 0.001), b)
    assert not on_blossom(b + (0.0, 1.01 * r, 0.02), b)  # beside it
    assert not on_blossom(b + (0.0, 0.0, -0.001), b)  # slid off, under it


def test_a_landing_task_refuses_bad_input():
    with pytest.raises(UserError, match="two rows"):
        t3.Task3D("land", ((0, 0, 0, 0.01),))
    with pytest.raises(UserError, match="flare_deg"):
        t3.land((0.0, 0.0, 0.0), 0.008, flare_deg=100.0)
    with pytest.raises(UserError, match="flower_m"):
        t3.land((0.0, float("nan"), 0.0), 0.008)
    with pytest.raises(UserError, match="standing_m"):
        t3.land((0.0, 0.0, 0.0), -0.1)
    with pytest.raises(UserError, match="no flowers"):
        Flight3D(controller="monarch").land_on(0)
    with pytest.raises(UserError, match="flowers"):
        Flight3D(controller="monarch", flowers=[(0.0, 0.0)])


def test_the_blossom_touched_is_the_blossom_drawn():
    f = Flight3D(controller="monarch", flowers=FLOWERS, ground_m=-1.0)
    g = f.model.geom("blossom_1")
    assert tuple(g.size) == BLOSSOM_SIZE_M and g.contype == 1
    assert f.model.geom("stem_1").contype == 0


def test_a_landing_garden_logs_its_visits_and_gives_up_a_flower_it_cannot_reach(monkeypatch):
    """A garden told to land: each butterfly aims at its first flower; one that has not touched down within
    GIVE_UP_S logs a missed visit and aims at its next flower in its order (the shipped monarch was not evolved to
    land, so it circles its flowers); the scene draws legs."""
    from lifelike_mj.butterfly.flight3d import garden as G

    monkeypatch.setattr(G, "GIVE_UP_S", 2.0)
    g = G.Garden(2, "monarch", seed=3, n_flowers=4, land=True, flutter=0.0)
    assert g.land and g.model.geom("b0_leg_0_left") is not None
    first = [int(np.argmin(np.linalg.norm(g.blossoms[:, :2] - t.rows[0][:2], axis=1))) for t in g.tasks]
    g.step(round(2.5 / g.dt))
    visits = g.visits()
    for i in range(2):
        assert visits[i][0] == {"flower": first[i], "touchdown_s": None, "touchdown_speed_m_s": None,
                                "take_off_s": None, "stayed": None}
        assert g._batch.tasks[i, t3.T_ROW0 : t3.T_ROW0 + 2] == pytest.approx(g.blossoms[g._orders[i][1], :2])
    assert not g.state()["perched"].any() and (g.state()["waypoints_passed"] == 0).all()
    g.reset()  # every butterfly aims at its first flower again
    assert g._batch.tasks[0, t3.T_ROW0] == pytest.approx(g.blossoms[first[0], 0]) and g.visits() == [[], []]
    assert not G.Garden(2, "monarch", seed=3, n_flowers=4).land  # not evolved to land: it passes the flowers by
