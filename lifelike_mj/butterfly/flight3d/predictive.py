"""Predictive sampling on the designed controller: the butterfly looks ahead in gusts (issue 42).

The designed controller (:mod:`~lifelike_mj.butterfly.flight3d.designed`) is a linear regulator on the wing-beat
averaged model, linearised about level trims. In 1 m/s wind with 0.5 m/s gusts on every axis it loses its attitude
over and over (roll or pitch past 60 deg, 38-49 times in 30 s on the courses it fails) and completes about half the
courses. Two measurements say what is missing (``docs/results.md``):

* a search that flies copies of the simulation itself and knows **the air of now** (the present gust, held as it is
  over the horizon, no foresight) completes every course the designed controller fails; the same search given the
  controller's own wind estimate, made from the body's motion over whole wing beats, fails them too: that estimate
  misses the gusts almost entirely (0.4-0.5 m/s rms error on each axis, the size of the gusts themselves);
* the regulator itself does not profit from the true wind (a diagnosis of the eighth session): what the search adds
  is the nonlinear use of the authority the wings have, inside the natural envelope.

So this module gives the butterfly the two things, as an option on top of the designed controller:

1. **An airflow sense.** Insects sense the air moving past them with their antennae, and use it in flight control
   with a delay of about 20 ms, five times shorter than vision's (Fuller et al. 2014, PNAS 111: E1182; Sane et al.
   2007, Science 315: 863). The planner reads the air at the body as it was :data:`SENSE_DELAY_S` ago (mean wind and
   gust together), never the gusts to come.
2. **Predictive sampling** (Howell et al. 2022, "Predictive Sampling: Real-time Behaviour Synthesis with MuJoCo",
   arXiv 2212.00541, the derivative-free planner of MuJoCo MPC). Every :attr:`Planner.replan_s` (0.1 s, about one
   wing beat) the planner keeps a nominal correction to the designed controller's nine controls (the residual of
   :meth:`Flight3D.decide`, reach ``reach`` times :data:`~lifelike_mj.butterfly.flight3d.designed.R_SCALES`, then the
   envelope's limits), held over the horizon. It draws ``samples`` candidates around it (Gaussian, ``sigma`` in units
   of the reach; the nominal and the designed controller alone, zero correction, are always among them), flies each
   in a copy of the flight (the same MuJoCo state, the controller's own state, the task's progress) for
   ``horizon_s`` through the sensed air held steady, and keeps the cheapest as the new nominal; ``iterations``
   rounds, then the main flight flies the nominal for ``replan_s``.

The cost of a candidate (metres): the distance to the waypoint aimed at when the horizon ends, less
:data:`PASS_M` per waypoint passed within it, plus :data:`UPSET_COST` per 10 ms decision with roll or pitch beyond
:data:`UPSET_DEG`, :data:`TUMBLE_COST` for a tumble, and ``action_cost`` times the correction's mean square.

Compute: ``samples x iterations`` copies flown ``horizon_s`` for every ``replan_s`` flown, 32 x 0.6 s per 0.1 s by
default: about 12 s per second flown on one core of the development machine, the copies spread over the threads of
``NUMBA_NUM_THREADS``. Same seed, same flight.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: The airflow sense's delay (s): the antennae's, about 20 ms in flies (Fuller et al. 2014).
SENSE_DELAY_S = 0.02
#: A candidate's cost per waypoint passed within the horizon (m).
PASS_M = 1.5
#: Roll or pitch (deg) beyond which a copy counts as upset, and its cost per 10 ms decision so spent (m).
UPSET_DEG = 60.0
UPSET_COST = 10.0
#: The cost of a tumble within the horizon (m).
TUMBLE_COST = 100.0


class Planner:
    """Predictive sampling (module docstring) for ``flight``, a :class:`~lifelike_mj.butterfly.flight3d.flight.
    Flight3D` with a designed controller flown compiled and a waypoint task. ``samples`` candidates (at least 2),
    ``iterations`` rounds per plan, ``horizon_s`` looked ahead, re-planned every ``replan_s`` (a whole number of the
    controller's decisions), ``sigma`` the candidates' spread and ``reach`` the corrections' (in the controls' Bryson
    scales), ``action_cost`` the weight of a correction's mean square; ``seed`` draws the candidates.

    ``Planner(flight).fly(30.0)`` flies the course with the planner for at most 30 s (or until its last waypoint or a
    tumble); :meth:`step` plans and flies one ``replan_s``."""

    def __init__(self, flight, *, samples: int = 16, iterations: int = 2, horizon_s: float = 0.6,
                 replan_s: float = 0.1, sigma: float = 0.3, reach: float = 3.0, action_cost: float = 1.0,
                 seed: int = 0) -> None:
        import mujoco

        from lifelike_mj.butterfly.flight3d import designed as D
        from lifelike_mj.butterfly.flight3d.loop import Batch
        from lifelike_mj.butterfly.flight3d.tasks import R_STEPS

        if getattr(flight, "designed", None) is None:
            raise UserError("the predictive planner needs a flight with a designed controller (design3d), flown "
                            "compiled.")
        if flight.task.kind != "waypoints":
            raise UserError(f"the predictive planner flies courses (a waypoint task), not a {flight.task.kind} task.")
        self.samples = checks.whole("samples", samples, 2)
        self.iterations = checks.whole("iterations", iterations, 1)
        self.sigma = checks.number("sigma", sigma, 0.0, 10.0)
        self.reach = checks.number("reach", reach, 0.0, 100.0, lo_open=True)
        self.action_cost = checks.number("action_cost", action_cost, 0.0, 1e6)
        self.flight = flight
        mb = flight._batch
        decision_s = mb.every * mb.dt
        self.decisions = max(1, int(round(checks.number("replan_s", replan_s, 0.0, 10.0, lo_open=True) / decision_s)))
        self.horizon = max(1, int(round(checks.number("horizon_s", horizon_s, 0.0, 10.0, lo_open=True) / decision_s)))
        self.replan_s, self.horizon_s = self.decisions * decision_s, self.horizon * decision_s
        self.delay = int(round(SENSE_DELAY_S / decision_s))
        self.rng = np.random.default_rng(seed)
        self.scale = D.R_SCALES * self.reach
        mb.residual_scale = self.scale
        self.waypoints = np.array([r[:3] for r in flight.task.rows], float)
        self.upset_rad = math.radians(UPSET_DEG)
        self._mujoco = mujoco
        m = flight.model
        self.copies = [mujoco.MjData(m) for _ in range(self.samples)]
        self.batch = Batch(m, self.copies, np.repeat(mb.tasks, self.samples, 0), None, dt_s=mb.dt,
                           records=np.repeat(mb.records, self.samples, 0), tumble_rad=mb.tumble_rad, base=mb.base,
                           designed=flight.designed)
        self.batch.residual_scale = self.scale
        self.nominal = np.zeros(9)
        #: The weight of the mean square roll and pitch in :meth:`costs` (0: none).
        self.attitude_weight = 0.0
        if int(mb.records[0][R_STEPS]) == 0:
            flight.decide(None)
        self._air: deque = deque(maxlen=self.delay + 1)
        self._sense()

    def _sense(self) -> None:
        from lifelike_mj.butterfly.flight3d import model as mj3d

        self._air.append(np.array(self.flight.data.userdata[mj3d.U_AIR : mj3d.U_AIR + 3]))

    @property
    def sensed_air_m_s(self) -> np.ndarray:
        """The air's velocity at the body (m/s, world axes) as the airflow sense gives it now: as it was
        :data:`SENSE_DELAY_S` ago (or at the start, if the flight is younger)."""
        return self._air[0].copy()

    def _load(self) -> None:
        """Every copy at the main flight's state (:meth:`_set_air` then sets the air it flies in)."""
        mb, cb = self.flight._batch, self.batch
        for d in self.copies:
            self._mujoco.mj_copyData(d, self.flight.model, self.flight.data)
        cb.tasks[:] = mb.tasks[0]
        cb.records[:] = mb.records[0]
        for a, b in zip(cb.designed_states, mb.designed_states):
            a[:] = b[0]
        cb.baselines[:] = mb.baselines[0]
        cb.observations[:] = mb.observations[0]
        self._set_air()

    def _set_air(self) -> None:
        """The copies' air: the sensed air held steady, no gusts."""
        from lifelike_mj.butterfly.flight3d.tasks import R_GUST, T_GUST, T_GUST_W, T_WIND

        cb = self.batch
        cb.tasks[:, T_GUST] = 0.0
        cb.tasks[:, T_GUST_W] = 0.0
        cb.tasks[:, T_WIND : T_WIND + 3] = self.sensed_air_m_s
        cb.records[:, R_GUST : R_GUST + 3] = 0.0

    def costs(self, candidates: np.ndarray) -> np.ndarray:
        """The cost (module docstring) of each of ``candidates``, each flown in a copy from the main flight's state:
        one correction per copy (rows of nine numbers in [-1, 1]) held over the horizon, or ``(copies, segments, 9)``
        corrections held in turn for equal parts of it. :attr:`attitude_weight` (0 unless set) adds the mean square
        roll and pitch (rad^2) over the horizon's decisions."""
        from lifelike_mj.butterfly.flight3d.flight import euler_from_quat
        from lifelike_mj.butterfly.flight3d.tasks import R_PASSED, R_TUMBLED

        plans = np.asarray(candidates, dtype=np.float64)
        plans = plans[:, None, :] if plans.ndim == 2 else plans
        per = max(1, self.horizon // plans.shape[1])
        self._load()
        rq = self.flight._root_q
        p0 = self.flight.waypoints_passed
        upsets, att, n = np.zeros(self.samples), np.zeros(self.samples), 0
        for h in range(plans.shape[1]):
            for _ in range(per):
                self.batch.decide(plans[:, h, :], 10**12)
                n += 1
                for i, d in enumerate(self.copies):
                    rp = euler_from_quat(d.qpos[rq + 3 : rq + 7])[:2]
                    att[i] += float(rp @ rp)
                    upsets[i] += bool(np.any(np.abs(rp) > self.upset_rad))
        c = np.zeros(self.samples)
        for i, d in enumerate(self.copies):
            rec = self.batch.records[i]
            passed = int(rec[R_PASSED])
            aim = self.waypoints[min(passed, len(self.waypoints) - 1)]
            c[i] = (float(np.linalg.norm(d.qpos[rq : rq + 3] - aim)) - PASS_M * (passed - p0)
                    + self.attitude_weight * att[i] / n + UPSET_COST * upsets[i] + TUMBLE_COST * (rec[R_TUMBLED] >= 0))
            c[i] += self.action_cost * float(np.mean(np.square(plans[i])))
        return c

    def plan(self) -> np.ndarray:
        """The next correction (nine numbers in [-1, 1]): ``iterations`` rounds of sampling around the nominal."""
        for _ in range(self.iterations):
            cand = self.nominal[None] + self.sigma * self.rng.standard_normal((self.samples, 9))
            cand[0] = self.nominal
            cand[1] = 0.0
            cand = np.clip(cand, -1.0, 1.0)
            self.nominal = cand[int(np.argmin(self.costs(cand)))].copy()
        return self.nominal.copy()

    def step(self, each=None) -> bool:
        """Plan, then fly the main flight ``replan_s`` with the plan (``each()``, if given, after every decision of
        the controller); ``False`` once the flight has ended (a tumble) or passed its last waypoint. After the last
        waypoint the designed controller flies on alone."""
        f = self.flight
        done = f.tumbled or f.waypoints_passed >= len(self.waypoints)
        act = np.zeros(9) if done else self.plan()
        for _ in range(self.decisions):
            if f.tumbled:
                break
            f.decide(act)
            self._sense()
            if each is not None:
                each()
        return not (f.tumbled or f.waypoints_passed >= len(self.waypoints))

    def fly(self, seconds: float) -> dict:
        """Fly with the planner for at most ``seconds`` (s) of flight time, or until the last waypoint or a tumble;
        returns the waypoints passed, the time flown (s) and whether it tumbled."""
        seconds = checks.number("seconds", seconds, 0.0, 1e6, lo_open=True)
        f = self.flight
        while f.time < seconds - 1e-9 and self.step():
            pass
        return {"passed": f.waypoints_passed, "time_s": round(f.time, 4), "tumbled": bool(f.tumbled)}

    def record(self, duration_s: float) -> dict:
        """:meth:`Flight3D.record` with the planner: fly ``duration_s`` (s) and return the path sampled at every
        decision of the controller (10 ms), the current state first (``t_s`` and the flight's ``state()`` arrays); it
        ends at the first re-planning at or after ``duration_s``."""
        duration_s = checks.positive("duration", duration_s, "s")
        f = self.flight
        rows, times = [f.state()], [f.time]

        def sample() -> None:
            rows.append(f.state())
            times.append(f.time)

        end = f.time + duration_s
        while f.time < end - 1e-9 and not f.tumbled:
            self.step(sample)
        out = {k: np.array([r[k] for r in rows]) for k in rows[0]}
        out["t_s"] = np.array(times)
        return out
