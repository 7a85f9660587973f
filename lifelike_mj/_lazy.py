"""Lazy public names for the package's ``__init__`` files: a name is imported on first use, so that
``import lifelike_mj.butterfly`` costs nothing and never loads MuJoCo before it is needed.

With the environment variable ``LIFELIKE_MJ_EAGER=1`` every public name is imported at once instead
(what a documentation generator such as pdoc needs, as it reads a module's namespace directly).

Before that eager import, :func:`offscreen_gl_for_documentation` sets ``MUJOCO_GL`` when it is unset on Linux:
MuJoCo's default OpenGL backend there, GLFW, runs a child Python when it is imported (the ``glfw`` package asks
its library's version that way), pdoc's import guard replaces that child by ``echo``, and the failed ``glfw``
import is a ``SyntaxError`` that ``import mujoco`` does not catch, so that the whole package failed to import
under ``pdoc`` with or without a display.
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
        offscreen_gl_for_documentation()
        for name in names:
            namespace[name] = __getattr__(name)
    return __getattr__, __dir__, sorted(names)


#: The offscreen OpenGL backends :func:`offscreen_gl_for_documentation` may choose, each with the libraries that
#: MuJoCo's module for it loads (any one of them).
_DOC_GL_LIBRARIES = {"egl": ("libEGL.so.1", "libEGL.so"), "osmesa": ("libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so")}


def offscreen_gl_for_documentation() -> str | None:
    """For the eager import (``LIFELIKE_MJ_EAGER=1``): on Linux with ``MUJOCO_GL`` unset, set it to ``egl`` or
    ``osmesa``, the first whose library loads, else to ``disable`` (nothing is drawn while documenting), so that
    ``import mujoco`` does not import GLFW (module docstring); returns the value set, or ``None`` when ``MUJOCO_GL``
    was already set, ``mujoco`` already imported, or the system is not Linux (MuJoCo's default there runs no child
    process). It loads libraries but starts no process (a documentation generator may forbid that):
    :func:`lifelike_mj.render.gl.ensure_gl_backend` is the check that a backend really renders."""
    import ctypes
    import sys

    if os.environ.get("MUJOCO_GL", "").strip() or "mujoco" in sys.modules or not sys.platform.startswith("linux"):
        return None
    chosen = "disable"
    for backend, libraries in _DOC_GL_LIBRARIES.items():
        for library in libraries:
            try:
                ctypes.CDLL(library)
            except OSError:
                continue
            chosen = backend
            break
        if chosen != "disable":
            break
    os.environ["MUJOCO_GL"] = chosen
    return chosen
