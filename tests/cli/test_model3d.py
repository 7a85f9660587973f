"""``lifelike-mj butterfly model3d``: bad input refused before any work; a small model built with its provenance."""

from __future__ import annotations

import json

import pytest
from battery import check_refusal

from lifelike_mj.cli import main

CASES = [
    (["butterfly", "model3d", "--out", "m.json", "--speeds", "0.1"], "expected 1 to 50 different speeds within 0.25", {}),
    (["butterfly", "model3d", "--out", "m.json", "--speeds", "1,1"], "different speeds", {}),
    (["butterfly", "model3d", "--out", "m.json", "--climbs", "fast"], "expected numbers separated by commas", {}),
    (["butterfly", "model3d", "--out", "m.json"], "already exists", {"m.json": "{}"}),
    (["butterfly", "model3d", "--out", "m.txt"], ".json", {}),
]


@pytest.mark.parametrize("argv,needle,files", CASES, ids=[" ".join(c[0][2:]) for c in CASES])
def test_model3d_refuses_bad_input_before_any_work(argv, needle, files, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


@pytest.mark.slow
def test_model3d_writes_a_model_with_its_provenance(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    # 2 m/s: the trim that the least squares find quickest from the filmed gait (17 s here; 1.5 m/s takes minutes)
    assert main(["butterfly", "model3d", "--out", "m.json", "--speeds", "2", "--climbs", "0", "--json"]) == 0
    d = json.loads((tmp_path / "m.json").read_text())
    assert d["provenance"]["parameters"]["speeds_m_s"] == [2.0] and d["force_law"] == "calibrated"
    (p,) = d["points"]
    assert p["trimmed"] and abs(p["flown"]["speed_m_s"] - 2.0) < 0.15 and len(p["A"]) == 9
    assert abs(d["filmed_flight"]["calibrated"]["climb_m_s"] - 0.38) < 0.06
