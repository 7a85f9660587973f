"""A first run says, in one line, that it compiles, and only while the cache is cold (lifelike_mj._numba_cache)."""

from __future__ import annotations

import pytest

from lifelike_mj import _numba_cache, progress

LINE = "compiling the 3D flight (first run only, about 40 s)\n"


@pytest.fixture
def cold(tmp_path, monkeypatch):
    """A fresh keyed cache folder, as a new source or a first install has, and a fresh process's memory."""
    monkeypatch.setattr(_numba_cache, "_FOLDER", tmp_path)
    monkeypatch.setattr(_numba_cache, "_SEEN", set())
    return tmp_path


def test_a_cold_cache_says_so_once_then_never(cold, capsys):
    assert _numba_cache.compiled("flight3d-fly") is False
    with _numba_cache.compile_notice("flight3d-fly", "the 3D flight", 40.0):
        pass
    assert capsys.readouterr().err == LINE
    with _numba_cache.compile_notice("flight3d-fly", "the 3D flight", 40.0):  # the same process, later
        pass
    assert capsys.readouterr().err == ""
    assert _numba_cache.compiled("flight3d-fly") is True
    _numba_cache._SEEN.clear()  # a later process, on the same source
    with _numba_cache.compile_notice("flight3d-fly", "the 3D flight", 40.0):
        pass
    assert capsys.readouterr().err == ""


def test_a_compile_that_fails_is_not_marked(cold, capsys):
    with pytest.raises(KeyboardInterrupt), _numba_cache.compile_notice("flight3d-fly", "the 3D flight", 40.0):
        raise KeyboardInterrupt
    assert _numba_cache.compiled("flight3d-fly") is False
    assert capsys.readouterr().err == LINE


def test_quiet_and_the_users_own_folder_say_nothing(cold, capsys, monkeypatch):
    progress.set_enabled(False)
    try:
        with _numba_cache.compile_notice("flight3d-fly", "the 3D flight", 40.0):
            pass
    finally:
        progress.set_enabled(True)
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(_numba_cache, "_FOLDER", None)  # NUMBA_CACHE_DIR set by the user: cannot be told
    monkeypatch.setattr(_numba_cache, "_SEEN", set())
    assert _numba_cache.compiled("flight3d-batch") is None
    with _numba_cache.compile_notice("flight3d-batch", "the 3D flight", 40.0):
        pass
    assert capsys.readouterr().err == ""


def test_the_line_leaves_a_running_bar_intact(capsys):
    """With a bar on screen the line goes through tqdm (the bar is cleared, the line printed, the bar redrawn)."""
    bar = progress.bar(3, "stage")
    try:
        progress.line("compiling the 3D flight (first run only, about 40 s)")
    finally:
        bar.close()
    err = capsys.readouterr().err
    assert LINE in err and "stage" in err
    progress.set_enabled(False)
    try:
        progress.line("nothing")
    finally:
        progress.set_enabled(True)
    assert "nothing" not in capsys.readouterr().err
