"""Checkpoint files: data only (an ``.npz`` read with ``allow_pickle=False``), replaced atomically after
every generation.

A checkpoint is a NumPy zip archive. Its member ``meta`` holds UTF-8 JSON (as ``uint8``); every array of
the checkpoint is its own member ``a0``, ``a1``, ..., referred to from the JSON as ``{"__array__": "a0"}``.
Non-finite floats are written as ``{"__float__": "nan" | "inf" | "-inf"}`` so the JSON stays strict.
Reading one never runs code from the file: ``numpy.load(..., allow_pickle=False)`` refuses object
arrays, and the JSON decoder builds only dicts, lists, strings and numbers.

Layout of ``meta`` (``version`` 2)::

    format       "lifelike_mj.evolve.checkpoint"
    version      2
    fingerprint  problem.fingerprint()
    dim, maximize
    optimizer    "rcga" | "cmaes" | "crs2" | "esch" | "isres"
    seed         int
    population   the resolved population size (int)
    budget       {"kind": "generations" | "evaluations", "value": int}
    state        the optimiser's state: arrays, numbers and strings only
                 (rcga: population, fitness, PCG64 state; cmaes: the fitness log that replays it;
                 nlopt: the log of points and values)
    history      list of per-generation records
    best_x, best_f, evaluations, generations
    elapsed_s    optimisation seconds so far (summed over sessions)
    finished     True once the budget is spent
    saved_at     time.time() of writing
    package      lifelike-mj version that wrote it

Version 1 files (lifelike-mj 0.2 and earlier) were pickles; they are refused, not read.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import time
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path
from lifelike_mj.schema import validate

FORMAT = "lifelike_mj.evolve.checkpoint"
VERSION = 2
#: Largest checkpoint read (bytes): a bigger file is refused before it is opened.
MAX_BYTES = 2 * 1024**3
_PICKLE_MAGIC = (b"\x80",)


def _encode(value: Any, arrays: dict[str, np.ndarray]) -> Any:
    if isinstance(value, np.ndarray):
        if value.dtype == object:
            raise TypeError("a checkpoint cannot hold object arrays")
        key = f"a{len(arrays)}"
        arrays[key] = value
        return {"__array__": key}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value):
            raise TypeError("checkpoint dict keys must be strings")
        return {k: _encode(v, arrays) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_encode(v, arrays) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else {"__float__": repr(v)}
    if value is None or isinstance(value, str):
        return value
    raise TypeError(f"a checkpoint cannot hold a {type(value).__name__}")


def _decode(value: Any, arrays: Any, path: Path) -> Any:
    if isinstance(value, dict):
        if set(value) == {"__array__"}:
            key = value["__array__"]
            if not isinstance(key, str) or key not in arrays.files:
                raise UserError(f"checkpoint {path} is damaged (it refers to a missing array {key!r}).")
            return arrays[key]
        if set(value) == {"__float__"}:
            if value["__float__"] not in ("nan", "inf", "-inf"):
                raise UserError(f"checkpoint {path} is damaged (bad number {value['__float__']!r}).")
            return float(value["__float__"])
        return {k: _decode(v, arrays, path) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v, arrays, path) for v in value]
    return value


def save_checkpoint(path: str | Path, data: dict[str, Any]) -> None:
    """Write ``data`` (without ``format``/``version``, which are added) atomically and durably to ``path``.

    ``data`` may hold dicts with string keys, lists, tuples (read back as lists), strings, numbers,
    booleans, ``None`` and NumPy arrays of numbers; anything else is a ``TypeError``.
    """
    from lifelike_mj import __version__

    payload = {"format": FORMAT, "version": VERSION, **data, "saved_at": time.time(), "package": __version__}
    arrays: dict[str, np.ndarray] = {}
    meta = json.dumps(_encode(payload, arrays), allow_nan=False).encode("utf-8")
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, meta=np.frombuffer(meta, dtype=np.uint8), **arrays)
            fh.flush()
            os.fsync(fh.fileno())


def is_checkpoint(path: str | Path) -> bool:
    """Whether ``path`` looks like a checkpoint of any version (a zip with ``meta``, or an old pickle)."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4)
    except OSError:
        return False
    if head[:1] in _PICKLE_MAGIC:
        return True
    if head != b"PK\x03\x04":
        return False
    try:
        with zipfile.ZipFile(path) as z:
            return "meta.npy" in z.namelist()
    except (zipfile.BadZipFile, OSError):
        return False


