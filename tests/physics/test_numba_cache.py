"""The numba cache cannot serve stale code: its folder is keyed on the whole package's source."""

import os
import shutil
import subprocess
import sys

from lifelike_mj import _numba_cache


def test_any_edit_of_any_module_selects_a_fresh_cache_folder(tmp_path):
    copy = tmp_path / "lifelike_mj"
    shutil.copytree(_numba_cache._PKG, copy, ignore=shutil.ignore_patterns("__pycache__", "*.nb?"))
    key = _numba_cache.source_key(copy)
    assert key == _numba_cache.source_key(copy)  # stable
    ann = copy / "butterfly" / "ann.py"  # a module whose functions are inlined into other modules' loops
    ann.write_text(ann.read_text() + "\n# an edit\n")
    assert _numba_cache.source_key(copy) != key
    (copy / "butterfly" / "new_module.py").write_text("x = 1\n")
    assert len({key, _numba_cache.source_key(copy)}) == 2


def _numba_cache_dir(env):
    code = "import lifelike_mj, numba; print(numba.config.CACHE_DIR)"
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          check=True).stdout.strip()


def test_importing_the_package_points_numba_at_the_keyed_folder(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    got = _numba_cache_dir(env)
    assert got == str(tmp_path / "lifelike-mj" / "numba" / _numba_cache.source_key())
    # a folder the user chose is left alone
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")
    assert _numba_cache_dir(env) == str(tmp_path / "mine")
