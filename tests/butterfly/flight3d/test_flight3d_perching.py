"""The designed controller's landing (flight3d.perching and the compiled loop's approach, trigger and tracking)."""

import json
import math

import mujoco
import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d import designed_kernel as DK
from lifelike_mj.butterfly.flight3d import perching as P
from lifelike_mj.errors import UserError

SPEC = json.loads(open("controllers/butterfly3d/designed.json").read())


@pytest.fixture(scope="module")
def plant():
    return P.Plant(SPEC)


@pytest.fixture(scope="module")
def snap(plant):
    return plant.settled(1.0)


def test_settled_at_the_phase_asked(plant, snap):
    """The approach's state is taken at the step its phase passes the one asked, level at the approach's speed."""
    psi = snap.userdata[P.mj3d.U_PSI0] % (2 * math.pi)
    step = 2 * math.pi * snap.userdata[P.mj3d.U_P0] * plant.dt  # the phase one step moves
    assert 0.0 <= psi - 1.0 < step + 1e-9
    assert abs(snap.qvel[0] - P.APPROACH_M_S) < 0.25 and abs(snap.qpos[2]) < 1e-12


def test_perturbation_moves_the_error_by_its_step(plant, snap):
    """Each tracked coordinate moved by h reads back as h in that coordinate alone (the attitude as a body-frame
    rotation, the phase wrapped)."""
    m = plant.m
    qj, dj, _ = P.mj3d.driven_dofs(m)
    s0 = P.state_vector(snap, qj, dj)
    assert np.array_equal(P.state_error(s0, s0), np.zeros(P.N_STATE))
    for i in range(P.N_STATE):
        d = mujoco.MjData(m)
        mujoco.mj_copyData(d, m, snap)
        P._perturb(d, i, 1e-3, qj, dj)
        e = P.state_error(P.state_vector(d, qj, dj), s0)
        want = np.zeros(P.N_STATE)
        want[i] = 1e-3
        assert np.allclose(e, want, atol=1e-9), i


@pytest.mark.parametrize("yaw", [0.0, 2.0, -2.7])
def test_the_loop_reads_the_error_in_the_manoeuvres_frame(plant, snap, yaw):
    """The compiled loop's tracking error (``designed_kernel.tracking_error``) of a state moved into a garden (the
    flower elsewhere, the final's bearing ``yaw``) equals the design's (``perching.state_error``) of the same state
    in the manoeuvre's own frame."""
    m = plant.m
    qj, dj, _ = P.mj3d.driven_dofs(m)
    nom = P.state_vector(snap, qj, dj)
    d = mujoco.MjData(m)
    mujoco.mj_copyData(d, m, snap)
    for i, h in ((0, 0.02), (1, -0.01), (2, 0.005), (4, 0.1), (7, 0.05), (10, 0.3), (23, 0.2)):
        P._perturb(d, i, h, qj, dj)
    local = P.state_error(P.state_vector(d, qj, dj), nom)
    # the same body in a garden: the standing point at S, the final's x along yaw
    S = np.array([1.3, -0.7, 0.25])
    c, s = math.cos(yaw), math.sin(yaw)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    g = mujoco.MjData(m)
    mujoco.mj_copyData(g, m, d)
    rel = d.qpos[0:3] - P.standing_point()
    g.qpos[0:3] = S + Rz @ rel
    g.qvel[0:3] = Rz @ d.qvel[0:3]
    qz = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)])
    q = np.empty(4)
    mujoco.mju_mulQuat(q, qz, d.qpos[3:7].copy())
    g.qpos[3:7] = q
    st = np.zeros(len(DK.ST_NAMES))
    st[DK.ST_LAND + 3], st[DK.ST_LAND + 4 : DK.ST_LAND + 7] = yaw, S
    lc = DK.landing_tables(None)[4]
    e = DK.tracking_error(st, g.userdata, g.qpos, g.qvel, nom, lc)
    assert np.allclose(e, local, atol=1e-9)


