"""Every script in examples/ runs as a user would run it (a fresh process, from the repository)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parent.parent / "examples").glob("*.py"))
NEEDS_GL = {"render_your_run.py"}
#: Examples of an optional extra: run where it is installed, skipped (with the reason) elsewhere.
NEEDS_MODULE = {"gym_sb3_ppo.py": "stable_baselines3", "gym_sb3_flight3d.py": "stable_baselines3"}


def test_there_are_examples():
    assert len(EXAMPLES) >= 5


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(script, tmp_path, request):
    if script.name in NEEDS_GL:
        request.getfixturevalue("gl_backend")
    if script.name in NEEDS_MODULE:
        pytest.importorskip(NEEDS_MODULE[script.name], reason="the rl extra (pip install torch==2.13.0 'lifelike-mj[rl]')")
    args = [str(tmp_path)] if script.name in NEEDS_GL else []
    r = subprocess.run([sys.executable, str(script), *args], capture_output=True, text=True, cwd=tmp_path,
                       env=dict(os.environ), timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    assert r.stdout.strip()
    if script.name in NEEDS_GL:
        assert {p.name for p in tmp_path.iterdir()} >= {"flight.gif", "flock.png", "tank.gif"}


def test_readme_python_runs(tmp_path):
    """The README's Python section runs as written (its blocks one after another, as in a notebook)."""
    import re

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    section = readme[readme.index("## From Python"):]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert blocks
    r = subprocess.run([sys.executable, "-c", "\n".join(blocks)], capture_output=True, text=True, cwd=tmp_path,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