def check_checkpoint_path(path: str | Path, *, resume: bool, overwrite: bool) -> None:
    """Before a run starts: :class:`UserError` unless ``path`` may be used as its checkpoint.

    A path that is not a regular file is refused; an existing checkpoint without ``resume`` needs
    ``overwrite``; an existing file that is not a checkpoint is never replaced; the folder must be writable.
    """
    path = Path(path)
    if path.exists() and not path.is_file():
        raise UserError(f"checkpoint {path} is not a regular file.")
    if path.exists() and not resume:
        if not is_checkpoint(path):
            raise UserError(f"{path} exists and is not a checkpoint; it is not replaced (choose another --checkpoint).")
        if not overwrite:
            raise UserError(f"checkpoint {path} already exists: continue it with --resume, or replace it with "
                            "--overwrite.")
    from lifelike_mj.paths import check_writable

    check_writable(path, what="checkpoint")


@contextlib.contextmanager
def guarded_run_files(out: str | Path, checkpoint: str | Path | None, *, resume: bool,
                      overwrite: bool) -> Iterator[Path]:
    """The files of an evolution that writes its result to ``out`` (``.json``) and checkpoints every
    generation (``checkpoint``, default ``out`` + ``.ckpt``; yielded). Nothing is lost: before any work, an
    existing ``out`` or checkpoint is refused unless ``resume`` or ``overwrite``, a checkpoint equal to
    ``out`` is refused, and both files are locked for the whole block, so a second run on the same files
    stops at once with a sentence."""
    from lifelike_mj.io import check_unclaimed, exclusive
    from lifelike_mj.paths import check_output_file, check_writable

    out = Path(out)
    ckpt = Path(checkpoint) if checkpoint else out.with_name(out.name + ".ckpt")
    if ckpt.absolute().resolve() == out.absolute().resolve():
        raise UserError(f"the checkpoint and the controller file are the same file ({out}); give another --checkpoint.")
    check_output_file(out, "--out", suffixes=(".json",), overwrite=True, claim=False)
    check_writable(ckpt, "checkpoint")
    check_unclaimed(ckpt, "checkpoint")
    with exclusive(out, "--out", overwrite=overwrite or resume), exclusive(ckpt, "checkpoint",
                                                                           overwrite=overwrite or resume):
        check_output_file(out, "--out", suffixes=(".json",), overwrite=overwrite or resume)
        check_checkpoint_path(ckpt, resume=resume, overwrite=overwrite)
        yield ckpt


# ---- the one description of a checkpoint ---------------------------------------------------------------

#: The optimisers whose state a checkpoint holds, and the layout of each state.
_NLOPT = ("crs2", "esch", "isres")
#: The optimisers by name (:func:`lifelike_mj.evolve.optimize`), each with its own state in a checkpoint.
OPTIMIZERS = ("rcga", "cmaes", *_NLOPT)