@pytest.mark.parametrize("yaw", [0.0, 2.4])
def test_a_take_off_starts_its_manoeuvre_where_the_body_is(plant, yaw):
    """At a take-off the compiled loop places the take-off's frame (``designed_kernel.rise``) so that a body in the
    nominal's first state, anywhere in a garden and facing anywhere, reads no error from it (``tracking_error``)."""
    lm, ls, lu, lk, lc = DK.landing_tables(SPEC["landing"])
    j = len(lm) - 1
    assert lm[j, 0] == -1.0 and lm[j, 1] == len(SPEC["landing"]["take_off"]["commands"])
    n0 = ls[j, 0]
    d = mujoco.MjData(plant.m)
    d.qpos[:] = plant.d.qpos
    c, s = math.cos(yaw), math.sin(yaw)
    d.qpos[0:3] = [2.0 + c * n0[0] - s * n0[1], -1.5 + s * n0[0] + c * n0[1], 0.4 + n0[2]]
    d.qvel[0:3] = [c * n0[3] - s * n0[4], s * n0[3] + c * n0[4], n0[5]]
    mujoco.mju_mulQuat(d.qpos[3:7], np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]), n0[6:10].copy())
    d.qvel[3:6] = n0[10:13]
    qj, dj, _ = P.mj3d.driven_dofs(plant.m)
    d.qpos[qj], d.qvel[dj] = n0[13:18], n0[18:23]
    d.userdata[:] = plant.d.userdata
    d.userdata[P.mj3d.U_PSI0] = n0[23]
    d.userdata[P.mj3d.U_P0 : P.mj3d.U_P0 + P.N_PARAMS] = n0[24 : 24 + P.N_PARAMS]
    d.userdata[P.mj3d.U_DP0 : P.mj3d.U_DP0 + P.N_PARAMS] = n0[24 + P.N_PARAMS :]
    st = np.zeros(len(DK.ST_NAMES))
    DK.rise(st, d.qpos, ls, j)
    assert st[DK.ST_LAND] == 1.0 and st[DK.ST_LAND + 1] == j and st[DK.ST_LAND + 2] == 0.0
    e = DK.tracking_error(st, d.userdata, d.qpos, d.qvel, n0, lc)
    assert np.allclose(e, 0.0, atol=1e-9), e
    d.qpos[2] += 0.01  # and an error where there is one
    assert abs(DK.tracking_error(st, d.userdata, d.qpos, d.qvel, n0, lc)[2] - 0.01) < 1e-9


@pytest.mark.parametrize("gap, starts", [(0.0, True), (0.15, True), (-0.15, True), (0.25, False), (-0.3, False)])
def test_a_manoeuvre_starts_only_near_its_own_phase_of_the_beat(gap, starts):
    """``trigger`` starts the manoeuvre whose phase is nearest the beat's only within ``START_PHASE_GAP_RAD`` of it
    (started an eighth of a beat off, the phase-0 manoeuvre came down at 0.5-0.9 m/s on a tenth of its landings): a
    body at bin 2's start distance, on the final at the approach's height, flying at the flower."""
    lm, ls, lu, lk, lc = DK.landing_tables(SPEC["landing"])
    j = 2
    task = np.zeros(DK.L.T_ROW0 + 8)
    qpos = np.zeros(7)
    qpos[0], qpos[2], qpos[3] = -lm[j, 0], lc[0], 1.0
    qvel = np.zeros(6)
    qvel[0] = 1.5
    st = np.zeros(len(DK.ST_NAMES))
    assert DK.trigger(st, task, qpos, qvel, lm[j, 2] + gap, lm, lc) is starts
    assert (st[DK.ST_LAND], st[DK.ST_LAND + 1]) == ((1.0, j) if starts else (0.0, 0.0))


