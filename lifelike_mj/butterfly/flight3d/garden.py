"""A garden of 3D butterflies: flowers as waypoints, each butterfly on its own course, all in one scene.

:class:`Garden` is a stepper (the shape of :mod:`lifelike_mj.stepper`): ``n`` butterflies, each simulated on
its own ``mjData`` of the one-butterfly model and flown together by the compiled threaded batch
(:class:`~lifelike_mj.butterfly.flight3d.loop.Batch`). They do not touch or disturb each other (the
air's force law has no wake). Each butterfly's course visits the garden's flowers in an order drawn by
its own seed, with its own flutter; ``model``/``data`` are a drawing scene (ground, flowers, ``n``
butterflies) posed from the simulations by :meth:`Garden.sync`, with a fixed camera ``overview`` and
a chase camera from :func:`chase_camera`.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.butterfly.flight3d import model as mj3d
from lifelike_mj.butterfly.flight3d.controllers import Controller3D, load_controller
from lifelike_mj.butterfly.flight3d.flight import DT_S
from lifelike_mj.butterfly.flight3d.kinematics import Kinematics
from lifelike_mj.butterfly.flight3d.loop import Batch, attitude
from lifelike_mj.butterfly.flight3d.tasks import R_DIVERGED, R_PASSED, Task3D, new_record
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.stepper import StepCounter

#: The ground lies this far below the flight altitude 0 (m).
GROUND_M = -1.0
#: Flower colours (RGBA).
_PETALS = ((0.92, 0.3, 0.55, 1), (0.98, 0.85, 0.2, 1), (0.55, 0.35, 0.85, 1), (0.98, 0.55, 0.2, 1), (1, 1, 1, 1))
_WING_COLOURS = ((0.98, 0.85, 0.25, 0.95), (0.95, 0.55, 0.15, 0.95), (0.35, 0.55, 0.95, 0.95), (0.95, 0.95, 0.9, 0.95))
#: Waypoints on each butterfly's course (the flowers visited, in its order, over and over).
COURSE_LENGTH = 40
#: Names of :meth:`Garden.state` and their units (one row per butterfly).
STATE_UNITS = {
    "position_m": "m: each thorax's origin, x and y in the garden's plane, z up",
    "attitude_rad": "rad: each body's roll (right wing down > 0), pitch (nose up > 0), yaw (left > 0)",
    "waypoints_passed": "flowers passed on each butterfly's course, in order",
}


def flowers(seed: int, n: int = 12, size_m: float = 8.0, heights_m: float = 0.5) -> np.ndarray:
    """``(n, 3)``: the blossoms (m) of a garden drawn by ``seed``: spread over a ``size_m`` square at least
    1.2 m apart, at altitudes within ``+-heights_m / 2`` of the flight altitude 0."""
    rng = np.random.default_rng([seed, 1])
    pts: list[np.ndarray] = []
    while len(pts) < n:
        p = np.array([*rng.uniform(-size_m / 2, size_m / 2, 2), rng.uniform(-heights_m / 2, heights_m / 2)])
        if all(np.linalg.norm(p[:2] - q[:2]) >= 1.2 for q in pts):
            pts.append(p)
    return np.array(pts)


def course_among(blossoms: np.ndarray, seed: int, length: int = COURSE_LENGTH) -> np.ndarray:
    """A course of ``length`` waypoints visiting the blossoms in random orders drawn by ``seed``, never the
    same flower twice in a row, each waypoint 0.15 m above its blossom."""
    rng = np.random.default_rng([seed, 2])
    order: list[int] = []
    while len(order) < length:
        perm = list(rng.permutation(len(blossoms)))
        if order and perm[0] == order[-1]:
            perm.append(perm.pop(0))
        order += perm
    return blossoms[order[:length]] + np.array([0.0, 0.0, 0.15])


def scene_model(n: int, blossoms: np.ndarray, size_m: float = 8.0, animal: str = "swallowtail") -> mujoco.MjModel:
    """The drawing scene: the ground, the flowers (a stem and a blossom each) and ``n`` butterflies of ``animal``
    (bodies ``b{i}_butterfly``), a fixed camera ``overview``."""
    spec = mujoco.MjSpec.from_file(str(mj3d.model_path()))
    spec.delete(spec.body("butterfly"))
    ground = spec.geom("ground")
    ground.pos = [0.0, 0.0, GROUND_M]
    ground.size = [3.0 * size_m, 3.0 * size_m, 1.0]
    spec.visual.global_.offwidth = 1920
    spec.visual.global_.offheight = 1080
    spec.visual.map.znear = 0.001
    spec.visual.map.zfar = 200.0
    stem = (0.25, 0.55, 0.2, 1.0)
    for k, b in enumerate(blossoms):
        spec.worldbody.add_geom(name=f"stem_{k}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, size=[0.006, 0, 0],
                                fromto=[b[0], b[1], GROUND_M, b[0], b[1], b[2] - 0.01], rgba=stem,
                                contype=0, conaffinity=0)
        spec.worldbody.add_geom(name=f"blossom_{k}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=[0.05, 0.05, 0.015],
                                pos=list(b), rgba=_PETALS[k % len(_PETALS)], contype=0, conaffinity=0)
        spec.worldbody.add_geom(name=f"heart_{k}", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.015, 0, 0],
                                pos=[b[0], b[1], b[2] + 0.01], rgba=(0.95, 0.8, 0.1, 1), contype=0, conaffinity=0)
    for i in range(n):
        one = mj3d.build_spec(animal=animal)
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

    ``controller``: a 3D controller (name, path or :class:`~lifelike_mj.butterfly.flight3d.controllers.Controller3D`);
    ``flutter``, ``gust_m_s``, ``gust_vertical_m_s``, ``wind_to_m_s`` (or ``wind_from_m_s``; ``wind_m_s``, the
    older spelling of ``wind_to_m_s``): each butterfly's flutter and the weather
    (:class:`~lifelike_mj.butterfly.flight3d.tasks.Task3D`); ``speed_m_s``: the cruise speed; ``dt_s`` the time step.
    """

    @checks.known_keywords
    def __init__(self, n: int = 20, controller="steer", *, seed: int = 0, n_flowers: int = 10, size_m: float = 6.0,
                 speed_m_s: float = 1.5, flutter: float = 0.1, gust_m_s: float = 0.0, wind_to_m_s=None,
                 gust_vertical_m_s: float | None = None, dt_s: float = DT_S, n_strips: int = 8, n_chord: int = 2,
                 force_law: str | None = None, wind_from_m_s=None, wind_m_s=None) -> None:
        self.n = checks.whole("the number of butterflies", n, 1, 500)
        self.controller = controller if isinstance(controller, Controller3D) else load_controller(controller)
        self.seed = checks.whole("seed", seed, 0, 2**32 - 1)
        self.size_m = checks.number("garden size", size_m, 2.0, 100.0, unit="m")
        self.blossoms = flowers(self.seed, checks.whole("the number of flowers", n_flowers, 2, 200), self.size_m)
        self.dt = checks.positive("time step dt_s", dt_s, "s")
        wind = checks.one_wind("Garden", wind_to_m_s, wind_from_m_s, wind_m_s, "to") or (0.0, 0.0, 0.0)
        self.tasks = [Task3D("waypoints", tuple(tuple(float(v) for v in p)
                                                   for p in course_among(self.blossoms, self.seed * 1000 + i)),
                                speed_m_s=checks.positive("speed_m_s", speed_m_s, "m/s"), name=f"butterfly {i}",
                                wind_to_m_s=wind, gust_m_s=gust_m_s, gust_vertical_m_s=gust_vertical_m_s,
                                flutter=flutter,
                                seed=(self.seed * 1000 + i) % 2**32) for i in range(self.n)]
        self._phys = mj3d.build_model(animal=self.controller.animal)
        self._phys.opt.timestep = self.dt
        self._n_strips, self._n_chord = n_strips, n_chord
        self._force_law = force_law or self.controller.force_law
        self._model = scene_model(self.n, self.blossoms, self.size_m, self.controller.animal)
        self._data = mujoco.MjData(self._model)
        self._blocks = [int(self._model.jnt_qposadr[self._model.joint(f"b{i}_root").id]) for i in range(self.n)]
        self._task_arr = np.array([t.as_array(COURSE_LENGTH) for t in self.tasks])
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
        self._datas = []
        for task in self.tasks:
            d = mj3d.setup_data(self._phys, Kinematics(ctl.base, ctl.omega_c_rad_s), force_law=self._force_law,
                                n_strips=self._n_strips, n_chord=self._n_chord, animal=ctl.animal)
            a = rng.uniform(0, 2 * math.pi)
            start = np.array([0.6 * self.size_m * math.cos(a), 0.6 * self.size_m * math.sin(a), rng.uniform(-0.2, 0.2)])
            first = np.array(task.rows[0])
            yaw = math.atan2(first[1] - start[1], first[0] - start[0])
            d.qpos[0:3] = start
            d.qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
            self._datas.append(d)
        self._batch = Batch(self._phys, self._datas, self._task_arr, ctl, dt_s=self.dt,
                            records=new_record(self.n, COURSE_LENGTH))
        self._recs = self._batch.records

    def step(self, n: int = 1) -> None:
        """Advance every butterfly ``n`` steps (threads over the butterflies)."""
        n = checks.whole("the number of steps", n, 0)
        if n == 0:
            return
        self._batch.advance(n)
        self._k += n
        bad = self._batch.diverged()
        if len(bad):
            i = int(bad[0])
            step = int(self._recs[i, R_DIVERGED])
            raise Diverged(f"butterfly {i} of the garden diverged at step {step}: its speed ran away or MuJoCo found "
                           f"its state unstable; the likely cause is the time step ({self.dt:g} s) or the wind.", step)

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
        (:data:`STATE_UNITS`)."""
        pos = np.array([d.qpos[0:3] for d in self._datas])
        att = np.array([attitude(d.qpos[3:7]) for d in self._datas])
        return {"position_m": pos, "attitude_rad": att, "waypoints_passed": self._recs[:, R_PASSED].copy()}


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
