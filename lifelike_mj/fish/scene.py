"""The tank scene for N fish, built with MjSpec from ``models/tank.xml`` and ``models/fish.xml``.

World frame: x along the tank (horizontal in the side view), y depth (towards the side camera),
z up, origin at the centre of the floor. The water fills ``[-L/2, L/2] x [-D/2, D/2] x [0, H]``.
The filmed tank of Satoi et al. 2015 (section 4) was about 5 m wide, 1 m high and 0.5 m deep;
:func:`tank_size` keeps those proportions at any scale (default 0.6: 3.0 x 0.3 x 0.6 m).

Besides the main model, :func:`build_scene` compiles a *vision model*: the same base scene without
the fish. The fish cast their vision rays (section 3.6) into it, so every static geom of the base
scene is seen (walls, floor, the water surface, and any obstacle a user adds to the base spec),
and the cost of a ray does not grow with the number of fish.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.fish.params import MAX_FISH
from lifelike_mj.paths import model_path

#: The filmed tank (section 4): length (x, m), depth (y, m), height (z, m).
FILMED_TANK_M = (5.0, 0.5, 1.0)
DEFAULT_TANK_SCALE = 1.0
WALL_THICKNESS_M = 0.02
#: Snout to tail tip of models/fish.xml (m), the body length of every "per body length" number.
BODY_LENGTH_M = 0.070
#: The sides a tank may have (m): at least 2.5 body lengths, at most twice the longest side of ``--tank-scale``'s
#: largest tank (the command line's ``--tank`` and the Python API take the same).
MIN_TANK_SIDE_M = 2.5 * BODY_LENGTH_M
MAX_TANK_SIDE_M = 100.0
#: MuJoCo's arena per body for the broad phase's sweep (its boxes and sort buffers; bytes), per fish for contacts and
#: their constraint rows (16 contacts of about 2 kB each), and on top of both (:func:`arena_bytes`).
ARENA_BYTES_PER_BODY = 256
ARENA_BYTES_PER_FISH = 32 * 2**10
ARENA_SLACK_BYTES = 16 * 2**20
#: Fish attached per intermediate spec (MjSpec attach costs grow with the size of the target spec).
_GROUP = 32


def tank_size(scale: float = DEFAULT_TANK_SCALE) -> tuple[float, float, float]:
    """Water volume ``(L, D, H)`` in m: the filmed tank times ``scale``."""
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and scale > 0):
        raise UserError(f"tank scale must be a positive number, got {scale!r}.")
    return tuple(float(scale * s) for s in FILMED_TANK_M)  # type: ignore[return-value]


def tank_problem(size, given: object = None) -> tuple[tuple[float, float, float] | None, str]:
    """``(sides, "")`` for a valid water volume ``size`` (length, depth, height; m): three finite numbers, each side
    from :data:`MIN_TANK_SIDE_M` (2.5 body lengths) to :data:`MAX_TANK_SIDE_M`; else ``(None, problem)``, the
    problem a phrase without its subject ("must be ..., got ``given``"; ``given`` defaults to ``size``) for the
    caller to name the argument. A string is not a size, even of digits."""
    shown = size if given is None else given
    if len(repr(shown)) > 60:
        shown = f"{repr(shown)[:57]}..." if isinstance(shown, str) else _Shown(f"a {type(shown).__name__}")
    sides = f"each {MIN_TANK_SIDE_M:.3f} m (2.5 body lengths) to {MAX_TANK_SIDE_M:g} m"
    try:
        vals = None if isinstance(size, (str, bytes)) else checks.vector("size", size, 3, "m")
    except UserError:
        vals = None
    if vals is None or min(vals) <= 0.0:
        return None, f"must be three positive lengths L,D,H in m (length, depth, height), {sides}, got {shown!r}"
    if min(vals) < MIN_TANK_SIDE_M * (1.0 - 1e-9):  # the bound itself is allowed, whatever its rounding
        return None, f"must have every side of the tank at least {MIN_TANK_SIDE_M:.3f} m (2.5 body lengths), got {shown!r}"
    if max(vals) > MAX_TANK_SIDE_M:
        return None, f"must have every side of the tank at most {MAX_TANK_SIDE_M:g} m, got {shown!r}"
    return vals, ""  # type: ignore[return-value]


class _Shown(str):
    """A value's description in an error sentence, written as is (``{!r}`` without quotes)."""

    def __repr__(self) -> str:
        return str(self)


