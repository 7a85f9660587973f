"""The virtual aquarium: a tank whose fish react to the people watching it (the use that Satoi et al. 2015
have in mind), as two stated rules on top of the four motion units. Nothing else of the model changes.

* **A tap on the glass** at a point ``p``: every fish whose centre lies within :data:`TAP_RADIUS_M` of ``p``
  startles. For :data:`STARTLE_S` it accelerates at every control step (motion unit *accelerate*, in place
  of the Markov chain's draw) with the strongest push the preset draws (``r_max_N``), pointed away from
  ``p`` (in eq. 2-9's angles: the push's direction in the fish's frame is the direction from ``p`` to the
  fish). A fish farther away does not notice.
* **A food pellet** dropped at ``(x, y)``: it appears at the surface and sinks at :data:`FOOD_SINK_M_S` to
  the bottom. A fish within :data:`FOOD_SIGHT_M` of a pellet notices it: when its Markov chain chooses to
  accelerate, it pushes toward the nearest pellet it notices (with the preset's mean push,
  ``(r_min_N + r_max_N) / 2``) instead of in a drawn direction; its timing stays the chain's. The first fish
  whose centre comes within :data:`EAT_RADIUS_M` of a pellet eats it.
* **Fish compete for food** (``compete=True``; off by default): when two fish or more go for the same pellet, each
  pushes toward it with the strongest push the preset draws (``r_max_N``) in place of the mean: a scramble, the
  nearest fish arriving first and its rivals pressing behind. A fish that heeds its neighbours (a social preset) keeps
  its social turn on top of the push toward the pellet, so a school follows the fish that go for food.

* **A startle spreads** (``cascade=True``; off by default): a fish that sees a neighbour start an escape may
  startle too, as startles spread through real schools (Rosenthal et al. 2015). It sees a neighbour within
  :data:`CASCADE_RANGE_BL` body lengths and outside the rear blind sector of its preset (``social_blind_deg``). Each
  such escape is judged once, :data:`CASCADE_LATENCY_S` after it began (the time to see it and for the Mauthner
  cells to fire), and startles the fish with the probability ``1 / (1 + exp(-(a + b ln d)))``. Here ``d`` is the
  distance in body lengths, and ``a`` and ``b`` are :data:`CASCADE_LOGIT`. Rosenthal et al. fitted this form,
  falling with the log of the distance, to golden shiners; the numbers are ours: 0.9 at 1 body length, 0.5 at 3,
  0.1 at 9. A fish startled by a neighbour flees the way that neighbour flees. For :data:`CASCADE_REFRACTORY_S`
  after its own escape began, a fish catches no other (so a startle runs through a school once). ``startle(i)`` startles one fish
  alone, as a looming object only it sees.

The random numbers are drawn as without the aquarium (the tank's policies, :class:`~lifelike_mj.fish.sim.Tank`; the
cascade's draws come from a generator of their own), so until the first tap or pellet a tank swims exactly as the
same tank without them.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.fish.params import ACCELERATE
from lifelike_mj.fish.sim import Tank

#: A tap startles the fish within this distance of it (m).
TAP_RADIUS_M = 1.0
#: A startle lasts this long (s).
STARTLE_S = 0.25
#: A fish notices a pellet within this distance (m).
FOOD_SIGHT_M = 1.5
#: A pellet sinks this fast (m/s) until it lies on the bottom.
FOOD_SINK_M_S = 0.05
#: A fish eats a pellet when its centre comes this close (m).
EAT_RADIUS_M = 0.04
#: A startle cascade (module docstring): how far a fish sees an escape (body lengths), how long after an escape began
#: a neighbour reacts to it (s), and the logistic law's ``(a, b)`` of the probability that it does.
CASCADE_RANGE_BL = 10.0
CASCADE_LATENCY_S = 0.05
#: A fish that escaped does not catch another escape from a neighbour for this long after its own began (s): a
#: startle runs through a school once rather than echoing back and forth.
CASCADE_REFRACTORY_S = 3.0
CASCADE_LOGIT = (2.2, -2.0)
#: A pellet's radius (m) and colour, as the viewers draw it.
PELLET_DRAWN_M = 0.02
PELLET_RGBA = (0.75, 0.45, 0.15, 1.0)


def _angles(direction_body: np.ndarray) -> tuple[float, float]:
    """eq. 2-9's push angles ``(theta, phi)`` (deg) of a unit direction in the fish's frame (x ahead, y left,
    z up): the push is ``r (sin theta sin phi, sin theta cos phi, cos theta)``."""
    x, y, z = direction_body
    return math.degrees(math.acos(max(-1.0, min(1.0, z)))), math.degrees(math.atan2(x, y))


class Aquarium:
    """A :class:`~lifelike_mj.fish.sim.Tank` with taps and food (module docstring), in the stepper shape.

    ``tank``: the tank (a :class:`~lifelike_mj.fish.sim.Tank` made with no policies of its own); ``cascade`` and
    ``compete`` (True or False, nothing else): the rules of the module docstring. ``tap(point_m)`` and
    ``drop_food(x_m, y_m)`` act now;
    ``pellets_m`` holds the pellets still in the water; ``startled`` says which fish are startled."""

    @checks.known_keywords
    def __init__(self, tank: Tank, cascade: bool = False, compete: bool = False) -> None:
        if not isinstance(tank, Tank):
            what = repr(tank) if len(repr(tank)) <= 60 else f"a {type(tank).__name__}"
            raise UserError(f"tank must be a fish Tank (lifelike_mj.fish.Tank(params, n_fish, seed, size)), got {what}.")
        cascade = checks.flag("cascade", cascade)
        compete = checks.flag("compete", compete)
        if tank.mu_policy is not None or tank.push_policy is not None:
            raise UserError("the aquarium needs a tank without policies of its own.")
        self.tank = tank
        self.cascade = cascade
        self.compete = compete
        #: When each fish's last escape began (s; -inf: none), and the escapes each fish has judged.
        self.startled_at = np.full(tank.n_fish, -np.inf)
        self._judged = np.zeros((tank.n_fish, tank.n_fish), dtype=bool)
        self._cascade_rng = np.random.default_rng([tank.seed, 28])
        self.tank.mu_policy, self.tank.push_policy = self._mu, self._push
        self.dt = tank.dt
        self._startle_until = np.full(tank.n_fish, -np.inf)
        self._startle_from = np.zeros((tank.n_fish, 3))
        self.pellets_m = np.zeros((0, 3))
        self.eaten = 0
        #: Which fish ate each pellet eaten, in order.
        self.eaters: list[int] = []

    # ---- the stepper shape ----------------------------------------------------------------------
    @property
    def steps(self) -> int:
        return self.tank.steps

    @property
    def time(self) -> float:
        return self.tank.time

    @property
    def model(self):
        return self.tank.model

    @property
    def data(self):
        return self.tank.data

    def reset(self, seed: int | None = None) -> None:
        self.tank.reset(seed)
        self._startle_until[:] = -np.inf
        self.startled_at[:] = -np.inf
        self._judged[:] = False
        self._cascade_rng = np.random.default_rng([self.tank.seed, 28])
        self.pellets_m = np.zeros((0, 3))
        self.eaten = 0
        self.eaters = []

    def step(self, n: int = 1) -> None:
        for _ in range(checks.whole("the number of steps", n, 0)):
            self.tank.step(1)
            self._food()
            if self.cascade:
                self._spread()

    def state(self) -> dict[str, np.ndarray]:
        return {**self.tank.state(), "startled": self.startled, "pellets_m": self.pellets_m.copy()}

    def sync(self) -> None:
        self.tank.sync()

    def marks(self) -> list:
        """The pellets, for the viewers (:func:`lifelike_mj.render.viewer.mark_geoms`)."""
        return [(p, PELLET_DRAWN_M, PELLET_RGBA) for p in self.pellets_m]

    # ---- what the viewers do ----------------------------------------------------------------------
    @property
    def startled(self) -> np.ndarray:
        """Which fish are startled now."""
        return self._startle_until > self.time

    def tap(self, point_m) -> int:
        """A tap on the glass at ``point_m`` (x, y, z in m, on or near the tank): the fish within
        :data:`TAP_RADIUS_M` startle (module docstring). Returns how many."""
        p = np.asarray(point_m, dtype=float).reshape(-1)
        L, D, H = self.tank.scene.size
        if p.shape != (3,) or not np.all(np.isfinite(p)) or np.any(np.abs(p[:2]) > np.array([L, D]) / 2 + 0.1) \
                or not -0.1 <= p[2] <= H + 0.1:
            raise UserError(f"a tap is a point x, y, z (m) on the tank ({L:g} x {D:g} x {H:g} m, centred on x = y = 0, "
                            f"bottom at z = 0), got {point_m!r}.")
        pos, _ = self.tank.snapshot()
        near = np.linalg.norm(pos - p, axis=1) <= TAP_RADIUS_M
        self._begin(near, p)
        return int(near.sum())

    def startle(self, fish: int) -> None:
        """Startle fish ``fish`` alone (as a looming object only it sees), fleeing straight ahead."""
        i = checks.whole("the fish", fish, 0, self.tank.n_fish - 1)
        pos, quat = self.tank.snapshot()
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, quat[i])
        ahead = R.reshape(3, 3)[:, 0]
        mask = np.zeros(self.tank.n_fish, dtype=bool)
        mask[i] = True
        self._begin(mask, pos[i] - ahead)

    def _begin(self, mask: np.ndarray, away_from) -> None:
        """Startle the fish of ``mask``, fleeing from the point(s) ``away_from`` (m)."""
        self._startle_until[mask] = self.time + STARTLE_S
        self._startle_from[mask] = away_from
        self.startled_at[mask] = self.time
        self._judged[:, mask] = False  # a new escape: its neighbours judge it afresh

    def _spread(self) -> None:
        """The cascade (module docstring): each fish judges, once, each escape it sees that began
        :data:`CASCADE_LATENCY_S` ago or more and is still on."""
        from lifelike_mj.fish.scene import BODY_LENGTH_M

        t = self.time
        seen = self.startled & (t - self.startled_at >= CASCADE_LATENCY_S - 1e-9)
        if not seen.any():
            return
        pos, quat = self.tank.snapshot()
        R = np.empty(9)
        cos_blind = -math.cos(math.radians(self.tank.params.social_blind_deg) / 2.0)
        a, b = CASCADE_LOGIT
        fresh = np.zeros(self.tank.n_fish, dtype=bool)
        origin = np.zeros((self.tank.n_fish, 3))
        for i in np.flatnonzero(~self.startled & (t - self.startled_at >= CASCADE_REFRACTORY_S)):
            mujoco.mju_quat2Mat(R, quat[i])
            ahead = R.reshape(3, 3)[:, 0]
            for j in np.flatnonzero(seen & ~self._judged[i]):
                d = pos[j] - pos[i]
                dist = float(np.linalg.norm(d))
                if dist > CASCADE_RANGE_BL * BODY_LENGTH_M or dist < 1e-9 or float(ahead @ d) / dist < cos_blind:
                    continue
                self._judged[i, j] = True
                p = 1.0 / (1.0 + math.exp(-(a + b * math.log(max(dist / BODY_LENGTH_M, 1e-3)))))
                if self._cascade_rng.random() < p and not fresh[i]:
                    fresh[i] = True
                    # flee the way the neighbour flees: from a point as far behind this fish as its threat is
                    origin[i] = pos[i] + (self._startle_from[j] - pos[j])
        if fresh.any():
            self._begin(fresh, origin[fresh])

    def drop_food(self, x_m: float, y_m: float) -> None:
        """A pellet at ``(x_m, y_m)`` on the surface (module docstring)."""
        L, D, H = self.tank.scene.size
        x = checks.number("the food's x", x_m, -L / 2, L / 2, unit="m")
        y = checks.number("the food's y", y_m, -D / 2, D / 2, unit="m")
        self.pellets_m = np.vstack([self.pellets_m, [x, y, H]])

    # ---- the rules ---------------------------------------------------------------------------------
    def _mu(self, tank: Tank) -> np.ndarray:
        return np.where(self.startled, ACCELERATE, -1)

    def _push(self, tank: Tank) -> np.ndarray:
        p = tank.params
        out = np.full((tank.n_fish, 3), np.nan)
        startled = self.startled
        if not startled.any() and len(self.pellets_m) == 0:
            return out
        pos, quat = tank.snapshot()
        R = np.empty(9)
        going = self._going_for(pos)
        for i in range(tank.n_fish):
            if startled[i]:
                target, r = pos[i] + (pos[i] - self._startle_from[i]), p.r_max_N  # away from the tap
            elif going[i] >= 0:
                k = int(going[i])
                rivals = self.compete and int(np.sum(going == k)) > 1
                target, r = self.pellets_m[k], p.r_max_N if rivals else 0.5 * (p.r_min_N + p.r_max_N)
            else:
                continue
            d = target - pos[i]
            norm = np.linalg.norm(d)
            if norm < 1e-9:
                continue
            mujoco.mju_quat2Mat(R, quat[i])
            theta, phi = _angles(R.reshape(3, 3).T @ (d / norm))
            out[i] = (r, theta, phi)
        return out

    def going_for(self) -> np.ndarray:
        """Per fish, the pellet it goes for (an index into ``pellets_m``: the nearest it notices, within
        :data:`FOOD_SIGHT_M`), or -1: none, or the fish is startled."""
        return self._going_for(self.tank.snapshot()[0])

    def _going_for(self, pos: np.ndarray) -> np.ndarray:
        """:meth:`going_for` for the fish's positions ``pos`` (F, 3) m, already read."""
        out = np.full(self.tank.n_fish, -1)
        if len(self.pellets_m) == 0:
            return out
        dist = np.linalg.norm(pos[:, None, :] - self.pellets_m[None, :, :], axis=-1)
        k = np.argmin(dist, axis=1)
        sees = dist[np.arange(len(pos)), k] <= FOOD_SIGHT_M
        out[sees] = k[sees]
        out[self.startled] = -1
        return out

    def _food(self) -> None:
        if len(self.pellets_m) == 0:
            return
        self.pellets_m[:, 2] = np.maximum(self.pellets_m[:, 2] - FOOD_SINK_M_S * self.dt, 0.0)
        pos, _ = self.tank.snapshot()
        gone = np.zeros(len(self.pellets_m), dtype=bool)
        for k, pellet in enumerate(self.pellets_m):
            dist = np.linalg.norm(pos - pellet, axis=1)
            if np.min(dist) <= EAT_RADIUS_M:
                gone[k] = True
                self.eaters.append(int(np.argmin(dist)))
        self.eaten += int(gone.sum())
        self.pellets_m = self.pellets_m[~gone]


