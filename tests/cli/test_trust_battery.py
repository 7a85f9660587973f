"""The second round of bad inputs (issue 24), against the surfaces added after the first: the 3D butterfly's files
and commands, export, the viewers' options; and, for every command, a size just over each of its limits. Each
case ends in exit status 2 with one sentence, within seconds, before anything is written (the runner of
``test_bad_input_battery``). Then concurrency: every command that writes refuses an output another run holds,
naming it, and two real processes on one output leave exactly one winner and its file.

Each case: (argv, a piece of the expected sentence, files to create first in the working folder).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest
from battery import check_refusal, snapshot

from lifelike_mj.butterfly.flight3d.controllers import withdrawn_file
from lifelike_mj.cli import main

STEER = json.loads(withdrawn_file("steer").read_text())


def c3(**changes) -> dict:
    """The (withdrawn, kept) ``steer`` controller with ``changes`` (``b_NAME``: a base entry; ``None``: the key removed)."""
    d = json.loads(json.dumps(STEER))
    for k, v in changes.items():
        if k.startswith("b_"):
            d["base"][k[2:]] = v
        elif v is None:
            d.pop(k, None)
        else:
            d[k] = v
    return d


FLY3D = ["butterfly", "fly3d", "--duration", "0.5", "--controller", "c.json"]
DEEP = "[" * 100_000 + "]" * 100_000
LONG = "a" * 300

CASES = [
    # --- the 3D controller file: types, shapes, bounds, nesting (its schema: docs/schemas/butterfly3d-controller)
    (FLY3D, "base.frequency_hz must be a number in (0, 100], got True", {"c.json": c3(b_frequency_hz=True)}),
    (FLY3D, "base.frequency_hz must be a number in (0, 100], got '12'", {"c.json": c3(b_frequency_hz="12")}),
    (FLY3D, "base.frequency_hz must be a number in (0, 100], got 100.5", {"c.json": c3(b_frequency_hz=100.5)}),
    (FLY3D, "base.offset_left must be a number in [-3.14159, 3.14159]", {"c.json": c3(b_offset_left=4.0)}),
    (FLY3D, "base must be an object, got [1, 2]", {"c.json": c3(base=[1, 2])}),
    (FLY3D, "base has an unknown key 'flap_hz'", {"c.json": c3(b_flap_hz=10.0)}),
    (FLY3D, "scale must be an object, got [1, 2]", {"c.json": c3(scale=[1, 2])}),
    (FLY3D, "scale.frequency must be a number in [0, 3.14159], got '3'", {"c.json": c3(scale={"frequency": "3"})}),
    (FLY3D, "every must be a whole number from 1 to 12,000, got 12001", {"c.json": c3(every=12001)}),
    (FLY3D, "every must be a whole number from 1 to 12,000, got 10000000", {"c.json": c3(every=10**31)}),
    (FLY3D, "every must be a whole number from 1 to 12,000, got 2.0", {"c.json": c3(every=2.0)}),
    (FLY3D, "every must be a whole number from 1 to 12,000, got True", {"c.json": c3(every=True)}),
    (FLY3D, "omega_c_rad_s must be a number in (0, 10000], got 1e+308", {"c.json": c3(omega_c_rad_s=1e308)}),
    (FLY3D, "omega_c_rad_s must be a number in (0, 10000], got '6'", {"c.json": c3(omega_c_rad_s="6")}),
    (FLY3D, "must be a whole number from 1 to 256, got", {"c.json": c3(layers=[10.0, 9.0])}),
    (FLY3D, "layers[1] must be a whole number from 1 to 256, got 257", {"c.json": c3(layers=[10, 257, 9])}),
    (FLY3D, "layers must have 2 to 6 whole numbers, got 7", {"c.json": c3(layers=[10, 4, 4, 4, 4, 4, 9])}),
    (FLY3D, "layers must be a list, got '10,9'", {"c.json": c3(layers="10,9")}),
    (FLY3D, "layers must be whole numbers running from 10 or 11 inputs to 9 outputs", {"c.json": c3(layers=[6, 1])}),
    (FLY3D, "must be a number in [-1e+06, 1e+06], got 1e+308", {"c.json": c3(weights=[1e308] * 99)}),
    (FLY3D, "must be a number in [-1e+06, 1e+06], got inf",
     {"c.json": json.dumps(c3()).replace('"weights": [', '"weights": [1e999, ', 1)}),
    (FLY3D, "weights must be a list", {"c.json": c3(weights={"a": 1})}),
    (FLY3D, "need 99 finite weights", {"c.json": c3(weights=[0.0] * 98)}),
    (FLY3D, "inputs must be 'ground' or 'air', got ['air']", {"c.json": c3(inputs=["air"])}),
    (FLY3D, "provenance must be an object, got [1]", {"c.json": c3(provenance=[1])}),
    (FLY3D, "unknown key 'wieghts' (did you mean 'weights'?)", {"c.json": {**c3(weights=None), "wieghts": []}}),
    (FLY3D, "lacks 'weights'", {"c.json": c3(weights=None)}),
    (FLY3D, "format version True", {"c.json": c3(version=True)}),
    (FLY3D, "nested too deeply", {"c.json": DEEP}),
    (FLY3D, "not strict JSON (NaN", {"c.json": '{"format": "lifelike-mj/butterfly3d-controller", "weights": [NaN]}'}),
    (["butterfly", "fly", "--controller", "c.json"], "nested too deeply", {"c.json": DEEP}),
    (["fish", "swim", "--preset", "p.json"], "nested too deeply", {"p.json": DEEP}),
    (["boids", "run", "--preset", "b.json"], "nested too deeply", {"b.json": DEEP}),
    (["butterfly", "evolve3d", "--start", "c.json"], "every must be a whole number", {"c.json": c3(every="1")}),
    (["butterfly", "garden", "--controller", "c.json"], "base must be an object", {"c.json": c3(base=3)}),
    (["export", "butterfly3d", "--out", "a.glb", "--controller", "c.json"], "scale must be an object",
     {"c.json": c3(scale=True)}),
    # --- the other formats' new bounds (numbers that reach compiled code)
    (["fish", "swim", "--preset", "p.json"], "r_max_N must be a number in [0, 1000], got 1e+300",
     {"p.json": {"format": "lifelike-mj/fish-preset", "parameters": {"r_max_N": 1e300}}}),
    (["fish", "swim", "--preset", "p.json"], "substeps must be a whole number from 1 to 100, got 4.0",
     {"p.json": {"format": "lifelike-mj/fish-preset", "parameters": {"substeps": 4.0}}}),
    (["fish", "swim", "--preset", "p.json"], "same_as must be a text",
     {"p.json": {"format": "lifelike-mj/fish-preset", "same_as": ["B-D"]}}),
    (["boids", "run", "--preset", "b.json"], "W_a[0][0] must be a number in [-1000, 1000]",
     {"b.json": {"format": "lifelike-mj/boids-preset", "W_a": [[1e9]], "W_c": [[0.01]]}}),
    (["boids", "run", "--preset", "b.json"], "settings.r_c must be a number in (0, 1000]",
     {"b.json": {"format": "lifelike-mj/boids-preset", "W_a": [[0.5]], "W_c": [[0.01]], "settings": {"r_c": 1e6}}}),
    (["butterfly", "fly", "--controller", "c.json"], "flap.frequency_hz must be a number in (0, 1000]",
     {"c.json": {"format": "lifelike-mj/butterfly-controller", "type": "constant", "parameters": {"phi_deg": 0},
                 "flap": {"frequency_hz": 1e6, "theta_min_deg": -30, "theta_max_deg": 60}}}),
    # --- export: windows and sizes before any simulation
    (["export", "fish", "--out", "a.glb", "--start", "3000", "--duration", "0.01"], "holds a single frame", {}),
    (["export", "fish", "--out", "a.glb", "--duration", "1201", "--fps", "30"], "asks for 36,031 frames; at most "
     "36,001", {}),
    (["export", "butterfly3d", "--out", "a.glb", "--garden", "500", "--start", "1662", "--duration", "5"],
     "asks for 1,000,200,000 body-steps; at most 1,000,000,000", {}),
    (["export", "boids", "--out", "a.glb", "--n", "2000", "--start", "997001", "--steps", "3000"],
     "asks for 2,000,002,000 agent-steps; at most 2,000,000,000", {}),
    (["export", "fish", "--out", LONG + ".glb"], "this file system allows 255", {}),
    (["export", "fish", "--out", f"x/{LONG}/a.glb"], "this file system allows 255", {}),
    # --- export's keys and loops
    (["export", "fish", "--out", "a.glb", "--duration", "0.5", "--loop"], "too short to blend 1 s", {}),
    (["export", "butterfly3d", "--out", "a.glb", "--task", "level", "--duration", "0.3", "--loop"],
     "too short to hold whole wing beats", {}),
    (["export", "fish", "--out", "a.glb", "--key-tolerance", "abc"], "a distance and an angle", {}),
    (["export", "fish", "--out", "a.glb", "--key-tolerance", "1mm,90deg"], "angle must be a number in [0.01, 45]", {}),
    (["butterfly", "fly3d", "--out", LONG], "this file system allows 255", {}),
    # --- the viewers' options
    (["view", "butterfly3d", "--web", "--host", "10.255.255.1"], "is not an address of this machine", {}),
    (["view", "fish", "--web", "--host", "203.0.113.7"], "is not an address of this machine", {}),
    (["view", "boids", "--steps", "0"], "--steps", {}),
    (["view", "butterfly3d", "--port", "80"], "add --web", {}),
    # --- every command at a size just over each of its limits
    (["butterfly", "assess3d", "--courses", "0-1000"], "asks for 1,001 seeds; at most 1,000", {}),
    (["butterfly", "assess3d", "--duration", "5.5"], "needs a duration of at least 6 s", {}),
    (["butterfly", "fly", "--controller", "simple_rule", "--duration", "3600", "--dt", "3.5e-6"],
     "asks for 1,028,571,429 time steps; at most 1,000,000,000", {}),
    (["butterfly", "fly", "--controller", "simple_rule", "--duration", "3600", "--dt", "3.5e-4"],
     "asks for 10,285,714 rows; at most 10,000,000", {}),
    (["butterfly", "compare", "--controller", "simple_rule", "--duration", "3600", "--dt", "3.5e-6"],
     "at most 1,000,000,000", {}),
    (["butterfly", "trim", "--dt", "1.6e-6"], "asks for 1,037,500,000 time steps; at most 1,000,000,000", {}),
    (["butterfly", "evolve", "--optimizer", "rcga", "--population", "100", "--generations", "416667", "--executor",
      "serial"], "asks for 1,000,000,800,000 steps; at most 1,000,000,000,000", {}),
    (["butterfly", "evolve3d", "--population", "100", "--generations", "781251"],
     "asks for 1,000,001,280,000 steps; at most 1,000,000,000,000", {}),
    (["butterfly", "garden", "--duration", "600", "--fps", "61", "--out", "g.mp4"], "asks for 36,600 frames", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--step", "0.01", "--max", "1.0"], "40,401 wind cells", {}),
    (["fish", "swim", "--n", "5000", "--duration", "34"], "asks for 10,200,000 track rows; at most 10,000,000", {}),
    (["fish", "swim", "--n", "5000", "--duration", "834"], "asks for 1,000,800,000 fish-steps", {}),
    (["fish", "swim", "--video", "v.mp4", "--duration", "1201", "--video-duration", "1201"], "--video-duration", {}),
    (["boids", "run", "--n", "200001", "--steps", "10000"], "asks for 2,000,010,000 agent-steps", {}),
    (["boids", "sweep", "--executor", "serial", "--x", "wa_cross=0:1:1001"], "asks for 1,001 values; at most 1,000",
     {}),
    (["boids", "sweep", "--executor", "serial", "--x", "wa_cross=0:1:2", "--seeds", "0-10000"],
     "asks for 10,001 seeds; at most 10,000", {}),
    (["boids", "sweep", "--executor", "serial", "--n", "2000", "--steps", "100000", "--x", "wa_cross=0:1:101",
      "--seeds", "0"],
     "asks for 20,200,000,000 agent-steps; at most 20,000,000,000", {}),
    (["render", "butterfly", "--out", "v.mp4", "--duration", "600", "--fps", "61"], "asks for 36,600 frames", {}),
    (["render", "fish", "--out", "v.mp4", "--duration", "600", "--fps", "61"], "control", {}),
    (["render", "boids", "--out", "v.mp4", "--steps", "100001"], "--steps", {}),
    # --- the commands the first battery left out
    (["butterfly", "timestep", "--cd", "0"], "--cd", {}),
    (["butterfly", "timestep", "--backend", "paper", "--config", "rich"], "only apply to --backend mujoco", {}),
    (["butterfly", "assess", "--controller", "c.json"], "is not a butterfly controller", {"c.json": STEER}),
    (["butterfly", "speed-limit", "--rho", "-1"], "--rho", {}),
    (["fish", "drag-check", "--fish", "3"], "has no option", {}),
    (["bench", "fish", "--long-minutes", "601"], "--long-minutes", {}),
    (["bench", "boids", "--repeats", "4"], "--repeats", {}),
    (["bench", "boids", "--max-n", "999"], "--max-n", {}),
    (["view", "butterfly", "--duration", "-1"], "--duration", {}),
    (["view", "butterfly", "--controller", "c.json"], "nested too deeply", {"c.json": DEEP}),
    (["reproduce", "fish", "--out", "afile"], "is a file", {"afile": "x"}),
    (["reproduce", "boids", "--out", "r"], "already holds report.md", {"r/report.md": "mine"}),
    (["export", "butterfly", "--out", "a.glb", "--duration", "601"], "--duration", {}),
    (["export", "butterfly", "--out", "a.glb", "--duration", "0.01"], "holds a single frame", {}),
]


def test_the_second_battery_is_large():
    assert len(CASES) >= 70


@pytest.mark.parametrize("argv, needle, files", CASES, ids=[" ".join(c[0])[:60] for c in CASES])
def test_bad_input_is_one_sentence_and_exit_2(argv, needle, files, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


# ---- concurrency: every command that writes ---------------------------------------------------------------------

#: Every command that writes, with the output another run holds (a file, or a folder of outputs).
WRITERS = [
    (["butterfly", "fly", "--controller", "simple_rule", "--duration", "1", "--out", "o"], "o"),
    (["butterfly", "evolve", "--optimizer", "rcga", "--generations", "1", "--executor", "serial", "--out", "c.json"],
     "c.json"),
    (["butterfly", "evolve", "--optimizer", "rcga", "--generations", "1", "--executor", "serial", "--out", "c.json"],
     "c.json.ckpt"),
    (["butterfly", "windmap", "--controller", "ann_paper", "--plot", "m.png"], "m.png"),
    (["butterfly", "fly3d", "--duration", "1", "--out", "o"], "o"),
    (["butterfly", "evolve3d", "--generations", "1", "--out", "c.json"], "c.json"),
    (["butterfly", "garden", "--n", "2", "--duration", "1", "--out", "g.mp4"], "g.mp4"),
    (["butterfly", "garden", "--n", "2", "--duration", "1", "--paths", "p.png"], "p.png"),
    (["fish", "swim", "--duration", "1", "--out", "o"], "o"),
    (["fish", "swim", "--duration", "1", "--video", "v.mp4"], "v.mp4"),
    (["boids", "run", "--n", "10", "--steps", "20", "--out", "o"], "o"),
    (["boids", "run", "--n", "10", "--steps", "20", "--plot", "p.png"], "p.png"),
    (["boids", "sweep", "--n", "10", "--steps", "20", "--executor", "serial", "--x", "wa_cross=0:1:2", "--out", "o"],
     "o"),
    (["render", "butterfly", "--duration", "0.1", "--out", "v.mp4"], "v.mp4"),
    (["render", "fish", "--duration", "0.1", "--out", "v.gif"], "v.gif"),
    (["render", "boids", "--steps", "10", "--out", "v.mp4"], "v.mp4"),
    (["bench", "fish", "--repeats", "1", "--out", "b.json"], "b.json"),
    (["reproduce", "fish", "--out", "r"], "r"),
    (["reproduce", "all", "--out", "r"], "r/boids"),
    (["export", "butterfly", "--duration", "0.2", "--out", "a.glb"], "a.glb"),
    (["export", "butterfly3d", "--duration", "0.2", "--out", "a.gltf"], "a.gltf"),
    (["export", "fish", "--duration", "0.2", "--out", "a.html"], "a.html"),
    (["export", "boids", "--n", "10", "--steps", "20", "--steps-per-frame", "5", "--out", "a.usda"], "a.usda"),
]


@pytest.mark.parametrize("argv, held", WRITERS, ids=[f"{' '.join(a[:2])} {h}" for a, h in WRITERS])
def test_an_output_another_run_holds_is_refused_naming_it(argv, held, tmp_path, monkeypatch, capsys, other_process):
    monkeypatch.chdir(tmp_path)
    (tmp_path / held).parent.mkdir(parents=True, exist_ok=True)
    pid = other_process.hold(tmp_path / held)
    before = snapshot(tmp_path)
    t0 = time.perf_counter()
    code = main(list(argv))
    err = capsys.readouterr().err
    assert code == 2, err
    assert "another run is writing" in err and f"process {pid}" in err and "Traceback" not in err
    assert time.perf_counter() - t0 < 20
    assert snapshot(tmp_path) == before, "something was written"


def _lifelike(*args: str, cwd: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "lifelike_mj", *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


@pytest.mark.parametrize("creature, extra", [("fish", ["--duration", "120", "--n", "30"])])
def test_two_exports_to_one_file_started_together_leave_the_first_ones_file(creature, extra, tmp_path):
    """Two real processes: the first claims the file; the second, started while the first works, exits 2 naming it;
    the file is the first one's (its seed in the file's provenance)."""
    first = _lifelike("export", creature, "--out", "a.glb", "--seed", "1", *extra, cwd=tmp_path)
    lock = tmp_path / ".a.glb.lock"
    end = time.monotonic() + 60
    while not lock.exists() and time.monotonic() < end and first.poll() is None:
        time.sleep(0.05)
    second = _lifelike("export", creature, "--out", "a.glb", "--seed", "2", *extra, cwd=tmp_path)
    out2, err2 = second.communicate(timeout=120)
    out1, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2 and "another run is writing --out" in err2 and f"process {first.pid}" in err2, err2
    from pygltflib import GLTF2

    extras = GLTF2().load(str(tmp_path / "a.glb")).asset.extras
    assert extras["parameters"]["seed"] == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.glb"]  # no lock or temporary file left


def test_two_fly3d_runs_into_one_folder_leave_the_first_ones_files(tmp_path):
    first = _lifelike("butterfly", "fly3d", "--duration", "3", "--seed", "1", "--task", "course", "--out", "o",
                      cwd=tmp_path)
    end = time.monotonic() + 60
    while not (tmp_path / ".o.lock").exists() and time.monotonic() < end and first.poll() is None:
        time.sleep(0.05)
    second = _lifelike("butterfly", "fly3d", "--duration", "3", "--seed", "2", "--task", "course", "--out", "o",
                       cwd=tmp_path)
    _o2, err2 = second.communicate(timeout=120)
    _o1, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2 and f"process {first.pid}" in err2, err2
    assert "course seed 1" in (tmp_path / "o" / "summary.json").read_text()


def test_a_file_that_appears_during_the_run_is_kept(tmp_path, monkeypatch, capsys):
    """The final rename re-checks: a file another program made while the run worked is not replaced."""
    import lifelike_mj.export as export

    monkeypatch.chdir(tmp_path)
    write = export.write_poses

    def meanwhile(poses, path, *a, **k):
        Path(path).write_text("made by someone else")
        return write(poses, path, *a, **k)

    monkeypatch.setattr(export, "write_poses", meanwhile)
    assert main(["export", "fish", "--duration", "0.2", "--out", "a.glb"]) == 2
    err = capsys.readouterr().err
    assert "appeared while this run was working" in err and "Traceback" not in err
    assert (tmp_path / "a.glb").read_text() == "made by someone else"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.glb"]


@pytest.mark.parametrize("errno_name, words", [("ENOSPC", "no space left"), ("EROFS", "read-only"),
                                               ("ENAMETOOLONG", "name is too long")])
def test_a_file_system_refusal_while_writing_is_one_sentence(errno_name, words, tmp_path, monkeypatch, capsys):
    """No space, a read-only file system or a name too long met while writing: one sentence, exit 2, nothing
    left half-written."""
    import errno
    import os

    import lifelike_mj.io as io

    monkeypatch.chdir(tmp_path)

    def refuse(path):
        raise OSError(getattr(errno, errno_name), os.strerror(getattr(errno, errno_name)), str(path))

    monkeypatch.setattr(io, "_fsync", refuse)
    assert main(["export", "fish", "--duration", "0.2", "--out", "a.glb"]) == 2
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("simulating")]
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in err, err
    assert not any(p.name.endswith(".glb") for p in tmp_path.iterdir())
