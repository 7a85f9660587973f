"""The machine a benchmark ran on, for its JSON and docs/performance.md."""

from __future__ import annotations

import os
import platform


def machine_info() -> dict:
    """Platform, processor, core count, numba threads and library versions."""
    import mujoco
    import numba

    from lifelike_mj import __version__

    return {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "numba_threads": numba.get_num_threads(),
        "python": platform.python_version(),
        "mujoco": mujoco.__version__,
        "numba": numba.__version__,
        "lifelike_mj": __version__,
    }
