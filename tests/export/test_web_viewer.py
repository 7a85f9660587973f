"""``lifelike-mj view CREATURE --web``: MuJoCo's web viewer on each live creature, bound to this machine only,
drawn in headless Chromium (the creature is drawn: the picture differs from the same scene without it, and it
changes as the simulation runs), the aquarium's buttons pressed in the page reach the tank, and Ctrl+C stops
it with exit status 130."""

import signal
import socket
import subprocess
import sys
import textwrap
import threading
from pathlib import Path

import pytest

from lifelike_mj.cli import main


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _listening(port: int) -> list[str]:
    """The local addresses (hex, as /proc/net/tcp* gives them) listening on ``port``."""
    found = []
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            local, state = line.split()[1], line.split()[3]
            if state == "0A" and int(local.split(":")[1], 16) == port:
                found.append(local.split(":")[0])
    return found


def _listening_soon(port: int, seconds: float = 60.0) -> list[str]:
    """:func:`_listening`, waited for: the server says its address just before it listens."""
    import time

    end = time.monotonic() + seconds
    while not (found := _listening(port)) and time.monotonic() < end:
        time.sleep(0.1)
    return found


def _start(argv: list[str]) -> tuple[subprocess.Popen, str, str]:
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line, keys = proc.stdout.readline(), ""
    while line.startswith("keys:"):  # the scene's keys come first
        keys, line = line.strip(), proc.stdout.readline()
    assert line.startswith("web viewer: http://"), (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, line.split()[2], keys


#: The same command with the creatures' geoms moved to group 5, which viewers do not draw by default: the
#: empty scene, with the same camera (a tracking camera still follows the invisible body).
EMPTY = textwrap.dedent("""
    import sys
    import lifelike_mj.render.web as web
    launch = web.launch_web
    def without_creatures(model, data, *args, **kwargs):
        model.geom_group[model.geom_bodyid > 0] = 5
        return launch(model, data, *args, **kwargs)
    web.launch_web = without_creatures
    from lifelike_mj.cli import main
    sys.exit(main(sys.argv[1:]))
""")
#: Each creature's command, and the buttons pressed between the two pictures (the fish's panel: "drop a food
#: pellet", then "tap the front glass", then the shadow that looms over one fish).
SCENES = {"fish": (["fish", "--seed", "1"], "126,128 126,102 126,154"), "butterfly": (["butterfly"], ""),
          "butterfly3d": (["butterfly3d"], ""), "boids": (["boids", "--n", "100"], "")}
#: What the server prints when each of those buttons reaches the scene.
LABELS = {"fish": ["drop a food pellet", "tap the front glass", "a shadow looms over one fish: it alone startles"]}


class _Said:
    """The lines a server prints, read as they come (a thread), so that a press in the page can be confirmed: the
    i-th press took effect when the server has printed the i-th of ``labels``."""

    def __init__(self, proc: subprocess.Popen, labels: list[str]) -> None:
        self.lines: list[str] = []
        self.labels = labels
        self.changed = threading.Condition()
        self.thread = threading.Thread(target=self._read, args=(proc,), daemon=True)
        self.thread.start()

    def _read(self, proc: subprocess.Popen) -> None:
        for line in proc.stdout:
            with self.changed:
                self.lines.append(line)
                self.changed.notify_all()

    def text(self) -> str:
        with self.changed:
            return "".join(self.lines)

    def pressed(self, i: int, seconds: float = 10.0) -> bool:
        """Whether the i-th label has been printed (after the ones before it), waiting for it at most ``seconds``."""
        def seen() -> bool:
            said = [line.rstrip("\n") for line in self.lines if line.rstrip("\n") in self.labels]
            return said[:i + 1] == self.labels[:i + 1]
        with self.changed:
            return self.changed.wait_for(seen, timeout=seconds)


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="reads the listening sockets from Linux's /proc")
@pytest.mark.parametrize("scene", ["fish"])
def test_the_web_viewer_draws_the_live_creature_on_localhost_only(chromium, tmp_path, scene):
    """Drawn in Chromium for the fish (whose panel has buttons); the other creatures' servers are checked without
    a browser below (the page and the drawing are MuJoCo's, the same for every model: a browser run costs about
    a minute a creature on two cores)."""
    args, clicks = SCENES[scene]
    port, empty_port = _free_port(), _free_port()
    live, url, keys = _start([sys.executable, "-m", "lifelike_mj", "view", *args, "--web", "--port", str(port)])
    said = _Said(live, LABELS.get(scene, []))
    empty, empty_url, _ = _start([sys.executable, "-c", EMPTY, "view", *args, "--web", "--port", str(empty_port)])
    try:
        assert url == f"http://localhost:{port}/"
        assert _listening_soon(port) == ["0100007F"]  # 127.0.0.1 only: not reachable from another machine
        r = chromium.check("web", url, empty_url, str(tmp_path), clicks=clicks, pressed=said.pressed)
    finally:
        live.send_signal(signal.SIGINT)  # Ctrl+C
        empty.send_signal(signal.SIGINT)
        try:
            err = live.communicate(timeout=60)[1]
            said.thread.join(timeout=60)
            out = said.text()
            empty.communicate(timeout=60)
        finally:  # never leave a server behind, even when it does not stop
            for proc in (live, empty):
                if proc.poll() is None:
                    proc.kill()
                    proc.communicate()
    assert live.returncode == 130 and "interrupted" in err and "Traceback" not in err, err
    assert r["errors"] == [], r
    first, empty_shot, later = r["shots"][0], r["shots"][1], r["shots"][2]
    assert chromium.changed_pixels(first, empty_shot) > 50  # the creature is drawn
    assert chromium.changed_pixels(first, later) > 20  # and moves
    if scene != "fish":
        return
    assert keys == ("keys: Space tap the front glass; Enter drop a food pellet; Right a shadow looms over one fish: it "
                    "alone startles")
    # the buttons reached the aquarium, in order
    assert "drop a food pellet\ntap the front glass\na shadow looms over one fish: it alone startles" in out, (out, r["presses"])


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="reads the listening sockets from Linux's /proc")
@pytest.mark.parametrize("scene", ["boids", "butterfly", "butterfly3d"])
def test_the_web_viewer_serves_each_live_creature_on_localhost_only(scene):
    import urllib.request

    args, _ = SCENES[scene]
    port = _free_port()
    live, url, _ = _start([sys.executable, "-m", "lifelike_mj", "view", *args, "--web", "--port", str(port)])
    try:
        assert url == f"http://localhost:{port}/"
        assert _listening_soon(port) == ["0100007F"]  # 127.0.0.1 only
        with urllib.request.urlopen(url, timeout=60) as page:
            assert page.status == 200 and b"<" in page.read(4096)
    finally:
        live.send_signal(signal.SIGINT)  # Ctrl+C
        try:
            out, err = live.communicate(timeout=60)
        finally:
            if live.poll() is None:
                live.kill()
                live.communicate()
    assert live.returncode == 130 and "interrupted" in err and "Traceback" not in err, err


