"""Where an output came from: the package version, the command line (or the Python call), the time,
and every parameter, recorded in every file written (JSON files under ``"provenance"``; PNG figures in
their text chunks)."""

from __future__ import annotations

import platform
import shlex
import sys
from datetime import datetime, timezone
from typing import Any

_command: str | None = None


def set_command(argv: list[str]) -> None:
    """Called by the command line with its arguments: outputs then record ``lifelike-mj ARGS``."""
    global _command
    _command = "lifelike-mj " + shlex.join(argv)


def command() -> str:
    """The command that is running: ``lifelike-mj ...`` from the command line, else the Python script."""
    if _command is not None:
        return _command
    return "python " + shlex.join(sys.argv) if sys.argv and sys.argv[0] else "python (interactive)"


def versions() -> dict[str, str]:
    """Versions of this package and of the libraries that make its numbers."""
    from importlib.metadata import PackageNotFoundError, version

    from lifelike_mj import __version__

    out = {"lifelike-mj": __version__, "python": platform.python_version()}
    for lib in ("mujoco", "numpy", "numba"):
        try:
            out[lib] = version(lib)
        except PackageNotFoundError:  # pragma: no cover - all are dependencies
            pass
    return out


def provenance(**parameters: Any) -> dict[str, Any]:
    """``{"versions", "command", "created", "parameters"}`` for an output file; ``parameters`` are
    every setting that made it (plain JSON-able values)."""
    return {"versions": versions(), "command": command(),
            "created": datetime.now(timezone.utc).isoformat(timespec="seconds"), "parameters": parameters}


def png_metadata() -> dict[str, str]:
    """Text chunks for a PNG figure: the software and the command that drew it."""
    from lifelike_mj import __version__

    return {"Software": f"lifelike-mj {__version__}", "Description": command()}