def json_schema() -> dict:
    """The JSON Schema of a checkpoint's ``meta`` (``docs/schemas/evolve-checkpoint.schema.json``): every field's
    type and bounds, the optimiser's state per optimiser, and, for each NumPy array the JSON refers to
    (``{"__array__": "a0"}``), its kind and shape under the keyword ``x-array`` (``"dim"`` and ``"population"``
    stand for the checkpoint's own values, ``"*"`` for any length). :func:`load_checkpoint` enforces it before any
    value is used."""
    nonfinite = {"type": "object", "properties": {"__float__": {"enum": ["nan", "inf", "-inf"]}},
                 "required": ["__float__"], "additionalProperties": False}
    real = {"anyOf": [{"type": "number"}, nonfinite]}

    def array(kind: str, *shape: int | str, finite: bool = False) -> dict:
        return {"type": "object", "properties": {"__array__": {"type": "string"}}, "required": ["__array__"],
                "additionalProperties": False, "x-array": {"kind": kind, "shape": list(shape), "finite": finite}}

    def obj(props: dict, required: list[str] | None = None) -> dict:
        return {"type": "object", "properties": props, "required": list(props) if required is None else required,
                "additionalProperties": False}

    count = {"type": "integer", "minimum": 0}
    u128 = {"type": "integer", "minimum": 0, "maximum": 2**128 - 1}
    states = {
        "rcga": obj({"P": array("float", "population", "dim", finite=True), "f": array("float", "population"),
                     "rng": obj({"bit_generator": {"const": "PCG64"}, "state": obj({"state": u128, "inc": u128}),
                                 "has_uint32": {"enum": [0, 1]},
                                 "uinteger": {"type": "integer", "minimum": 0, "maximum": 2**32 - 1}})}),
        "cmaes": obj({"F": array("float", "*"), "sizes": array("int", "*"), "digest": {"type": "string"},
                      "cma_version": {"type": "string"}}),
        **{n: obj({"X": array("float", "*", "dim", finite=True), "F": array("float", "*"),
                   "nlopt_version": {"type": "string"}}) for n in _NLOPT},
    }
    record = obj({"generation": {"type": "integer", "minimum": 1}, "best": real, "mean": real,
                  "evaluations": count, "elapsed_s": {"type": "number", "minimum": 0}})
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://lifelike-mj.example/schemas/evolve-checkpoint.schema.json",
        "title": "lifelike-mj evolution checkpoint (the JSON member 'meta' of the .npz)",
        "description": "Arrays live beside the JSON in the .npz, referred to as {\"__array__\": NAME}; non-finite "
                       "numbers are {\"__float__\": \"nan\" | \"inf\" | \"-inf\"}.",
        "type": "object",
        "properties": {
            "format": {"const": FORMAT}, "version": {"const": VERSION}, "fingerprint": {"type": "string"},
            "dim": {"type": "integer", "minimum": 1, "maximum": 10**7}, "maximize": {"type": "boolean"},
            "optimizer": {"enum": list(OPTIMIZERS)}, "seed": {"type": "integer", "minimum": 0, "maximum": 2**64 - 1},
            "population": {"type": "integer", "minimum": 1, "maximum": 10**7},
            "budget": obj({"kind": {"enum": ["generations", "evaluations"]},
                           "value": {"type": "integer", "minimum": 1}}),
            "state": {"type": "object"},
            "history": {"type": "array", "items": record},
            "best_x": {"anyOf": [{"type": "null"}, array("float", "dim", finite=True)]},
            "best_f": real, "evaluations": count, "generations": count,
            "elapsed_s": {"type": "number", "minimum": 0}, "finished": {"type": "boolean"},
            "saved_at": {"type": "number"}, "package": {"type": "string"},
        },
        "required": ["format", "version", "fingerprint", "dim", "maximize", "optimizer", "seed", "population", "budget",
                     "state", "history", "best_x", "best_f", "evaluations", "generations", "elapsed_s", "finished"],
        "additionalProperties": False,
        "allOf": [{"if": {"properties": {"optimizer": {"const": n}}, "required": ["optimizer"]},
                   "then": {"properties": {"state": st}}} for n, st in states.items()],
    }


