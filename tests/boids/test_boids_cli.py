"""Boids commands and sweeps: JSON keys, trajectories on disk, one-sentence errors, and the same
sweep table on the serial, the process-pool and the Ray evaluator."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lifelike_mj.boids.experiments import LABELS, OUTPUTS, Sweep, apply_axis, run_sweep
from lifelike_mj.boids.presets import load_preset
from lifelike_mj.cli import main
from lifelike_mj.errors import UserError


def test_boids_run_json_plot_and_trajectories(capsys, tmp_path):
    code = main(["boids", "run", "--preset", "5a", "--n", "120", "--steps", "300", "--json",
                 "--plot", str(tmp_path / "p.png"), "--out", str(tmp_path)])
    out = json.loads(capsys.readouterr()[0])
    assert code == 0 and out["label"] in LABELS
    for key in ("segregation_index", "centroid_distance", "radius_ratio", "radial_sorting_error", "n_groups",
                "polarisation"):
        assert key in out, key
    lines = (tmp_path / "trajectories.csv").read_text().splitlines()
    assert lines[0] == "step,agent,type,x,y,z,vx,vy,vz" and len(lines) > 120
    z = np.load(tmp_path / "trajectories.npz")
    assert z["positions"].shape[1:] == (120, 3) and (tmp_path / "p.png").stat().st_size > 0


@pytest.mark.parametrize("argv", [
    ["boids", "run", "--preset", "9z"],
    ["boids", "run", "--wa", "0.5,0.1;0.1", "--wc", "0.01,0;0,0.01"],
    ["boids", "run", "--wa", "0.5,0.1;0.1,0.5", "--wc", "0.01"],
    ["boids", "run", "--wa", "0.5,0.1;0.1,0.5"],
    ["boids", "run", "--n", "1"],
    ["boids", "run", "--dims", "4"],
    ["boids", "sweep", "--x", "wq=0:1:3"],
    ["boids", "sweep", "--x", "wa_cross=0:1"],
    ["boids", "sweep", "--seeds", "a-b", "--x", "wa_cross=0:1:2"],
])
def test_boids_bad_input_exit_2(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr()[1]
    assert err.startswith("lifelike-mj: error:") and err.count("\n") == 1


def test_r_s_not_below_r_a_is_an_error(tmp_path, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"format": "lifelike-mj/boids-preset", "version": 1, "name": "bad",
                               "W_a": [[0.5]], "W_c": [[0.01]], "settings": {"r_s": 3.0}}))
    assert main(["boids", "run", "--preset", str(bad)]) == 2
    assert "R_s" in capsys.readouterr()[1]


def test_sweep_axes():
    p = load_preset("5a")
    assert apply_axis(p, "wa_cross", -0.2).wa == ((0.5, -0.2), (-0.2, 0.5))
    assert apply_axis(p, "wc_10", 0.3).wc == ((0.01, 0.01), (0.3, 0.01))
    assert apply_axis(p, "wa", 0.1).wa == ((0.1, 0.1), (0.1, 0.1))
    with pytest.raises(UserError):
        apply_axis(p, "wa_22", 0.1)


def test_sweep_same_table_on_serial_and_process():
    sweep = Sweep(load_preset("5a"), ("wa_cross",), n=80, n_steps=200)
    a = run_sweep(sweep, [[0.5, -0.2]], [0, 1], executor="serial")
    b = run_sweep(sweep, [[0.5, -0.2]], [0, 1], executor="process", workers=2)
    assert a["rows"] == b["rows"] and len(a["rows"]) == 4
    assert set(a["rows"][0]) >= set(OUTPUTS) | {"seed", "wa_cross"}


def test_sweep_same_table_on_ray():
    """The sweep on the project's Ray evaluator (the one the evolution uses) gives the serial table."""
    ray = pytest.importorskip("ray")
    sweep = Sweep(load_preset("4c"), ("wc_cross",), n=80, n_steps=200)
    a = run_sweep(sweep, [[0.002, 0.006]], [3], executor="serial")
    started = not ray.is_initialized()  # another test of this process may have left its cluster running
    if started:
        ray.init(num_cpus=2, include_dashboard=False)
    try:
        b = run_sweep(sweep, [[0.002, 0.006]], [3], executor="ray", workers=2)
    finally:
        if started:
            ray.shutdown()
    assert a["rows"] == b["rows"] and len(a["rows"]) == 2
