"""Every file written says where it came from: the version, the command, and every parameter."""

import json

import numpy as np
from PIL import Image

from lifelike_mj import __version__
from lifelike_mj.cli import main


def _prov(path):
    p = json.loads(path.read_text())["provenance"]
    assert p["versions"]["lifelike-mj"] == __version__ and p["versions"]["mujoco"]
    assert p["command"].startswith("lifelike-mj ")
    return p


def test_fly_records_controller_constants_and_conditions(tmp_path):
    out = tmp_path / "f"
    assert main(["butterfly", "fly", "--controller", "simple_rule", "--duration", "1", "--wind", "-2,0.5",
                 "--mass-g", "0.3", "--out", str(out)]) == 0
    p = _prov(out / "summary.json")
    assert "--wind -2,0.5" in p["command"]
    q = p["parameters"]
    assert q["wind_from_m_s"] == [-2.0, 0.5] and q["params"]["mass_kg"] == 0.3e-3 and q["dt_s"] == 1.0 / 1200.0
    assert q["controller"]["parameters"] == {"phi_up_deg": 12.77, "phi_down_deg": 0.0}
    png = Image.open(out / "flight.png")
    assert png.text["Software"] == f"lifelike-mj {__version__}" and "butterfly fly" in png.text["Description"]


def test_fish_swim_records_the_preset(tmp_path):
    out = tmp_path / "s"
    assert main(["fish", "swim", "--fish", "2", "--duration", "1", "--seed", "4", "--out", str(out)]) == 0
    q = _prov(out / "measures.json")["parameters"]
    assert q["seed"] == 4 and q["n_fish"] == 2 and q["preset"]["parameters"]["r_max_N"] == 0.03


def test_custom_boids_run_records_its_matrices_and_can_keep_the_whole_run(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    base = ["boids", "run", "--wa", "0.5,0.1;0.1,0.5", "--wc", "0.01,0;0,0.02", "--n", "40", "--steps", "300"]
    assert main(base + ["--out", str(a)]) == 0
    assert main(base + ["--out", str(b), "--record-every", "1"]) == 0
    q = _prov(a / "measures.json")["parameters"]
    assert q["W_a"] == [[0.5, 0.1], [0.1, 0.5]] and q["W_c"] == [[0.01, 0.0], [0.0, 0.02]] and q["n"] == 40
    ma, mb = (json.loads((d / "measures.json").read_text()) for d in (a, b))
    for k in ("label", "polarisation", "segregation_index", "n_groups"):  # the label does not depend on K
        assert ma[k] == mb[k], k
    steps = np.load(b / "trajectories.npz")["steps"]
    assert np.array_equal(steps, np.arange(301))


def test_videos_record_the_version_and_command(tmp_path, gl_backend):
    out = tmp_path / "v.gif"
    assert main(["render", "fish", "--out", str(out), "--duration", "0.2", "--width", "64", "--height", "48"]) == 0
    comment = Image.open(out).info["comment"].decode()
    assert comment.startswith(f"lifelike-mj {__version__}; lifelike-mj render fish --out ")
