"""``lifelike-mj butterfly design3d``: bad input refused before any work; a controller file written from the shipped
averaged model, read back, flown by ``fly3d`` and refused, in one sentence, where only network controllers fly."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from battery import check_refusal

from lifelike_mj.cli import main

MODEL = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "monarch_model.json"

CASES = [
    (["butterfly", "design3d", "--out", "c.json", "--model", "nowhere.json"], "nowhere.json", {}),
    (["butterfly", "design3d", "--out", "c.json", "--model", "m.json"], "averaged model m.json", {"m.json": "[1, 2]"}),
    (["butterfly", "design3d", "--out", "c.json", "--model", "m.json"], "points must have 2 to",
     {"m.json": json.dumps({"animal": "monarch", "force_law": "calibrated", "points": []})}),
    (["butterfly", "design3d", "--out", "c.json", "--speeds", "9"], "within 0.25", {}),
    (["butterfly", "design3d", "--out", "c.json"], "already exists", {"c.json": "{}"}),
    (["butterfly", "design3d", "--out", "c.txt"], ".json", {}),
]


@pytest.mark.parametrize("argv,needle,files", CASES, ids=[" ".join(c[0][2:]) for c in CASES])
def test_design3d_refuses_bad_input_before_any_work(argv, needle, files, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


def test_design3d_refuses_a_model_without_two_level_trims(tmp_path, monkeypatch, capsys):
    d = json.loads(MODEL.read_text())
    d["points"] = [p for p in d["points"] if p["climb_m_s"] != 0.0 or p["speed_m_s"] == 1.5]
    check_refusal(["butterfly", "design3d", "--out", "c.json", "--model", "m.json"], "1 level trims",
                  {"m.json": json.dumps(d)}, tmp_path, monkeypatch, capsys)


@pytest.fixture(scope="module")
def designed_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("design3d")
    out = folder / "mine.json"
    assert main(["butterfly", "design3d", "--model", str(MODEL), "--out", str(out), "--no-landing", "--json"]) == 0
    return out


def test_design3d_writes_a_controller_that_reads_back_equal_and_flies_level(designed_file, capsys):
    from lifelike_mj.butterfly.flight3d.designed import DesignedController, load_any

    d = json.loads(designed_file.read_text())
    assert d["kind"] == "designed" and d["animal"] == "monarch" and d["force_law"] == "calibrated"
    assert d["provenance"]["parameters"]["model"] == str(MODEL) and len(d["schedule"]) == 9
    ctl = load_any(designed_file)
    assert isinstance(ctl, DesignedController) and ctl.name == "mine"
    assert json.loads(json.dumps(ctl.to_dict())) == d  # read back as written
    capsys.readouterr()
    assert main(["butterfly", "fly3d", "--controller", str(designed_file), "--speed", "1.5", "--duration", "6",
                 "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["altitude_max_m"] - s["altitude_min_m"] < 0.15 and s["roll_max_deg"] < 3.0  # its start dips 10 cm
    assert 8.0 < s["distance_m"] < 10.0  # 1.5 m/s for 6 s


def test_a_designed_controller_is_refused_in_one_sentence_where_networks_fly(designed_file, tmp_path, monkeypatch,
                                                                           capsys):
    check_refusal(["butterfly", "evolve3d", "--start", str(designed_file), "--out", "e.json"],
                  "is a designed controller", {}, tmp_path, monkeypatch, capsys)


@pytest.mark.parametrize("change,needle", [
    (lambda d: d["schedule"].reverse(), "must rise"),
    (lambda d: d["schedule"][0]["K"].pop(), "K"),
    (lambda d: d.update(kind="loop"), "designed"),
    (lambda d: d["schedule"][1].update(command=[-1.0] * 13), "frequency"),
    (lambda d: d.update(schedule=d["schedule"][:1]), "schedule"),
], ids=["speeds falling", "a gain short of a row", "an unknown kind", "a command out of bounds", "one trim"])
def test_a_bad_designed_controller_file_is_one_sentence(designed_file, change, needle):
    from lifelike_mj.butterfly.flight3d.designed import controller_from_dict
    from lifelike_mj.errors import UserError

    d = json.loads(designed_file.read_text())
    change(d)
    with pytest.raises(UserError, match=needle) as e:
        controller_from_dict(d, "bad")
    assert "\n" not in str(e.value)


def test_the_shipped_designed_controller_is_what_design3d_makes_from_the_shipped_model(designed_file):
    """``controllers/butterfly3d/designed.json`` is remade by its recorded command: the same schedule, to the bit (its
    landing, which takes that command about 6 minutes more, was remade equal to the bit once by hand)."""
    from lifelike_mj.paths import controllers_dir

    shipped = json.loads((controllers_dir() / "butterfly3d" / "designed.json").read_text())
    assert shipped["provenance"]["command"] == ("lifelike-mj butterfly design3d --model "
                                                "benchmarks/results/monarch_model.json --out "
                                                "controllers/butterfly3d/designed.json --overwrite")
    assert shipped["provenance"]["parameters"]["landing"] is True and len(shipped["landing"]["manoeuvres"]) == 8
    assert shipped["schedule"] == json.loads(designed_file.read_text())["schedule"]


def test_the_level_flight_commands_fly_the_designed_controller_by_default(capsys):
    """``measure3d`` with no ``--controller`` flies the shipped designed controller, inside the natural envelope
    (issue 42: 9.5-11 Hz, dorsal gap 35-50 deg, strokes of 110-130 deg; the evolved monarch flies 8.7-9.0 Hz, 77-80 deg)."""
    capsys.readouterr()
    assert main(["butterfly", "measure3d", "--settle", "3", "--window", "2", "--json"]) == 0
    m = json.loads(capsys.readouterr().out)
    assert m["controller"] == "designed" and m["animal"] == "monarch"
    assert 9.5 <= m["flap_frequency_hz"] <= 11.0 and 35.0 <= m["dorsal_gap_deg"] <= 50.0
    assert 110.0 <= m["stroke_left_deg"] <= 130.0 and abs(m["roll_mean_deg"]) <= 3.0
