"""The MuJoCo viewer on a live simulation: one real-time loop for every creature.

:func:`view` opens ``mujoco.viewer.launch_passive`` on a stepper's model and data (the shape of
:mod:`lifelike_mj.stepper`) and steps it in about real time, until the window is closed or a
number of steps has been shown. Without a display ``launch_passive`` kills the whole process, so
:func:`require_display` checks first and reports its absence as a
:class:`~lifelike_mj.errors.UserError`.
"""

from __future__ import annotations

import contextlib
import os
import queue
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from lifelike_mj.errors import UserError

#: Wall-clock interval between viewer refreshes, s (about 60 Hz).
FRAME_S = 1.0 / 60.0
#: At most this much wall-clock time's worth of steps is run between two refreshes; if the
#: simulation falls further behind the wall clock (a slow machine, a window drag), the viewer slows
#: down instead of freezing while it catches up.
MAX_CATCH_UP_S = 0.1


def has_display() -> bool:
    """Whether a window can be opened: on Linux, ``DISPLAY`` or ``WAYLAND_DISPLAY`` is set;
    assumed true on macOS and Windows."""
    if sys.platform.startswith("linux"):
        return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))
    return True


def require_display(creature: str) -> None:
    """Raise :class:`UserError` (pointing to ``view CREATURE --web`` and, where there is one, ``render
    CREATURE``) when :func:`has_display` says no window can be opened: ``launch_passive`` would kill the
    whole process."""
    if not has_display():
        video = f" or `lifelike-mj render {creature} --out FILE.mp4`" if creature != "butterfly3d" else ""
        raise UserError("no display found (DISPLAY and WAYLAND_DISPLAY are unset), so the viewer cannot open a "
                        f"window; use `lifelike-mj view {creature} --web` (a browser){video} instead.")


#: The keys a scene may use, by name, with their GLFW key codes (what the desktop viewer's key callback gets).
KEY_CODES = {"Space": 32, "Enter": 257, "Right": 262, "Left": 263, "Down": 264, "Up": 265,
             **{str(d): ord(str(d)) for d in range(10)}}  # 0-5 are here to be refused by name (MuJoCo's groups)


def mujoco_viewer_keys() -> dict[int, str]:
    """The keys MuJoCo's desktop viewer acts on itself in a passive window, by GLFW key code, with what each does:
    every visualisation and rendering flag's shortcut (``mjVISSTRING``, ``mjRNDSTRING``: all 26 letters and some
    punctuation), the geom groups' ``0``-``5``, the help and panels' F1-F7, Tab, Escape, ``[`` ``]``, Page Up and
    Backspace (reset). A scene key must be none of these (:class:`Control`): pressed in the window, it would change
    the viewer as well as the scene."""
    import mujoco

    taken: dict[int, str] = {}
    for name, _default, key in [*mujoco.mjVISSTRING, *mujoco.mjRNDSTRING]:
        if key:
            taken[ord(key.upper())] = f"MuJoCo's {name} toggle"
    for g in range(6):
        taken[ord(str(g))] = f"MuJoCo's geom group {g} toggle"
    for code, what in ((258, "Tab: the side panels"), (256, "Escape: the free camera"), (ord("["), "the cameras"),
                       (ord("]"), "the cameras"), (266, "Page Up: select the parent body"), (259, "Backspace: reset"),
                       *((290 + i, f"F{i + 1}: panels and labels") for i in range(7))):
        taken[code] = f"MuJoCo's {what}"
    return taken


@dataclass(frozen=True)
class Control:
    """One interaction of a live scene: ``key`` (a name of :data:`KEY_CODES`: the desktop viewer's key, never one
    MuJoCo's viewer uses itself, :func:`mujoco_viewer_keys`; ``""`` for a web viewer button alone), ``label`` (the
    web viewer's button, and the list of keys printed at the start) and ``act()``, run between two steps."""

    key: str
    label: str
    act: Callable[[], object]

    def __post_init__(self) -> None:
        if self.key and self.key not in KEY_CODES:
            raise UserError(f"a scene key is one of {', '.join(KEY_CODES)}, got {self.key!r}.")
        if self.key and KEY_CODES[self.key] in mujoco_viewer_keys():
            raise UserError(f"key {self.key!r} is {mujoco_viewer_keys()[KEY_CODES[self.key]]}; choose another.")

    @property
    def code(self) -> int:
        """The GLFW key code of :attr:`key`."""
        return KEY_CODES[self.key]


def keys_text(pairs) -> str:
    """``(key, label)`` pairs as the viewers list them: ``"Up climb 0.5 m; Down descend 0.5 m"``."""
    return "; ".join(f"{k} {label}" for k, label in pairs if k)


def _mark(geom, pos, radius_m: float, rgba) -> None:
    """Make ``geom`` (an ``MjvGeom``) a sphere of ``radius_m`` at ``pos`` in colour ``rgba``."""
    import mujoco
    import numpy as np

    mujoco.mjv_initGeom(geom, int(mujoco.mjtGeom.mjGEOM_SPHERE), np.array([radius_m, 0.0, 0.0]),
                        np.asarray(pos, dtype=float), np.eye(3).reshape(-1), np.asarray(rgba, dtype=np.float32))


def mark_geoms(marks) -> list:
    """``MjvGeom`` spheres of ``marks``: ``(position (m), radius (m), rgba)`` triples (things a scene shows that
    its model does not hold, such as food pellets)."""
    import mujoco

    out = []
    for pos, r, rgba in marks:
        g = mujoco.MjvGeom()
        _mark(g, pos, r, rgba)
        out.append(g)
    return out


