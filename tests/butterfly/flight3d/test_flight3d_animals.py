"""Real wings: the monarch's measured outline as fore and hind wing, its exact air force, its inertia and its
drawing; the planform geometry underneath (triangulation, area moments, lamina inertia)."""

import math

import mujoco
import numpy as np
import pytest
from matplotlib.path import Path

from lifelike_mj.butterfly.flight3d import animals
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.kinematics import Kinematics, KinematicsCommand
from lifelike_mj.errors import UserError
from lifelike_mj.physics import planform
from lifelike_mj.physics.callbacks import passive_callback

MONARCH = animals.animal("monarch")
BUSY = KinematicsCommand(frequency_hz=10.2, amplitude_left=1.0, amplitude_right=0.9, offset_right=0.1,
                         feather_mean_left=0.2, feather_amplitude_left=0.6, feather_amplitude_right=0.5,
                         feather_phase=1.0, abdomen_mean=-0.3, abdomen_amplitude=0.25, abdomen_phase=0.5)


@pytest.fixture(scope="module")
def monarch_model():
    return mj3d.build_model(animal="monarch")


def _raster(polygons, n=1500):
    """Independent check of the closed forms: points of a fine grid inside any of the polygons."""
    pts = np.concatenate(polygons)
    lo, hi = pts.min(0), pts.max(0)
    xs = lo[0] + (np.arange(n) + 0.5) / n * (hi[0] - lo[0])
    ys = lo[1] + (np.arange(n) + 0.5) / n * (hi[1] - lo[1])
    X, Y = np.meshgrid(xs, ys)
    grid = np.c_[X.ravel(), Y.ravel()]
    inside = np.zeros(len(grid), dtype=bool)
    for poly in polygons:
        inside |= Path(poly).contains_points(grid)
    return grid[inside], (hi[0] - lo[0]) * (hi[1] - lo[1]) / n / n


