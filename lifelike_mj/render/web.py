"""MuJoCo's web viewer (``mujoco.studio``) on a live simulation, for machines without a display.

:func:`launch_web` serves the viewer over HTTP: open the address it prints in a browser on this machine, or
through an SSH tunnel (``ssh -L 8080:localhost:8080 host``). It binds ``localhost`` unless another host is
asked for. MuJoCo's own launcher binds every interface (``::``) and has no authentication, so anyone who
can reach the machine could watch and drive the simulation; this module binds the host it is given
(MuJoCo 4.0 has no setting for it, so the binding function is wrapped while the viewer starts) and warns
when that host is not the loopback.

The viewer is driven by the same real-time loop as the desktop viewer (:func:`lifelike_mj.render.viewer.view`).
It starts from the desktop viewer's view of the creature (following it where the desktop viewer does); drag
to orbit, scroll to zoom.
"""

from __future__ import annotations

import contextlib
import ipaddress
import logging
import socket
import sys
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from lifelike_mj.errors import UserError

#: Hosts that only this machine can reach.
LOOPBACK = ("localhost", "127.0.0.1", "::1")


@dataclass(frozen=True)
class WebOptions:
    """Where the web viewer listens: ``host`` (default ``localhost``; ``0.0.0.0`` or ``::`` for every
    interface) and ``port`` (0: the first free one from 8080)."""

    host: str = "localhost"
    port: int = 0

    def check(self) -> WebOptions:
        """The options, or a :class:`UserError` naming what is wrong, before anything starts."""
        if not 0 <= int(self.port) <= 65535:
            raise UserError(f"--port must be a whole number from 0 to 65,535, got {self.port}.")
        try:
            infos = socket.getaddrinfo(self.host, None, type=socket.SOCK_STREAM)
        except (socket.gaierror, UnicodeError):
            raise UserError(f"--host {self.host!r} is not an address or a name this machine can resolve.") from None
        if not any(_can_bind(family, addr) for family, _t, _p, _c, addr in infos):
            shown = ", ".join(sorted({str(a[0]) for *_x, a in infos}))
            raise UserError(f"--host {self.host!r} ({shown}) is not an address of this machine, so nothing can listen "
                            "on it; give localhost, one of this machine's addresses, or 0.0.0.0 for every one.")
        return self

    @property
    def is_loopback(self) -> bool:
        if self.host == "localhost":
            return True
        try:
            return ipaddress.ip_address(self.host).is_loopback
        except ValueError:
            return False


def _can_bind(family: int, addr: tuple) -> bool:
    """Whether a socket can be bound to ``addr`` (port 0: none is taken) here: false for an address that is not one
    of this machine's."""
    try:
        with socket.socket(family, socket.SOCK_STREAM) as sock:
            sock.bind((addr[0], 0, *addr[2:]))
        return True
    except OSError:
        return False


class _Shown:
    """What the simulation's loop hands the viewer's thread: ``marks``, the ``MjvGeom`` spheres to add."""

    def __init__(self) -> None:
        self.marks: list = []


def _on(event_type):
    """``messages.handler`` for a method handling ``event_type``: the handler is found by its argument's
    annotation, which postponed annotations turn into a string that a class made in a function cannot
    resolve, so the class itself is given."""
    from mujoco.studio import messages

    def stamp(fn):
        fn.__annotations__ = {"event": event_type, "return": None}
        return messages.handler(fn)

    return stamp


class _Handle:
    """The web viewer in the shape :func:`~lifelike_mj.render.viewer.view` drives: ``lock()``, ``sync()``,
    ``is_running()``, ``cam``, ``opt`` (the last two are accepted and not sent)."""

    def __init__(self, handle: Any, model: Any, data: Any, url: str, shown: _Shown | None = None) -> None:
        import mujoco

        self.handle, self.model, self.data, self.url = handle, model, data, url
        self.cam = mujoco.MjvCamera()
        self.opt = mujoco.MjvOption()
        self.shown = shown or _Shown()

    def set_marks(self, geoms: list) -> None:
        self.shown.marks = geoms  # one assignment: the viewer's thread reads the whole list or the previous one

    def lock(self):
        return contextlib.nullcontext()

    def sync(self) -> None:
        self.handle.sync(self.model, self.data)

    def is_running(self) -> bool:
        return self.handle.is_running()

    def __enter__(self) -> _Handle:
        return self

    def __exit__(self, *exc) -> None:
        self.handle.__exit__(*exc)


