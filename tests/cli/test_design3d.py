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
    assert main(["butterfly", "design3d", "--model", str(MODEL), "--out", str(out), "--json"]) == 0
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
    check_refusal(["butterfly", "land3d", "--controller", str(designed_file)], "is a designed controller", {},
                  tmp_path, monkeypatch, capsys)


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