def test_ear_clipping_covers_a_concave_polygon_exactly_and_refuses_a_crossing_one():
    comb = np.array([[0, 0], [4, 0], [4, 3], [3, 3], [3, 1], [2, 1], [2, 3], [1, 3], [1, 1], [0, 1.0]])
    for poly in (comb, comb[::-1]):
        tris = planform.triangulate(poly)
        assert len(tris) == len(poly) - 2
        u, v = tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
        areas = 0.5 * (u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
        assert (areas > 0).all()  # every triangle counter-clockwise, none folded over
        assert areas.sum() == pytest.approx(abs(planform.signed_area(poly)), rel=1e-14)
    assert planform.signed_area(comb) == pytest.approx(4 + 2 * 2)
    with pytest.raises(UserError, match="crosses itself"):
        planform.triangulate(np.array([[0, 0], [2, 2], [2, 0], [0, 1.0]]))
    with pytest.raises(UserError, match="at least three"):
        planform.triangulate(np.array([[0, 0], [1, 1.0]]))


def test_the_triangles_area_moments_are_ellingtons_closed_forms():
    """Chord proportional to span (the paper's planform 2): r_k^k = 2 / (k + 2), so r1, r2, r3 = 0.667, 0.707,
    0.737 whatever the triangle's width."""
    tris = planform.triangulate(np.array([[0.0, 0.0], [-0.02, 0.055], [0.03, 0.055]]))
    m = planform.area_moments(tris)
    assert m["area_m2"] == pytest.approx(0.5 * 0.05 * 0.055, rel=1e-14)
    for k in (1, 2, 3):
        assert m[f"r{k}"] == pytest.approx((2.0 / (k + 2)) ** (1.0 / k), rel=1e-13)


def test_the_monarch_outline_is_the_measured_chord_table():
    """Area and moments from the triangles equal those of the measured leading and trailing edges integrated
    along the span (an independent computation), and the radii are the butterfly's, not the triangle's."""
    e = animals.MONARCH_EDGES_CM * 1e-2
    r = np.linspace(0.0, e[-1, 0], 400_001)
    c = np.interp(r, e[:, 0], e[:, 2]) - np.interp(r, e[:, 0], e[:, 3])
    S = np.trapezoid(c, r)
    R = e[-1, 0]
    m = MONARCH.moments
    assert m["area_m2"] == pytest.approx(S, rel=1e-9)
    assert 12.6e-4 < S < 12.8e-4  # 12.69 cm^2 per side
    for k in (1, 2, 3):
        want = (np.trapezoid(c * r**k, r) / (S * R**k)) ** (1.0 / k)
        assert m[f"r{k}"] == pytest.approx(want, rel=1e-8)
    assert m["r2"] == pytest.approx(0.543, abs=0.001) and m["r3"] == pytest.approx(0.580, abs=0.001)
    # fore and hind wing: two surfaces, together the outline, the fore wing the larger (57 %)
    fore, hind = (planform.area_moments(planform.triangulate(s), R)["area_m2"] for s in MONARCH.surfaces)
    assert fore + hind == pytest.approx(S, rel=1e-12)
    assert 0.55 < fore / S < 0.60


def test_the_wing_inertia_is_a_plate_over_the_outline(monarch_model):
    """The compiled wing body's mass, mass centre and inertia equal a fine raster of the outline with the
    measured 0.0251 g spread evenly (and the whole animal weighs the measured 0.3079 g)."""
    m = monarch_model
    assert m.body_subtreemass[m.body("butterfly").id] == pytest.approx(MONARCH.mass_kg, rel=1e-12)
    assert MONARCH.mass_kg == pytest.approx(0.3079e-3, rel=1e-12)
    pts, da = _raster(MONARCH.surfaces)
    assert len(pts) * da == pytest.approx(MONARCH.moments["area_m2"], rel=2e-3)
    mass = MONARCH.mass_wing_kg
    com = pts.mean(0)
    d = pts - com
    I_want = mass * np.array([[np.mean(d[:, 1] ** 2), -np.mean(d[:, 0] * d[:, 1])],
                              [-np.mean(d[:, 0] * d[:, 1]), np.mean(d[:, 0] ** 2)]])
    for side, sign in (("left", 1.0), ("right", -1.0)):
        b = m.body(f"wing_{side}")
        assert b.mass[0] == pytest.approx(mass, rel=1e-12)
        np.testing.assert_allclose(b.ipos, [com[0], sign * com[1], 0.0], atol=2e-5)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, b.iquat)
        R = R.reshape(3, 3)
        inertia = R @ np.diag(b.inertia) @ R.T
        want = I_want * np.array([[1, sign], [sign, 1]])
        np.testing.assert_allclose(inertia[:2, :2], want, rtol=0, atol=5e-3 * np.abs(want).max())
        assert inertia[2, 2] == pytest.approx(inertia[0, 0] + inertia[1, 1], rel=1e-9)  # a plate


def _mesh_area(m, geom):
    """Area of a drawn wing slab's face (half of its faces parallel to the slab, the rim left out)."""
    g = m.geom(geom)
    mid = int(m.geom_dataid[g.id])
    v = m.mesh_vert[m.mesh_vertadr[mid] : m.mesh_vertadr[mid] + m.mesh_vertnum[mid]]
    f = m.mesh_face[m.mesh_faceadr[mid] : m.mesh_faceadr[mid] + m.mesh_facenum[mid]]
    cross = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    normal = np.linalg.svd(v - v.mean(0))[2][2]  # the slab's thin direction
    flat = np.abs(cross @ normal) > 0.99 * np.linalg.norm(cross, axis=1)
    return 0.25 * np.linalg.norm(cross[flat], axis=1).sum()


