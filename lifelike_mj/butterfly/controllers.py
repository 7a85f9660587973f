"""Butterfly controllers as plain-data files (JSON): flap pattern + pitch law + provenance.

A controller file looks like::

    {"format": "lifelike-mj/butterfly-controller", "version": 1,
     "type": "simple_rule",
     "flap": {"frequency_hz": 10.0, "theta_min_deg": -90.0, "theta_max_deg": 90.0},
     "parameters": {"phi_up_deg": 12.77, "phi_down_deg": 0.0},
     "provenance": {"source": "...", "created": "..."}}

Pitch laws (``type``), each set once per integration step (Oe 2010 section 5.1):

* ``simple_rule``: ``phi = phi_up`` while ``omega > 0`` (upstroke, see ``OMEGA_EPS``) else ``phi_down`` (section 5.1);
* ``constant``: ``phi = phi_deg`` at all times (used for the glide of section 7.1 with a fixed
  flap angle);
* ``ann``: the evolved neural network of section 6 (``butterfly/ann.py``): parameters ``inputs``
  (``relative`` or ``ground``), ``input_scale`` (units in the key names), ``max_dphi_deg``,
  ``phi_limit_deg`` and the 49 ``weights``.

Compiled code sees a controller as ``(kind, params)``: an integer code and a float array.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly import ann
from lifelike_mj.butterfly.params import MAX_FLAP_HZ, FlapPattern
from lifelike_mj.errors import UserError
from lifelike_mj.paths import load_named_json, shipped_names
from lifelike_mj.schema import check_header, validate

FORMAT = "lifelike-mj/butterfly-controller"

#: Compiled pitch-law codes (must match ``pitch_command`` in ``paper.py`` and the MuJoCo loop).
KIND_CONSTANT = 0
KIND_SIMPLE_RULE = 1
KIND_ANN = 2
#: A network of another shape than the paper's 6-6-1 (``layers`` in the file).
KIND_MLP = 3
#: The simple rule's upstroke test is ``omega > OMEGA_EPS`` (rad/s): at a stroke reversal omega is
#: zero up to rounding (+-1e-14), and a bare ``omega > 0`` would let rounding pick the pitch.
OMEGA_EPS = 1e-9

#: Parameters (all in degrees) each pitch law requires.
PITCH_LAWS: dict[str, tuple[int, tuple[str, ...]]] = {
    "constant": (KIND_CONSTANT, ("phi_deg",)),
    "simple_rule": (KIND_SIMPLE_RULE, ("phi_up_deg", "phi_down_deg")),
    "ann": (KIND_ANN, ("weights",)),
}


#: Bounds of a controller's numbers (files and Python alike): a pitch (deg), a network weight, an input scale.
MAX_PITCH_DEG = 90.0
MAX_WEIGHT = 1.0e6
MAX_INPUT_SCALE = 1.0e6

#: Optional parameters of an ann controller file besides its weights.
ANN_OPTIONAL = ("inputs", "input_scale", "layers", "max_dphi_deg", "phi_limit_deg")


@dataclass(frozen=True)
class ButterflyController:
    """A flap pattern plus a pitch law with its parameters (degrees at this edge)."""

    type: str
    flap: FlapPattern
    parameters: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    name: str = ""

    def __post_init__(self) -> None:
        if self.type not in PITCH_LAWS:
            raise UserError(f"unknown controller type {self.type!r}; known types: {', '.join(sorted(PITCH_LAWS))}.")
        needed = PITCH_LAWS[self.type][1]
        missing = [k for k in needed if k not in self.parameters]
        if missing:
            raise UserError(f"controller of type {self.type!r} lacks parameter(s) {', '.join(missing)}.")
        if self.type == "ann":
            _check_ann(self.parameters, where=f"controller {self.name}" if self.name else "controller")
            return
        for k in needed:
            checks.number(f"controller parameter {k}", self.parameters[k], -MAX_PITCH_DEG, MAX_PITCH_DEG, unit="deg")

    def compiled(self) -> tuple[int, np.ndarray]:
        """``(kind, params)`` for compiled code; angles converted to rad."""
        kind, names = PITCH_LAWS[self.type]
        if self.type == "ann":
            p = self.parameters
            if self.layers == ann.PAPER_LAYERS:
                return kind, ann.compile_params(p["inputs"], self.input_scale(), p["weights"], float(p["max_dphi_deg"]),
                                                float(p["phi_limit_deg"]))
            return KIND_MLP, ann.compile_mlp(p["inputs"], self.input_scale(), p["weights"], self.layers,
                                             float(p["max_dphi_deg"]), float(p["phi_limit_deg"]))
        return kind, np.radians([float(self.parameters[k]) for k in names])

    def input_scale(self) -> dict:
        """The network's input scales (ann only): the file's values over the flap's defaults."""
        scales = ann.default_scales(self.flap)
        scales.update(self.parameters.get("input_scale", {}))
        return scales

    def with_inputs(self, inputs: str) -> ButterflyController:
        """Copy of an ann controller fed ``relative`` (air) or ``ground`` velocities (section 7.2)."""
        if self.type != "ann":
            raise UserError(f"only ann controllers take velocity inputs; {self.name or 'this one'} is {self.type!r}.")
        if inputs not in ann.INPUT_KINDS:
            raise UserError(f"inputs must be one of {', '.join(ann.INPUT_KINDS)}, got {inputs!r}.")
        return replace(self, parameters={**self.parameters, "inputs": inputs})

    def with_parameters(self, **overrides: float | None) -> ButterflyController:
        """Copy with some parameters replaced (``None`` values are ignored)."""
        params = dict(self.parameters)
        for k, v in overrides.items():
            if v is None:
                continue
            if k not in PITCH_LAWS[self.type][1]:
                raise UserError(f"controller type {self.type!r} has no parameter {k}.")
            params[k] = float(v)
        return replace(self, parameters=params)

    @property
    def layers(self) -> tuple[int, ...]:
        """Layer sizes of an ann controller's network (``[6, 6, 1]``, the paper's, unless the file says)."""
        return tuple(int(x) for x in self.parameters.get("layers", ann.PAPER_LAYERS))

    @property
    def weights(self) -> np.ndarray:
        """The genome of an ann controller (49 floats for the paper's network)."""
        return np.asarray(self.parameters["weights"], dtype=float)

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "version": 1,
            "type": self.type,
            "flap": {
                "frequency_hz": self.flap.frequency_hz,
                "theta_min_deg": self.flap.theta_min_deg,
                "theta_max_deg": self.flap.theta_max_deg,
            },
            "parameters": dict(self.parameters),
            "provenance": dict(self.provenance),
        }