def launch_viewer(m, d, key_callback: Callable[[int], None] | None = None):
    """``mujoco.viewer.launch_passive`` on model ``m`` and data ``d``, side panels hidden; a viewer
    that cannot start (macOS outside ``mjpython``) is a :class:`UserError`."""
    import mujoco.viewer

    before = set(threading.enumerate())
    try:
        handle = mujoco.viewer.launch_passive(m, d, show_left_ui=False, show_right_ui=False, key_callback=key_callback)
    except RuntimeError as exc:
        raise UserError(f"the MuJoCo viewer cannot start here ({str(exc).strip()}).") from None
    return _Joined(handle, [t for t in threading.enumerate() if t not in before])


class _Joined:
    """A passive viewer's handle whose close also waits for the viewer's thread to end: a process that exits while
    that thread still tears its window down crashes (a segmentation fault, seen under Xvfb in most such exits)."""

    def __init__(self, handle, threads) -> None:
        self._handle, self._threads = handle, threads

    def __getattr__(self, name: str):
        return getattr(self._handle, name)

    def close(self) -> None:
        self._handle.close()
        for t in self._threads:
            t.join(timeout=10.0)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _show_marks(viewer, marks) -> None:
    """The stepper's marks (:func:`mark_geoms`) into the desktop viewer's user scene, or the web viewer's."""
    if hasattr(viewer, "set_marks"):
        viewer.set_marks(mark_geoms(marks))
        return
    scn = viewer.user_scn
    scn.ngeom = 0
    for pos, r, rgba in marks[: scn.maxgeom]:
        _mark(scn.geoms[scn.ngeom], pos, r, rgba)
        scn.ngeom += 1


def view(stepper: Any, steps_per_s: float, end_step: int | None = None,
         setup: Callable[[Any], None] | None = None, web: Any = None, controls: Sequence[Control] = ()) -> None:
    """Show ``stepper`` in the MuJoCo viewer, ``steps_per_s`` steps per wall-clock second, until the
    window is closed or the stepper reaches step ``end_step`` (``None``: until closed).

    ``setup(viewer)`` places the viewer's camera (called under the viewer's lock before the first
    refresh). The stepper is advanced with ``step(n)`` and drawn after ``sync()``; when it cannot keep
    up, the clock is re-anchored and the view runs slower than asked rather than freezing.

    ``web``: :class:`~lifelike_mj.render.web.WebOptions` to show it in MuJoCo's web viewer instead (no display
    needed; :func:`~lifelike_mj.render.web.launch_web`), until the stepper reaches ``end_step`` or Ctrl+C.

    ``controls``: the scene's interactions (:class:`Control`): keys in the desktop viewer, buttons in the web
    viewer's "lifelike-mj" panel. Pressed in the viewer's thread, each is queued and run here between two
    steps, so that the stepper is only ever touched by this loop. A stepper with a ``marks()`` method has
    those spheres drawn too (:func:`mark_geoms`).
    """
    pending: queue.SimpleQueue = queue.SimpleQueue()
    by_key = {c.code: c for c in controls if c.key}
    if by_key:
        print("keys: " + keys_text((c.key, c.label) for c in controls), flush=True)
    if web is not None:
        from lifelike_mj.render.web import launch_web

        opened = launch_web(stepper.model, stepper.data, web, setup=setup, controls=controls, pending=pending)
    else:
        def on_key(key: int) -> None:  # GLFW's key codes (KEY_CODES)
            if key in by_key:
                pending.put(by_key[key])

        opened = launch_viewer(stepper.model, stepper.data, key_callback=on_key if by_key else None)
    stop = threading.Event()  # Ctrl+C ends the loop between two frames, never inside MuJoCo's viewer code
    with opened as viewer, _ctrl_c_sets(stop):
        with viewer.lock():
            viewer.opt.sitegroup[:] = 0
            if setup is not None:
                setup(viewer)
        max_chunk = max(1, int(round(MAX_CATCH_UP_S * steps_per_s)))
        start = time.perf_counter()
        at_start = int(stepper.steps)
        while viewer.is_running() and not stop.is_set():
            target = at_start + int((time.perf_counter() - start) * steps_per_s)
            if target - stepper.steps > max_chunk:  # fell behind: re-anchor the clock, run slower than asked
                target = int(stepper.steps) + max_chunk
                at_start, start = target, time.perf_counter()
            if end_step is not None:
                target = min(target, end_step)
            with viewer.lock():
                while not pending.empty():
                    control = pending.get()
                    control.act()
                    print(control.label, flush=True)
                if target > stepper.steps:
                    stepper.step(target - int(stepper.steps))
                stepper.sync()
                if hasattr(stepper, "marks"):
                    _show_marks(viewer, stepper.marks())
            viewer.sync()
            if end_step is not None and stepper.steps >= end_step:
                break
            time.sleep(FRAME_S)
    if stop.is_set():  # the viewer is closed: now the interruption goes on to the caller
        raise KeyboardInterrupt


@contextlib.contextmanager
def _ctrl_c_sets(stop: threading.Event):
    """While the block runs (in the main thread), Ctrl+C sets ``stop`` instead of raising wherever the main
    thread happens to be: a KeyboardInterrupt inside the web viewer's sync could leave its lock held and the
    shutdown waiting on it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, lambda signum, frame: stop.set())
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
