"""Atomic file writing: a file is either its old self or complete, never half-written."""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success it is flushed to disk (fsync) and
    replaces ``path``; on failure or interruption it is removed."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=target.suffix, dir=target.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file the user's usual mode
    try:
        yield Path(tmp)
        _fsync(tmp)
        os.replace(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@contextlib.contextmanager
def exclusive(path: str | Path, what: str = "output") -> Iterator[None]:
    """Hold an exclusive lock on ``path`` (through the file ``path.lock`` beside it) while the block runs,
    so that two runs cannot write the same output; a second run gets a :class:`UserError` at once.
    The lock file is removed at the end; a lock left by a killed process is free again (``flock``)."""
    import fcntl

    from lifelike_mj.errors import UserError

    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    lock = target.with_name(target.name + ".lock")
    fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            other = os.pread(fd, 32, 0).decode(errors="replace").strip()
            raise UserError(f"another run is writing {what} {target} (process {other or 'unknown'}); wait for it "
                            "or choose another file.") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        try:
            yield
        finally:
            with contextlib.suppress(OSError):
                os.unlink(lock)
    finally:
        os.close(fd)


def _fsync(path: str) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return Path(path)


def strict(data: object) -> object:
    """``data`` made fit for strict JSON: every NaN or infinite float becomes ``null``, and a dict that
    held one as a value gains ``"undefined": {key: reason}`` naming it (NaN: not defined for this run;
    +-inf: unbounded)."""
    import math

    def plain(v: object) -> object:
        if hasattr(v, "item") and hasattr(v, "dtype") and getattr(v, "shape", None) == ():  # a NumPy scalar
            return v.item()
        return v

    def walk(v: object) -> object:
        v = plain(v)
        if isinstance(v, dict):
            out, why = {}, {}
            for k, x in v.items():
                x = plain(x)
                if isinstance(x, float) and not math.isfinite(x):
                    why[str(k)] = "not defined for this run (NaN)" if math.isnan(x) else f"unbounded ({x})"
                out[k] = walk(x)
            if why:
                old = out.get("undefined")
                out["undefined"] = {**old, **why} if isinstance(old, dict) else why
            return out
        if isinstance(v, (list, tuple)):
            return [walk(x) for x in v]
        if isinstance(v, float) and not math.isfinite(v):
            return None
        return v

    return walk(data)


def dumps(data: object, indent: int | None = 2) -> str:
    """Strict JSON text of ``data`` (see :func:`strict`): never a bare ``NaN`` or ``Infinity``."""
    return json.dumps(strict(data), indent=indent, allow_nan=False)


def write_json(path: str | Path, data: object) -> Path:
    """Write ``data`` as indented strict JSON (:func:`strict`), atomically."""
    return write_text(path, dumps(data) + "\n")


def write_npz(path: str | Path, **arrays: object) -> Path:
    """Write NumPy arrays as a compressed ``.npz``, atomically."""
    import numpy as np

    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return Path(path)
