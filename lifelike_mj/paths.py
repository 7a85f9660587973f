"""Where the model and controller files live, and the one loader of "a shipped name or a path".

In a checkout they are the top-level ``models/`` and ``controllers/`` folders; a wheel installs
the same folders as ``lifelike_mj/models`` and ``lifelike_mj/controllers`` (see pyproject.toml).
Both hold one folder per creature: ``models/butterfly/butterfly.xml``,
``controllers/fish/B-D.json``.
"""

from __future__ import annotations

import errno
import json
import sys
from collections.abc import Iterable
from pathlib import Path

from lifelike_mj.errors import UserError

_PKG = Path(__file__).resolve().parent

#: Largest file :func:`read_json` accepts (bytes): a controller or preset is a few hundred kB at most.
MAX_JSON_BYTES = 20_000_000


def _data_dir(name: str) -> Path:
    for candidate in (_PKG.parent / name, _PKG / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"cannot find the {name}/ folder of lifelike-mj (looked beside {_PKG})")


def models_dir() -> Path:
    """Folder with the MJCF models, one folder per creature."""
    return _data_dir("models")


def controllers_dir() -> Path:
    """Folder with the controller and preset files, one folder per creature."""
    return _data_dir("controllers")


def model_path(creature: str, file: str) -> Path:
    """Path of the shipped MJCF ``file`` of ``creature`` (``model_path("fish", "tank.xml")``)."""
    return models_dir() / creature / file


def shipped_names(creature: str) -> list[str]:
    """Names of the JSON files shipped in ``controllers/<creature>/``, sorted."""
    return sorted(p.stem for p in (controllers_dir() / creature).glob("*.json"))


def resolve(creature: str, name_or_path: str | Path, what: str) -> Path:
    """The file that ``name_or_path`` means: a path (anything ending in ``.json`` or that exists) or
    the name of a file shipped in ``controllers/<creature>/``. A folder is never a file, so a folder that
    happens to have a shipped file's name (``monarch/`` in the working folder) does not hide it. ``what`` names
    the kind of file in the :class:`UserError` raised when there is no such file ("boids preset")."""
    text = str(name_or_path)
    path = Path(text)
    shipped = controllers_dir() / creature / f"{text}.json"
    if text.endswith(".json") or (_exists(path) and not (path.is_dir() and shipped.is_file())):
        return existing_file(path, what)
    path = shipped
    if not path.is_file():
        raise UserError(f"unknown {what} {text!r}; shipped: {', '.join(shipped_names(creature))} "
                        "(or give the path of a JSON file).")
    return path


def existing_file(path: str | Path, what: str) -> Path:
    """``path`` if it is an existing regular file; else a :class:`UserError` saying what it is instead."""
    p = Path(path)
    if not _exists(p):
        try:
            p.stat()
        except OSError as exc:
            if exc.errno not in (errno.ENOENT, errno.ENOTDIR):
                raise UserError(f"{what} file {str(p)[:80]} cannot be read: {exc.strerror}.") from None
        raise UserError(f"{what} file {p} does not exist.")
    if p.is_dir():
        raise UserError(f"{what} file {p} is a folder, not a file.")
    if not p.is_file():
        raise UserError(f"{what} file {p} is not a regular file (a pipe or a device?).")
    return p


def _exists(p: Path) -> bool:
    """``p.exists()``, false for a name the file system refuses (too long) instead of an ``OSError``."""
    try:
        return p.exists()
    except OSError:
        return False


def _existing_parent(path: Path) -> Path:
    parent = path.absolute().parent
    while not _exists(parent):
        parent = parent.parent
    return parent


def _missing_folders(p: Path, what: str, levels: int, target: Path | None = None) -> Path:
    """The nearest existing folder above ``p``; a :class:`UserError` if more than ``levels`` folders would have to
    be made to reach ``p`` (a mistyped path is not made silently, least of all at the top of the file system)."""
    parent = _existing_parent(p)
    try:
        missing = len(p.absolute().relative_to(parent).parts) - 1
    except ValueError:
        missing = 0
    if missing > levels:
        first = next((q for q in reversed(p.parents) if not _exists(q)), p.parent)  # as the user wrote it
        raise UserError(f"{what} {target or p} cannot be written: the folder {first} does not exist (make it first, "
                        "or give a path in a folder that exists).")
    return parent


