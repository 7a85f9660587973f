"""The one shape of every simulation in lifelike-mj, and recorded runs played back in it.

Every creature's simulation (:class:`lifelike_mj.butterfly.Flight` on either backend,
:class:`lifelike_mj.fish.Tank`, :class:`lifelike_mj.boids.Flock`) has the same shape,
:class:`Stepper`: built from parameters and a seed, then

* ``reset(seed=None)``: back to the start (a new seed draws a new start where there is randomness);
* ``step(n=1)``: advance ``n`` steps (an unstable simulation raises
  :class:`~lifelike_mj.errors.Diverged`, naming the cause and the step);
* ``steps``, ``time`` (s), ``dt`` (s per step; the boids' steps have no seconds: ``dt = 1``);
* ``state()``: named arrays whose names end in their unit (``position_m``, ``velocity_m_s``);
* ``record(...)``: a trajectory of the creature's kind;
* ``model``, ``data``: the MuJoCo model and data that show the current state, after ``sync()``.

The viewer (:func:`lifelike_mj.render.view`), the video recorder (:func:`lifelike_mj.render.film`) and
the reports drive this shape and nothing else. :class:`Playback` gives a run you already recorded
the same shape, so that it can be filmed or viewed like a live one.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Stepper(Protocol):
    """The shape shared by every simulation (module docstring)."""

    dt: float

    @property
    def steps(self) -> int: ...

    @property
    def time(self) -> float: ...

    def reset(self, seed: int | None = None) -> None: ...

    def step(self, n: int = 1) -> None: ...

    def state(self) -> dict[str, np.ndarray]: ...

    def sync(self) -> None: ...

    @property
    def model(self) -> Any: ...

    @property
    def data(self) -> Any: ...


class StepCounter:
    """``steps`` and ``time`` of a stepper that counts its steps in ``_k`` and has a ``dt``."""

    _k: int = 0
    dt: float

    @property
    def steps(self) -> int:
        """Steps taken since the start (or the last ``reset``)."""
        return self._k

    @property
    def time(self) -> float:
        """``steps * dt``: simulated time (s; the boids' steps have no seconds and ``dt = 1``)."""
        return self._k * self.dt


class Playback(StepCounter):
    """A recorded run in the stepper shape: step ``k`` shows frame ``k`` of the recording.

    ``model``/``data``: the MuJoCo model and data that show it; ``pose(k)`` places ``data`` at frame
    ``k`` (and computes what drawing needs); ``n_frames`` frames, ``dt`` seconds apart. Stepping past
    the last frame holds the last frame.
    """

    def __init__(self, model: Any, data: Any, n_frames: int, pose: Callable[[int], None], dt: float,
                 state: Callable[[int], dict[str, np.ndarray]] | None = None) -> None:
        if n_frames < 1:
            raise ValueError("a recording needs at least one frame")
        self.model, self.data, self.n_frames, self._pose, self.dt = model, data, int(n_frames), pose, float(dt)
        self._state = state
        self._k = 0

    def reset(self, seed: int | None = None) -> None:
        self._k = 0

    def step(self, n: int = 1) -> None:
        self._k += int(n)

    @property
    def frame(self) -> int:
        """The frame shown: the step, held at the last frame."""
        return min(self._k, self.n_frames - 1)

    def state(self) -> dict[str, np.ndarray]:
        return self._state(self.frame) if self._state is not None else {}

    def sync(self) -> None:
        self._pose(self.frame)

