"""The API reference builds from the docstrings (pdoc) with the README's command as written, and documents the
public names."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def readme_api_command() -> tuple[list[str], str]:
    """The README's API-reference command: its setup part (``pip install ...``) as words, and the rest as written."""
    readme = re.sub(r"```.*?```", "", (ROOT / "README.md").read_text(encoding="utf-8"), flags=re.S)
    found = [span for span in readme.split("`")[1::2] if re.search(r"\bpdoc lifelike_mj\b", span)]
    assert len(found) == 1, found
    setup, _, rest = found[0].partition("&&")
    assert setup.strip().startswith("pip install "), found[0]  # a setup line: this machine is set up already
    return shlex.split(setup), rest.strip()


def _user_environment() -> dict[str, str]:
    """This process's environment as a user's shell has it: no MUJOCO_GL (the test session sets one), the venv's
    scripts (pdoc) first on the PATH."""
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def test_api_reference_builds_with_the_readmes_command_as_written(tmp_path):
    """``LIFELIKE_MJ_EAGER=1 pdoc lifelike_mj -o site`` run by a shell, from a folder other than the repository, with
    no ``MUJOCO_GL`` set: it failed under pdoc's import guard, which stops the child process that GLFW (MuJoCo's
    default OpenGL backend) starts when it is imported."""
    pytest.importorskip("pdoc")
    _, command = readme_api_command()
    assert command == "LIFELIKE_MJ_EAGER=1 pdoc lifelike_mj -o site", command
    r = subprocess.run(["bash", "-c", command], capture_output=True, text=True, cwd=tmp_path, env=_user_environment(),
                       timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "Warn" not in r.stderr, r.stderr[-3000:]
    site = tmp_path / "site"
    pages = {p.relative_to(site).as_posix() for p in site.rglob("*.html")}
    for page in ("lifelike_mj.html", "lifelike_mj/butterfly.html", "lifelike_mj/fish.html", "lifelike_mj/boids.html",
                 "lifelike_mj/evolve.html", "lifelike_mj/render.html", "lifelike_mj/stepper.html",
                 "lifelike_mj/butterfly/sim.html", "lifelike_mj/butterfly/flight.html", "lifelike_mj/envs/butterfly3d.html"):
        assert page in pages, page
    # every public module (no part of its path private; the command line is documented by --help) has a page
    import lifelike_mj

    root = Path(lifelike_mj.__file__).parent
    missing = []
    for f in sorted(root.rglob("*.py")):
        parts = f.relative_to(root.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts) or "cli" in parts:
            continue
        if "/".join(parts) + ".html" not in pages:
            missing.append(".".join(parts))
    assert not missing, f"no API page for {missing}"
    flight = (site / "lifelike_mj" / "butterfly.html").read_text()
    assert "PitchObservation" in flight and "Flight" in flight and "Oe, Suzuki, Yamamoto" in flight
    env3d = (site / "lifelike_mj" / "envs" / "butterfly3d.html").read_text()
    assert "speed_ref_m_s" in env3d  # the docstring's tables, filled in from the code


#: What a module a package imports is installed by: an optional dependency's import name, by its distribution.
_IMPORT_NAMES = {"usd-core": "pxr", "import-linter": "importlinter", "stable-baselines3": "stable_baselines3"}


def test_the_readmes_install_line_installs_what_the_api_reference_imports(tmp_path):
    """On a fresh install of only what the README's line installs (the package and the extras it names), the eager
    import that pdoc makes (every public name, every module) works: the optional dependencies of the other extras are
    made unimportable, and the whole package imported as pdoc imports it."""
    tomllib = pytest.importorskip("tomllib", reason="Python 3.11's tomllib reads pyproject.toml")
    words, _ = readme_api_command()
    spec = next(w for w in words if w.startswith("."))
    named = set(re.fullmatch(r"\.\[([\w,-]+)\]", spec).group(1).split(","))
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project["optional-dependencies"]
    assert named <= set(extras), named

    def dist(req: str) -> str:
        return re.match(r"[A-Za-z0-9_.-]+", req).group(0).lower()

    installed = {dist(r) for r in project["dependencies"]} | {dist(r) for e in named for r in extras[e]}
    absent = sorted({dist(r) for e in extras.values() for r in e} - installed)
    blocked = sorted({_IMPORT_NAMES.get(d, d.replace("-", "_")) for d in absent})
    assert "gymnasium" not in blocked, "the line must install gymnasium: lifelike_mj.envs imports it"
    code = f"""
import importlib, importlib.abc, pkgutil, sys
BLOCKED = {blocked!r}
class Absent(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
sys.meta_path.insert(0, Absent())
import lifelike_mj
for m in pkgutil.walk_packages(lifelike_mj.__path__, "lifelike_mj."):
    if not m.name.endswith("__main__"):
        importlib.import_module(m.name)
print("imported", len(sys.modules))
"""
    env = dict(_user_environment(), LIFELIKE_MJ_EAGER="1")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=600)
    assert r.returncode == 0, f"with {blocked} absent:\n{r.stderr[-3000:]}"


def test_the_eager_import_chooses_a_backend_without_glfw(tmp_path):
    """Under ``LIFELIKE_MJ_EAGER=1`` with ``MUJOCO_GL`` unset, ``import lifelike_mj`` sets it (to egl, osmesa or
    disable) before MuJoCo is imported, so that GLFW is never imported; a value the user set is kept."""
    if not sys.platform.startswith("linux"):
        pytest.skip("MuJoCo's default backend starts a process on import only on Linux")
    code = "import os, sys, lifelike_mj; print(os.environ.get('MUJOCO_GL'), 'glfw' in sys.modules)"
    env = dict(_user_environment(), LIFELIKE_MJ_EAGER="1")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                         timeout=600, check=True).stdout.split()
    assert out[0] in ("egl", "osmesa", "disable") and out[1] == "False", out
    kept = "import os; from lifelike_mj import _lazy; print(_lazy.offscreen_gl_for_documentation(), os.environ['MUJOCO_GL'])"
    out = subprocess.run([sys.executable, "-c", kept], capture_output=True, text=True, cwd=tmp_path,
                         env=dict(_user_environment(), MUJOCO_GL="osmesa"), timeout=600, check=True).stdout.split()
    assert out == ["None", "osmesa"], out
