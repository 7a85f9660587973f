"""Installing MuJoCo's process-global callbacks, in one place.

MuJoCo's callbacks (``mjcb_passive`` ...) are global to the process and shared by every model
and thread. :func:`passive_callback` installs one for the duration of a ``with`` block and puts
back whatever was installed before, even when the block raises.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import mujoco


@contextlib.contextmanager
def passive_callback(callback) -> Iterator[None]:
    """Install ``callback`` (a Python callable or a ctypes/numba C function) as ``mjcb_passive``."""
    previous = mujoco.get_mjcb_passive()
    mujoco.set_mjcb_passive(callback)
    try:
        yield
    finally:
        mujoco.set_mjcb_passive(previous)
