"""The JSON Schemas published in docs/schemas/ are current, and agree with what the loaders accept."""

import json
from pathlib import Path

import pytest

from lifelike_mj.cli.schemas import write_schemas
from lifelike_mj.paths import controllers_dir

DOCS = Path(__file__).resolve().parent.parent / "docs" / "schemas"
KINDS = {"butterfly": "butterfly-controller", "butterfly3d": "butterfly3d-controller", "fish": "fish-preset",
         "boids": "boids-preset"}


def test_published_schemas_are_current(tmp_path):
    for path in write_schemas(tmp_path):
        assert (DOCS / path.name).read_text() == path.read_text(), f"regenerate {path.name}: python -c " \
            "\"from lifelike_mj.cli.schemas import write_schemas; write_schemas('docs/schemas')\""


def test_schema_keys_are_the_loaders_keys():
    from lifelike_mj.fish.params import _FIELDS

    fish = json.loads((DOCS / "fish-preset.schema.json").read_text())
    assert set(fish["properties"]["parameters"]["properties"]) == _FIELDS
    assert set(fish["properties"]) == {"format", "version", "name", "description", "parameters", "same_as"}
    boids = json.loads((DOCS / "boids-preset.schema.json").read_text())
    assert set(boids["properties"]["settings"]["properties"]) == {"r_s", "r_a", "r_c", "w_s", "box"}
    bf = json.loads((DOCS / "butterfly-controller.schema.json").read_text())
    assert set(bf["properties"]) == {"format", "version", "name", "description", "type", "flap", "parameters",
                                     "provenance"}


@pytest.mark.parametrize("creature", ["butterfly", "butterfly3d", "fish", "boids"])
def test_every_shipped_file_validates(creature):
    jsonschema = pytest.importorskip("jsonschema")
    for path in sorted((controllers_dir() / creature).glob("*.json")):
        data = json.loads(path.read_text())
        name = ("boids-grid" if data["format"].endswith("grid") else "butterfly3d-designed"
                if data.get("kind") == "designed" else KINDS[creature])
        jsonschema.validate(data, json.loads((DOCS / f"{name}.schema.json").read_text()))


def test_a_typo_fails_the_schema_too():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((DOCS / "fish-preset.schema.json").read_text())
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({"format": "lifelike-mj/fish-preset", "parameters": {"r_max_n": 0.03}}, schema)
