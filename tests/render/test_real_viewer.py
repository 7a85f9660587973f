"""The live scenes in MuJoCo's real desktop viewer, on a virtual screen (Xvfb) with keys pressed by xdotool: each
scene key changes the scene and nothing of the viewer (its options and camera, and the picture of a frozen
scene), while one of MuJoCo's own shortcuts pressed the same way is seen to change it (so the check can fail);
and 20 viewer runs with every key pressed exit cleanly (the viewer's thread used to crash the process at exit).

Needs Debian's ``xvfb`` and ``xdotool`` (``.ci/run`` installs them); skipped, saying so, where they are missing.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.boids.render import KEYS as BOIDS_KEYS
from lifelike_mj.butterfly.flight3d.view import FLIGHT3D_KEYS
from lifelike_mj.fish.aquarium import KEYS as FISH_KEYS

CHILD = Path(__file__).with_name("real_viewer_child.py")
#: xdotool's names of the scene keys.
XKEYS = {"Space": "space", "Enter": "Return", "Up": "Up", "Down": "Down", "Left": "Left", "Right": "Right",
         **{str(d): str(d) for d in range(10)}}
SCENES = {"butterfly3d": FLIGHT3D_KEYS, "fish": FISH_KEYS, "boids": BOIDS_KEYS}


#: How each scene is told to stop after about ``s`` seconds (the flock counts steps: 150 a second in the viewer).
def _stop(creature: str, s: float) -> list[str]:
    return ["--steps", str(int(150 * s))] if creature == "boids" else ["--duration", str(s)]


#: A scene key that does not move what is drawn may redraw at most this share of the window's pixels (a food
#: pellet appearing); MuJoCo's wireframe toggle redraws far more.
MAX_CHANGED = 0.003
#: The keys that move what is drawn by design (the flock scattered afresh): their options are still checked, and
#: the picture after them is the new reference.
REDRAWS = {("boids", "Enter")}

pytestmark = pytest.mark.skipif(not (shutil.which("Xvfb") and shutil.which("xdotool")),
                                reason="needs Xvfb and xdotool (Debian's xvfb and xdotool; .ci/run installs them)")


def _xvfb():
    """An Xvfb of its own (it picks a free display number): ``(process, ":N")``."""
    r, w = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-screen", "0", "1024x768x24", "-nolisten", "tcp"],
                            pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    with os.fdopen(r) as fh:
        return proc, f":{fh.readline().strip()}"


@pytest.fixture(scope="module")
def displays():
    """Two virtual screens (two viewer runs at once, one on each)."""
    made = [_xvfb(), _xvfb()]
    yield [d for _p, d in made]
    for proc, _d in made:
        proc.terminate()
        proc.wait(10)


@pytest.fixture(scope="module")
def display(displays):
    return displays[0]


class Child:
    """One ``lifelike-mj view`` in the real viewer (:mod:`real_viewer_child`), its JSON lines on a queue."""

    def __init__(self, display: str, creature: str, *args: str) -> None:
        env = dict(os.environ, DISPLAY=display, PYTHONUNBUFFERED="1")
        env.pop("WAYLAND_DISPLAY", None)
        self.display = display
        self.proc = subprocess.Popen([sys.executable, str(CHILD), creature, *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, env=env)
        self.lines: queue.Queue = queue.Queue()
        self.printed: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.printed.append(line)
            if line.startswith("{"):
                self.lines.put(json.loads(line))

    def expect(self, event: str, timeout: float = 60.0) -> dict:
        end = time.monotonic() + timeout
        while True:
            left = end - time.monotonic()
            if left <= 0:
                self.proc.kill()
                pytest.fail(f"no {event!r} from the viewer within {timeout:g} s: {self.proc.stderr.read()[-2000:]}")
            try:
                msg = self.lines.get(timeout=left)
            except queue.Empty:
                continue
            if msg["event"] == event:
                return msg

    def xdo(self, *args: str) -> str:
        return subprocess.run(["xdotool", *args], env=dict(os.environ, DISPLAY=self.display), capture_output=True,
                              text=True, timeout=30, check=True).stdout

    def focus(self) -> None:
        wid = self.xdo("search", "--sync", "--onlyvisible", "--name", "MuJoCo").split()[0]
        self.xdo("windowfocus", "--sync", wid)

    def press(self, key: str) -> None:
        self.xdo("key", XKEYS.get(key, key))

    def screenshot(self) -> np.ndarray:
        from PIL import ImageGrab

        return np.asarray(ImageGrab.grab(xdisplay=self.display).convert("RGB"), dtype=np.int16)

    def finish(self, timeout: float = 60.0) -> tuple[int, str]:
        try:
            self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.send_signal(signal.SIGINT)
            self.proc.wait(15)
        return self.proc.returncode, self.proc.stderr.read()


def _changed(a: np.ndarray, b: np.ndarray) -> float:
    """The share of pixels that differ by more than a few levels in some channel."""
    return float(np.mean(np.abs(a - b).max(axis=2) > 8))


@pytest.mark.parametrize("creature", list(SCENES))
def test_each_scene_key_changes_the_scene_and_not_the_viewer(display, creature):
    child = Child(display, creature, "--freeze", *_stop(creature, 600))
    base = child.expect("ready")["options"]
    child.focus()
    time.sleep(1.0)
    before = child.screenshot()
    for key, label in SCENES[creature]:
        child.press(key)
        got = child.expect("control", timeout=20)
        assert got["label"] == label, (key, got)
        assert got["options"] == base, f"{key} changed the viewer's options"
        time.sleep(0.3)  # a dozen frames
        now = child.screenshot()
        share = _changed(before, now)
        if (creature, key) in REDRAWS:
            before = now
            continue
        assert share < MAX_CHANGED, f"{key} redrew {share:.1%} of the window"
    # MuJoCo's own shortcuts, pressed the same way, are seen: T (transparency) in the options, W (wireframe) in
    # the picture; the same checks would fail a scene key that clashed with one of them
    child.press("t")
    child.press("w")
    time.sleep(1.0)
    after = child.screenshot()
    child.proc.send_signal(signal.SIGINT)
    code, err = child.finish()
    assert _changed(before, after) > 10 * MAX_CHANGED
    assert code in (0, 130), err[-2000:]


def _run_pressing_every_key(display: str, creature: str) -> tuple[int, str, list[str]]:
    """One viewer run: every scene key pressed, each seen to act, then the window closed as a user closes it
    (MuJoCo's Ctrl+Q): the exit status, stderr and the keys that acted."""
    child = Child(display, creature, *_stop(creature, 120))
    child.expect("ready")
    child.focus()
    child.xdo("key", "--delay", "30", *(XKEYS[k] for k, _label in SCENES[creature]))
    acted = [child.expect("control", timeout=30)["label"] for _k in SCENES[creature]]
    child.press("ctrl+q")
    code, err = child.finish()
    return code, err, acted


def test_twenty_viewer_runs_with_every_key_pressed_exit_cleanly(displays):
    """7 + 7 + 6 runs of the three scenes (two at a time, one per screen), every key pressed in each, then the window
    closed: exit status 0 every time, and each key acted."""
    from concurrent.futures import ThreadPoolExecutor

    runs = ["butterfly3d"] * 7 + ["fish"] * 7 + ["boids"] * 6
    with ThreadPoolExecutor(len(displays)) as pool:
        results = list(pool.map(lambda ic: _run_pressing_every_key(displays[ic[0] % len(displays)], ic[1]),
                                enumerate(runs)))
    for i, (creature, (code, err, acted)) in enumerate(zip(runs, results)):
        assert code == 0, f"run {i + 1} ({creature}) ended with {code}: {err[-2000:]}"
        assert "Traceback" not in err and "Segmentation" not in err
        assert acted == [label for _k, label in SCENES[creature]], (i, creature, acted)
