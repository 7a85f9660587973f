"""Numba's on-disk cache, keyed on this package's source.

Numba keys a cached function on the modification time of the file that defines it only, so a
compiled loop that inlines a function from another module (the pitch laws of ``flight.py`` and
``ann.py`` inside the backends' loops, for example) keeps serving the old machine code after that
other module changes. Here every cache lives in a folder named after a hash of the whole
package's source and numba's version: any edit to any module selects a fresh folder, so no stale
code can be served. Folders unused for 30 days are removed.

:func:`configure` runs on ``import lifelike_mj`` (before numba is imported) unless the user has set
``NUMBA_CACHE_DIR`` (then the user's folder is used as it is) or numba is already imported.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import shutil
import sys
import time
from collections.abc import Iterator
from pathlib import Path

_PKG = Path(__file__).resolve().parent
#: Cache folders not used for this many days are removed.
KEEP_DAYS = 30
#: The keyed folder :func:`configure` chose for this process (``None``: the user's own, or none).
_FOLDER: Path | None = None
#: The groups of compiled functions :func:`compile_notice` has seen compiled (or found compiled) in this process.
_SEEN: set[str] = set()


def source_key(root: Path = _PKG) -> str:
    """A hash of every ``.py`` file under ``root`` (paths and contents) and of numba's version."""
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    try:  # numba's own version file, found without importing numba or importlib.metadata (slow)
        import importlib.util

        spec = importlib.util.find_spec("numba")
        if spec is not None and spec.origin:
            h.update((Path(spec.origin).parent / "_version.py").read_bytes())
    except (ImportError, OSError, ValueError):  # numba missing or laid out otherwise: the key covers our source
        pass
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """Where the keyed folders live: ``$XDG_CACHE_HOME/lifelike-mj/numba`` (``~/.cache/...``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "lifelike-mj" / "numba"


def configure() -> Path | None:
    """Point numba's cache at the folder of the current source (see the module docstring); returns it,
    or ``None`` when left alone (``NUMBA_CACHE_DIR`` set by the user, numba already imported, or no
    writable cache folder)."""
    if "NUMBA_CACHE_DIR" in os.environ or "numba" in sys.modules:
        return None
    root = cache_root()
    folder = root / source_key()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)
    except OSError:
        return None
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    global _FOLDER
    _FOLDER = folder
    _prune(root, folder)
    return folder


def _marker(name: str) -> Path | None:
    return None if _FOLDER is None else _FOLDER / f"compiled-{name}"


def compiled(name: str) -> bool | None:
    """Whether the group of compiled functions ``name`` (``"flight3d-fly"``) has been compiled into this source's
    cache folder (:func:`compile_notice` marks it); ``None`` when that cannot be told (the user's own
    ``NUMBA_CACHE_DIR``, whose entries numba keys on each file's time stamp alone, or no cache folder)."""
    marker = _marker(name)
    return None if marker is None else marker.is_file()


@contextlib.contextmanager
def compile_notice(name: str, what: str, seconds: float) -> Iterator[None]:
    """Around the first call of a group of cached compiled functions: when this source's cache folder does not hold
    them yet, one line on stderr before the call, ``compiling the 3D flight (first run only, about 40 s)`` (``what``,
    ``seconds``: the measured compile), so that a first run is not silent while it compiles; when the block ends
    without an error, a marker file in the folder records the group as compiled. Nothing is printed when the group
    is compiled already, when it cannot be told (:func:`compiled` is ``None``), a second time in one process, or
    with progress off (``--quiet``: :func:`lifelike_mj.progress.enabled`)."""
    if name in _SEEN:
        yield
        return
    state = compiled(name)
    if state is False:
        from lifelike_mj import progress

        progress.line(f"compiling {what} (first run only, about {seconds:.0f} s)")
    yield
    _SEEN.add(name)
    if state is False:
        try:
            _marker(name).touch()  # type: ignore[union-attr]
        except OSError:
            pass


def _prune(root: Path, keep: Path) -> None:
    cutoff = time.time() - KEEP_DAYS * 86400
    try:
        for d in root.iterdir():
            if d != keep and d.is_dir() and d.stat().st_mtime < cutoff:
                shutil.rmtree(d, ignore_errors=True)
    except OSError:
        pass
