"""A network trained through NetworkInputs/NetworkActions (as an RL library would) leaves as a controller
file that flies the same flight: the weights' order, the input scaling and the output's G are right."""

import numpy as np
import pytest

pytest.importorskip("gymnasium")

from lifelike_mj.butterfly import Flight, ann  # noqa: E402
from lifelike_mj.envs.butterfly import ButterflyPitchEnv  # noqa: E402
from lifelike_mj.envs.policies import NetworkActions, NetworkInputs, network_controller  # noqa: E402


def _forward(layers, x):
    """The network as an RL library computes it: hidden layers G(W x + b), the output W x + b."""
    for w, b in layers[:-1]:
        x = np.array([ann.transfer(float(s)) for s in w @ x + b])
    w, b = layers[-1]
    return w @ x + b


def test_an_exported_network_flies_what_it_flew_in_the_env():
    rng = np.random.default_rng(3)
    layers = [(rng.normal(0, 1.0, (5, 6)), rng.normal(0, 0.3, 5)), (rng.normal(0, 1.0, (4, 5)), rng.normal(0, 0.3, 4)),
              (rng.normal(0, 1.0, (1, 4)), rng.normal(0, 0.3, 1))]
    env = NetworkActions(NetworkInputs(ButterflyPitchEnv(duration_s=1.0)))
    obs, _ = env.reset()
    ys, total, done = [], 0.0, False
    while not done:
        obs, r, term, trunc, _ = env.step(np.clip(_forward(layers, obs), -2.0, 2.0))
        ys.append(env.unwrapped.flight.observation().altitude_m)
        total, done = total + r, term or trunc
    ctrl = network_controller(layers)
    assert ctrl.parameters["layers"] == [6, 5, 4, 1]
    tr = Flight(ctrl).record(duration_s=1.0)
    np.testing.assert_allclose(tr.y[1:], ys, rtol=1e-9, atol=1e-12)
    assert tr.fitness == pytest.approx(total, rel=1e-9)
    assert np.ptp(tr.phi) > 0.05  # the network moved the pitch: the test compares flights that differ by control


def test_the_wrappers_refuse_what_they_cannot_do():
    from lifelike_mj.errors import UserError

    with pytest.raises(UserError, match="action_mode='dphi'"):
        NetworkActions(ButterflyPitchEnv(action_mode="phi"))