#: The aquarium's keys and what each does (none of them is one of MuJoCo's viewer's own).
KEYS = (("Space", "tap the front glass"), ("Enter", "drop a food pellet"),
        ("Right", "a shadow looms over one fish: it alone startles"))


def controls(aquarium: Aquarium, seed: int = 0) -> list:
    """The aquarium's keys and buttons (:data:`KEYS`; :class:`lifelike_mj.render.viewer.Control`): Space taps the
    front glass (the side the viewers look from, y < 0) level with a fish drawn at random, Enter drops a pellet at
    a random place along the middle of the surface, Right startles one fish drawn at random alone
    (:meth:`Aquarium.startle`; with the cascade on, its neighbours may follow). ``seed`` draws the places and
    fish."""
    from lifelike_mj.render.viewer import Control

    rng = np.random.default_rng(seed)
    L, D, _H = aquarium.tank.scene.size

    def tap() -> None:
        pos, _ = aquarium.tank.snapshot()
        k = int(rng.integers(len(pos)))
        aquarium.tap((pos[k, 0], -D / 2, pos[k, 2]))

    def food() -> None:
        aquarium.drop_food(float(rng.uniform(-0.4 * L, 0.4 * L)), 0.0)

    def loom() -> None:
        aquarium.startle(int(rng.integers(aquarium.tank.n_fish)))

    return [Control(key, label, act) for (key, label), act in zip(KEYS, (tap, food, loom), strict=True)]
