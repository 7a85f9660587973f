"""Shared fixtures."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image, ImageSequence

from lifelike_mj.errors import UserError


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
    stand-ins opened (each counts its ``sync`` calls and has a real ``cam`` and ``opt``)."""
    import contextlib

    import mujoco
    import mujoco.viewer

    class StandInViewer:
        def __init__(self, m, d):
            self.m, self.d, self.syncs = m, d, 0
            self.cam, self.opt = mujoco.MjvCamera(), mujoco.MjvOption()

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def lock(self):
            return contextlib.nullcontext()

        def is_running(self):
            return True

        def sync(self):
            self.syncs += 1

    opened = []

    def launch_passive(m, d, **kwargs):
        opened.append(StandInViewer(m, d))
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
