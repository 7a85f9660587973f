"""Flight3D's parts given apart (issue 42, point 8): the butterfly and the world as objects, the flat keywords of before
taken for one release with a note, the same flight either way."""

import warnings

import numpy as np
import pytest

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d import Butterfly, Flight3D, World, level
from lifelike_mj.butterfly.flight3d.controllers import default_base
from lifelike_mj.butterfly.flight3d.parts import BUTTERFLY_KEYWORDS, WORLD_KEYWORDS, with_force_law
from lifelike_mj.errors import UserError


def _state_after(f: Flight3D, steps: int = 200) -> np.ndarray:
    f.step(steps)
    return np.concatenate([f.data.qpos, f.data.qvel])


def test_the_grouped_and_the_flat_keywords_fly_the_same_flight():
    cmd = default_base("monarch")
    grouped = Flight3D(cmd, butterfly=Butterfly("monarch", force_law="calibrated", n_strips=4),
                       world=World(wind_to_m_s=(0.5, 0.2, 0.0), contact=True), task=level(1.5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        flat = Flight3D(cmd, animal="monarch", force_law="calibrated", n_strips=4, wind_to_m_s=(0.5, 0.2, 0.0),
                        contact=True, task=level(1.5))
    assert grouped.animal == flat.animal == "monarch" and grouped.options == flat.options and grouped.contact
    np.testing.assert_array_equal(_state_after(grouped), _state_after(flat))
    assert flat.butterfly == Butterfly("monarch", force_law="calibrated", n_strips=4)
    assert flat.world == World(wind_to_m_s=(0.5, 0.2, 0.0), contact=True)


def test_a_flat_keyword_is_taken_with_a_note_naming_its_new_place():
    checks._RENAMED.discard("Flight3D(flowers=...)")
    with pytest.warns(DeprecationWarning, match=r"Flight3D\(flowers=\.\.\.\) is now Flight3D\(world=World\(flowers"):
        f = Flight3D(controller="monarch", flowers=[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0)], ground_m=-1.0)
    assert f.world.flowers is not None and f.contact  # flowers imply contact, as before


def test_a_part_given_twice_or_of_the_wrong_kind_is_one_sentence():
    with pytest.raises(UserError, match="give the butterfly once"):
        Flight3D(butterfly=Butterfly("monarch"), animal="monarch")
    with pytest.raises(UserError, match="give the world once"):
        Flight3D(world=World(contact=True), ground_m=-1.0)
    with pytest.raises(UserError, match=r"butterfly is a flight3d.Butterfly, got 'monarch'"):
        Flight3D(butterfly="monarch")
    with pytest.raises(UserError, match="world is a flight3d.World"):
        Flight3D(world={"contact": True})
    with pytest.raises(UserError, match="give the wind once"):
        Flight3D(world=World(wind_to_m_s=(1.0, 0.0, 0.0), wind_from_m_s=(1.0, 0.0, 0.0)))
    with pytest.raises(UserError, match="unknown wing-force law"):
        Flight3D(butterfly=Butterfly(force_law="vortex"))


def test_a_controllers_animal_and_law_fill_what_the_butterfly_leaves_open():
    f = Flight3D(controller="monarch", butterfly=Butterfly(n_strips=4))
    assert f.animal == "monarch" and f.options["force_law"] == f.network.force_law
    g = Flight3D(controller="monarch", butterfly=Butterfly(force_law="exact"))
    assert g.options["force_law"] == "exact"


def test_every_flat_keyword_has_a_place_and_with_force_law_keeps_the_rest():
    assert set(BUTTERFLY_KEYWORDS) | set(WORLD_KEYWORDS) >= {
        "animal", "force_law", "params", "masses", "drag_frame", "body_areas_m2", "n_strips", "n_chord", "drive_hz",
        "omega_c", "wind_to_m_s", "wind_from_m_s", "wind_m_s", "contact", "flowers", "ground_m"}
    kw = with_force_law({"butterfly": Butterfly("monarch", n_strips=4), "dt_s": 0.001}, "strip")
    assert kw["butterfly"] == Butterfly("monarch", force_law="strip", n_strips=4) and kw["dt_s"] == 0.001