def from_dict(data: object, name: str = "") -> ButterflyController:
    """Validate plain data and build a controller; malformed data raises :class:`UserError`."""
    where = f"controller {name}" if name else "controller"
    check_header(data, FORMAT, where, kind="butterfly controller file")
    if not isinstance(data.get("type"), str) or data["type"] not in PITCH_LAWS:  # clearer than the schema's
        raise UserError(f"{where}: unknown controller type {data.get('type')!r}; known types: "
                        f"{', '.join(sorted(PITCH_LAWS))}.")
    validate(data, json_schema(), where)
    flap = data["flap"]
    pattern = FlapPattern(flap.get("frequency_hz", 10.0), flap["theta_min_deg"], flap["theta_max_deg"])
    return ButterflyController(data["type"], pattern, dict(data["parameters"]), dict(data.get("provenance", {})), name)


def _check_ann(p: dict, where: str) -> None:
    w = p.get("weights")
    if not isinstance(w, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in w):
        raise UserError(f"{where} needs 'weights' as a list of numbers.")
    try:
        layers = ann.check_layers(p.get("layers", ann.PAPER_LAYERS))
    except ValueError as exc:
        raise UserError(f"{where}: {exc}.") from None
    if len(w) != ann.n_weights(layers):
        what = "the network of section 6" if layers == ann.PAPER_LAYERS else f"a {list(layers)} network"
        raise UserError(f"{where} has {len(w)} weights; {what} needs {ann.n_weights(layers)}.")
    if not all(math.isfinite(x) and abs(x) <= MAX_WEIGHT for x in w):
        raise UserError(f"{where} has weights that are not finite numbers within +-{MAX_WEIGHT:g}.")
    if p.get("inputs") not in ann.INPUT_KINDS:
        raise UserError(f"{where} needs 'inputs' to be one of {', '.join(ann.INPUT_KINDS)}.")
    for key in ("max_dphi_deg", "phi_limit_deg"):
        v = p.get(key)
        if not checks.is_number(v) or not (math.isfinite(v) and 0 < v <= 90):
            raise UserError(f"{where} needs '{key}' to be a number of degrees in (0, 90].")
    scales = p.get("input_scale", {})
    if not isinstance(scales, dict):
        raise UserError(f"{where} has an 'input_scale' entry that is not an object.")
    for key, v in scales.items():
        if key not in ann.SCALE_KEYS:
            raise UserError(f"{where} has an unknown input scale {key!r}; known: {', '.join(ann.SCALE_KEYS)}.")
        ok = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and abs(v) <= MAX_INPUT_SCALE
        if not ok or (key != "theta_center_deg" and v <= 0):
            raise UserError(f"{where} has input scale {key} = {v!r}; it must be a positive number up to "
                            f"{MAX_INPUT_SCALE:g}.")