def test_the_drawn_wings_are_the_outline_the_air_pushes(monarch_model):
    m = monarch_model
    for side in ("left", "right"):
        areas = [_mesh_area(m, f"wing_{side}"), _mesh_area(m, f"wing_{side}_1")]
        want = [planform.area_moments(planform.triangulate(s))["area_m2"] for s in MONARCH.surfaces]
        np.testing.assert_allclose(areas, want, rtol=1e-6)
        assert m.geom(f"wing_{side}").group[0] == 0 and m.geom(f"wing_{side}_1").group[0] == 0  # drawn


def test_the_stroke_plane_is_tilted_with_the_top_of_the_stroke_rearward(monarch_model):
    """The monarch's stroke plane lies 25.4 deg from the body's transverse plane: raising a wing carries its
    tip up and back, lowering it down and forward."""
    m = monarch_model
    d = mujoco.MjData(m)
    d.qpos[3] = 1.0
    q, _, _ = mj3d.driven_dofs(m)
    tips = {}
    for angle in (-0.8, 0.0, 0.8):
        d.qpos[q[0]] = angle
        mujoco.mj_kinematics(m, d)
        tips[angle] = d.site_xpos[m.site("wing_left_tip").id] - d.xpos[m.body("wing_left").id]
    up, down = tips[0.8] - tips[0.0], tips[-0.8] - tips[0.0]
    assert up[2] > 0 and up[0] < 0 and down[2] < 0 and down[0] > 0
    axis = d.xmat[m.body("wing_left").id].reshape(3, 3)[:, 0]  # the flap axis
    assert math.degrees(math.atan2(axis[2], axis[0])) == pytest.approx(25.4, abs=1e-9)


def _monarch_state(m, law, seed=3):
    k = Kinematics(BUSY)
    k.advance(0.021)
    d = mj3d.setup_data(m, k, force_law=law, air_m_s=(0.4, -0.2, 0.3), animal="monarch")
    rng = np.random.default_rng(seed)
    q = rng.normal(size=4)
    d.qpos[3:7] = q / np.linalg.norm(q)
    d.qvel[:] = rng.normal(0, 2, m.nv)
    d.time = 0.0125
    mj3d.load_kinematics(d, k)
    return d


