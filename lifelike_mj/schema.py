"""One validation path for every file format the project reads.

Each format has one description, its JSON Schema (draft 2020-12), built in code by the module that owns the
format and written to ``docs/schemas/`` for editors. Loaders check the header (:func:`check_header`: the
format and its version, with the clearest sentence for a file of another kind), then the whole document
against that schema (:func:`validate`): types, shapes, sizes and bounds, unknown keys named with the closest
known one ("did you mean"), missing keys named. A number is a finite JSON number, never a string, a bool or
an infinity (``1e999`` parses as one). Only then does a loader convert values (``float()``, ``int()``) and
build its object, whose own checks add what a schema cannot say (a schedule's first row at 0 s, ``r_min`` not
above ``r_max``, as many weights as the layers need).

Every failure is one sentence (:class:`~lifelike_mj.errors.UserError`) naming the file, the place in it
(``base.frequency_hz``, ``weights[3]``) and what was expected.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Iterable, Sequence

from lifelike_mj import checks
from lifelike_mj.errors import UserError


def check_header(data: object, fmt: str, where: str, versions: Iterable[int] = (1,), kind: str = "file") -> dict:
    """``data`` as a dict whose ``format`` is ``fmt`` and whose ``version`` (1 when absent) is one of
    ``versions``; else one sentence."""
    if not isinstance(data, dict):
        raise UserError(f"{where} is not a {kind}: it holds a JSON {type(data).__name__}, not an object.")
    if "format" not in data:
        raise UserError(f"{where} is not a {kind}: it has no \"format\" key (a {kind} says \"format\": \"{fmt}\").")
    if data.get("format") != fmt:
        raise UserError(f"{where} is not a {kind} (its format is {_json(data.get('format'))}, expected {fmt!r}).")
    versions = tuple(versions)
    v = data.get("version", 1)
    if not checks.is_whole(v) or v not in versions:
        raise UserError(f"{where} has format version {v!r}; this lifelike-mj reads version "
                        f"{' or '.join(str(x) for x in versions)}.")
    return data


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


# ---- validating a document against its schema -------------------------------------------------------

#: Keywords of our own (ignored by other JSON Schema tools): ``x-array`` marks a NumPy array stored beside the
#: JSON (a checkpoint's), checked by the ``arrays`` function given to :func:`validate`.
X_ARRAY = "x-array"


def _finite_number(checker, value) -> bool:
    return checks.is_number(value) and math.isfinite(float(value))


def _whole_number(checker, value) -> bool:
    return checks.is_whole(value)  # a JSON integer: 2.0 is a float, as json reads it


@functools.lru_cache(maxsize=1)
def _validator_class():
    from jsonschema import Draft202012Validator, validators

    types = Draft202012Validator.TYPE_CHECKER.redefine_many({"number": _finite_number, "integer": _whole_number})
    return validators.extend(Draft202012Validator, type_checker=types)


def _with_arrays(arrays: Callable[[object, dict], str | None]):
    from jsonschema import ValidationError, validators

    def x_array(validator, spec, instance, schema):
        problem = arrays(instance, spec)
        if problem:
            yield ValidationError(problem)

    return validators.extend(_validator_class(), validators={X_ARRAY: x_array})


def validate(data: object, schema: dict, where: str, arrays: Callable | None = None) -> None:
    """:class:`UserError` (one sentence, beginning with ``where``) unless ``data`` is valid against ``schema``.
    ``arrays(instance, spec)``: for documents with :data:`X_ARRAY` keywords, returns what is wrong with the array
    ``instance`` refers to (``None`` if nothing)."""
    from jsonschema.exceptions import best_match

    cls = _validator_class() if arrays is None else _with_arrays(arrays)
    too_long(data, schema, where)  # a list longer than allowed is refused by its length, before its items are looked at
    try:
        errors = list(cls(schema).iter_errors(data))
        # an unknown key first: a misspelt key also leaves a required one missing, and the typo is the news
        unknown = [e for e in errors if e.validator == "additionalProperties"]
        err = best_match(unknown or errors)
    except RecursionError:
        raise UserError(f"{where} is nested too deeply to be one of ours.") from None
    if err is not None:
        raise UserError(sentence(err, where))


def too_long(data: object, schema: dict, where: str) -> None:
    """A :class:`UserError` for the first list in ``data`` longer than ``schema`` allows (``maxItems``), in the
    sentence :func:`validate` gives it, found without looking at the items of a list too long: the validator itself
    checks every item of a list before its length (a file of millions of numbers took a minute to refuse)."""
    found = _too_long(data, schema)
    if found is None:
        return
    from collections import deque

    from jsonschema.exceptions import ValidationError

    path, node, items = found
    raise UserError(sentence(ValidationError(f"too long: {len(items)} items", validator="maxItems",
                                             validator_value=node["maxItems"], instance=items, schema=node,
                                             path=deque(path)), where))


def _too_long(data: object, schema: object, path: tuple = ()):
    """The first list in ``data`` longer than its schema's ``maxItems``: ``(path, schema, list)``, or ``None``; it
    looks inside a list only when the list itself is within its bound, so that its cost never grows past the bounds."""
    if not isinstance(schema, dict):
        return None
    if isinstance(data, list):
        bound = schema.get("maxItems")
        if bound is None:
            return None
        if len(data) > bound:
            return path, schema, data
        items = schema.get("items")
        for i, v in enumerate(data if isinstance(items, dict) else ()):
            found = _too_long(v, items, (*path, i))
            if found is not None:
                return found
        return None
    props = schema.get("properties")
    if isinstance(data, dict) and isinstance(props, dict):
        for k, v in data.items():
            found = _too_long(v, props.get(k), (*path, k))
            if found is not None:
                return found
    for sub in schema.get("allOf", ()):  # the branches that apply (if/then/else on small schemas: cheap)
        if isinstance(sub, dict) and "if" in sub:
            sub = sub.get("then") if _validator_class()(sub["if"]).is_valid(data) else sub.get("else")
        found = _too_long(data, sub, path)
        if found is not None:
            return found
    return None


def path_text(path: Sequence) -> str:
    """``("base", "frequency_hz")`` as ``base.frequency_hz``, ``("weights", 3)`` as ``weights[3]``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _show(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:45] + " ... " + text[-10:]


