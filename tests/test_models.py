"""Every MJCF in models/ loads, steps a simulated second without warnings, names everything, and
has the expected masses and wing geometry (Oe 2010 section 4: m = 0.319 g, L = 5.5 cm, W = 5 cm,
planform 2 with its centre of pressure at 0.8 L, eq. 3-6)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from lifelike_mj.butterfly import controllers
from lifelike_mj.butterfly.backends import mj as mjbackend
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.paths import model_path, models_dir
from lifelike_mj.physics.callbacks import passive_callback

MODELS = sorted(models_dir().glob("*/*.xml"))
P = ButterflyParams()


def _is_butterfly(m: mujoco.MjModel) -> bool:
    """A model of the planar backends' layout (the 3D butterfly, with feathering hinges, has its own)."""
    names = {m.body(i).name for i in range(m.nbody)}
    joints = {m.joint(j).name for j in range(m.njnt)}
    return ({"butterfly", "wing_left", "wing_right"} <= names and m.nuserdata >= mjbackend.N_USERDATA
            and "feather_left" not in joints)


def _wing_triangle(m: mujoco.MjModel, side: str) -> np.ndarray:
    """The wing's compiled mesh vertices in its body frame, projected on the wing plane (x chord, y span):
    the distinct corners of the planform (m)."""
    g = m.geom(f"wing_{side}")
    mesh = int(m.geom_dataid[g.id])
    adr, num = m.mesh_vertadr[mesh], m.mesh_vertnum[mesh]
    v = m.mesh_vert[adr:adr + num].astype(float)
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, m.geom_quat[g.id])
    body = m.geom_pos[g.id] + v @ R.reshape(3, 3).T  # mesh frame -> wing body frame
    return np.unique(np.round(body[:, :2], 7), axis=0)


def _area(corners: np.ndarray) -> float:
    """Area of the convex polygon with these corners (shoelace after sorting by angle), m^2."""
    c = corners - corners.mean(axis=0)
    order = np.argsort(np.arctan2(c[:, 1], c[:, 0]))
    x, y = corners[order, 0], corners[order, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def test_models_folder_has_the_butterflies():
    names = {p.name for p in MODELS}
    assert {"butterfly.xml", "butterfly_rich.xml"} <= names


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.name)
def test_model_steps_one_second_without_warnings(path):
    m = mujoco.MjModel.from_xml_path(str(path))
    n = int(round(1.0 / m.opt.timestep))
    if _is_butterfly(m):
        modes = ("tip", "strip")
        rule = controllers.load("simple_rule")
    else:
        modes = (None,)
    for mode in modes:
        if mode is None:
            d = mujoco.MjData(m)
            for _ in range(n):
                mujoco.mj_step(m, d)
        else:
            d = mjbackend.setup_data(m, rule, force_mode=mode)
            with passive_callback(mjbackend.COMPILED_PASSIVE):
                for _ in range(n):
                    mujoco.mj_step(m, d)
        assert d.time == pytest.approx(1.0, abs=1.5 * m.opt.timestep)
        assert np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
        warnings = {mujoco.mjtWarning(i).name: d.warning[i].number for i in range(len(d.warning))}
        assert all(v == 0 for v in warnings.values()), (path.name, mode, warnings)


@pytest.mark.parametrize("path", MODELS, ids=lambda p: p.name)
def test_everything_is_named(path):
    m = mujoco.MjModel.from_xml_path(str(path))
    unnamed = [f"body {i}" for i in range(1, m.nbody) if not m.body(i).name]
    unnamed += [f"joint {i}" for i in range(m.njnt) if not m.joint(i).name]
    unnamed += [f"geom {i}" for i in range(m.ngeom) if not m.geom(i).name]
    assert not unnamed, f"{path.name}: unnamed {', '.join(unnamed)}"


def test_paper_model_masses():
    m = mujoco.MjModel.from_xml_path(str(model_path("butterfly", "butterfly.xml")))
    assert m.body_subtreemass[m.body("butterfly").id] == pytest.approx(0.319e-3, rel=0, abs=1e-12)
    for side in ("left", "right"):
        assert m.body_mass[m.body(f"wing_{side}").id] == pytest.approx(1e-8, rel=0, abs=1e-15)


def test_rich_model_masses():
    m = mujoco.MjModel.from_xml_path(str(model_path("butterfly", "butterfly_rich.xml")))
    assert m.body_subtreemass[m.body("butterfly").id] == pytest.approx(0.319e-3, rel=0, abs=1e-12)
    assert m.body_mass[m.body("butterfly").id] == pytest.approx(0.287e-3, rel=0, abs=1e-12)
    for side in ("left", "right"):
        assert m.body_mass[m.body(f"wing_{side}").id] == pytest.approx(0.016e-3, rel=0, abs=1e-12)


@pytest.mark.parametrize("name", ["butterfly.xml", "butterfly_rich.xml"])
def test_wing_is_planform_2_with_centre_of_pressure_at_0_8_L(name):
    m = mujoco.MjModel.from_xml_path(str(model_path("butterfly", name)))
    for side, sign in (("left", 1.0), ("right", -1.0)):
        corners = _wing_triangle(m, side)
        assert len(corners) == 3
        # apex on the flap axis (the hinge, at the wing body's origin), tip edge W wide at span L
        np.testing.assert_allclose(sorted(corners[:, 1] * sign), [0.0, P.span_m, P.span_m], atol=1e-7)
        np.testing.assert_allclose(np.ptp(corners[:, 0]), P.width_m, atol=1e-7)
        assert _area(corners) == pytest.approx(P.span_m * P.width_m / 2.0, rel=1e-5)  # eq. 3: integral of W x/L
        hinge = m.joint(f"flap_{side}")
        np.testing.assert_array_equal(m.jnt_pos[hinge.id], 0.0)
        cp = m.site_pos[m.site(f"wing_{side}_cp").id]
        assert math.dist(cp, m.jnt_pos[hinge.id]) == pytest.approx(mjbackend.CP_FRACTION * P.span_m, abs=1e-12)
        assert cp[1] * sign > 0


def test_build_model_applies_mass_and_span():
    p = ButterflyParams(mass_kg=0.5e-3, span_m=0.06)
    for config in ("paper", "rich"):
        m = mjbackend.build_model(p, config)
        assert m.body_subtreemass[m.body("butterfly").id] == pytest.approx(0.5e-3, rel=0, abs=1e-12)
        for side, sign in (("left", 1.0), ("right", -1.0)):
            cp = m.site_pos[m.site(f"wing_{side}_cp").id]
            np.testing.assert_allclose(cp, [0.0, sign * 0.8 * 0.06, 0.0], atol=1e-12)
            assert _area(_wing_triangle(m, side)) == pytest.approx(0.06 * p.width_m / 2.0, rel=1e-5)


def test_every_subpackage_is_installed():
    """A non-editable install (CI's) carries every package folder: pyproject lists them all."""
    from pathlib import Path

    import pytest

    tomllib = pytest.importorskip("tomllib")  # Python 3.11+

    root = Path(__file__).resolve().parent.parent
    listed = set(tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(root).parts) for p in (root / "lifelike_mj").rglob("__init__.py")}
    assert found <= listed, sorted(found - listed)