@pytest.mark.parametrize("law", ["exact", "strip", "quasi_steady"])
def test_the_compiled_callback_equals_its_python_twin_on_the_monarch(monarch_model, law):
    m = monarch_model
    d = _monarch_state(m, law)
    got = []
    for cb in (mj3d.COMPILED_PASSIVE, mj3d.python_passive):
        with passive_callback(cb):
            mujoco.mj_forward(m, d)
        got.append((d.qfrc_passive.copy(), d.userdata[mj3d.U_OUT : mj3d.U_OUT + mj3d.N_OUT].copy()))
    scale = np.abs(got[1][0]).max()
    assert scale > 1e-5
    np.testing.assert_allclose(got[0][0], got[1][0], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(got[0][1], got[1][1], rtol=0, atol=1e-12 * np.abs(got[1][1]).max())


def test_the_exact_force_over_the_outline_is_the_integral_over_it():
    """On the measured outline the exact law equals eq. 1 summed over a fine raster of the fore and hind wing
    (an independent quadrature), also where the normal speed changes sign across the wing; the panel laws'
    strips come within 0.1 % of it."""
    rng = np.random.default_rng(7)
    p = mj3d.ButterflyParams()
    tris, rc = mj3d.wing_triangles(p, "monarch")
    pts, da = _raster(MONARCH.surfaces, 1000)
    for trial in range(3):
        q = rng.normal(size=4)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
        R = R.reshape(3, 3)
        s0 = rng.uniform(0.3, 1.0)
        side = 1.0 if trial % 2 == 0 else -1.0
        omega = R @ np.array([-3.0 * side * s0 / MONARCH.span_m, rng.normal(0, 40.0), rng.normal(0, 5.0)])
        lin = R @ np.array([rng.normal(), rng.normal(), s0])
        exact = np.zeros(15)
        mj3d.wing_exact(side, R, lin, omega, p.rho, p.cd, tris.ravel(), len(tris), rc, exact)
        where = pts[:, :1] * R[:, 0][None, :] + side * pts[:, 1:] * R[:, 1][None, :]
        vn = (lin[None, :] + np.cross(omega[None, :], where)) @ R[:, 2]
        assert vn.min() < 0.0 < vn.max()  # the sign changes across the wing
        dF = -0.5 * p.rho * p.cd * vn * np.abs(vn) * da
        force = dF.sum() * R[:, 2]
        moment = np.cross(where, dF[:, None] * R[:, 2][None, :]).sum(0)
        np.testing.assert_allclose(exact[:3], force, rtol=0, atol=3e-3 * np.abs(force).max())
        np.testing.assert_allclose(exact[3:6], moment, rtol=0, atol=3e-3 * np.abs(moment).max())
        pan = mj3d.outline_panels(MONARCH, n_strips=20, n_chord=4)
        got = np.zeros(15)
        mj3d.wing_panels(2, pan.ravel(), len(pan), side, R, lin, omega, p.rho, p.cd, np.ones(3), got)
        assert np.abs(got[:6] - exact[:6]).max() < 1e-3 * np.abs(exact[:6]).max()


def test_measured_wings_refuse_the_papers_tip_law_and_mass_layout(monarch_model):
    with pytest.raises(UserError, match="tip-speed law"):
        mj3d.setup_data(monarch_model, Kinematics(), force_law="tip", animal="monarch")
    with pytest.raises(UserError, match="mass layout"):
        mj3d.build_model(masses="paper", animal="monarch")
    with pytest.raises(UserError, match="unknown butterfly 'monach'.*monarch"):
        animals.animal("monach")


def test_a_controller_carries_its_butterfly_through_its_file_and_into_a_flight(tmp_path):
    """A controller evolved on the monarch says so in its file; loading it flies the monarch's model (its
    masses), while the shipped controllers (no "animal" key) keep flying the swallowtail they were evolved on."""
    import json

    from lifelike_mj.butterfly import flight3d

    res, ctrl = flight3d.evolve(flight3d.TASK_SETS["steer"]()[:1], tmp_path / "m.json", population=4, generations=1,
                                duration_s=0.25, progress=False, animal="monarch")
    data = json.loads((tmp_path / "m.json").read_text())
    assert data["animal"] == "monarch" and data["provenance"]["problem"]["animal"] == "monarch"
    assert data["base"]["frequency_hz"] == pytest.approx(10.2)  # the monarch's base kinematics
    f = flight3d.Flight3D(controller=tmp_path / "m.json")
    assert f.animal == "monarch"
    assert f.model.body_subtreemass[1] == pytest.approx(MONARCH.mass_kg, rel=1e-12)
    steer = flight3d.Flight3D(controller=flight3d.withdrawn_file("steer"))
    assert steer.animal == "swallowtail" and steer.model.body_subtreemass[1] == pytest.approx(0.319e-3, rel=1e-9)
    assert data["force_law"] == "exact" and f.options["force_law"] == "exact"
    qs = dict(data, force_law="quasi_steady")
    (tmp_path / "qs.json").write_text(json.dumps(qs))
    assert flight3d.Flight3D(controller=tmp_path / "qs.json").options["force_law"] == "quasi_steady"
    assert flight3d.Flight3D(controller=tmp_path / "qs.json", force_law="exact").options["force_law"] == "exact"
    for key, value in (("animal", "moth"), ("force_law", "tip")):
        (tmp_path / "bad.json").write_text(json.dumps(dict(data, **{key: value})))
        with pytest.raises(UserError, match=key):
            flight3d.load_controller(tmp_path / "bad.json")


def test_the_exported_rig_draws_the_outline_the_air_pushes():
    """The rig an animator gets (glTF skin, USD skeleton) carries the monarch's wings as the model draws them:
    each surface's upper face, the same area as the outline the force integrates over, bound to its wing's bone,
    in the monarch's pattern (orange ground, black margin)."""
    from lifelike_mj.butterfly import look
    from lifelike_mj.butterfly.flight3d.flight import Flight3D
    from lifelike_mj.export.poses import record_poses

    f = Flight3D(KinematicsCommand(frequency_hz=10.2), animal="monarch")
    poses = record_poses(f, 0.05, fps=30.0)
    (rig,) = look.rigs(poses)
    assert rig.extras["pattern"] == "monarch"
    for side in ("left", "right"):
        surfaces = look.outline_surfaces(f.model, f.model.body(f"wing_{side}").id)
        assert len(surfaces) == 2
        area = 0.0
        for v, t, _ in surfaces:
            a, b, c = v[t[:, 0], :2], v[t[:, 1], :2], v[t[:, 2], :2]
            twice = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
            assert (twice > 0).all()  # every upper-face triangle faces up
            area += 0.5 * twice.sum()
        assert area == pytest.approx(MONARCH.moments["area_m2"], rel=1e-6)
    wing = next(p for p in rig.mesh.parts if p[0].name == "wing")[0]
    img = wing.image.reshape(-1, 4)[:, :3].astype(int)
    orange = np.all(np.abs(img - [235, 120, 20]) < 60, axis=1).mean()
    black = np.all(img < 40, axis=1).mean()
    assert orange > 0.2 and black > 0.1


def test_a_butterfly_with_legs_stands_on_the_ground_with_its_wings_closed():
    """With contact, the monarch's legs carry it: dropped from 8 mm with its wings closed over its back, it stands
    on its four feet, upright and still (within 0.1 mm and 1 deg over a second); the wings, the body and the
    abdomen touch nothing. Without contact (the flight model) it falls through the ground."""
    import math

    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    closed = KinematicsCommand(frequency_hz=10.2, offset_left=math.radians(85.0), offset_right=math.radians(85.0),
                               amplitude_left=0.0, amplitude_right=0.0, abdomen_mean=-0.3)
    f = Flight3D(closed, animal="monarch", contact=True, start_m=(0.0, 0.0, -4.0 + 0.008))
    f.step(400)
    before = f.data.qpos[:7].copy()
    f.step(800)
    assert np.abs(f.data.qpos[:3] - before[:3]).max() < 1e-4
    att = np.degrees(f.state()["attitude_rad"])
    assert abs(att[0]) < 1.0 and abs(att[1]) < 5.0
    m = f.model
    touching = {m.geom(int(g)).name for c in f.data.contact[: f.data.ncon] for g in (c.geom1, c.geom2)}
    assert touching == {"ground", "leg_0_left", "leg_0_right", "leg_1_left", "leg_1_right"}
    g = Flight3D(closed, animal="monarch", start_m=(0.0, 0.0, -4.0 + 0.008))
    g.step(400)
    assert g.data.qpos[2] < -4.2 and g.data.ncon == 0


def test_a_garden_of_monarchs_draws_and_flies_monarchs():
    """A garden flown by the monarch controller: its physics is the monarch's (masses, the quasi-steady law the
    controller keeps) and its drawing scene shows monarchs (their measured outlines, in orange)."""
    from lifelike_mj.butterfly.flight3d.garden import Garden

    g = Garden(2, "monarch", seed=3, n_flowers=3)
    assert g.controller.animal == "monarch" and g._force_law == "quasi_steady"
    assert g._phys.body_subtreemass[1] == pytest.approx(MONARCH.mass_kg, rel=1e-12)
    names = {g.model.geom(i).name for i in range(g.model.ngeom)}
    assert {"b0_wing_left", "b0_wing_left_1", "b1_wing_right_1"} <= names
    g.step(80)
    assert np.isfinite(g._batch.records[:, 0]).all()
