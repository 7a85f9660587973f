"""What a hostile user of the environments meets (issue 41): a bad count of copies, a bad seed or an action that is
not finite ends in one sentence naming it; the pages in docs/envs/ are what the code renders now; and Gymnasium's
checker passes as the pages show it, on a machine without a display."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import lifelike_mj.envs  # noqa: E402,F401  (registers the environments)
from lifelike_mj.butterfly import flight3d  # noqa: E402
from lifelike_mj.envs import butterfly, butterfly3d, pages  # noqa: E402
from lifelike_mj.envs.butterfly import ButterflyPitchEnv  # noqa: E402
from lifelike_mj.envs.butterfly3d import ButterflyFlight3DEnv, ButterflyFlight3DVectorEnv  # noqa: E402
from lifelike_mj.envs.vector import ButterflyPitchVectorEnv  # noqa: E402
from lifelike_mj.errors import UserError  # noqa: E402

DOCS = Path(__file__).resolve().parents[2] / "docs" / "envs"
#: Each id with its vector form's largest count of copies.
VECTOR_IDS = {"lifelike_mj/ButterflyPitch-v0": 1_000_000, "lifelike_mj/ButterflyPitchWind-v0": 1_000_000,
              "lifelike_mj/ButterflyFlight3D-v0": 10_000}
SHORT = {"lifelike_mj/ButterflyPitch-v0": {"duration_s": 0.05}, "lifelike_mj/ButterflyPitchWind-v0": {"duration_s": 0.05},
         "lifelike_mj/ButterflyFlight3D-v0": {"duration_s": 0.05, "task": "course"}}


# ---- the count of copies ------------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", VECTOR_IDS)
@pytest.mark.parametrize("bad", [0, -1, 2.5, "4", True, np.array([2, 3]), None, 10**7])
def test_a_bad_num_envs_is_one_sentence_naming_it_and_its_range(env_id, bad):
    most = VECTOR_IDS[env_id]
    with pytest.raises(UserError, match=rf"^num_envs must be a whole number from 1 to {most}, got .+\.$"):
        gym.make_vec(env_id, num_envs=bad, vectorization_mode="vector_entry_point", **SHORT[env_id])


@pytest.mark.parametrize("env_id", VECTOR_IDS)
def test_a_numpy_integer_is_a_count_of_copies(env_id):
    env = gym.make_vec(env_id, num_envs=np.int64(2), vectorization_mode="vector_entry_point", **SHORT[env_id])
    assert env.num_envs == 2 and type(env.unwrapped.num_envs) is int
    assert env.reset(seed=0)[0].shape[0] == 2


# ---- seeds ----------------------------------------------------------------------------------------------------------

BAD_SEEDS = [-1, -(2**40), 2**32, 2.5, True, "3", np.array([1])]


@pytest.mark.parametrize("make", [lambda: ButterflyFlight3DEnv(task="course", duration_s=0.05),
                                  lambda: ButterflyPitchEnv(duration_s=0.05),
                                  lambda: gym.make("lifelike_mj/ButterflyFlight3D-v0", task="wind", duration_s=0.05)],
                         ids=["3d", "pitch", "3d-made"])
@pytest.mark.parametrize("bad", BAD_SEEDS, ids=repr)
def test_a_bad_seed_is_one_sentence_naming_it_and_its_range(make, bad):
    env = make()
    with pytest.raises(UserError, match=rf"^seed must be a whole number from 0 to {2**32 - 1}, got .+\.$"):
        env.reset(seed=bad)


@pytest.mark.parametrize("cls", [ButterflyFlight3DVectorEnv, ButterflyPitchVectorEnv])
@pytest.mark.parametrize("bad", [-1, 2.5, True, "3", [0, -5], [0, 2**32]], ids=repr)
def test_a_bad_seed_of_a_vector_env_is_one_sentence_naming_it(cls, bad):
    env = cls(num_envs=2, duration_s=0.05)
    with pytest.raises(UserError, match=rf"^seed must be a whole number from 0 to {2**32 - 1}, got .+\.$"):
        env.reset(seed=bad)


def test_the_seeds_range_is_taken_whole_and_numpy_integers_are_seeds():
    """0 and 2^32 - 1 are seeds; a NumPy integer seeds as the same int (Gymnasium alone refuses it)."""
    env = ButterflyFlight3DEnv(task="course", duration_s=0.05)
    for edge in (0, 2**32 - 1):
        env.reset(seed=edge)
    a, _ = env.reset(seed=np.int64(7))
    name_a = env.episode_task.name
    b, _ = env.reset(seed=7)
    assert np.array_equal(a, b) and env.episode_task.name == name_a
    v = ButterflyFlight3DVectorEnv(num_envs=2, task="course", duration_s=0.05)
    assert np.array_equal(v.reset(seed=np.int64(7))[0], v.reset(seed=[7, 8])[0])
    assert np.array_equal(v.reset(seed=np.array([7, 8]))[0][0], b)


def test_a_negative_course_seed_is_one_sentence():
    with pytest.raises(UserError, match=r"seed must be a whole number from 0 to 4294967295, got -1"):
        flight3d.course(-1)


# ---- actions that are not finite -----------------------------------------------------------------------------------


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf], ids=str)
def test_an_action_that_is_not_finite_is_said_to_be_so(value):
    env = ButterflyFlight3DEnv(duration_s=0.05)
    env.reset(seed=0)
    a = np.zeros(flight3d.N_ACT)
    a[4] = value
    with pytest.raises(UserError, match=rf"^the action's entry 4 \(feather_sym\) is {value}, not a finite number\.$"):
        env.step(a)
    v = ButterflyFlight3DVectorEnv(num_envs=2, duration_s=0.05)
    v.reset(seed=0)
    a = np.zeros((2, flight3d.N_ACT))
    a[1, 8] = value
    with pytest.raises(UserError, match=rf"^the actions' entry \[1, 8\] \(copy 1's frequency\) is {value}, not a finite"):
        v.step(a)
    p = ButterflyPitchEnv(duration_s=0.05)
    p.reset(seed=0)
    with pytest.raises(UserError, match="^every action must be a finite number"):
        p.step(np.array([value]))
    pv = ButterflyPitchVectorEnv(num_envs=2, duration_s=0.05)
    pv.reset(seed=0)
    with pytest.raises(UserError, match="^every action must be a finite number"):
        pv.step(np.array([0.0, value]))


def test_a_wrong_shape_is_still_said_to_be_a_shape():
    env = ButterflyFlight3DEnv(duration_s=0.05)
    env.reset(seed=0)
    with pytest.raises(UserError, match=r"^an action must have shape \(9,\) .*got shape \(8,\)\.$"):
        env.step(np.full(8, np.nan))


# ---- the pages, rendered from the code -----------------------------------------------------------------------------


@pytest.mark.parametrize("page", sorted(pages.PAGES))
def test_each_page_is_what_the_code_renders_now(page):
    """``docs/envs/<page>`` is the output of ``python -m lifelike_mj.envs.pages`` on the current code."""
    assert (DOCS / page).read_text(encoding="utf-8") == pages.render(page), (
        f"docs/envs/{page} is out of date: run python -m lifelike_mj.envs.pages")


def test_the_pages_check_says_so_when_a_page_is_stale(tmp_path):
    assert pages.main(["--out", str(tmp_path)]) == 0
    assert pages.main(["--check", "--out", str(tmp_path)]) == 0
    (tmp_path / "butterfly_flight3d.md").write_text("# stale\n")
    assert pages.main(["--check", "--out", str(tmp_path)]) == 1


def test_the_names_tables_are_what_the_environments_use():
    """The tables the pages are rendered from are the ones the environments give and the controllers read: the
    names at reset, the observation's and action's sizes, the 3D observation's bounds."""
    env = ButterflyFlight3DEnv(duration_s=0.05)
    obs, info = env.reset(seed=0)
    assert info["observation_names"] == butterfly3d.OBSERVATION_NAMES == flight3d.OBS_NAMES
    assert obs.shape == env.observation_space.shape == (len(butterfly3d.OBSERVATIONS),) == (11,)
    assert pages.names(butterfly3d.ACTIONS) == flight3d.ACTION_NAMES
    assert env.action_space.shape == (len(butterfly3d.ACTIONS),)
    assert np.array_equal(env.observation_space.high, [e.bound for e in butterfly3d.OBSERVATIONS])
    assert [e.scale for e in butterfly3d.ACTIONS] == list(flight3d.Controller3D([11, 9], np.zeros(108)).scale)
    p = ButterflyPitchEnv(duration_s=0.05)
    obs, info = p.reset(seed=0)
    assert info["observation_names"] == butterfly.OBSERVATION_NAMES == pages.names(butterfly.OBSERVATIONS)
    assert obs.shape == (len(butterfly.OBSERVATIONS),)
    page = (DOCS / "butterfly_flight3d.md").read_text(encoding="utf-8")
    assert "`Box((11,), float64)`" in page and "| 10 | `speed_ref_m_s` | m/s |" in page