def test_a_landing_file_is_checked():
    """A controller file's landing with arrays of the wrong shapes, or not numbers, gets one sentence."""
    t = 3
    good = {"phase_rad": 0.0, "start_m": 0.5, "states": np.zeros((t + 1, P.N_STATE + 1)).tolist(),
            "commands": np.zeros((t, P.N_PARAMS)).tolist(), "gains": np.zeros((t, P.N_CONTROL, P.N_STATE)).tolist()}
    P.check_landing({"manoeuvres": [good]}, "here")
    with pytest.raises(UserError, match="shapes"):
        P.check_landing({"manoeuvres": [dict(good, states=good["states"][:-1])]}, "here")
    with pytest.raises(UserError, match="arrays of numbers"):
        P.check_landing({"manoeuvres": [dict(good, gains=[["a"]])]}, "here")
    bad = dict(good, commands=np.full((t, P.N_PARAMS), np.nan).tolist())
    with pytest.raises(UserError, match="not finite"):
        P.check_landing({"manoeuvres": [bad]}, "here")
    with pytest.raises(UserError, match="take-off has states"):
        P.check_landing({"manoeuvres": [good], "take_off": dict(good, gains=good["gains"][:-1])}, "here")


#: Gardens no design or choice of this landing has seen (the design's tuning gardens were 100-111), four flowers each:
#: three visits a garden, a failed visit ending it.
REPORT_GARDENS = range(400, 410)


@pytest.mark.slow
def test_the_shipped_controller_lands_on_unseen_gardens():
    """The shipped designed controller, flown through ``land3d``'s ``visit_flowers``, lands within the touchdown bound,
    stays on the blossom and perches upright to the end of a 2 s perch on at least 9 of 10 visits of gardens it was
    never tuned on, and takes off for the next."""
    from lifelike_mj.butterfly.flight3d.flowers import place_flowers
    from lifelike_mj.butterfly.flight3d.landing import visit_flowers

    ctrl = DK.load_compiled("designed")
    good = total = 0
    for seed in REPORT_GARDENS:
        res = visit_flowers(ctrl, place_flowers(seed, 4, 6.0), 2.0)
        for v in res["visits"]:
            total += 1
            good += v["within_bound"] and v["stayed"] and v["upright"]
    assert total >= 25 and good >= 0.9 * total, (good, total)


@pytest.mark.slow
def test_design_landing_writes_what_the_loop_flies():
    """``design_landing`` (here two chains of two manoeuvres, with two generations each, and a take-off of one) gives
    manoeuvres whose arrays pass the file's check and load as the loop's tables, each with the phase and start
    distance it was shot at, the take-off last, and records how."""
    halves = ((4, ((3, 4),)), (6, ((7, 6),)))
    land = P.design_landing(SPEC, workers=2, generations=(2, 2), halves=halves, take_off=1)
    P.check_landing(land, "here")
    ms = land["manoeuvres"]
    assert [round(m["phase_rad"] / (2 * math.pi / P.N_BINS)) for m in ms] == [b for b, t in
                                                                             zip((3, 4, 6, 7), land["shooting"]["touched"]) if t]
    assert all(abs(m["start_m"] - m["decisions"][14]) < 1e-6 and len(m["states"]) == len(m["commands"]) + 1
               for m in ms)
    lm, ls, lu, lk, _ = DK.landing_tables(land)
    rising = land["take_off"]
    assert lm.shape == (len(ms) + 1, 3) and np.array_equal(lm[:, 1], [len(m["commands"]) for m in [*ms, rising]])
    assert (lm[:-1, 0] > 0).all() and lm[-1, 0] == -1.0 and rising["shooting"]["generations"] == 1
    assert max(rising["drop_m"]) < 0.02 and min(rising["gain_m"]) > 0.0  # from the start's decisions, it climbs
    assert land["shooting"]["first_generations"] == 2 and land["shooting"]["start"] == P.DECISION_START.tolist()
    assert land["shooting"]["halves"] == [[4, [[3, 4]]], [6, [[7, 6]]]]