def check_tank(size, name: str = "size") -> tuple[float, float, float]:
    """The water volume ``size`` (length, depth, height; m) as three floats, or a :class:`UserError` naming ``name``
    (:func:`tank_problem`: each side 2.5 body lengths to :data:`MAX_TANK_SIDE_M`, as ``--tank`` takes)."""
    vals, problem = tank_problem(size)
    if vals is None:
        raise UserError(f"{name} {problem}.")
    return vals


def arena_bytes(n_bodies: int, n_fish: int) -> int:
    """The memory (bytes) that MuJoCo's arena (``mjData``'s contacts, constraints and stack; ``<size memory>``) needs
    for a tank of ``n_bodies`` bodies (the world included) holding ``n_fish`` fish: the broad phase holds two lists of
    every pair of bodies (``mj_collision``'s and ``mj_broadphase``'s, 4 bytes a pair each) and its sweep
    buffers (:data:`ARENA_BYTES_PER_BODY`), while the contacts (up to :data:`ARENA_BYTES_PER_FISH` per fish, fish
    that touch included) and :data:`ARENA_SLACK_BYTES` come on top. Measured on MuJoCo 3.3-4.0: 100.5 MB of stack for
    5,000 fish (``mjData.maxuse_stack``)."""
    nb = int(n_bodies)
    return 4 * nb * (nb - 1) + ARENA_BYTES_PER_BODY * nb + ARENA_BYTES_PER_FISH * int(n_fish) + ARENA_SLACK_BYTES


def base_spec(size=None) -> mujoco.MjSpec:
    """The tank of ``models/tank.xml`` with its walls resized to the water volume ``size`` (m)."""
    L, D, H = check_tank(size if size is not None else tank_size())
    t = WALL_THICKNESS_M
    spec = mujoco.MjSpec.from_file(str(model_path("fish", "tank.xml")))
    boxes = {
        "floor": ((L / 2 + 2 * t, D / 2 + 2 * t, t), (0.0, 0.0, -t)),
        "lid": ((L / 2 + 2 * t, D / 2 + 2 * t, t), (0.0, 0.0, H + t)),
        "wall_back": ((L / 2 + 2 * t, t, H / 2), (0.0, D / 2 + t, H / 2)),
        "wall_front": ((L / 2 + 2 * t, t, H / 2), (0.0, -D / 2 - t, H / 2)),
        "wall_left": ((t, D / 2, H / 2), (-L / 2 - t, 0.0, H / 2)),
        "wall_right": ((t, D / 2, H / 2), (L / 2 + t, 0.0, H / 2)),
    }
    for name, (half, pos) in boxes.items():
        g = spec.geom(name)
        g.size = list(half)
        g.pos = list(pos)
    planes = {"glass_floor": (0.0, 0.0, 0.0), "glass_lid": (0.0, 0.0, H), "glass_back": (0.0, D / 2, H / 2),
              "glass_front": (0.0, -D / 2, H / 2), "glass_left": (-L / 2, 0.0, H / 2), "glass_right": (L / 2, 0.0, H / 2)}
    for name, pos in planes.items():
        spec.geom(name).pos = list(pos)
    # side camera: the whole length in a 4:3 frame (vertical field of view 30 deg)
    half_h = math.radians(30.0) / 2
    half_w = math.atan(math.tan(half_h) * 4.0 / 3.0)
    dist = max(0.55 * L / math.tan(half_w), 0.55 * H / math.tan(half_h))
    spec.camera("side").pos = [0.0, -(D / 2 + dist), H / 2]
    spec.camera("oblique").pos = [0.0, -(D / 2 + 0.62 * dist), H / 2 + 0.33 * dist]
    return spec


@dataclass(frozen=True)
class FishScene:
    """A compiled tank with ``n`` fish, and its fish-free vision model."""

    model: mujoco.MjModel
    vision_model: mujoco.MjModel
    size: tuple[float, float, float]
    body: np.ndarray  # (n,) body ids of the fish
    qadr: np.ndarray  # (n,) qpos addresses of their free joints
    dadr: np.ndarray  # (n,) qvel addresses
    mass_kg: float
    inertia: np.ndarray  # (3,) principal moments (kg m^2), body frame = inertia frame
    head_m: float  # distance of the snout (vision origin) ahead of the centre of mass

    @property
    def n(self) -> int:
        return len(self.body)


