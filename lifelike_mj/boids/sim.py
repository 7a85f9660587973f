"""A flock of heterogeneous boids (Nakamura 2013) in the stepper shape every creature shares.

:class:`Flock` holds the agents' positions, velocities and types and steps them with the compiled
cell-list engine (:mod:`lifelike_mj.boids.engine`, eq. 1-9). Between steps a script may change
the weight matrices (:meth:`Flock.set_weights`) or add agents (:meth:`Flock.add_agents`); the MuJoCo
scene that shows the flock (mocap bodies, :mod:`lifelike_mj.boids.scene`) follows. Units are the
paper's: lengths in box units, time in engine steps (``dt = 1``).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from lifelike_mj import checks
from lifelike_mj.boids.engine import (
    N_AGENTS,
    BoidParams,
    BoidRun,
    _as3,
    _steps,
    check_cost,
    diverged_speed,
    divergence_message,
    initial_state,
)
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.stepper import StepCounter

#: Names of :meth:`Flock.state` and their units.
STATE_UNITS = {
    "position_box": "box units: each agent's position in the box [0, L]^D",
    "velocity_box_per_step": "box units per step: each agent's velocity",
    "type": "each agent's type (0 = A, 1 = B, ...)",
}


#: The most agents a flock holds: the command line's ``--n`` bound, run in ``tests/test_documented_limits.py`` (a
#: million agents at the paper's density: 0.4 s a step, 1.3 GB with one frame's measures). The scaling benchmark goes
#: further on the engine itself (``boids/bench.py``).
MAX_FLOCK = 1_000_000


class Flock(StepCounter):
    """``n`` agents with parameters ``params`` (:class:`~lifelike_mj.boids.engine.BoidParams`; default
    the paper's 5a weights) started from ``seed`` (:func:`~lifelike_mj.boids.engine.initial_state`).
    One step is one engine step (eq. 1-2 with ``dt = 1``)."""

    @checks.known_keywords
    def __init__(self, params: BoidParams | None = None, n: int = N_AGENTS, seed: int = 0) -> None:
        if params is None:
            from lifelike_mj.boids.presets import load_preset

            params = load_preset("5a")
        if not isinstance(params, BoidParams):
            raise UserError(f"params must be BoidParams (boids.load_preset('5a'), or BoidParams(...)), got {params!r}.")
        self.params = params
        self._n0 = checks.whole("the number of agents", n, 2, MAX_FLOCK)
        self._seed = checks.whole("seed", seed, 0, 2**32 - 1)
        self.reset()

    # ---- the stepper shape ---------------------------------------------------------------------

    @property
    def seed(self) -> int:
        return self._seed

    @property
    def dt(self) -> float:
        """Time per step (the engine's dt, in steps: 1)."""
        return float(self.params.dt)

    @property
    def n(self) -> int:
        return len(self.types)

    def reset(self, seed: int | None = None) -> None:
        """Back to a random start (:func:`~lifelike_mj.boids.engine.initial_state`) with ``seed`` (or the
        flock's own), ``n`` agents as built."""
        if seed is not None:
            self._seed = checks.whole("seed", seed, 0, 2**32 - 1)
        x, v, self.types = initial_state(self.params, self._n0, self._seed)
        self._x, self._v = _as3(x), _as3(v)
        self._k = 0
        self._scene = None

    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps; a run that diverges raises :class:`~lifelike_mj.errors.Diverged` naming
        the step and the likely cause."""
        n = checks.whole("the number of steps", n, 0)
        if n:
            check_cost(self.params, self.n, n, f"Flock.step({n})")
            self._run(n)

    def state(self) -> dict[str, np.ndarray]:
        """Positions, velocities (n, D) and types (n,) (:data:`STATE_UNITS`), as copies."""
        D = self.params.dims
        return {"position_box": self._x[:, :D].copy(), "velocity_box_per_step": self._v[:, :D].copy(),
                "type": self.types.copy()}

    def record(self, n_steps: int, every: int = 1, record_from: int = 0, extra_steps=(),
               progress: bool = False) -> BoidRun:
        """Run ``n_steps`` steps; the state every ``every`` steps from ``record_from`` on (counted from
        now: 0 is the current state) and at the ``extra_steps`` (same count). The run's ``steps`` are
        the flock's step numbers."""
        n_steps = checks.whole("the number of steps", n_steps, 1)
        every = checks.whole("record_every", every, 1)
        check_cost(self.params, self.n, n_steps, f"recording {n_steps:,} steps")
        frames = (n_steps - min(max(int(record_from), 0), n_steps)) // every + 1 + len(extra_steps)
        checks.work(f"recording {self.n:,} agents every {every} steps over {n_steps:,} steps", float(frames) * self.n,
                    checks.MAX_RECORD_ROWS, "agent rows", "fewer agents, or recording less often or less")
        t0 = time.perf_counter()
        k0, D, n = self._k, self.params.dims, self.n
        rec = sorted({s for s in range(0, n_steps + 1, every) if s >= record_from}
                     | {int(s) for s in extra_steps if 0 <= s <= n_steps})
        X = np.empty((len(rec), n, 3))
        V = np.empty((len(rec), n, 3))
        r = 0
        if rec and rec[0] == 0:
            X[0], V[0] = self._x, self._v
            r = 1
        done = 0
        bar = None
        if progress:
            from lifelike_mj.progress import bar as progress_bar

            bar = progress_bar(n_steps, "boids", unit="step")
        try:
            while done < n_steps:
                k = (rec[r] if r < len(rec) else n_steps) - done
                self._run(k)
                done += k
                if r < len(rec) and done == rec[r]:
                    X[r], V[r] = self._x, self._v
                    r += 1
                if bar is not None:
                    bar.update(k)
        finally:
            if bar is not None:
                bar.close()
        return BoidRun(self.params, self._seed, self.types.copy(), k0 + np.array(rec), X[:, :, :D].copy(),
                       V[:, :, :D].copy(), time.perf_counter() - t0)

    # ---- changing the flock between steps -------------------------------------------------------

    def scatter(self, seed: int) -> None:
        """The agents placed afresh at random, as a new start drawn with ``seed`` would place them
        (:func:`~lifelike_mj.boids.engine.initial_state`: positions away from the walls, tiny velocities), each
        keeping its type; the weights and the step count go on. What the viewer's restart key does: a mixed flock
        again, under the weights flown now."""
        x, v, _types = initial_state(self.params, self.n, checks.whole("seed", seed, 0))
        self._x[:] = _as3(x)
        self._v[:] = _as3(v)

    def set_weights(self, wa=None, wc=None) -> None:
        """Replace the alignment and/or cohesion matrix (``k x k``, rows: own type) from the next step on;
        the number of types stays."""
        new = dataclasses.replace(self.params, wa=self.params.wa if wa is None else wa,
                                  wc=self.params.wc if wc is None else wc)
        if new.n_types != self.params.n_types:
            raise UserError(f"the flock has {self.params.n_types} types; the new matrices have {new.n_types}.")
        self.params = new

    def add_agents(self, positions, velocities=None, types=None) -> None:
        """Add agents at ``positions`` (m, D) in box units, with ``velocities`` (default 0) and ``types``
        (default 0); they take part from the next step on."""
        D = self.params.dims
        x = np.atleast_2d(np.asarray(positions, dtype=float))
        v = np.zeros_like(x) if velocities is None else np.atleast_2d(np.asarray(velocities, dtype=float))
        t = np.zeros(len(x), dtype=np.int64) if types is None else np.asarray(types, dtype=np.int64).reshape(-1)
        if x.shape[1:] != (D,) or v.shape != x.shape or t.shape != (len(x),):
            raise UserError(f"new agents need positions and velocities of shape (m, {D}) and m types.")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise UserError("new agents need finite positions and velocities.")
        if np.any((x < 0) | (x > self.params.box)):
            raise UserError(f"new agents must be inside the box [0, {self.params.box:g}]^{D}.")
        if np.any((t < 0) | (t >= self.params.n_types)):
            raise UserError(f"types must be from 0 to {self.params.n_types - 1}.")
        self._x = np.concatenate([self._x, _as3(x)])
        self._v = np.concatenate([self._v, _as3(v)])
        self.types = np.concatenate([self.types, t])
        self._scene = None

    # ---- drawing -------------------------------------------------------------------------------

    def _scene_pair(self):
        if self._scene is None:
            import mujoco

            from lifelike_mj.boids.scene import build_scene

            m, layout = build_scene(self.n, self.types, box=self.params.box, dims=self.params.dims)
            self._scene = (m, mujoco.MjData(m), layout)
        return self._scene

    @property
    def model(self):
        """The MuJoCo scene of the flock (mocap bodies; rebuilt when agents are added)."""
        return self._scene_pair()[0]

    @property
    def data(self):
        return self._scene_pair()[1]

    @property
    def layout(self):
        """The scene's :class:`~lifelike_mj.boids.scene.BoidsLayout`."""
        return self._scene_pair()[2]

    def sync(self) -> None:
        """Place the scene's bodies at the agents (positions, and orientations along the velocities)."""
        from lifelike_mj.boids.scene import update

        m, d, layout = self._scene_pair()
        D = self.params.dims
        update(m, d, layout, self._x[:, :D], self._v[:, :D])

    # ---- internals ------------------------------------------------------------------------------

    def _run(self, n: int) -> None:
        wa, wc, c = self.params.arrays()
        bad = _steps(self._x, self._v, self.types, wa, wc, c, self.params.dims == 2, int(n), diverged_speed(self.params))
        if bad:
            step = self._k + bad
            self._k = step
            raise Diverged(divergence_message(self.params, step), step)
        self._k += n


def simulate(params: BoidParams, n: int = N_AGENTS, n_steps: int = 3000, seed: int = 0, record_every: int = 1,
             record_from: int = 0, progress: bool = False, extra_steps=()) -> BoidRun:
    """Run ``n_steps`` steps from :func:`initial_state`; record the state every ``record_every``
    steps from step ``record_from`` on (step 0 = the initial state), and at the ``extra_steps``
    (:meth:`Flock.record` of a new flock). Raises
    :class:`~lifelike_mj.errors.Diverged` if the run diverges (section 2.2: w_a >= 10 or w_c >= 1)."""
    return Flock(params, n, seed).record(n_steps, record_every, record_from, extra_steps, progress)