def test_host_and_port_need_web_and_only_the_loopback_goes_unwarned(capsys):
    from lifelike_mj.render.web import WebOptions

    assert main(["view", "fish", "--port", "8090"]) == 2
    assert "add --web" in capsys.readouterr().err
    assert main(["view", "fish", "--web", "--host", "no-such-host.invalid"]) == 2
    assert "--host" in capsys.readouterr().err
    assert all(WebOptions(h).is_loopback for h in ("localhost", "127.0.0.1", "::1"))
    assert not any(WebOptions(h).is_loopback for h in ("0.0.0.0", "::", "192.168.1.5"))  # these get the warning


def test_a_tab_closed_normally_is_not_reported_as_an_error():
    """asyncio logs a websocket that a browser closed normally while MuJoCo's server was sending to it ("Task
    exception was never retrieved", with a traceback): the viewer leaves that one out, and only that one."""
    import logging

    from websockets.exceptions import ConnectionClosedError, ConnectionClosedOK
    from websockets.frames import Close

    from lifelike_mj.render.web import _ClosedNormally

    def record(exc):
        return logging.LogRecord("asyncio", logging.ERROR, __file__, 1, "Task exception was never retrieved", None,
                                 (type(exc), exc, None))

    keep = _ClosedNormally().filter
    assert not keep(record(ConnectionClosedOK(Close(1001, ""), Close(1001, ""), True)))
    assert keep(record(ConnectionClosedError(Close(1011, "boom"), None, None)))
    assert keep(record(RuntimeError("a real error")))