def _first_view(model: Any, setup: Callable[[Any], None] | None) -> list:
    """The web viewer's plugin that starts it from the desktop viewer's camera, as ``setup(viewer)`` places it
    (a tracking camera keeps tracking its body), each time a model arrives; none without ``setup``."""
    if setup is None:
        return []
    import mujoco
    from mujoco.studio import messages, plugin

    probe = _Handle(None, model, None, "")
    mujoco.mjv_defaultFreeCamera(model, probe.cam)
    setup(probe)
    cam = probe.cam

    class FirstView(plugin.ViewerPlugin):
        shown = None

        @_on(messages.UpdateEvent)
        def on_update(self, event) -> None:
            viewer = self.viewer
            if viewer.model is self.shown or viewer.model.nbody != model.nbody:
                return
            self.shown = viewer.model
            c = viewer.camera
            c.type, c.trackbodyid, c.fixedcamid = cam.type, cam.trackbodyid, cam.fixedcamid
            c.lookat[:] = cam.lookat
            c.distance, c.azimuth, c.elevation = cam.distance, cam.azimuth, cam.elevation

    return [FirstView()]


def _buttons(controls, pending, shown: _Shown) -> list:
    """The web viewer's plugin that draws a "lifelike-mj" panel with one button per control, queues the
    pressed ones in ``pending`` (run by the simulation's loop) and adds ``shown``'s marks to the scene; none
    without controls."""
    if not controls:
        return []
    from mujoco.studio import messages, plugin
    from mujoco.studio.dear_imgui import dear_imgui as imgui

    class Buttons(plugin.ViewerPlugin):
        @_on(messages.UpdateEvent)
        def on_update(self, event) -> None:
            self.viewer.extra_geoms[:] = shown.marks

        @_on(messages.BuildGuiEvent)
        def on_gui(self, event) -> None:
            imgui.Begin("lifelike-mj")
            for c in controls:
                if imgui.Button(f"{c.label} [{c.key}]" if c.key else c.label):
                    pending.put(c)
            imgui.End()

    return [Buttons()]


class _ClosedNormally(logging.Filter):
    """Leaves out asyncio's report of a websocket that a browser closed normally (``ConnectionClosedOK``: a tab
    closed or reloaded) while MuJoCo's web server was still sending to it. Nothing went wrong, yet asyncio logs it
    with a traceback ("Task exception was never retrieved"), seen at Ctrl+C under load."""

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        return not (exc is not None and type(exc).__name__ == "ConnectionClosedOK")


def _quiet_normal_closes() -> None:
    log = logging.getLogger("asyncio")
    if not any(isinstance(f, _ClosedNormally) for f in log.filters):
        log.addFilter(_ClosedNormally())


def launch_web(model: Any, data: Any, options: WebOptions | None = None, title: str = "lifelike-mj",
               setup: Callable[[Any], None] | None = None, controls=(), pending=None):
    """Start MuJoCo's web viewer on ``model`` and ``data`` (module docstring), print its address, and return a
    handle for :func:`~lifelike_mj.render.viewer.view`. ``setup(viewer)`` places the first view as it places
    the desktop viewer's camera (:func:`_first_view`); ``controls`` become buttons whose presses are put in
    ``pending`` (:func:`_buttons`). A port that is taken, or a MuJoCo without the web viewer,
    is a :class:`UserError`."""
    options = (options or WebOptions()).check()
    _quiet_normal_closes()
    try:
        from mujoco.studio import launch_web as lw
        from mujoco.studio import viewer_protocol, web_viewer
        from mujoco.studio.web import web_server
    except ImportError:
        raise UserError("this MuJoCo has no web viewer (mujoco.studio, MuJoCo 4 or newer).") from None
    bound: dict[str, Any] = {}
    ready = threading.Event()
    bind, banner = web_server.bind_public_socket, web_viewer._print_url_banner

    def bind_here(_host: str, port: int = 0):
        try:
            sock = bind(options.host, port)
        except Exception as exc:  # a port taken, an address not on this machine
            bound["error"] = exc
            ready.set()
            raise
        bound["port"] = sock.getsockname()[1]
        return sock

    def quiet_banner(_host: str, port: int) -> None:
        ready.set()

    web_server.bind_public_socket, web_viewer._print_url_banner = bind_here, quiet_banner
    try:
        shown = _Shown()
        plugins = _first_view(model, setup) + _buttons(controls, pending, shown)
        handle = lw.launch(viewer_protocol.ViewerConfig(gfx="web", http_port=int(options.port), title=title),
                           plugins=plugins)
        ready.wait(timeout=60.0)
    finally:
        web_server.bind_public_socket, web_viewer._print_url_banner = bind, banner
    if "port" not in bound:
        with contextlib.suppress(Exception):
            handle.close()
        why = bound.get("error", "it did not start within 60 s")
        raise UserError(f"the web viewer could not listen on {options.host} port {options.port or 'from 8080'}: {why}.")
    handle.set_model(model, data=data)
    host = "localhost" if options.is_loopback else (socket.getfqdn() if options.host in ("::", "0.0.0.0") else options.host)
    url = f"http://{'[' + host + ']' if ':' in host else host}:{bound['port']}/"
    print(f"web viewer: {url} (Ctrl+C to stop)", flush=True)
    if not options.is_loopback:
        print(f"warning: the web viewer listens on {options.host}, with no password and no encryption: anyone who "
              "can reach this machine can watch and drive the simulation.", file=sys.stderr, flush=True)
    return _Handle(handle, model, data, url, shown)