def check_writable(path: str | Path, what: str = "output") -> Path:
    """Before any work: :class:`UserError` unless a file could be written at ``path`` (its folder exists
    and is writable; ``path`` itself is not a folder or another kind of file)."""
    p = Path(path)
    _check_name(p, _existing_parent(p), what)
    parent = _missing_folders(p, what, 0)
    if p.exists() and p.is_dir():
        raise UserError(f"{what} {p} is a folder; give a file name.")
    if p.exists() and not p.is_file():
        raise UserError(f"{what} {p} exists and is not a regular file.")
    _probe(parent, p, what, "written")
    return p


def _check_name(p: Path, parent: Path, what: str) -> None:
    """:class:`UserError` if a part of ``p`` still to be made is longer than the file system allows, or the
    whole path is (``NAME_MAX``, ``PATH_MAX`` of the folder that exists)."""
    import os

    try:
        name_max = os.pathconf(parent, "PC_NAME_MAX")
        path_max = os.pathconf(parent, "PC_PATH_MAX")
    except (OSError, ValueError):
        return
    try:
        rest = p.absolute().relative_to(parent).parts
    except ValueError:
        rest = (p.name,)
    for part in rest:
        if len(part.encode()) > name_max:
            raise UserError(f"{what} {str(p)[:80]}... cannot be written: the name {part[:40]!r}... is "
                            f"{len(part.encode())} bytes long, and this file system allows {name_max}.")
    if len(str(p.absolute()).encode()) >= path_max:
        raise UserError(f"{what} {str(p)[:80]}... cannot be written: its path is {len(str(p.absolute()).encode())} "
                        f"bytes long, and this file system allows {path_max - 1}.")


def _probe(folder: Path, target: Path, what: str, verb: str) -> None:
    """:class:`UserError` unless ``folder`` is a folder in which a file can be made (tried with an
    anonymous temporary file, gone at once: ``os.access`` says yes to root everywhere, even in /proc);
    ``verb`` ("written", "made") phrases the sentence about ``target``."""
    import tempfile

    if not folder.is_dir():
        raise UserError(f"{what} {target} cannot be {verb}: {folder} is a file, not a folder.")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise UserError(f"{what} {target} cannot be written in {folder} ({exc.strerror or type(exc).__name__}).") from None


def check_output_file(path: str | Path, what: str, *, suffixes: Iterable[str] = (), overwrite: bool = False,
                      claim: bool = True) -> Path:
    """Before any work: the file ``path`` may be written (:func:`check_writable`), ends in one of
    ``suffixes`` (if given), and does not exist unless ``overwrite``; then it is claimed for this process
    (:func:`lifelike_mj.io.claim`, unless ``claim`` is false), so that a second run writing it stops at once and
    the final write re-checks that nobody made it meanwhile."""
    p = Path(path)
    suffixes = tuple(suffixes)
    if suffixes and p.suffix.lower() not in suffixes:
        raise UserError(f"{what} must end in {' or '.join(suffixes)}, got {str(p)!r}.")
    check_writable(p, what)
    from lifelike_mj.io import check_unclaimed

    check_unclaimed(p, what)
    for claimed in (False, True) if claim else (False,):  # checked again once claimed: another run may just have written it
        if claimed:
            from lifelike_mj.io import claim as _claim

            _claim(p, what, overwrite=overwrite)
        if p.exists() and not overwrite:
            raise UserError(f"{what} {p} already exists; add --overwrite to replace it.")
    return p


