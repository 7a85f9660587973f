"""Where the model and controller files live, in a source checkout and in an installed wheel.

In a checkout they are the top-level ``models/`` and ``controllers/`` folders; a wheel installs
the same folders as ``lifelike_mj/models`` and ``lifelike_mj/controllers`` (see pyproject.toml).
"""

from __future__ import annotations

from pathlib import Path

_PKG = Path(__file__).resolve().parent


def _data_dir(name: str) -> Path:
    for candidate in (_PKG.parent / name, _PKG / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"cannot find the {name}/ folder of lifelike-mj (looked beside {_PKG})")


def models_dir() -> Path:
    """Folder with the MJCF models."""
    return _data_dir("models")


def controllers_dir() -> Path:
    """Folder with the controller files."""
    return _data_dir("controllers")
