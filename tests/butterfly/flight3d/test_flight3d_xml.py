"""The 3D swallowtail (models/butterfly/butterfly3d.xml): mass budget, joints, signs of the angles."""

import mujoco
import numpy as np
import pytest

from lifelike_mj import paths

MODEL = paths.model_path("butterfly", "butterfly3d.xml")
#: The measured tree-nymph masses (g) whose proportions the model takes, and Oe 2010's total (g).
TREE_NYMPH = {"head": 0.02, "thorax": 0.1808, "abdomen": 0.1808, "wing": 0.0587}
TOTAL_G = 0.319


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(MODEL))


def test_masses_add_to_the_papers_total_in_the_measured_proportions(model):
    assert model.body_subtreemass[model.body("butterfly").id] * 1e3 == pytest.approx(TOTAL_G, abs=1e-9)
    whole = TREE_NYMPH["head"] + TREE_NYMPH["thorax"] + TREE_NYMPH["abdomen"] + 2 * TREE_NYMPH["wing"]
    scale = TOTAL_G / whole
    for body, want in (("wing_left", TREE_NYMPH["wing"]), ("wing_right", TREE_NYMPH["wing"]),
                       ("abdomen", TREE_NYMPH["abdomen"]), ("butterfly", TREE_NYMPH["head"] + TREE_NYMPH["thorax"])):
        assert model.body(body).mass[0] * 1e3 == pytest.approx(want * scale, abs=2e-5), body


def test_looks_mass_and_fluid_are_separate_and_nothing_drives_the_body(model):
    assert model.nu == 0 and model.opt.density == 0.0 and model.opt.viscosity == 0.0
    for g in range(model.ngeom):
        name = model.geom(g).name
        if name.endswith("_mass"):
            assert model.geom_group[g] == 4 and model.geom(name[: -len("_mass")]).id >= 0
        elif name != "ground":
            assert model.geom_group[g] == 0
    # only the drawn geoms' own mass is zero: the bodies' masses are the mass geoms' sums
    spec = mujoco.MjSpec.from_file(str(MODEL))
    assert all(g.mass == 0 for g in spec.geoms if g.classname.name == "looks")
    kinds = {model.joint(j).name: int(model.jnt_type[j]) for j in range(model.njnt)}
    hinge = int(mujoco.mjtJoint.mjJNT_HINGE)
    assert kinds == {"root": int(mujoco.mjtJoint.mjJNT_FREE), "abdomen": hinge, "flap_left": hinge,
                     "feather_left": hinge, "flap_right": hinge, "feather_right": hinge}


def _pose(model, **angles):
    d = mujoco.MjData(model)
    for name, value in angles.items():
        d.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    mujoco.mj_kinematics(model, d)
    return d


@pytest.mark.parametrize("side", ["left", "right"])
def test_the_angles_turn_the_way_their_names_say(model, side):
    rest = _pose(model)
    up = _pose(model, **{f"flap_{side}": 0.5})
    tip = f"wing_{side}_tip"
    assert up.site(tip).xpos[2] == pytest.approx(0.055 * np.sin(0.5), rel=1e-9)  # flap > 0: the wing up
    # feathering turns the wing about its flapped span: the tip stays, the leading edge (+x) goes down
    both = _pose(model, **{f"flap_{side}": 0.5, f"feather_{side}": 0.3})
    np.testing.assert_allclose(both.site(tip).xpos, up.site(tip).xpos, atol=1e-12)
    lead_rest = rest.body(f"wing_{side}").xmat.reshape(3, 3)[:, 0]
    lead = _pose(model, **{f"feather_{side}": 0.3}).body(f"wing_{side}").xmat.reshape(3, 3)[:, 0]
    assert lead_rest[2] == pytest.approx(0.0, abs=1e-12) and lead[2] == pytest.approx(-np.sin(0.3), rel=1e-9)


def test_abdomen_up_is_positive(model):
    d = _pose(model, abdomen=0.4)
    tail = d.body("abdomen").xmat.reshape(3, 3) @ np.array([-0.01, 0.0, 0.0])
    assert tail[2] == pytest.approx(0.01 * np.sin(0.4), rel=1e-9)