def check_output_dir(path: str | Path, what: str, names: Iterable[str] = (), *, overwrite: bool = False,
                     claim: bool = True, make: int = 1) -> Path:
    """Before any work: the folder ``path`` may be made or written into (at most ``make`` folders made to reach
    it: by default ``path`` itself, in a folder that exists), and none of the files ``names`` it will hold exists
    yet unless ``overwrite``; the folder is claimed for this process (:func:`lifelike_mj.io.claim`), as
    :func:`check_output_file` claims a file."""
    p = Path(path)
    _check_name(p / "x", p if _exists(p) else _existing_parent(p), what)
    parent = p if _exists(p) else _missing_folders(p / "x", what, make, target=p)
    if p.exists() and not p.is_dir():
        raise UserError(f"{what} {p} is a file; give a folder.")
    _probe(parent, p, what, "made")
    from lifelike_mj.io import check_unclaimed

    check_unclaimed(p, what)
    names = tuple(names)
    for claimed in (False, True) if claim else (False,):  # checked again once claimed, as a file is
        if claimed:
            from lifelike_mj.io import claim as _claim

            _claim(p, what, overwrite=overwrite)
        there = [n for n in names if (p / n).exists()] if not overwrite else []
        if there:
            raise UserError(f"{what} {p} already holds {', '.join(there[:3])}{' ...' if len(there) > 3 else ''}; "
                            "add --overwrite to replace them, or choose another folder.")
    return p


def read_json(path: str | Path, what: str, max_bytes: int | None = None) -> object:
    """The content of the JSON file ``path``, as plain data. Reading never runs code; a file that is missing, a
    folder, not readable UTF-8 JSON, or larger than ``max_bytes`` (:data:`MAX_JSON_BYTES` by default, checked
    before it is read) is a :class:`UserError` saying which."""
    p = Path(path)
    limit = MAX_JSON_BYTES if max_bytes is None else int(max_bytes)
    if p.is_dir():
        raise UserError(f"{what} file {p} is a folder, not a file.")
    try:
        size = p.stat().st_size
        if size <= limit:
            return json.loads(p.read_text(encoding="utf-8"), parse_constant=_no_constant, object_pairs_hook=_no_twins)
    except FileNotFoundError:
        raise UserError(f"{what} file {p} does not exist.") from None
    except UnicodeDecodeError:
        raise UserError(f"{what} file {p} is not a JSON file (not UTF-8 text).") from None
    except json.JSONDecodeError as exc:
        raise UserError(f"{what} file {p} is not a JSON file ({exc.msg.lower()} at line {exc.lineno}, column "
                        f"{exc.colno}).") from None
    except _NotStrict as exc:
        raise UserError(f"{what} file {p} is not strict JSON ({exc}).") from None
    except (OSError, ValueError) as exc:
        why = exc.strerror.lower() if isinstance(exc, OSError) and exc.strerror else exc.__class__.__name__
        raise UserError(f"{what} file {p} cannot be read as JSON ({why}).") from None
    except RecursionError:  # json's decoder recurses once per level of nesting
        raise UserError(f"{what} file {p} is nested too deeply to be one (more than about "
                        f"{sys.getrecursionlimit()} levels of lists or objects).") from None
    shown = f"{limit / 1e6:g} MB" if limit >= 1_000_000 else f"{limit / 1e3:g} kB"
    raise UserError(f"{what} file {p} is {size / 1e6:.1f} MB, larger than any {what} file can be (at most {shown}).")


def load_named_json(creature: str, name_or_path: str | Path, what: str) -> tuple[object, Path]:
    """:func:`resolve` then :func:`read_json`: ``(data, path)``."""
    path = resolve(creature, name_or_path, what)
    return read_json(path, what), path


def _no_twins(pairs: list) -> dict:
    """An object whose keys are each given once (JSON allows a repeated key, and Python's reader keeps the last,
    silently: a file that says a thing twice says nothing clear)."""
    seen = {}
    for k, v in pairs:
        if k in seen:
            raise _NotStrict(f"the key {k!r} is given twice in one object")
        seen[k] = v
    return seen


class _NotStrict(ValueError):
    """A constant (NaN, Infinity) that Python's JSON reader takes and strict JSON does not."""


def _no_constant(name: str) -> float:
    raise _NotStrict(f"{name} is not a number in strict JSON")
