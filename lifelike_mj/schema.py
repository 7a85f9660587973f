"""Checks shared by every preset and controller file: the format and version, and keys: an unknown
key is named with the closest known one ("did you mean"), a missing key is named, and a number is a
finite JSON number (never a string or a bool). Each file's own values are ranged by the class it
builds (:class:`~lifelike_mj.fish.params.FishParams`, :class:`~lifelike_mj.boids.engine.BoidParams`,
:class:`~lifelike_mj.butterfly.controllers.ButterflyController`)."""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable

from lifelike_mj import checks
from lifelike_mj.errors import UserError


def check_header(data: object, fmt: str, where: str, versions: Iterable[int] = (1,), kind: str = "file") -> dict:
    """``data`` as a dict whose ``format`` is ``fmt`` and whose ``version`` (1 when absent) is one of
    ``versions``; else one sentence."""
    if not isinstance(data, dict):
        raise UserError(f"{where} is not a {kind}: it holds a JSON {type(data).__name__}, not an object.")
    if data.get("format") != fmt:
        raise UserError(f"{where} is not a {kind} (its format is {data.get('format')!r}, expected {fmt!r}).")
    versions = tuple(versions)
    v = data.get("version", 1)
    if not checks.is_whole(v) or v not in versions:
        raise UserError(f"{where} has format version {v!r}; this lifelike-mj reads version "
                        f"{' or '.join(str(x) for x in versions)}.")
    return data


def check_keys(obj: dict, allowed: Iterable[str], where: str, required: Iterable[str] = ()) -> None:
    """Unknown keys of ``obj`` are an error naming the closest allowed key; so are missing ``required`` ones."""
    allowed = list(allowed)
    for key in obj:
        if key not in allowed:
            close = difflib.get_close_matches(str(key), allowed, n=1, cutoff=0.6)
            hint = f" (did you mean {close[0]!r}?)" if close else f"; known keys: {', '.join(allowed)}"
            raise UserError(f"{where} has an unknown key {key!r}{hint}.")
    missing = [k for k in required if k not in obj]
    if missing:
        raise UserError(f"{where} lacks {', '.join(repr(k) for k in missing)}.")


def finite(value: object, name: str, where: str) -> float:
    """A finite JSON number (not a string, a bool or a list) as a float."""
    if not checks.is_number(value) or not math.isfinite(float(value)):
        raise UserError(f"{where}: {name} must be a finite number, got {value!r}.")
    return float(value)


def number_list(value: object, name: str, where: str, length: int | None = None, min_length: int = 1) -> list[float]:
    """A list of finite numbers (of ``length`` items, or at least ``min_length``)."""
    if not isinstance(value, list):
        raise UserError(f"{where}: {name} must be a list of numbers, got {value!r}.")
    if (length is not None and len(value) != length) or len(value) < min_length:
        want = f"{length}" if length is not None else f"at least {min_length}"
        raise UserError(f"{where}: {name} must have {want} numbers, got {len(value)}.")
    return [finite(v, f"{name}[{i}]", where) for i, v in enumerate(value)]


def document_schema(fmt: str, title: str, properties: dict, required: list[str], description: str = "") -> dict:
    """A JSON Schema (draft 2020-12) of a file with ``format``/``version`` headers and ``properties``,
    unknown keys refused (``additionalProperties: false``), as the loaders refuse them."""
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": f"https://lifelike-mj.example/schemas/{fmt.split('/')[-1]}.schema.json",
        "title": title,
        "description": description,
        "type": "object",
        "properties": {"format": {"const": fmt}, "version": {"const": 1, "description": "file format version"},
                       "name": {"type": "string"}, "description": {"type": "string"}, **properties},
        "required": ["format", *required],
        "additionalProperties": False,
    }


_UNITS = {"_N": "N", "_deg": "deg", "_m": "m", "_m2": "m^2", "_m5": "m^5", "_s": "s", "_hz": "Hz",
          "_kg_m3": "kg/m^3", "_per_deg": "1/deg", "_bl_s": "body lengths/s", "_cm2": "cm^2", "_g": "g"}


def unit_of(name: str) -> str:
    """The unit a key's name ends in (``r_max_N`` -> ``N``), or ``""``."""
    for suffix, unit in sorted(_UNITS.items(), key=lambda kv: -len(kv[0])):
        if name.endswith(suffix):
            return unit
    return ""


def number(description: str = "", minimum: float | None = None, maximum: float | None = None,
           exclusive_minimum: float | None = None) -> dict:
    """The JSON Schema of a number."""
    out: dict = {"type": "number"}
    if description:
        out["description"] = description
    if minimum is not None:
        out["minimum"] = minimum
    if exclusive_minimum is not None:
        out["exclusiveMinimum"] = exclusive_minimum
    if maximum is not None:
        out["maximum"] = maximum
    return out
