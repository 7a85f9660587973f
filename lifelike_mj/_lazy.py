"""Lazy public names for the package's ``__init__`` files: a name is imported on first use, so that
``import lifelike_mj.butterfly`` costs nothing and never loads MuJoCo before it is needed.

With the environment variable ``LIFELIKE_MJ_EAGER=1`` every public name is imported at once instead
(what a documentation generator such as pdoc needs, as it reads a module's namespace directly).
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable


def attach(package: str, names: dict[str, str], namespace: dict | None = None
           ) -> tuple[Callable[[str], object], Callable[[], list[str]], list[str]]:
    """``(__getattr__, __dir__, __all__)`` for ``package`` whose public ``names`` map to the module
    (relative to the package, ``"sim"``, or ``"."`` for a submodule of that name) defining them.
    ``namespace``: the package's ``globals()``, filled at once when ``LIFELIKE_MJ_EAGER`` is set."""

    def __getattr__(name: str) -> object:
        if name not in names:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        where = names[name]
        if where == ".":
            return importlib.import_module(f"{package}.{name}")
        value = getattr(importlib.import_module(f"{package}.{where}"), name)
        return value

    def __dir__() -> list[str]:
        return sorted(names)

    if namespace is not None and os.environ.get("LIFELIKE_MJ_EAGER"):
        for name in names:
            namespace[name] = __getattr__(name)
    return __getattr__, __dir__, sorted(names)
