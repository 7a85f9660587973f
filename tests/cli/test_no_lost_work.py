"""Nothing a user made is lost: evolve refuses to replace a finished run, a checkpoint that is the
controller file, or a file that is not a checkpoint; two runs cannot write one output."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from lifelike_mj.cli import main
from lifelike_mj.io import lock_path


@pytest.fixture
def small_problem(monkeypatch):
    from lifelike_mj.butterfly import evolution

    def small(task, backend, inputs, params, hidden=None):
        return evolution.PitchProblem(duration_s=0.2)

    monkeypatch.setattr(evolution, "make_problem", small)


def _evolve(tmp_path, *extra, out="ctrl.json"):
    return ["butterfly", "evolve", "--optimizer", "rcga", "--population", "6", "--generations", "2", "--executor",
            "serial", "--quiet", "--out", str(tmp_path / out), *extra]


def test_rerun_on_a_finished_out_is_refused_and_changes_nothing(tmp_path, capsys, small_problem):
    assert main(_evolve(tmp_path)) == 0
    ctrl, ckpt = tmp_path / "ctrl.json", tmp_path / "ctrl.json.ckpt"
    before = (ctrl.read_bytes(), ckpt.read_bytes())
    capsys.readouterr()
    assert main(_evolve(tmp_path, "--seed", "1")) == 2
    err = capsys.readouterr().err
    assert "already exists" in err and "--overwrite" in err and "Traceback" not in err
    assert (ctrl.read_bytes(), ckpt.read_bytes()) == before
    # --resume on the finished run returns it unchanged; --overwrite starts a new one
    assert main(_evolve(tmp_path, "--resume")) == 0
    assert json.loads(ctrl.read_text())["parameters"] == json.loads(before[0])["parameters"]
    assert main(_evolve(tmp_path, "--seed", "1", "--overwrite")) == 0
    assert json.loads(ctrl.read_text())["provenance"]["seed"] == 1


def test_checkpoint_equal_to_out_is_refused(tmp_path, capsys, small_problem):
    assert main(_evolve(tmp_path, "--checkpoint", str(tmp_path / "ctrl.json"))) == 2
    assert "same file" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_an_unrelated_file_is_never_turned_into_a_checkpoint(tmp_path, capsys, small_problem):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    for extra in ([], ["--overwrite"], ["--resume"]):
        assert main(_evolve(tmp_path, "--checkpoint", str(notes), *extra)) == 2
        assert "not a" in capsys.readouterr().err
        assert notes.read_text() == "my notes\n"
    assert not (tmp_path / "ctrl.json").exists()


def test_a_second_run_on_the_same_out_stops_at_once(tmp_path, capsys, small_problem, other_process):
    pid = other_process.hold(tmp_path / "ctrl.json")
    t0 = time.perf_counter()
    assert main(_evolve(tmp_path)) == 2
    assert time.perf_counter() - t0 < 5
    err = capsys.readouterr().err
    assert "another run is writing" in err and f"process {pid}" in err
    assert not (tmp_path / "ctrl.json").exists()
    other_process.close()
    assert main(_evolve(tmp_path)) == 0  # the lock is released with its holder
    assert not lock_path(tmp_path / "ctrl.json").exists() and not lock_path(tmp_path / "ctrl.json.ckpt").exists()


def test_two_concurrent_processes_one_wins(tmp_path):
    """Two real processes on one --out: the second stops with exit 2 while the first goes on to finish."""
    argv = [sys.executable, "-m", "lifelike_mj", "butterfly", "evolve", "--optimizer", "rcga", "--population", "6",
            "--generations", "1000000", "--executor", "serial", "--quiet", "--out", str(tmp_path / "c.json")]
    # runs until stopped; Ctrl-C's default restored (a shell's background job starts with SIGINT ignored)
    first = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.time() + 180
        while not (tmp_path / "c.json.ckpt").exists() and time.time() < deadline:
            time.sleep(0.1)
        second = subprocess.run(argv, capture_output=True, text=True, timeout=180)
        assert second.returncode == 2 and "another run is writing" in second.stderr, second.stderr
        first.send_signal(signal.SIGINT)
        out, err = first.communicate(timeout=60)
        assert first.returncode == 130, err[-3000:]
        assert json.loads((tmp_path / "c.json").read_text())["provenance"]["interrupted"]
    finally:
        if first.poll() is None:
            first.kill()


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie (dead, not yet reaped) counts as gone
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(") ", 1)[1][0] != "Z"
    except OSError:
        return False


def _children(pid):
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as fh:
            return [int(c) for c in fh.read().split()]
    except OSError:
        return []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_the_main_process_leaves_no_worker_alive(tmp_path):
    """SIGKILL the main process of a pooled evolve run: within 5 s no worker is left, and the reader of its
    stdout sees the end of the stream (so `$(lifelike-mj ...)` does not hang)."""
    argv = [sys.executable, "-m", "lifelike_mj", "butterfly", "evolve", "--optimizer", "rcga", "--population", "8",
            "--generations", "1000000", "--executor", "process", "--workers", "2", "--quiet", "--out",
            str(tmp_path / "c.json")]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 120
        while not (tmp_path / "c.json.ckpt").exists() and time.time() < deadline:
            time.sleep(0.1)
        workers = _children(proc.pid)
        assert len(workers) >= 2  # the pool's workers (and the resource tracker)
        proc.kill()
        proc.wait(timeout=10)
        t0 = time.time()
        while any(_alive(w) for w in workers) and time.time() - t0 < 5:
            time.sleep(0.1)
        assert not any(_alive(w) for w in workers), [w for w in workers if _alive(w)]
        assert proc.stdout.read() == b""  # EOF: nobody holds the pipe any more
    finally:
        if proc.poll() is None:
            proc.kill()


def test_ctrl_c_before_the_first_generation_exits_130_and_writes_nothing(tmp_path, capsys, small_problem,
                                                                          monkeypatch):
    from lifelike_mj.evolve import rcga

    def interrupted(run):
        raise KeyboardInterrupt

    monkeypatch.setattr(rcga, "run_rcga", interrupted)
    assert main(_evolve(tmp_path)) == 130
    err = capsys.readouterr().err
    assert "interrupted: stopped before the first generation was evaluated; nothing was written." in err
    assert not (tmp_path / "ctrl.json").exists() and not (tmp_path / "ctrl.json.ckpt").exists()


def test_an_unstable_fish_tank_exits_2_naming_the_cause_and_writes_no_measures(tmp_path, capsys):
    strong = tmp_path / "strong.json"
    strong.write_text(json.dumps({"format": "lifelike-mj/fish-preset", "version": 1, "name": "strong",
                                  "parameters": {"r_min_N": 10, "r_max_N": 20}}))
    out = tmp_path / "out"
    assert main(["fish", "swim", "--preset", str(strong), "--duration", "2", "--out", str(out), "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and "became unstable" in captured.err and "r_min_N = 10 (default 0.01)" in captured.err
    assert not (out / "measures.json").exists()


def test_an_unstable_butterfly_exits_2_naming_the_cause(capsys):
    assert main(["butterfly", "fly", "--controller", "simple_rule", "--mass-g", "0.001", "--duration", "1",
                 "--json"]) == 2
    err = capsys.readouterr().err
    assert "diverged at step" in err and "mass_kg = 1e-06 (default 0.000319)" in err
