"""A garden of 3D butterflies: each butterfly visits the flowers in its own order, all in one scene.

:class:`Garden` is a stepper (the shape of :mod:`lifelike_mj.stepper`): ``n`` butterflies, each simulated on
its own ``mjData`` of the one-butterfly model and flown together by the compiled threaded batch
(:class:`~lifelike_mj.butterfly.flight3d.loop.Batch`). They do not touch or disturb each other (the
air's force law has no wake). Each butterfly visits the garden's flowers in an order drawn by its own seed, with
its own flutter, in one of two ways: it **lands** on each flower (a landing task,
:func:`~lifelike_mj.butterfly.flight3d.tasks.land`: it touches down on the blossom with its legs, perches with its
wings closed for a time drawn between :data:`PERCH_S`, and takes off for the next flower with a clap), or it
**passes** each flower 0.15 m above its blossom (a course of waypoints). ``model``/``data`` are a drawing scene
(ground, flowers, ``n`` butterflies) posed from the simulations by :meth:`Garden.sync`, with a fixed camera
``overview`` and a chase camera from :func:`chase_camera`.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d import tasks as t3
from lifelike_mj.butterfly.flight3d.controllers import Controller3D
from lifelike_mj.butterfly.flight3d.designed_kernel import CompiledDesigned, load_compiled
from lifelike_mj.butterfly.flight3d.flight import DT_S
from lifelike_mj.butterfly.flight3d.flowers import add_flowers, check_room, landing_surface, place_flowers
from lifelike_mj.butterfly.flight3d.kinematics import Kinematics
from lifelike_mj.butterfly.flight3d.landing import on_blossom
from lifelike_mj.butterfly.flight3d.loop import Batch, attitude, take_off_kinematics
from lifelike_mj.butterfly.flight3d.tasks import R_DIVERGED, R_PASSED, Task3D, new_record
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.stepper import StepCounter

#: The ground lies this far below the flight altitude 0 (m).
GROUND_M = -1.0
#: How long a butterfly stays perched on a flower (s): drawn uniformly between these, by its own seed.
PERCH_S = (2.0, 4.0)
#: A butterfly that has not touched down this long (s) after aiming at a flower gives it up for the next (a missed
#: visit, counted in :meth:`Garden.visits`).
GIVE_UP_S = 20.0
#: The landings are checked (a perch's end, a give-up) every this many seconds of flight.
CHECK_S = 0.05
_WING_COLOURS = ((0.98, 0.85, 0.25, 0.95), (0.95, 0.55, 0.15, 0.95), (0.35, 0.55, 0.95, 0.95), (0.95, 0.95, 0.9, 0.95))
#: Waypoints on each butterfly's course (the flowers visited, in its order, over and over).
COURSE_LENGTH = 40
#: Names of :meth:`Garden.state` and their units (one row per butterfly).
STATE_UNITS = {
    "position_m": "m: each thorax's origin, x and y in the garden's plane, z up",
    "attitude_rad": "rad: each body's roll (right wing down > 0), pitch (nose up > 0), yaw (left > 0)",
    "waypoints_passed": "flowers passed on each butterfly's course, in order (landing: flowers landed on)",
    "perched": "whether each butterfly sits on a flower now",
}


#: The garden's flower placement (:func:`~lifelike_mj.butterfly.flight3d.flowers.place_flowers`).
flowers = place_flowers


def visiting_order(n_flowers: int, seed: int, length: int = COURSE_LENGTH) -> list[int]:
    """``length`` flower indices: the ``n_flowers`` flowers in random orders drawn by ``seed``, one round after
    another, never the same flower twice in a row."""
    rng = np.random.default_rng([seed, 2])
    order: list[int] = []
    while len(order) < length:
        perm = [int(k) for k in rng.permutation(n_flowers)]
        if order and perm[0] == order[-1]:
            perm.append(perm.pop(0))
        order += perm
    return order[:length]


def course_among(blossoms: np.ndarray, seed: int, length: int = COURSE_LENGTH) -> np.ndarray:
    """A course of ``length`` waypoints visiting the blossoms in :func:`visiting_order`, each waypoint 0.15 m above
    its blossom."""
    return blossoms[visiting_order(len(blossoms), seed, length)] + np.array([0.0, 0.0, 0.15])


def scene_model(n: int, blossoms: np.ndarray, size_m: float = 8.0, animal: str = "swallowtail",
                legs: bool = False) -> mujoco.MjModel:
    """The drawing scene: the ground, the flowers (:func:`~lifelike_mj.butterfly.flight3d.flowers.add_flowers`) and
    ``n`` butterflies of ``animal`` (bodies ``b{i}_butterfly``; with ``legs``, the legs they stand on), a fixed camera
    ``overview``."""
    spec = mujoco.MjSpec.from_file(str(mj3d.model_path()))
    spec.delete(spec.body("butterfly"))
    ground = spec.geom("ground")
    ground.pos = [0.0, 0.0, GROUND_M]
    ground.size = [3.0 * size_m, 3.0 * size_m, 1.0]
    spec.visual.global_.offwidth = 1920
    spec.visual.global_.offheight = 1080
    spec.visual.map.znear = 0.001
    spec.visual.map.zfar = 200.0
    add_flowers(spec, blossoms, GROUND_M)
    for i in range(n):
        one = mj3d.build_spec(animal=animal)
        if legs:
            mj3d.add_legs(one)
        if animal == "swallowtail":
            one.material("wing").rgba = _WING_COLOURS[i % len(_WING_COLOURS)]
        one.visual.map.znear = spec.visual.map.znear  # the scene's (no attach conflict)
        one.nuserdata = spec.nuserdata
        spec.worldbody.add_frame().attach_body(one.body("butterfly"), f"b{i}_", "")
    d = 0.6 * size_m
    cam = spec.worldbody.add_camera(name="overview", pos=[-d, -d, 0.55 * d])
    cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
    cam.alt.xyaxes = [0.7071, -0.7071, 0.0, 0.257, 0.257, 0.932]  # looking at the middle from a corner, above
    from lifelike_mj.butterfly.render import dress

    return dress(spec.compile())


class Garden(StepCounter):
    """``n`` 3D butterflies in a garden of ``n_flowers`` flowers drawn by ``seed`` (module docstring).

    ``controller``: a 3D controller of either kind (a name, default the shipped ``designed``; a path; a
    :class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D` or a
    :class:`~lifelike_mj.butterfly.flight3d.designed_kernel.CompiledDesigned`);
    ``flutter``, ``gust_m_s``, ``gust_vertical_m_s``, ``wind_to_m_s`` (or ``wind_from_m_s``; ``wind_m_s``, the
    older spelling of ``wind_to_m_s``): each butterfly's flutter and the weather
    (:class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`); ``speed_m_s``: the cruise speed; ``dt_s`` the time step.
    ``land``: the butterflies land on the flowers (module docstring); default: a controller that lands (:func:`lands`:
    a designed controller with a landing, one with a ``land`` network, or evolved on the ``garden`` task set) lands,
    the others pass the flowers by (``land=True`` with a designed controller without a landing is refused).
    """

    @checks.known_keywords
    def __init__(self, n: int = 20, controller="designed", *, seed: int = 0, n_flowers: int = 10, size_m: float = 6.0,
                 speed_m_s: float = 1.5, flutter: float = 0.1, gust_m_s: float = 0.0, wind_to_m_s=None,
                 gust_vertical_m_s: float | None = None, dt_s: float = DT_S, n_strips: int = 8, n_chord: int = 2,
                 force_law: str | None = None, wind_from_m_s=None, wind_m_s=None, land: bool | None = None) -> None:
        self.n = checks.whole("the number of butterflies", n, 1, 500)
        self.controller = (controller if isinstance(controller, (Controller3D, CompiledDesigned))
                           else load_compiled(controller))
        #: Whether a designed controller flies the garden (else a network).
        self.designed = isinstance(self.controller, CompiledDesigned)
        self.seed = checks.whole("seed", seed, 0, 2**32 - 1)
        self.size_m = checks.number("garden size", size_m, 2.0, 100.0, unit="m")
        n_flowers = checks.whole("n_flowers", n_flowers, 2, 200)
        check_room(n_flowers, self.size_m, "n_flowers", "size_m")
        self.blossoms = flowers(self.seed, n_flowers, self.size_m)
        self.dt = checks.positive("time step dt_s", dt_s, "s")
        #: Whether the butterflies land on the flowers (else they pass them by).
        self.land = lands(self.controller) if land is None else checks.flag("land", land)
        if self.land and self.designed and not lands(self.controller):
            raise UserError("this designed controller has no landing (designed with --no-landing): its garden passes "
                            "the flowers by (land=False); design3d without --no-landing makes one that lands.")
        wind = checks.one_wind("Garden", wind_to_m_s, wind_from_m_s, wind_m_s, "to") or (0.0, 0.0, 0.0)
        self._speed = speed_m_s = checks.positive("speed_m_s", speed_m_s, "m/s")
        weather = {"wind_to_m_s": wind, "gust_m_s": gust_m_s, "gust_vertical_m_s": gust_vertical_m_s,
                   "flutter": flutter}
        self._orders = [visiting_order(len(self.blossoms), self.seed * 1000 + i) for i in range(self.n)]
        if self.land:
            self._standing = mj3d.standing_height_m(self.controller.animal)
            self.tasks = [t3.land(landing_surface(self.blossoms[o[0]]), self._standing, speed_m_s=speed_m_s,
                                  name=f"butterfly {i}").with_weather(**weather, seed=(self.seed * 1000 + i) % 2**32)
                          for i, o in enumerate(self._orders)]
        else:
            self.tasks = [Task3D("waypoints", tuple(tuple(float(v) for v in p)
                                                       for p in course_among(self.blossoms, self.seed * 1000 + i)),
                                 speed_m_s=speed_m_s, name=f"butterfly {i}", **weather,
                                 seed=(self.seed * 1000 + i) % 2**32) for i in range(self.n)]
        self._phys = (mj3d.build_model(animal=self.controller.animal, flowers=self.blossoms, ground_m=GROUND_M)
                      if self.land else mj3d.build_model(animal=self.controller.animal))
        self._phys.opt.timestep = self.dt
        self._n_strips, self._n_chord = n_strips, n_chord
        self._force_law = force_law or self.controller.force_law
        self._model = scene_model(self.n, self.blossoms, self.size_m, self.controller.animal, legs=self.land)
        self._data = mujoco.MjData(self._model)
        self._blocks = [int(self._model.jnt_qposadr[self._model.joint(f"b{i}_root").id]) for i in range(self.n)]
        self._rows = 2 if self.land else COURSE_LENGTH
        self._task_arr = np.array([t.as_array(self._rows) for t in self.tasks])
        #: Set to a list to collect the butterflies' positions (``(n, 3)``, m) at every :meth:`sync`.
        self.track: list[np.ndarray] | None = None
        self.reset()

    @property
    def model(self) -> mujoco.MjModel:
        return self._model

    @property
    def data(self) -> mujoco.MjData:
        return self._data

    def reset(self, seed: int | None = None) -> None:
        """Back to the start: each butterfly at rest at its own start point (drawn by the garden's seed: at the
        garden's edge, facing its first flower). ``seed``: accepted for the common shape; the garden's seed
        is fixed at construction."""
        self._k = 0
        rng = np.random.default_rng([self.seed, 3])
        ctl = self.controller
        # a designed controller starts from its trim at the cruise speed, its kinematics following in one beat
        command, omega_c = (ctl.start_command(self._speed), None) if self.designed else (ctl.base, ctl.omega_c_rad_s)
        self._datas = []
        for task in self.tasks:
            d = mj3d.setup_data(self._phys, Kinematics(command, omega_c), force_law=self._force_law,
                                n_strips=self._n_strips, n_chord=self._n_chord, animal=ctl.animal)
            a = rng.uniform(0, 2 * math.pi)
            start = np.array([0.6 * self.size_m * math.cos(a), 0.6 * self.size_m * math.sin(a), rng.uniform(-0.2, 0.2)])
            first = np.array(task.rows[0])
            yaw = math.atan2(first[1] - start[1], first[0] - start[0])
            d.qpos[0:3] = start
            d.qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
            self._datas.append(d)
        self._batch = Batch(self._phys, self._datas, self._task_arr.copy(),  # a landing changes the task arrays
                            None if self.designed else ctl, dt_s=self.dt, records=new_record(self.n, self._rows),
                            base=command.as_array() if self.designed else None, designed=ctl if self.designed else None)
        self._recs = self._batch.records
        # each butterfly's visits: (flower, touchdown time s, touchdown speed m/s, take-off time s or None), and
        # where it is in its order, since when it aims at its flower, how long it perches there
        self._visits: list[list[dict]] = [[] for _ in range(self.n)]
        self._at = [0] * self.n
        self._aim_since = [0.0] * self.n
        perch_rng = [np.random.default_rng([self.seed, 4, i]) for i in range(self.n)]
        self._perch_s = [[float(r.uniform(*PERCH_S)) for _ in range(COURSE_LENGTH)] for r in perch_rng]

    def step(self, n: int = 1) -> None:
        """Advance every butterfly ``n`` steps (threads over the butterflies); a landing garden looks after its
        perches and take-offs every :data:`CHECK_S` s."""
        n = checks.whole("the number of steps", n, 0)
        chunk = max(1, int(round(CHECK_S / self.dt))) if self.land else max(n, 1)
        while n > 0:
            k = min(n, chunk)
            self._batch.advance(k)
            self._k += k
            n -= k
            bad = self._batch.diverged()
            if len(bad):
                i = int(bad[0])
                step = int(self._recs[i, R_DIVERGED])
                raise Diverged(f"butterfly {i} of the garden diverged at step {step}: its speed ran away or MuJoCo found "
                               f"its state unstable; the likely cause is the time step ({self.dt:g} s) or the wind.",
                               step)
            if self.land:
                self._visit()

    def _visit(self) -> None:
        """The landing garden's bookkeeping after a chunk of steps: a touchdown is logged; a perch that has lasted its
        time ends in a take-off for the next flower; a flower not reached within :data:`GIVE_UP_S` is given up."""
        tasks, t = self._batch.tasks, self.time
        for i in range(self.n):
            rec, visits = self._recs[i], self._visits[i]
            perched = int(tasks[i, t3.T_KIND]) == t3.TASK_PERCH
            if perched and (not visits or visits[-1]["take_off_s"] is not None or visits[-1]["touchdown_s"] is None):
                visits.append(self._new_visit(i, float(rec[t3.R_LANDED_AT]), float(rec[t3.R_TOUCH_SPEED])))
            ends = perched and t >= visits[-1]["touchdown_s"] + self._perch_s[i][self._at[i] % COURSE_LENGTH]
            gives_up = not perched and t - self._aim_since[i] > GIVE_UP_S
            if not (ends or gives_up):
                continue
            if gives_up:
                visits.append(self._new_visit(i))
            else:
                visits[-1]["take_off_s"] = t
                visits[-1]["stayed"] = on_blossom(self._datas[i].qpos[0:3], self.blossoms[visits[-1]["flower"]])
                t3.start_take_off(rec, t)
                take_off_kinematics(self._datas[i].userdata, self._batch.base)
            self._at[i] += 1
            self._aim_since[i] = t
            surface = landing_surface(self.blossoms[self._orders[i][self._at[i] % COURSE_LENGTH]])
            tasks[i, t3.T_ROW0 : t3.T_ROW0 + 3] = surface
            tasks[i, t3.T_KIND] = t3.TASK_LAND
            rec[t3.R_LANDED_AT] = -1.0
            rec[t3.R_WP] = np.inf

    def _new_visit(self, i: int, touchdown_s: float | None = None, speed_m_s: float | None = None) -> dict:
        """A visit of butterfly ``i`` to the flower it aims at (:meth:`visits`' keys), not yet taken off from."""
        return {"flower": self._orders[i][self._at[i] % COURSE_LENGTH], "touchdown_s": touchdown_s,
                "touchdown_speed_m_s": speed_m_s, "take_off_s": None, "stayed": None}

    def visits(self) -> list[list[dict]]:
        """Each butterfly's visits so far, in order (a landing garden): ``flower`` (index into :attr:`blossoms`),
        ``touchdown_s`` and ``touchdown_speed_m_s`` (``None``: given up after :data:`GIVE_UP_S`), ``take_off_s``
        (``None``: still perched), ``stayed`` (whether it was still on the blossom when it took off:
        :func:`~lifelike_mj.butterfly.flight3d.landing.on_blossom`; ``None`` before)."""
        return [[dict(v) for v in vs] for vs in self._visits]

    def sync(self) -> None:
        """Pose the drawing scene at the butterflies' current states (and add them to :attr:`track`)."""
        for q0, d in zip(self._blocks, self._datas):
            self._data.qpos[q0 : q0 + d.qpos.size] = d.qpos
        if self.track is not None:
            self.track.append(np.array([d.qpos[0:3] for d in self._datas]))
        mujoco.mj_kinematics(self._model, self._data)
        mujoco.mj_comPos(self._model, self._data)
        mujoco.mj_camlight(self._model, self._data)  # the cameras and lights follow the bodies

    def state(self) -> dict[str, np.ndarray]:
        """``position_m`` ``(n, 3)``, ``attitude_rad`` ``(n, 3)`` (roll, pitch, yaw), ``waypoints_passed`` ``(n,)``
        (flowers passed, or landed on), ``perched`` ``(n,)`` (:data:`STATE_UNITS`)."""
        pos = np.array([d.qpos[0:3] for d in self._datas])
        att = np.array([attitude(d.qpos[3:7]) for d in self._datas])
        if self.land:
            passed = np.array([sum(v["touchdown_s"] is not None for v in vs) for vs in self._visits], dtype=float)
        else:
            passed = self._recs[:, R_PASSED].copy()
        return {"position_m": pos, "attitude_rad": att, "waypoints_passed": passed,
                "perched": self._batch.tasks[:, t3.T_KIND] == t3.TASK_PERCH}


def lands(controller) -> bool:
    """Whether ``controller`` lands: a designed controller with a landing (its manoeuvres:
    :mod:`~lifelike_mj.butterfly.flight3d.perching`), a network with a ``land`` behaviour network, or evolved on the
    ``garden`` task set (or started from one that was)."""
    if isinstance(controller, CompiledDesigned):
        return len(controller.landing[0]) > 0
    if not isinstance(controller, Controller3D):
        return False
    if "land" in controller.modes:
        return True
    prov = controller.provenance or {}
    while isinstance(prov, dict) and prov:
        if prov.get("task_set", (prov.get("parameters") or {}).get("task_set")) == "garden":
            return True
        prov = prov.get("started_from") or {}
    return False


def chase_camera(garden: Garden, butterfly: int = 0):
    """A camera that follows butterfly ``butterfly`` from behind and above."""
    from lifelike_mj.render import camera

    if not 0 <= butterfly < garden.n:
        raise UserError(f"the garden has butterflies 0 to {garden.n - 1}, not {butterfly}.")
    return camera.tracking(int(garden.model.body(f"b{butterfly}_butterfly").id), 0.6, 150.0, -20.0)


def film_garden(out_path, garden: Garden, duration_s: float = 10.0, fps: float = 30, width: int = 960,
                height: int = 540, camera_name: str = "overview", progress: bool = False) -> dict:
    """Film ``garden`` from its current state on for ``duration_s`` (s of flight, at real speed) into an
    ``.mp4`` or ``.gif``, from the fixed ``overview`` camera or ``chase`` (behind butterfly 0). Written
    atomically; returns :func:`~lifelike_mj.render.video.video_report`'s keys."""
    from lifelike_mj.render import camera
    from lifelike_mj.render.offscreen import Offscreen
    from lifelike_mj.render.video import film, video_target

    video_target(out_path, width, height)
    duration_s = checks.positive("duration", duration_s, "s")
    fps = checks.positive("fps", fps)
    if camera_name not in ("overview", "chase"):
        raise UserError(f"unknown garden camera {camera_name!r}; choose overview or chase.")
    n_frames = max(1, int(round(duration_s * fps)))
    k0 = garden.steps
    frames = [k0 + int(round(j / fps / garden.dt)) for j in range(n_frames)]
    garden.sync()
    cam = chase_camera(garden, 0) if camera_name == "chase" else camera.fixed(garden.model, "overview")
    with Offscreen(garden.model, width, height) as renderer:
        return film(out_path, garden, frames, renderer, cam, fps, camera_name, progress, "render garden")
