"""Shared fixtures."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image, ImageSequence

from lifelike_mj.errors import UserError

#: Test files whose tests pytest-xdist shares among its workers one by one: long commands, each independent of the
#: others. Every other file's tests run in one worker together (``--dist loadgroup``), its module fixtures made once.
SHARED_FILES = {"test_doc_commands.py"}


#: The compiled loops most test files fly, compiled once before pytest-xdist starts its workers (two processes at
#: once, :func:`pytest_configure`): without this, two workers that reach the same loop together each compile it (a
#: minute each for the designed controller's), and a fresh machine's suite pays that several times over.
WARM_UP = (
    "from lifelike_mj.butterfly.flight3d import Flight3D, level\n"
    "Flight3D(controller='designed', task=level(1.5)).step(16)\n"
    "Flight3D(controller='monarch', task=level(1.5)).step(16)\n",
    "from lifelike_mj.butterfly.flight3d.garden import Garden\n"
    "Garden(2, seed=0).step(16)\n",
)


def pytest_configure(config):
    """In pytest-xdist's controller, before its workers start: :data:`WARM_UP` (the compiled loops into numba's
    on-disk cache, which the workers then load). A warm-up that fails changes nothing: each test compiles what it
    needs, as it would without it."""
    if hasattr(config, "workerinput") or not config.getoption("numprocesses", None):
        return
    import sys

    warm = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for code in WARM_UP]
    for proc in warm:
        try:
            proc.wait(timeout=600)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Each test file one pytest-xdist group (:data:`SHARED_FILES` apart), before xdist reads the groups."""
    for item in items:
        if item.path.name not in SHARED_FILES:
            item.add_marker(pytest.mark.xdist_group(item.path.relative_to(config.rootpath).as_posix()))


@pytest.fixture(scope="session")
def gl_backend():
    """The offscreen backend this machine offers; skip the rendering tests only if there is none."""
    import mujoco

    from lifelike_mj.render import gl as video

    backend = video.ensure_gl_backend()
    if backend is None:
        pytest.skip("no offscreen OpenGL backend can be created here (tried MUJOCO_GL=egl and osmesa; install "
                    "libegl1 or libosmesa6)")
    try:
        from lifelike_mj.render.offscreen import Offscreen

        Offscreen(mujoco.MjModel.from_xml_string("<mujoco/>"), 16, 16).close()
    except UserError as exc:
        pytest.skip(f"no offscreen OpenGL context can be created here: {exc}")
    return backend


@pytest.fixture
def stand_in_viewer(monkeypatch):
    """Replace ``mujoco.viewer.launch_passive`` by a window-less stand-in; yields the list of the
    stand-ins opened (each counts its ``sync`` calls and has a real ``cam``, ``opt`` and ``user_scn``; set
    ``opened.viewer_class.presses`` to press keys)."""
    import contextlib

    import mujoco
    import mujoco.viewer

    class StandInViewer:
        """``presses``: ``{sync number: key code}``, pressed (through the key callback the viewer was given)
        when that many frames have been shown."""

        presses: dict[int, int] = {}

        def __init__(self, m, d, key_callback=None):
            self.m, self.d, self.syncs = m, d, 0
            self.cam, self.opt = mujoco.MjvCamera(), mujoco.MjvOption()
            self.user_scn = mujoco.MjvScene(m, maxgeom=100)
            self.key_callback = key_callback

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def close(self):
            pass

        def lock(self):
            return contextlib.nullcontext()

        def is_running(self):
            return True

        def sync(self):
            self.syncs += 1
            if self.syncs in self.presses and self.key_callback is not None:
                self.key_callback(self.presses[self.syncs])

    class Opened(list):
        viewer_class = StandInViewer

    opened = Opened()

    def launch_passive(m, d, key_callback=None, **kwargs):
        opened.append(StandInViewer(m, d, key_callback))
        return opened[-1]

    monkeypatch.setattr(mujoco.viewer, "launch_passive", launch_passive)
    return opened


def gif_frames(path) -> list[np.ndarray]:
    """The frames of a GIF as float RGB arrays."""
    with Image.open(path) as im:
        return [np.asarray(f.convert("RGB"), dtype=float) for f in ImageSequence.Iterator(im)]


def saved(fig, path):
    """``path``, after checking that a figure function returned its matplotlib ``Figure`` and wrote it
    there (figure functions return the figure and save only when given a path)."""
    from matplotlib.figure import Figure

    assert isinstance(fig, Figure), type(fig)
    assert path.is_file(), path
    return path


# ---- the exporters' tests (tests/export): one short run of each creature, and headless Chromium ----

from lifelike_mj.export.poses import record_poses  # noqa: E402

#: The creatures every exporter is checked on.
CREATURES = ("butterfly3d", "butterfly2d", "fish", "boids")


def _fresh(creature: str):
    """A new simulation of ``creature`` and its recording window: ``(sim, fps, time_scale, duration)``."""
    if creature == "butterfly3d":
        from lifelike_mj.butterfly import flight3d
        from lifelike_mj.butterfly.flight3d.flight import Flight3D

        return Flight3D(controller=flight3d.withdrawn_file("steer"), task=flight3d.course(100)), 30.0, 1.0, 1.0
    if creature == "butterfly2d":
        from lifelike_mj.butterfly import Flight

        return Flight(controller="simple_rule", backend="mujoco", config="rich"), 30.0, 1.0, 1.0
    if creature == "fish":
        from lifelike_mj.fish import Tank

        return Tank(n_fish=10, seed=1), 30.0, 1.0, 1.0
    from lifelike_mj.boids import Flock

    # a flock's steps have no seconds: a frame every 5 steps, 30 frames a second
    return Flock(n=300, seed=1), 0.2, 1.0 / 150.0, 150.0


