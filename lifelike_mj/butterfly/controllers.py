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
  flap angle).

Compiled code sees a controller as ``(kind, params)``: an integer code and a float array.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from lifelike_mj.butterfly.params import FlapPattern
from lifelike_mj.errors import UserError
from lifelike_mj.paths import controllers_dir

FORMAT = "lifelike-mj/butterfly-controller"

#: Compiled pitch-law codes (must match ``pitch_command`` in ``paper.py`` and the MuJoCo loop).
KIND_CONSTANT = 0
KIND_SIMPLE_RULE = 1
#: The simple rule's upstroke test is ``omega > OMEGA_EPS`` (rad/s): at a stroke reversal omega is
#: zero up to rounding (+-1e-14), and a bare ``omega > 0`` would let rounding pick the pitch.
OMEGA_EPS = 1e-9

#: Parameters (all in degrees) each pitch law requires.
PITCH_LAWS: dict[str, tuple[int, tuple[str, ...]]] = {
    "constant": (KIND_CONSTANT, ("phi_deg",)),
    "simple_rule": (KIND_SIMPLE_RULE, ("phi_up_deg", "phi_down_deg")),
}


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
        for k in needed:
            v = self.parameters[k]
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise UserError(f"controller parameter {k} must be a finite number, got {v!r}.")

    def compiled(self) -> tuple[int, np.ndarray]:
        """``(kind, params)`` for compiled code; angles converted to rad."""
        kind, names = PITCH_LAWS[self.type]
        return kind, np.radians([float(self.parameters[k]) for k in names])

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
    if not isinstance(data, dict):
        raise UserError(f"{where} is not a JSON object.")
    if data.get("format") != FORMAT:
        raise UserError(f"{where} is not a butterfly controller file (format must be {FORMAT!r}).")
    for key, kind in (("type", str), ("flap", dict), ("parameters", dict)):
        if not isinstance(data.get(key), kind):
            raise UserError(f"{where} needs a {key!r} entry of type {kind.__name__}.")
    flap = data["flap"]
    try:
        pattern = FlapPattern(
            float(flap.get("frequency_hz", 10.0)), float(flap["theta_min_deg"]), float(flap["theta_max_deg"])
        )
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, UserError):
            raise
        raise UserError(f"{where} has a malformed 'flap' entry (needs theta_min_deg and theta_max_deg numbers).") from None
    prov = data.get("provenance", {})
    if not isinstance(prov, dict):
        raise UserError(f"{where} has a 'provenance' entry that is not an object.")
    return ButterflyController(data["type"], pattern, dict(data["parameters"]), dict(prov), name)


def builtin_names() -> list[str]:
    """Names of the controllers shipped in ``controllers/butterfly/``."""
    return sorted(p.stem for p in (controllers_dir() / "butterfly").glob("*.json"))


def load(name_or_path: str | Path) -> ButterflyController:
    """Load a shipped controller by name (``simple_rule``) or any controller file by path."""
    text = str(name_or_path)
    path = Path(text)
    if not (text.endswith(".json") or path.exists()):
        path = controllers_dir() / "butterfly" / f"{text}.json"
        if not path.exists():
            raise UserError(f"unknown controller {text!r}; shipped controllers: {', '.join(builtin_names())}.")
    if not path.is_file():
        raise UserError(f"controller file {path} does not exist.")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise UserError(f"controller file {path} is not readable JSON ({exc.__class__.__name__}).") from None
    return from_dict(data, path.stem)
