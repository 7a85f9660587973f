"""Checkpoint files: one pickled dict, replaced atomically after every generation.

Layout (``version`` 1)::

    format       "lifelike_mj.evolve.checkpoint"
    version      1
    fingerprint  problem.fingerprint()
    dim, maximize
    optimizer    "rcga" | "cmaes" | "crs2" | "esch" | "isres"
    seed         int
    population   the resolved population size (int)
    budget       {"kind": "generations" | "evaluations", "value": int}
    state        the optimiser's full state (its own dict: populations, RNG states, pickled CMA-ES, ...)
    history      list of per-generation records
    best_x, best_f, evaluations, generations
    elapsed_s    optimisation seconds so far (summed over sessions)
    finished     True once the budget is spent
    saved_at     time.time() of writing

Checkpoints are pickles: load only files you (or your runs) wrote.
"""

from __future__ import annotations

import pickle
import time
from pathlib import Path
from typing import Any

from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path

FORMAT = "lifelike_mj.evolve.checkpoint"
VERSION = 1


def save_checkpoint(path: str | Path, data: dict[str, Any]) -> None:
    """Write ``data`` (without ``format``/``version``, which are added) atomically to ``path``."""
    payload = {"format": FORMAT, "version": VERSION, **data, "saved_at": time.time()}
    blob = pickle.dumps(payload, protocol=pickle.HIGHEST_PROTOCOL)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(blob)
            fh.flush()


def load_checkpoint(path: str | Path) -> dict[str, Any]:
    """Read a checkpoint; :class:`UserError` if it is unreadable or not a checkpoint of this version."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            data = pickle.load(fh)
    except FileNotFoundError:
        raise
    except Exception as exc:  # truncated, not a pickle, classes that no longer exist, ...
        raise UserError(f"checkpoint {path} is unreadable ({type(exc).__name__}: {exc}).") from exc
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise UserError(f"checkpoint {path} is not a lifelike_mj.evolve checkpoint.")
    if data.get("version") != VERSION:
        raise UserError(f"checkpoint {path} has format version {data.get('version')!r}, but this code reads version {VERSION}.")
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
