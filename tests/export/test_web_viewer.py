"""``lifelike-mj view fish --web``: MuJoCo's web viewer on the live tank, bound to this machine only, drawn in
headless Chromium (the fish are drawn: the picture differs from the same tank without fish, and it changes
as the simulation runs), its aquarium buttons pressed in the page reach the tank, and Ctrl+C stops it with
exit status 130."""

import signal
import socket
import subprocess
import sys
import textwrap
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


def _start(argv: list[str]) -> tuple[subprocess.Popen, str, str]:
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line, keys = proc.stdout.readline(), ""
    while line.startswith("keys:"):  # the scene's keys come first
        keys, line = line.strip(), proc.stdout.readline()
    assert line.startswith("web viewer: http://"), (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, line.split()[2], keys


EMPTY_TANK = textwrap.dedent("""
    import sys
    from lifelike_mj.fish import Tank
    from lifelike_mj.render.viewer import view
    from lifelike_mj.render.web import WebOptions
    tank = Tank(n_fish=10, seed=1)
    m = tank.model
    m.geom_rgba[m.geom_bodyid > 0, 3] = 0.0  # the same tank, the fish not drawn
    view(tank, 1.0 / tank.dt, None, None, web=WebOptions("localhost", int(sys.argv[1])))
""")


@pytest.mark.skipif(not Path("/proc/net/tcp").exists(), reason="reads the listening sockets from Linux's /proc")
def test_the_web_viewer_draws_the_live_tank_on_localhost_only(chromium, tmp_path):
    port, empty_port = _free_port(), _free_port()
    live, url, keys = _start([sys.executable, "-m", "lifelike_mj", "view", "fish", "--seed", "1", "--web",
                        "--port", str(port)])
    empty, empty_url, _ = _start([sys.executable, "-c", EMPTY_TANK, str(empty_port)])
    try:
        assert url == f"http://localhost:{port}/"
        assert _listening(port) == ["0100007F"]  # 127.0.0.1 only: not reachable from another machine
        # between the two pictures, the panel's buttons are pressed: "drop a food pellet", then "tap the front glass"
        r = chromium.check("web", url, empty_url, str(tmp_path), clicks="126,128 126,102")
    finally:
        live.send_signal(signal.SIGINT)  # Ctrl+C
        empty.send_signal(signal.SIGINT)
        try:
            out, err = live.communicate(timeout=60)
            empty.communicate(timeout=60)
        finally:  # never leave a server behind, even when it does not stop
            for proc in (live, empty):
                if proc.poll() is None:
                    proc.kill()
                    proc.communicate()
    assert live.returncode == 130 and "interrupted" in err and "Traceback" not in err, err
    assert keys == "keys: T tap the front glass; F drop a food pellet"
    assert "drop a food pellet\ntap the front glass" in out  # the buttons reached the aquarium, in order
    assert r["errors"] == [], r
    first, empty_shot, later = r["shots"][0], r["shots"][1], r["shots"][2]
    assert chromium.changed_pixels(first, empty_shot) > 50  # the fish are drawn
    assert chromium.changed_pixels(first, later) > 20  # and swim


def test_host_and_port_need_web_and_only_the_loopback_goes_unwarned(capsys):
    from lifelike_mj.render.web import WebOptions

    assert main(["view", "fish", "--port", "8090"]) == 2
    assert "add --web" in capsys.readouterr().err
    assert main(["view", "fish", "--web", "--host", "no-such-host.invalid"]) == 2
    assert "--host" in capsys.readouterr().err
    assert all(WebOptions(h).is_loopback for h in ("localhost", "127.0.0.1", "::1"))
    assert not any(WebOptions(h).is_loopback for h in ("0.0.0.0", "::", "192.168.1.5"))  # these get the warning
