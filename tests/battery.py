"""The runner of the bad-input batteries (``tests/cli/test_bad_input_battery.py``, ``test_trust_battery.py``): a
command given bad input ends in exit status 2 with one sentence on stderr (no traceback), within seconds, before
anything is written."""

from __future__ import annotations

import json
import signal
import time

import pytest

from lifelike_mj.cli import main


class _Hang(Exception):
    pass


def _alarm(signum, frame):
    raise _Hang


def make_files(tmp_path, files):
    for name, content in files.items():
        path = tmp_path / name
        if name.endswith("/"):
            path.mkdir(parents=True, exist_ok=True)
            continue
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        elif isinstance(content, str):
            path.write_text(content)
        else:
            path.write_text(json.dumps(content))


def snapshot(root):
    return {(p.relative_to(root), p.stat().st_mtime_ns, p.stat().st_size) for p in root.rglob("*")}


def check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys) -> None:
    """Run ``argv`` in ``tmp_path`` after making ``files`` there: exit 2, one sentence holding ``needle`` on stderr, no
    traceback, nothing on stdout, within 10 s, and the folder unchanged."""
    monkeypatch.chdir(tmp_path)
    make_files(tmp_path, files)
    before = snapshot(tmp_path)
    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(30)
    t0 = time.perf_counter()
    try:
        code = main(list(argv))
    except _Hang:
        pytest.fail(f"no answer within 30 s: {argv}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    elapsed = time.perf_counter() - t0
    out, err = capsys.readouterr()
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("[")]  # Ray's own log lines
    assert code == 2, (argv, out, err)
    assert len(lines) == 1 and lines[0].startswith("lifelike-mj: error: "), err
    assert needle in lines[0], (needle, lines[0])
    assert "Traceback" not in err and out == ""
    assert elapsed < 10, f"{elapsed:.1f} s to refuse {argv}"
    assert snapshot(tmp_path) == before, "something was written"


def check_python_refusal(call, needle: str, error: type = None) -> None:
    """Call ``call()`` (a Python surface given bad input): a :class:`~lifelike_mj.errors.UserError` (or ``error``) in one
    sentence holding ``needle``, within 10 s (an alarm at 30 s catches a hang: a loop without a bound)."""
    from lifelike_mj.errors import UserError

    old = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(30)
    t0 = time.perf_counter()
    try:
        with pytest.raises(error or UserError) as info:
            call()
    except _Hang:
        pytest.fail(f"no answer within 30 s: {call}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    text = str(info.value)
    assert needle in text, (needle, text)
    assert "\n" not in text and text.endswith((".", "?).")), text
    assert time.perf_counter() - t0 < 10, f"{time.perf_counter() - t0:.1f} s to refuse {call}"