def _json(value: object) -> str:
    """``value`` as the file spells it (``null``, ``true``), shortened for a sentence."""
    try:
        text = json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        text = repr(value)
    return text if len(text) <= 60 else text[:45] + " ... " + text[-10:]


def _branch(schema: dict) -> str:
    """One alternative of an ``anyOf`` in words: a number's range, ``a text``, ``true or false``, ``a list``,
    ``null``."""
    t = schema.get("type")
    if t in ("number", "integer") or (isinstance(t, list) and ("number" in t or "integer" in t)):
        return _kind(schema)
    return {"string": "a text", "boolean": "true or false", "array": "a list of numbers", "object": "an object",
            "null": "null"}.get(t if isinstance(t, str) else "", "another value")


def _kind(schema: dict) -> str:
    """What ``schema`` asks for, in words: ``a number in [0, 3.14159]``, ``a whole number of at least 1``."""
    t = schema.get("type")
    types = t if isinstance(t, list) else [t]
    lo, hi = schema.get("minimum"), schema.get("maximum")
    xlo, xhi = schema.get("exclusiveMinimum"), schema.get("exclusiveMaximum")
    if "integer" in types:
        noun = "a whole number"
        if lo is not None and hi is not None:
            return f"{noun} from {lo:,} to {hi:,}"
        return f"{noun} of at least {lo:,}" if lo is not None else noun
    if "number" in types:
        if lo is None and xlo is None and hi is None and xhi is None:
            return "a finite number"
        left = f"[{lo:g}" if lo is not None else (f"({xlo:g}" if xlo is not None else "(-inf")
        right = f"{hi:g}]" if hi is not None else (f"{xhi:g})" if xhi is not None else "inf)")
        return f"a number in {left}, {right}"
    words = {"object": "an object", "array": "a list", "string": "a text", "boolean": "true or false", "null": "null"}
    named = [words.get(str(x), str(x)) for x in types if x]
    return " or ".join(named) if named else "valid"


def sentence(err, where: str) -> str:
    """One sentence for the ``jsonschema`` error ``err`` in the file ``where``."""
    path = path_text(err.absolute_path)
    at = f"{where}: {path}" if path else where
    v, inst, sch = err.validator, err.instance, err.schema if isinstance(err.schema, dict) else {}
    if v in ("type", "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "multipleOf"):
        return f"{at} must be {_kind(sch)}, got {_show(inst)}."
    if v == "required":
        missing = [k for k in err.validator_value if isinstance(inst, dict) and k not in inst]
        return f"{at} lacks {', '.join(repr(k) for k in missing) or err.message}."
    if v == "additionalProperties" and isinstance(inst, dict):
        from lifelike_mj.errors import unknown_name

        known = list(sch.get("properties", {}))
        extra = [k for k in inst if k not in known]
        return str(unknown_name(f"{at} has an unknown key", extra[0] if extra else "?", known))
    if v in ("minItems", "maxItems", "prefixItems"):
        n = len(inst) if isinstance(inst, (list, tuple)) else 0
        lo, hi = sch.get("minItems"), sch.get("maxItems")
        want = f"{lo}" if lo == hi and lo is not None else (
            f"{lo} to {hi}" if lo is not None and hi is not None else (f"at least {lo}" if lo is not None else f"at most {hi}"))
        items = sch.get("items") if isinstance(sch.get("items"), dict) else {}
        noun = {"number": "numbers", "integer": "whole numbers", "array": "rows", "object": "objects"}.get(
            items.get("type"), "items")
        return f"{at} must have {want} {noun}, got {n}."
    if v in ("enum", "const"):
        allowed = err.validator_value if v == "enum" else [err.validator_value]
        return f"{at} must be {' or '.join(_show(a) for a in allowed)}, got {_show(inst)}."
    if v in ("minLength", "maxLength"):
        return f"{at} must be a text of {v.removesuffix('Length')}imum {err.validator_value} characters."
    if v in ("anyOf", "oneOf") and isinstance(err.validator_value, list):
        words = [_branch(b) for b in err.validator_value if isinstance(b, dict)]
        return f"{at} must be {' or '.join(w for i, w in enumerate(words) if w not in words[:i])}, got {_json(inst)}."
    if v == "uniqueItems":
        return f"{at} must not list an item twice, got {_json(inst)}."
    if v == X_ARRAY:
        return f"{at}: {err.message}."
    if v is None:  # a false schema: the key may not appear here
        return f"{at} is not allowed here."
    return f"{at}: {err.message}."
