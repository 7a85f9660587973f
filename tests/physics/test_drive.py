"""Prescribed joint accelerations on a free-floating body (the 3D butterfly's wings and abdomen)."""

import mujoco
import numpy as np
import pytest

from lifelike_mj import paths
from lifelike_mj.physics.drive import prescribed_torques

DRIVEN = ("flap_left", "flap_right", "feather_left", "feather_right", "abdomen")


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_path(str(paths.model_path("butterfly", "butterfly3d.xml")))


def _state(model, seed):
    rng = np.random.default_rng(seed)
    d = mujoco.MjData(model)
    d.qpos[:3] = rng.normal(0, 0.1, 3)
    q = rng.normal(size=4)
    d.qpos[3:7] = q / np.linalg.norm(q)
    d.qpos[7:] = rng.uniform(-0.8, 0.8, model.nq - 7)
    d.qvel[:] = rng.normal(0, 3.0, model.nv)
    return d


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_driven_joints_get_exactly_the_accelerations_asked_and_the_body_nothing(model, seed):
    d = _state(model, seed)
    dofs = np.array([model.jnt_dofadr[model.joint(n).id] for n in DRIVEN])
    a_star = np.random.default_rng(10 + seed).normal(0, 500.0, len(dofs))
    mujoco.mj_forward(model, d)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, d, M)
    c = d.qfrc_bias - d.qfrc_passive
    tau = prescribed_torques(M, c, dofs, a_star)
    d.qfrc_applied[:] = 0.0
    d.qfrc_applied[dofs] = tau
    mujoco.mj_forward(model, d)
    np.testing.assert_allclose(d.qacc[dofs], a_star, rtol=1e-9, atol=1e-6)
    free = np.setdiff1d(np.arange(model.nv), dofs)
    assert np.all(d.qfrc_applied[free] == 0.0)  # nothing acts on the free body but the joints' reactions
    # the body recoils: its accelerations are not those of free fall (the wings push it)
    assert np.abs(d.qacc[free][3:]).max() > 1.0


def test_the_joints_own_inertia_alone_misses_the_recoil(model):
    """Why the drive solves the blocks: the torque M_jj a* (the joint's own inertia) gives another
    acceleration on a light free body, by tens of percent."""
    d = _state(model, 5)
    dofs = np.array([model.jnt_dofadr[model.joint(n).id] for n in DRIVEN])
    mujoco.mj_forward(model, d)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, d, M)
    a_star = np.full(len(dofs), 300.0)
    d.qfrc_applied[dofs] = M[dofs, dofs] * a_star + (d.qfrc_bias - d.qfrc_passive)[dofs]
    mujoco.mj_forward(model, d)
    assert np.abs(d.qacc[dofs] / a_star - 1.0).max() > 0.2


def test_the_compiled_drive_reads_mujoco_itself_and_gives_the_same_torques(model):
    from lifelike_mj.physics import mjabi
    from lifelike_mj.physics.drive import native_torques

    d = _state(model, 7)
    mujoco.mj_forward(model, d)
    d.qfrc_passive[:] = np.linspace(-1e-4, 1e-4, model.nv)  # as if the air had pushed already
    dofs = np.array([model.jnt_dofadr[model.joint(n).id] for n in DRIVEN], dtype=np.int64)
    free = np.setdiff1d(np.arange(model.nv), dofs).astype(np.int64)
    a_star = np.linspace(-200.0, 300.0, len(dofs))
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, d, M)
    want = prescribed_torques(M, d.qfrc_bias - d.qfrc_passive, dofs, a_star)
    got = np.empty(len(dofs))
    native_torques(model._address, d._address, mjabi.offsets_tuple(), model.nv, dofs, free, a_star,
                   np.empty(model.nv * model.nv), np.empty(model.nv), got, np.empty(len(free) * (len(free) + 2)))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)