def build_scene(n_fish: int, size=None, spec: mujoco.MjSpec | None = None, nuserdata: int = 0) -> FishScene:
    """Compile the tank (``spec``, default :func:`base_spec` of ``size``) with ``n_fish`` fish.

    The fish are attached in groups of 32 (MjSpec's attach slows down as the target grows; groups
    keep 1,000 fish under a second). Fish ``i`` is body ``s<i // 32>/f<i>/fish``. ``nuserdata``: size of
    ``mjData.userdata`` (the simulation's per-model parameters)."""
    if not checks.is_whole(n_fish) or not 1 <= n_fish <= MAX_FISH:
        raise UserError(f"the number of fish must be a whole number from 1 to {MAX_FISH:,}, got {n_fish!r}.")
    n_fish = int(n_fish)
    if spec is None:
        spec = base_spec(size)
        size = check_tank(size if size is not None else tank_size())
    else:
        size = check_tank(size if size is not None else tank_size())
    vision_model = spec.copy().compile()
    fish = mujoco.MjSpec.from_file(str(model_path("fish", "fish.xml")))
    src = fish.body("fish")
    spec.copy_during_attach = True
    for start in range(0, n_fish, _GROUP):
        grp = mujoco.MjSpec()
        grp.copy_during_attach = True
        grp.option.timestep = spec.option.timestep
        for i in range(start, min(start + _GROUP, n_fish)):
            grp.worldbody.add_frame().attach_body(src, f"f{i}/", "")
        spec.attach(grp, frame=spec.worldbody.add_frame(), prefix=f"s{start // _GROUP}/")
    spec.nuserdata = int(nuserdata)
    # the arena grows with the square of the bodies (the broad phase's pair lists): the tank's own 64 MB holds a
    # thousand fish; a larger tank gets what it needs, and a smaller keeps the tank's own (the size changes no result)
    spec.memory = max(int(spec.memory), arena_bytes(len(spec.bodies), n_fish))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = spec.compile()
    body = np.array([model.body(fish_name(i)).id for i in range(n_fish)], dtype=np.int64)
    jnt = np.array([model.body_jntadr[b] for b in body], dtype=np.int64)
    if np.any(model.jnt_type[jnt] != mujoco.mjtJoint.mjJNT_FREE):
        raise RuntimeError("every fish must have a free joint")
    if np.any(np.abs(model.body_ipos[body]) > 0) or np.any(np.abs(model.body_iquat[body] - [1, 0, 0, 0]) > 0):
        raise RuntimeError("the fish's body frame must be its inertia frame (models/fish.xml)")
    head = model.site(fish_name(0).replace("/fish", "/head")).pos[0]
    return FishScene(model, vision_model, tuple(size), body, model.jnt_qposadr[jnt].astype(np.int64),
                     model.jnt_dofadr[jnt].astype(np.int64), float(model.body_mass[body[0]]),
                     model.body_inertia[body[0]].copy(), float(head))


def fish_name(i: int) -> str:
    """Body name of fish ``i`` in a scene of :func:`build_scene`."""
    return f"s{i // _GROUP}/f{i}/fish"


def inertia_box(mass_kg: float, inertia) -> np.ndarray:
    """Full side lengths (m) of the equivalent inertia box of a body (MuJoCo's inertia-box fluid
    model): ``b_x = sqrt(6 (I_y + I_z - I_x) / m)`` and cyclically."""
    I = np.asarray(inertia, dtype=float)
    return np.sqrt(6.0 * np.array([I[1] + I[2] - I[0], I[0] + I[2] - I[1], I[0] + I[1] - I[2]]) / mass_kg)


def box_areas(mass_kg: float, inertia) -> tuple[np.ndarray, np.ndarray]:
    """Drag areas of the equivalent inertia box: ``S_v`` (m^2, the face normal to each axis) and
    ``S_w`` (m^5, ``b_i (b_j^4 + b_k^4) / 32``), chosen so that ``1/2 rho C_D S v|v|`` with
    ``C_D = 1`` is MuJoCo's inertia-box quadratic drag (force and torque)."""
    b = inertia_box(mass_kg, inertia)
    sv = np.array([b[1] * b[2], b[2] * b[0], b[0] * b[1]])
    sw = np.array([b[0] * (b[1] ** 4 + b[2] ** 4), b[1] * (b[2] ** 4 + b[0] ** 4), b[2] * (b[0] ** 4 + b[1] ** 4)]) / 32.0
    return sv, sw
