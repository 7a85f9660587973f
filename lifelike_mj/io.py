"""Atomic file writing: a file is either its old self or complete, never half-written."""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path`` (same suffix); on success it is flushed to disk (fsync) and
    replaces ``path``; on failure or interruption it is removed.

    Where ``path`` (or the folder that holds it) was claimed by this process without leave to overwrite
    (:func:`claim`), the final step re-checks: the file is created exclusively, so a file that appeared
    meanwhile (written by some other program) is kept and this write is refused with a
    :class:`~lifelike_mj.errors.UserError`."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{_short(target.stem)}.", suffix=_short(target.suffix, 16), dir=target.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the file the user's usual mode
    try:
        yield Path(tmp)
        _fsync(tmp)
        _publish(tmp, target)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _short(text: str, n: int = 40) -> str:
    """``text`` cut to ``n`` characters, so that a temporary name stays short whatever the target's length."""
    return text[:n]


def _publish(tmp: str, target: Path) -> None:
    """Move the finished ``tmp`` to ``target``: replacing it, or, where ``target`` is claimed without leave to
    overwrite and this process has not written it yet, creating it exclusively (a hard link, which fails if
    the name exists)."""
    c = _claim_of(target)
    key = _key(target)
    if c is None or c.overwrite or key in c.written:
        os.replace(tmp, target)
    else:
        from lifelike_mj.errors import UserError

        appeared = UserError(f"{c.what} {target} appeared while this run was working (another program wrote it); "
                             "it is kept, and this run's result is not written (add --overwrite to replace it).")
        try:
            os.link(tmp, target)
        except FileExistsError:
            raise appeared from None
        except OSError:  # a file system without hard links: create the name exclusively, then fill it
            try:
                os.close(os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            except FileExistsError:
                raise appeared from None
            os.replace(tmp, target)
        else:
            os.unlink(tmp)
    if c is not None:
        c.written.add(key)


# ---- claims: one writer per output ---------------------------------------------------------------


@dataclasses.dataclass
class Claim:
    """This process's exclusive right to write ``path`` (a file, or a folder of outputs): an ``flock`` on a
    lock file beside it, held until :meth:`release`. ``overwrite``: whether an existing file may be replaced;
    ``written``: the files this process has written under the claim (they may be written again)."""

    path: Path
    what: str
    overwrite: bool
    fd: int
    lock: Path
    written: set = dataclasses.field(default_factory=set)

    def release(self) -> None:
        """Give the claim up: the lock file is removed, then unlocked."""
        _claims.pop(_key(self.path), None)
        if self.fd < 0:
            return
        with contextlib.suppress(OSError):
            os.unlink(self.lock)
        with contextlib.suppress(OSError):
            os.close(self.fd)
        self.fd = -1


#: The claims this process holds, by absolute path.
_claims: dict[str, Claim] = {}


def _key(path: Path) -> str:
    return os.path.normpath(os.path.abspath(path))


def _claim_of(target: Path) -> Claim | None:
    """The claim that covers ``target``: its own, or that of a folder it lies in."""
    if _claims:
        for p in (target, *target.absolute().parents):
            if (c := _claims.get(_key(p))) is not None:
                return c
    return None


def _held(what: str, target: Path, fd: int) -> Exception:
    """The error for ``target``, whose lock (open on ``fd``) another process holds: it names that process."""
    from lifelike_mj.errors import UserError

    other = os.pread(fd, 400, 0).decode(errors="replace").strip()
    return UserError(f"another run is writing {what} {target} (process {other or 'unknown'}); wait for it or choose "
                     "another name.")


def lock_path(path: str | Path) -> Path:
    """The lock file of ``path``: ``.NAME.lock`` beside it (a hash of the name where that would be too long)."""
    import hashlib

    p = Path(path)
    name = f".{p.name}.lock"
    if len(name.encode()) > 200:
        name = f".lifelike-mj-{hashlib.sha256(p.name.encode()).hexdigest()[:20]}.lock"
    return p.absolute().parent / name


def claim(path: str | Path, what: str = "output", *, overwrite: bool = False) -> Claim:
    """Claim ``path`` for this process (see :class:`Claim`): at once, or a
    :class:`~lifelike_mj.errors.UserError` naming the process that holds it. Claiming a path this process
    already holds returns that claim (leave to overwrite is kept if either asks for it). A lock left by a
    killed process is free again (``flock`` dies with its holder). Released by :meth:`Claim.release` or
    :func:`release_claims`."""
    import fcntl

    from lifelike_mj.errors import UserError

    target = Path(path)
    held = _claims.get(_key(target))
    if held is not None:
        held.overwrite = held.overwrite or overwrite
        return held
    lock = lock_path(target)
    lock.parent.mkdir(parents=True, exist_ok=True)
    for _ in range(20):  # a lock file removed between our open and our flock belongs to nobody: open it again
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            err = _held(what, target, fd)
            os.close(fd)
            raise err from None
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    else:
        raise UserError(f"the lock of {what} {target} keeps changing hands; try again.")
    import sys

    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}: {' '.join(['lifelike-mj', *sys.argv[1:]])[:300]}".encode(), 0)
    c = Claim(target, what, overwrite, fd, lock)
    _claims[_key(target)] = c
    return c


def check_unclaimed(path: str | Path, what: str = "output") -> None:
    """A :class:`~lifelike_mj.errors.UserError` naming the process that holds ``path``'s claim, if one does; this
    touches nothing (a lock file is only opened where it exists), so a command can check all of its outputs
    before it claims the first."""
    import fcntl


    target = Path(path)
    if _key(target) in _claims:
        return
    try:
        fd = os.open(lock_path(target), os.O_RDWR)
    except OSError:
        return
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            raise _held(what, target, fd) from None
    finally:
        os.close(fd)


def release_claims(keep: Iterable[str] = ()) -> None:
    """Give up every claim this process holds but those of the paths ``keep`` (:func:`held_claims`); the
    command line gives up those its command made when it ends."""
    keep = set(keep)
    for key, c in list(_claims.items()):
        if key not in keep:
            c.release()


def held_claims() -> tuple[str, ...]:
    """The paths this process holds claims on (for :func:`release_claims`)."""
    return tuple(_claims)


@contextlib.contextmanager
def exclusive(path: str | Path, what: str = "output", *, overwrite: bool = True) -> Iterator[Claim]:
    """Hold :func:`claim` on ``path`` while the block runs (a second run gets a :class:`UserError` at once);
    released at the end unless it was held before the block."""
    held = _claims.get(_key(Path(path)))
    c = claim(path, what, overwrite=overwrite)
    try:
        yield c
    finally:
        if held is None:
            c.release()


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
