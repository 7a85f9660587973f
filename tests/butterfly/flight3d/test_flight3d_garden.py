"""The garden: many 3D butterflies on their own courses among the flowers, drawn in one scene."""

import json

import numpy as np
import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.garden import Garden, course_among, flowers
from lifelike_mj.errors import UserError


def test_flowers_and_courses_are_drawn_by_seed():
    a, b = flowers(3), flowers(3)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, flowers(4))
    gaps = np.linalg.norm(a[:, None, :2] - a[None, :, :2], axis=2) + np.eye(len(a)) * 9
    assert gaps.min() >= 1.2
    course = course_among(a, 7)
    assert len(course) == 40 and np.all(np.linalg.norm(np.diff(course, axis=0), axis=1) > 0)  # never twice in a row


def test_each_garden_butterfly_flies_what_its_own_flight_flies():
    """The garden's threaded batch gives every butterfly the flight a Flight3D on the same task gives it."""
    ctl = flight3d.load_controller(flight3d.withdrawn_file("wind"))
    g = Garden(3, ctl, seed=2, flutter=0.1, gust_m_s=0.3)
    starts = [d.qpos[:7].copy() for d in g._datas]
    g.step(240)
    g.sync()
    state = g.state()
    for i in range(3):
        f = Flight3D(controller=ctl, task=g.tasks[i], n_strips=8, n_chord=2)
        f.data.qpos[:7] = starts[i]
        f.step(240)
        np.testing.assert_array_equal(f.state()["position_m"], state["position_m"][i])
        # and the scene shows it where it is
        body = g.model.body(f"b{i}_butterfly").id
        np.testing.assert_allclose(g.data.xpos[body], state["position_m"][i], atol=1e-12)


def test_a_garden_of_the_designed_controller_flies_each_butterfly_as_its_own_flight():
    """A garden of the shipped designed controller passing the flowers by (``land=False``; threaded,
    fly_designed_batch): each butterfly flies what a Flight3D of the same controller flies on its own task, and they
    pass flowers."""
    g = Garden(3, seed=2, flutter=0.1, gust_m_s=0.3, land=False)
    assert g.designed and g.controller.name == "designed" and not g.land
    starts = [d.qpos[:7].copy() for d in g._datas]
    g.step(800)
    state = g.state()
    for i in range(3):
        f = Flight3D(controller="designed", task=g.tasks[i])
        f.data.qpos[:7] = starts[i]
        f.step(800)
        np.testing.assert_array_equal(f.state()["position_m"], state["position_m"][i])
    g.step(int(round(9.0 / g.dt)))
    assert g.state()["waypoints_passed"].min() >= 2  # ten seconds among flowers 1.2 m or more apart


@pytest.mark.slow
def test_the_default_garden_lands_on_its_flowers():
    """The default garden (the shipped designed controller, which has a landing) lands: in 25 s each of four
    butterflies touches down on at least one flower within the bound, and every touchdown that has taken off again
    stayed on its blossom. A designed controller without a landing is refused ``land=True`` in one sentence."""
    from lifelike_mj.butterfly.flight3d.tasks import TOUCHDOWN_M_S

    g = Garden(4, seed=3)
    assert g.designed and g.land
    g.step(int(round(25.0 / g.dt)))
    visits = g.visits()
    for vs in visits:
        landed = [v for v in vs if v["touchdown_s"] is not None]
        assert landed and any(v["touchdown_speed_m_s"] <= TOUCHDOWN_M_S for v in landed), vs
        assert all(v["stayed"] for v in landed if v["take_off_s"] is not None), vs
    spec = json.loads(open("controllers/butterfly3d/designed.json").read())
    del spec["landing"]
    with pytest.raises(UserError, match="has no landing"):
        Garden(2, CompiledDesigned(spec), land=True)


@pytest.mark.slow
def test_the_default_gardens_butterflies_climb_from_their_perches():
    """The shipped designed controller takes off by its take-off manoeuvre (its landing's ``take_off``): in a garden
    it was never tuned on (seed 5, eight butterflies, 16 s), at least nine take-offs in ten never sink 5 cm below the
    perch in their first half second, and are higher than the perch at its end (without the manoeuvre, the
    regulator's take-off sank a median 0.30 m)."""
    g = Garden(8, seed=5)
    every = int(round(0.025 / g.dt))
    z, perched = [], []
    while g.time < 16.0:
        g.step(every)
        s = g.state()
        z.append(s["position_m"][:, 2].copy())
        perched.append(s["perched"].copy())
    z, perched = np.array(z), np.array(perched)
    climbs = []
    for i in range(g.n):
        for k in np.flatnonzero(perched[:-21, i] & ~perched[1:-20, i]) + 1:  # the first sample in the air
            climbs.append((z[k : k + 20, i].min() - z[k - 1, i] > -0.05, z[k + 18, i] > z[k - 1, i]))
    assert len(climbs) >= 8, climbs
    assert np.mean([a for a, _ in climbs]) >= 0.9 and np.mean([b for _, b in climbs]) >= 0.9, climbs


def test_bad_garden_arguments_are_one_sentence():
    with pytest.raises(UserError, match="number of butterflies"):
        Garden(0, flight3d.Controller3D([10, 9], flight3d.pd_prior([10, 9])))
    with pytest.raises(UserError, match="flutter"):
        Garden(2, flight3d.Controller3D([10, 9], flight3d.pd_prior([10, 9])), flutter=3.0)


def test_the_garden_films_and_its_frames_move(tmp_path):
    from PIL import Image, ImageSequence

    from lifelike_mj.butterfly.flight3d.garden import film_garden

    g = Garden(4, flight3d.withdrawn_file("steer"), seed=1)
    info = film_garden(tmp_path / "g.gif", g, duration_s=0.3, fps=10, width=160, height=90, camera_name="chase")
    assert info["frames"] == 3
    frames = [np.asarray(f.convert("RGB"), dtype=float) for f in ImageSequence.Iterator(Image.open(tmp_path / "g.gif"))]
    assert len(frames) == 3 and np.abs(frames[0] - frames[-1]).mean() > 0.5  # the scene changes as it flies
    with pytest.raises(UserError, match="overview or chase"):
        film_garden(tmp_path / "h.gif", g, camera_name="top")


def test_a_garden_that_diverges_says_so_in_one_sentence():
    """Euler at 1/200 s cannot fly the butterflies: the garden names the butterfly, the step and the likely cause."""
    import mujoco

    from lifelike_mj.errors import Diverged

    g = Garden(2, flight3d.withdrawn_file("steer"), seed=1, dt_s=1.0 / 200.0)
    g._phys.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    with pytest.raises(Diverged, match=r"butterfly \d of the garden diverged at step \d+: .* time step \(0.005 s\)") as e:
        g.step(2000)
    assert 0 < e.value.step <= 2000
