"""OpenGL for offscreen rendering: choose a backend that works on this machine, open a context.

MuJoCo's Python package picks its OpenGL backend from ``MUJOCO_GL`` once, when ``mujoco`` is first
imported. On a headless Linux machine call :func:`ensure_gl_backend` before anything imports
``mujoco`` (the command line does this first thing): it sets ``MUJOCO_GL`` to the first of ``egl``,
``osmesa`` that can create a context (probed in a subprocess, since a failed backend cannot be
unloaded). :func:`gl_context` opens its context from the backend's own module (``mujoco.egl``,
``mujoco.osmesa``, ``mujoco.glfw``), so it also works when ``mujoco`` was imported before
``MUJOCO_GL`` was set.

This module imports ``mujoco`` only inside functions, so importing it does not load MuJoCo.
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
from typing import Any

from lifelike_mj.errors import UserError

#: Offscreen backends tried, in order, when ``MUJOCO_GL`` is unset (Linux).
GL_CANDIDATES = ("egl", "osmesa")
#: ``MUJOCO_GL`` values that mean "glfw" to MuJoCo.
_GLFW_ALIASES = ("glfw", "glx", "enable", "enabled", "on", "true", "1")
_GL_DISABLED = ("disable", "disabled", "off", "false", "0")

_probe_cache: dict[str, bool] = {}
_PROBE_CODE = (
    "import mujoco\n"
    "c = mujoco.GLContext(16, 16)\n"
    "c.make_current()\n"
    "m = mujoco.MjModel.from_xml_string('<mujoco><worldbody><geom size=\"1\"/></worldbody></mujoco>')\n"
    "r = mujoco.MjrContext(m, mujoco.mjtFontScale.mjFONTSCALE_100)\n"
    "r.free()\n"
    "c.free()\n"
)


def _probe(backend: str) -> bool:
    """Whether ``MUJOCO_GL=backend`` can create an OpenGL context (tried in a subprocess)."""
    if backend not in _probe_cache:
        env = dict(os.environ, MUJOCO_GL=backend)
        try:
            res = subprocess.run([sys.executable, "-c", _PROBE_CODE], env=env, capture_output=True, timeout=120)
            _probe_cache[backend] = res.returncode == 0
        except (OSError, subprocess.SubprocessError):
            _probe_cache[backend] = False
    return _probe_cache[backend]


def ensure_gl_backend() -> str | None:
    """Set ``os.environ["MUJOCO_GL"]`` to a working offscreen backend if it is unset; return it.

    Call it before the first ``import mujoco`` of the process (MuJoCo reads ``MUJOCO_GL`` at import
    time). A value the user already set is respected and returned unchanged. On Linux the first of
    ``egl``, ``osmesa`` that can create a context is chosen (each probe is a short subprocess,
    about 1 s, done once per process); elsewhere (macOS, Windows) MuJoCo's default is kept and
    ``None`` returned. ``None`` also when no backend works; rendering then raises
    :class:`~lifelike_mj.errors.UserError`.
    """
    current = os.environ.get("MUJOCO_GL", "").strip()
    if current:
        return current.lower()
    if not sys.platform.startswith("linux"):
        return None
    for backend in GL_CANDIDATES:
        if _probe(backend):
            os.environ["MUJOCO_GL"] = backend
            return backend
    return None


def gl_context(width: int, height: int) -> tuple[Any, str]:
    """An OpenGL context made current, and the backend's name; :class:`UserError` if none works."""
    requested = os.environ.get("MUJOCO_GL", "").strip().lower()
    if requested in _GL_DISABLED:
        raise UserError(f"rendering is disabled by MUJOCO_GL={requested}; unset it or set it to egl or osmesa.")
    if not requested:
        requested = ensure_gl_backend() or ""
    if not requested:
        if sys.platform.startswith("linux"):
            raise UserError("no offscreen OpenGL backend works on this machine (tried EGL and OSMesa); install "
                            "libegl1 or libosmesa6 (e.g. `apt-get install libosmesa6`) or set MUJOCO_GL.")
        requested = "cgl" if sys.platform == "darwin" else "glfw"
    name = "glfw" if requested in _GLFW_ALIASES else requested
    try:
        module = importlib.import_module(f"mujoco.{name}")
        ctx = module.GLContext(width, height)
        ctx.make_current()
    except Exception as exc:  # noqa: BLE001 - any failure of the GL stack means "no backend"
        raise UserError(f"cannot create an offscreen OpenGL context with MUJOCO_GL={requested} "
                        f"({exc.__class__.__name__}: {str(exc).strip()[:160] or 'no detail'}); "
                        "try MUJOCO_GL=egl or MUJOCO_GL=osmesa.") from None
    return ctx, name
