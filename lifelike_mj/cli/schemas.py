"""The JSON Schemas of every file format, gathered from the modules that own them (for ``docs/schemas/``): the
same descriptions the loaders validate against (:func:`lifelike_mj.schema.validate`)."""

from __future__ import annotations

from pathlib import Path


def write_schemas(folder: str | Path) -> list[Path]:
    """Write every file format's JSON Schema into ``folder`` (for editors); returns the paths."""
    from lifelike_mj.boids.presets import grid_json_schema
    from lifelike_mj.boids.presets import json_schema as boids_schema
    from lifelike_mj.butterfly.controllers import json_schema as butterfly_schema
    from lifelike_mj.butterfly.flight3d.controllers import json_schema as butterfly3d_schema
    from lifelike_mj.butterfly.flight3d.designed import json_schema as designed_schema
    from lifelike_mj.cli.scene import json_schema as scene_schema
    from lifelike_mj.evolve.checkpoint import json_schema as checkpoint_schema
    from lifelike_mj.fish.params import json_schema as fish_schema
    from lifelike_mj.io import write_json

    out = Path(folder)
    docs = {"butterfly-controller": butterfly_schema(), "butterfly3d-controller": butterfly3d_schema(),
            "butterfly3d-designed": designed_schema(),
            "fish-preset": fish_schema(), "boids-preset": boids_schema(), "boids-grid": grid_json_schema(),
            "evolve-checkpoint": checkpoint_schema(), "scene": scene_schema()}
    return [write_json(out / f"{name}.schema.json", schema) for name, schema in docs.items()]
