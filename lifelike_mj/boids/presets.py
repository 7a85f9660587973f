"""Boids presets: the paper's eight two-type patterns (Nakamura 2013 Fig. 4-5) and the homogeneous
grid of its Fig. 2, as plain JSON in ``controllers/boids/``.

A pattern preset::

    {"format": "lifelike-mj/boids-preset", "version": 1, "name": "4a", "figure": "4a",
     "description": "...", "W_a": [[0.5, 0.01], [0.01, 0.5]], "W_c": [[0.01, 0.001], [0.001, 0.01]]}

optionally with ``"settings"`` overriding ``r_s``, ``r_a``, ``r_c``, ``w_s``, ``box`` (box units).
The grid (``fig2_grid.json``) lists the homogeneous ``w_a`` and ``w_c`` values of Fig. 2.
"""

from __future__ import annotations

from pathlib import Path

from lifelike_mj.boids.engine import MAX_BOX_ZONES, MAX_RADIUS, MAX_TYPES, MAX_WEIGHT, BoidParams
from lifelike_mj.errors import UserError
from lifelike_mj.paths import controllers_dir, load_named_json
from lifelike_mj.schema import check_header, validate

FORMAT = "lifelike-mj/boids-preset"
GRID_FORMAT = "lifelike-mj/boids-grid"
PATTERNS = ("4a", "4b", "4c", "4d", "5a", "5b", "5c", "5d")
_SETTINGS = ("r_s", "r_a", "r_c", "w_s", "box")
#: Largest homogeneous weight and grid of :func:`load_grid`.
MAX_GRID_WEIGHT = 100.0
MAX_GRID_CELLS = 10_000


def preset_path(name: str) -> Path:
    return controllers_dir() / "boids" / f"{name}.json"


def _read(ref: str | Path) -> tuple[dict, Path]:
    return load_named_json("boids", ref, "boids preset")


def load_preset(ref: str | Path, dims: int = 3) -> BoidParams:
    """A pattern preset by name (``4a`` ... ``5d``) or path, as :class:`BoidParams` in ``dims`` D."""
    data, p = _read(ref)
    where = f"boids preset {p}"
    check_header(data, FORMAT, where, kind="boids preset")
    validate(data, json_schema(), where)
    return BoidParams(wa=data["W_a"], wc=data["W_c"], dims=dims, name=data.get("name", p.stem),
                      **data.get("settings", {}))


def preset_info(ref: str | Path) -> dict:
    """The preset file's content (figure, description ...)."""
    return _read(ref)[0]


def load_grid(ref: str | Path = "fig2_grid") -> dict:
    """The homogeneous grid of Fig. 2: ``{"w_a": [...], "w_c": [...]}``."""
    data, p = _read(ref)
    where = f"boids grid {p}"
    check_header(data, GRID_FORMAT, where, kind="boids grid")
    validate(data, grid_json_schema(), where)
    axes = {k: [float(v) for v in data[k]] for k in ("w_a", "w_c")}
    if len(axes["w_a"]) * len(axes["w_c"]) > MAX_GRID_CELLS:
        raise UserError(f"{where} has {len(axes['w_a']) * len(axes['w_c'])} cells; at most {MAX_GRID_CELLS}.")
    return {**axes, "name": p.stem}


def homogeneous(w_a: float, w_c: float, dims: int = 3) -> BoidParams:
    """One type with alignment weight ``w_a`` and cohesion weight ``w_c`` (section 2)."""
    return BoidParams(wa=((w_a,),), wc=((w_c,),), dims=dims, name=f"w_a={w_a:g}, w_c={w_c:g}")


def json_schema() -> dict:
    """The JSON Schema of a boids preset file (``docs/schemas/boids-preset.schema.json``)."""
    from lifelike_mj.schema import document_schema, number

    matrix = {"type": "array", "minItems": 1, "maxItems": MAX_TYPES,
              "items": {"type": "array", "minItems": 1, "maxItems": MAX_TYPES, "items": number("", -MAX_WEIGHT, MAX_WEIGHT)},
              "description": "k x k weights, row: own type, column: the neighbour's type"}
    settings = {"type": "object", "additionalProperties": False, "properties": {
        "r_s": number("separation zone radius, box units", maximum=MAX_RADIUS, exclusive_minimum=0),
        "r_a": number("alignment zone radius, box units", maximum=MAX_RADIUS, exclusive_minimum=0),
        "r_c": number("cohesion zone radius, box units", maximum=MAX_RADIUS, exclusive_minimum=0),
        "w_s": number("separation weight (the paper: 0.05)", -MAX_WEIGHT, MAX_WEIGHT),
        "box": number("box side, box units (at most 200 R_c)", maximum=MAX_BOX_ZONES * MAX_RADIUS,
                      exclusive_minimum=0)}}
    return document_schema(FORMAT, "lifelike-mj boids preset", {"figure": {"type": "string"}, "W_a": matrix,
                           "W_c": matrix, "settings": settings}, ["W_a", "W_c"],
                           "Nakamura 2013: the alignment and cohesion matrices of a two-type (or k-type) flock.")


def grid_json_schema() -> dict:
    """The JSON Schema of a homogeneous grid file (``docs/schemas/boids-grid.schema.json``)."""
    from lifelike_mj.schema import document_schema

    axis = {"type": "array", "minItems": 1, "maxItems": MAX_GRID_CELLS,
            "items": {"type": "number", "minimum": 0, "maximum": MAX_GRID_WEIGHT}}
    return document_schema(GRID_FORMAT, "lifelike-mj boids grid", {"w_a": axis, "w_c": axis}, ["w_a", "w_c"],
                           "Nakamura 2013 Fig. 2: the homogeneous alignment and cohesion weights to sweep.")