def _run(creature: str):
    sim, fps, scale, duration = _fresh(creature)
    return sim, record_poses(sim, duration, fps=fps, time_scale=scale)


@pytest.fixture(scope="session")
def fresh():
    """``fresh(creature)``: a new simulation of the creature ``runs`` records, and its window: ``(sim, fps,
    time_scale, duration)``."""
    return _fresh


@pytest.fixture(scope="session")
def runs():
    """``runs(creature)``: ``(simulation at its last frame, poses)``, recorded on first use."""
    cache: dict = {}

    def get(creature: str):
        if creature not in cache:
            cache[creature] = _run(creature)
        return cache[creature]

    return get


@pytest.fixture(params=CREATURES)
def creature(request) -> str:
    """Each creature in turn."""
    return request.param


class _Chromium:
    """Headless Chromium driven by ``page_check.js`` (Node and npm's playwright-core, which ``.ci/run``
    installs into ``.ci/node``, with Debian's ``chromium``)."""

    modules = Path(__file__).resolve().parents[1] / ".ci" / "node" / "node_modules"

    def __init__(self, executable: str) -> None:
        self.executable = executable

    def check(self, *args: str, clicks: str = "", pressed: Callable[[int], bool] | None = None) -> dict:
        """``page_check.js`` run on ``args``: its JSON report. ``clicks`` ("x,y x,y"): pressed in a live viewer one by
        one; after the i-th, ``pressed(i)`` says whether it took effect (it waits for it), else it is pressed again,
        at most three times."""
        env = dict(os.environ, NODE_PATH=str(self.modules), CHROMIUM=self.executable, CLICKS=clicks)
        node = subprocess.Popen(["node", str(Path(__file__).parent / "export" / "page_check.js"), *args], env=env,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        timer = threading.Timer(300.0, node.kill)  # never a hang: at most five minutes
        timer.start()
        line = ""
        try:
            tries: dict[int, int] = {}
            for line in node.stdout:
                if not line.startswith('{"pressed":'):
                    break  # the report, the last line
                i = json.loads(line)["pressed"]
                tries[i] = tries.get(i, 0) + 1  # pressed once more, held longer (page_check.js)
                again = pressed is not None and not pressed(i) and tries[i] < 3
                node.stdin.write("again\n" if again else "next\n")
                node.stdin.flush()
            rest, err = node.communicate(timeout=240)
        finally:
            timer.cancel()
            if node.poll() is None:
                node.kill()
                node.communicate()
        assert node.returncode == 0, err
        report = json.loads((line + rest).strip().splitlines()[-1])
        return {**report, "presses": [tries[i] for i in sorted(tries)]}

    @staticmethod
    def changed_pixels(a: str, b: str) -> int:
        """Pixels whose colour differs by more than 8 of 255 in some channel between two screenshots."""
        x = np.asarray(Image.open(a).convert("RGB"), dtype=int)
        y = np.asarray(Image.open(b).convert("RGB"), dtype=int)
        return int(np.sum(np.abs(x - y).max(axis=2) > 8))


@pytest.fixture(scope="session")
def chromium() -> _Chromium:
    """Headless Chromium (:class:`_Chromium`), or a skip that says what is missing."""
    exe = shutil.which("chromium")
    if exe is None or shutil.which("node") is None or not (_Chromium.modules / "playwright-core").is_dir():
        pytest.skip("Chromium or playwright-core is not installed (.ci/run installs Debian's chromium and npm's "
                    "playwright-core)")
    return _Chromium(exe)


class _OtherProcess:
    """Claims on outputs held by another process (:func:`lifelike_mj.io.claim`), as a second run would find them."""

    def __init__(self) -> None:
        self.procs: list = []

    def hold(self, path) -> int:
        """Claim ``path`` in a child process that keeps it until the test ends; returns its process id."""
        import subprocess
        import sys

        code = ("import sys; from lifelike_mj.io import claim; claim(sys.argv[1], 'output'); print('held', flush=True); "
                "sys.stdin.read()")
        p = subprocess.Popen([sys.executable, "-c", code, str(path)], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             text=True)
        assert p.stdout.readline().strip() == "held"
        self.procs.append(p)
        return p.pid

    def close(self) -> None:
        for p in self.procs:
            p.stdin.close()
            p.wait(10)


@pytest.fixture
def other_process():
    """Hold outputs' claims from another process for the test's length (``other_process.hold(path)``)."""
    o = _OtherProcess()
    yield o
    o.close()


@pytest.fixture(scope="session")
def local_ray():
    """A local Ray cluster of 2 CPUs for the whole session (starting one takes about 20 s), shut down at its end."""
    ray = pytest.importorskip("ray")
    if not ray.is_initialized():
        ray.init(num_cpus=2, include_dashboard=False)
    yield ray
    ray.shutdown()
