"""The largest garden and flock the help texts and docstrings allow run, once (issue 41: a maximum that is documented
is a maximum that works); the largest tank is run in ``tests/fish/test_fish_trust.py``. Their peak memory and time
are measured by ``benchmarks/limits.py`` (``docs/performance.md``). Beyond the cost bound, the same requests are
refused before any work with the bound in the sentence."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from lifelike_mj.errors import UserError


@pytest.mark.slow
def test_the_largest_garden_steps():
    """``Garden(n=500)`` (``--garden`` and ``garden --n`` stop at 500 too): built, stepped, drawn."""
    from lifelike_mj.butterfly import flight3d
    from lifelike_mj.butterfly.flight3d.garden import Garden

    assert flight3d.Garden is Garden
    g = Garden(500, seed=1)
    g.step(12)
    g.sync()
    pos = g.state()["position_m"]
    assert pos.shape == (500, 3) and np.isfinite(pos).all()
    with pytest.raises(UserError, match="the number of butterflies must be a whole number from 1 to 500, got 501"):
        Garden(501)


@pytest.mark.slow
def test_the_largest_flock_steps_and_is_measured():
    """A million agents (the command line's ``--n`` bound) in a box wide enough for the paper's neighbour counts:
    stepped and measured (the k-d tree's measures); in the paper's own 20-unit box the same flock is refused before
    any work, since each agent would see about 48,000 neighbours."""
    from lifelike_mj import boids
    from lifelike_mj.boids import metrics as M
    from lifelike_mj.boids.sim import MAX_FLOCK as MAX_AGENTS
    from lifelike_mj.cli.boids import MAX_AGENTS as CLI_MAX

    assert CLI_MAX == MAX_AGENTS  # one bound for both faces

    wide = replace(boids.load_preset("5a"), box=300.0)
    f = boids.Flock(wide, n=MAX_AGENTS, seed=0)
    f.step(5)
    s = f.state()
    m = M.frame_measures(s["position_box"], s["velocity_box_per_step"], s["type"], box=300.0)
    assert np.isfinite(s["position_box"]).all() and m["n_groups"] >= 1 and 0.0 <= m["polarisation"] <= 1.0
    with pytest.raises(UserError, match="see about 47,713 neighbours each"):
        boids.Flock(n=MAX_AGENTS, seed=0).step(3)  # 1.4e11 visits: about 40 minutes


def test_a_flock_too_dense_to_step_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    from battery import check_refusal

    from lifelike_mj import boids
    from lifelike_mj.boids.sim import MAX_FLOCK

    check_refusal(["boids", "run", "--n", "1000000", "--steps", "10"], "4.77e+11 neighbour visits over 10 steps",
                  {}, tmp_path, monkeypatch, capsys)
    with pytest.raises(UserError, match="1,000,000 agents in a box 20 units wide"):
        boids.Flock(n=MAX_FLOCK).record(10)
    with pytest.raises(UserError, match="the number of agents must be a whole number from 2 to 1000000"):
        boids.Flock(n=MAX_FLOCK + 1)
    boids.Flock(n=300).step(10)  # the paper's flock is far inside the bound


def test_a_flock_is_checked_as_the_command_line_checks_it():
    from lifelike_mj import boids

    with pytest.raises(UserError, match="seed must be a whole number from 0 to 4294967295, got 1180591620717411303424"):
        boids.Flock(seed=2**70)
    with pytest.raises(UserError, match="params must be BoidParams"):
        boids.Flock(params="5a")
    with pytest.raises(UserError, match="seed must be a whole number from 0 to 4294967295, got -1"):
        boids.Flock(n=10).reset(seed=-1)