def _array_problem(arrays: Any, meta: dict) -> Any:
    """The ``x-array`` check of :func:`json_schema` over the archive ``arrays``: what is wrong with the array a
    reference names (``None`` if nothing)."""

    def check(ref: Any, spec: dict) -> str | None:
        if not isinstance(ref, dict) or not isinstance(ref.get("__array__"), str):
            return None  # the schema's own keywords report it
        key = ref["__array__"]
        if key not in arrays.files:
            return f"refers to an array {key!r} the file does not hold"
        a = arrays[key]
        kinds = {"float": "fiu", "int": "iu"}[spec["kind"]]
        if a.dtype.kind not in kinds and a.size:
            return f"must be an array of {spec['kind']}s, got {a.dtype}"
        want = [meta.get(d) if isinstance(d, str) and d != "*" else d for d in spec["shape"]]
        ok = a.ndim == len(want) and all(w == "*" or not checks.is_whole(w) or n == w for n, w in zip(a.shape, want))
        if not ok:
            return f"must be an array of shape ({', '.join(map(str, spec['shape']))}) = {tuple(want)}, got {a.shape}"
        if spec.get("finite") and a.size and not np.all(np.isfinite(a)):
            return "must hold finite numbers only"
        return None

    return check


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Read a checkpoint; :class:`UserError` if it is unreadable, an old pickle, or not a checkpoint of this
    version. ``FileNotFoundError`` if there is no file."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(path)
    if not path.is_file():
        raise UserError(f"checkpoint {path} is not a regular file.")
    if path.stat().st_size > MAX_BYTES:
        raise UserError(f"checkpoint {path} is larger than {MAX_BYTES // 1024**3} GiB; not read.")
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head[:1] in _PICKLE_MAGIC:
        raise UserError(f"checkpoint {path} is an old pickled checkpoint (lifelike-mj 0.2 or earlier); it is not "
                        "read because a pickle can run code: start the run again without --resume.")
    if head != b"PK\x03\x04":
        raise UserError(f"checkpoint {path} is not a lifelike_mj.evolve checkpoint.")
    try:
        with np.load(path, allow_pickle=False) as arrays:
            if "meta" not in arrays.files:
                raise UserError(f"checkpoint {path} is not a lifelike_mj.evolve checkpoint.")
            meta_raw = arrays["meta"]
            if meta_raw.dtype != np.uint8 or meta_raw.ndim != 1:
                raise UserError(f"checkpoint {path} is damaged (its meta is not text).")
            meta = json.loads(meta_raw.tobytes().decode("utf-8"))
            if not isinstance(meta, dict) or meta.get("format") != FORMAT:
                raise UserError(f"checkpoint {path} is not a lifelike_mj.evolve checkpoint.")
            if meta.get("version") != VERSION:
                raise UserError(f"checkpoint {path} has format version {meta.get('version')!r}, but this code reads "
                                f"version {VERSION}.")
            validate(meta, json_schema(), f"checkpoint {path}", arrays=_array_problem(arrays, meta))
            data = _decode(meta, arrays, path)
    except UserError:
        raise
    except RecursionError:
        raise UserError(f"checkpoint {path} is damaged (its meta is nested too deeply).") from None
    except Exception as exc:  # truncated zip, bad JSON, object arrays refused by allow_pickle=False, ...
        raise UserError(f"checkpoint {path} is unreadable ({type(exc).__name__}: {str(exc)[:160]}).") from None
    return data


def check_compatible(path: str | Path, data: dict[str, Any], *, fingerprint: str, dim: int, maximize: bool,
                     optimizer: str, seed: int, population: int, budget: dict[str, Any]) -> None:
    """:class:`UserError` unless the checkpoint ``data`` belongs to the run described by the other arguments."""
    if data.get("fingerprint") != fingerprint or data.get("dim") != dim or data.get("maximize") != maximize:
        raise UserError(f"checkpoint {path} is from a different problem ({data.get('fingerprint')!r}, "
                        f"not {fingerprint!r}).")
    mine = {"optimizer": optimizer, "seed": seed, "population": population}
    for key, want in mine.items():
        if data.get(key) != want:
            raise UserError(f"checkpoint {path} was written with {key} {data.get(key)!r}, but this run has {key} {want!r}.")
    theirs = data.get("budget") or {}
    if theirs != budget:
        raise UserError(f"checkpoint {path} was written with budget {theirs.get('kind')}={theirs.get('value')!r}, "
                        f"but this run asks for {budget['kind']}={budget['value']!r}.")