@pytest.mark.parametrize("cls", [ButterflyPitchEnv, ButterflyFlight3DEnv])
def test_the_docstrings_carry_the_same_tables(cls):
    assert "{observations}" not in cls.__doc__ and "{actions}" not in cls.__doc__
    module = sys.modules[cls.__module__]
    for e in module.OBSERVATIONS:
        assert re.search(rf"\| `{e.name}` \| {re.escape(e.unit)} \|", cls.__doc__), e.name


# ---- rendering without a display: Gymnasium's checker as the pages show it ------------------------------------------


def _python_blocks() -> list[tuple[str, str]]:
    out = []
    for page in sorted(DOCS.glob("*.md")):
        for i, block in enumerate(re.findall(r"```python\n(.*?)```", page.read_text(encoding="utf-8"), flags=re.S)):
            out.append((f"{page.name}:{i}", block))
    return out


def _headless() -> dict[str, str]:
    """This process's environment without a display, and with no OpenGL backend chosen (the package chooses)."""
    return {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MUJOCO_GL")}


def test_the_pages_show_gymnasiums_plain_checker():
    """What the pages show (and the next test runs) is ``check_env`` with no check skipped."""
    checks = [b for _, b in _python_blocks() if "check_env(" in b]
    assert len(checks) == len(pages.PAGES)
    for block in [*checks, pages.CHECK.format(env_id="lifelike_mj/ButterflyPitch-v0")]:
        assert re.search(r"^check_env\(gym\.make\(\"[^\"]+\"\)\.unwrapped\)$", block, flags=re.M), block


@pytest.mark.parametrize("where, block", _python_blocks(), ids=[w for w, _ in _python_blocks()])
def test_each_python_block_of_the_pages_runs_as_written_without_a_display(where, block, tmp_path, gl_backend):
    r = subprocess.run([sys.executable, "-c", block], capture_output=True, text=True, cwd=tmp_path, env=_headless(),
                       timeout=600)
    assert r.returncode == 0, f"{where}:\n{r.stderr[-3000:]}"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a display is looked for on Linux only")
def test_without_a_display_human_is_not_offered_and_is_refused_in_one_sentence(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    for env_id in ("lifelike_mj/ButterflyPitch-v0", "lifelike_mj/ButterflyFlight3D-v0"):
        env = gym.make(env_id)
        assert env.unwrapped.metadata["render_modes"] == ["rgb_array"]
        assert type(env.unwrapped).metadata["render_modes"] == ["rgb_array", "human"]  # what it implements
        with pytest.raises(UserError, match=r"^render_mode='human' opens the MuJoCo viewer's window, which needs a display"):
            gym.make(env_id, render_mode="human")


def test_with_a_display_human_is_offered(monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")
    assert ButterflyPitchEnv().metadata["render_modes"] == ["rgb_array", "human"]
    assert ButterflyFlight3DEnv(render_mode="human").render_mode == "human"