def ann_controller(weights, flap: FlapPattern | None = None, inputs: str = "relative",
                   provenance: dict | None = None, name: str = "", layers=ann.PAPER_LAYERS) -> ButterflyController:
    """An ann controller (section 6) with the documented input scales of ``butterfly/ann.py``;
    ``layers``: the network's shape (default the paper's ``[6, 6, 1]``).

    The default flap is section 6.3's: 10 Hz over [-60, 75] degrees."""
    flap = flap or FlapPattern(10.0, -60.0, 75.0)
    params = {
        "layers": list(ann.check_layers(layers)),
        "inputs": inputs,
        "max_dphi_deg": ann.DEFAULT_MAX_DPHI_DEG,
        "phi_limit_deg": ann.DEFAULT_PHI_LIMIT_DEG,
        "input_scale": ann.default_scales(flap),
        "weights": [float(x) for x in np.asarray(weights, dtype=float).ravel()],
    }
    return ButterflyController("ann", flap, params, dict(provenance or {}), name)


def builtin_names() -> list[str]:
    """Names of the controllers shipped in ``controllers/butterfly/``."""
    return shipped_names("butterfly")


def load(name_or_path: str | Path) -> ButterflyController:
    """Load a shipped controller by name (``simple_rule``) or any controller file by path."""
    data, path = load_named_json("butterfly", name_or_path, "controller")
    return from_dict(data, path.stem)


def json_schema() -> dict:
    """The JSON Schema of a butterfly controller file (``docs/schemas/butterfly-controller.schema.json``)."""
    from lifelike_mj.schema import document_schema, number

    angle = number("deg", -MAX_PITCH_DEG, MAX_PITCH_DEG)
    flap = {"type": "object", "additionalProperties": False, "required": ["theta_min_deg", "theta_max_deg"],
            "properties": {"frequency_hz": number("flap frequency, Hz (the paper: 10)", maximum=MAX_FLAP_HZ,
                                                  exclusive_minimum=0),
                           "theta_min_deg": number("lowest flap angle, deg", -180, 180),
                           "theta_max_deg": number("highest flap angle, deg", -180, 180)}}
    max_weights = ann.n_weights((ann.N_INPUTS, *[ann.MAX_WIDTH] * ann.MAX_HIDDEN_LAYERS, 1))
    ann_params = {"weights": {"type": "array", "maxItems": max_weights, "items": number("", -MAX_WEIGHT, MAX_WEIGHT),
                              "description": "49 weights for the 6-6-1 network, or as many as layers need"},
                  "inputs": {"enum": list(ann.INPUT_KINDS)},
                  "input_scale": {"type": "object", "additionalProperties": False,
                                  "properties": {k: number("", -MAX_INPUT_SCALE, MAX_INPUT_SCALE) for k in ann.SCALE_KEYS}},
                  "layers": {"type": "array", "minItems": 2, "maxItems": ann.MAX_HIDDEN_LAYERS + 2,
                             "items": {"type": "integer", "minimum": 1, "maximum": max(ann.MAX_WIDTH, ann.N_INPUTS)}},
                  "max_dphi_deg": number("largest change of pitch per step, deg", maximum=90, exclusive_minimum=0),
                  "phi_limit_deg": number("pitch limit, deg", maximum=90, exclusive_minimum=0)}
    laws = {"simple_rule": {"phi_up_deg": angle, "phi_down_deg": angle}, "constant": {"phi_deg": angle},
            "ann": ann_params}
    schema = document_schema(FORMAT, "lifelike-mj butterfly controller",
                             {"type": {"enum": sorted(PITCH_LAWS)}, "flap": flap, "parameters": {"type": "object"},
                              "provenance": {"type": "object"}}, ["type", "flap", "parameters"],
                             "Oe 2010: a flap pattern and a pitch law (section 5.1 rule, a constant, or the "
                             "section 6 network) with its parameters.")
    schema["allOf"] = [{"if": {"properties": {"type": {"const": t}}, "required": ["type"]},
                        "then": {"properties": {"parameters": {
                            "type": "object", "properties": props, "required": list(PITCH_LAWS[t][1]),
                            "additionalProperties": False}}}} for t, props in laws.items()]
    return schema
