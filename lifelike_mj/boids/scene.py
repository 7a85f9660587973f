"""The boids as MuJoCo mocap bodies (Nakamura 2013): a scene built with MjSpec for ``n`` agents.

The boids engine (:mod:`lifelike_mj.boids.engine`) moves the agents; MuJoCo only draws them. Each
agent is a mocap body carrying one ellipsoid, elongated along its local x axis
(:data:`BODY_SEMI_AXES`, box units), which :func:`update` points along the agent's velocity, and
coloured by type (:mod:`lifelike_mj.boids.palette`: A blue, B orange by default, or the paper's red
and yellow-green; further types get further colours). Nothing collides: every geom has ``contype = conaffinity = 0`` and contacts
are disabled in ``<option>``.

World frame = the engine's frame, in the paper's box units: the box is ``[0, L]^3`` (``L`` =
``box``, 20 in the paper), z up. The box is shown by its twelve edges (thin dark capsules) over a
light floor at ``z = 0``. In 2D (``dims = 2``) the agents move in the plane ``z =``
:data:`PLANE_Z_2D` just above the floor, which is the ``[0, L]^2`` square, outlined by its four edges.

Cameras (by name, :data:`CAMERAS`): ``overview`` (perspective, from above one corner: the whole
box), ``top`` (orthographic, looking down -z, x to the right and y up: the x-y projection of the
figures of :mod:`lifelike_mj.boids.figures`) and, in 3D only, ``side`` (orthographic, looking
along +y, x to the right and z up).

Memory. MuJoCo's collision broadphase asks its arena for about ``2 n^2`` bytes (18 MB for 3,000
bodies) even for geoms that cannot collide, so 3,000 mocap bodies overflow the default arena in
``mj_forward`` when contacts are enabled. Contacts are disabled here (``mj_forward`` then needs about
100 bytes per body), and :func:`scene_memory_bytes` still sizes ``<size memory>`` for the
broadphase up to :data:`_BROADPHASE_MAX_N` agents (so that toggling contacts back on in the viewer
does not fail); :func:`update` itself calls only ``mj_kinematics``.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import mujoco
import numpy as np

from lifelike_mj import checks
from lifelike_mj.boids.palette import type_rgba
from lifelike_mj.errors import UserError

#: Semi-axes (box units) of an agent's ellipsoid: along its velocity, across, and up.
BODY_SEMI_AXES = (0.35, 0.12, 0.12)
#: Height (box units) of the plane of a 2D run above the floor.
PLANE_Z_2D = 0.25
#: The cameras of a 3D scene; a 2D scene has the first two.
CAMERAS = ("overview", "top", "side")
#: Radius (box units) of the capsules that draw the box's edges.
EDGE_RADIUS = 0.08
#: Vertical field of view (deg) of the ``overview`` camera.
OVERVIEW_FOVY_DEG = 40.0
#: Below this speed (box units per step) an agent keeps its previous orientation.
MIN_SPEED = 1e-9
_BASE_MEMORY = 16 * 2**20
_BROADPHASE_MAX_N = 6000


def cameras_for(dims: int) -> tuple[str, ...]:
    """The camera names of a scene in ``dims`` dimensions."""
    return CAMERAS if dims == 3 else CAMERAS[:2]


def scene_memory_bytes(n: int) -> int:
    """``<size memory>`` (bytes) of a scene of ``n`` agents: 16 MiB, plus the broadphase's ``2 n^2``
    bytes up to :data:`_BROADPHASE_MAX_N` agents, else 1 KiB per agent (contacts are disabled, so
    ``mj_forward`` needs about 100 bytes per body)."""
    n = int(n)
    return _BASE_MEMORY + (2 * n * n + 64 * n if n <= _BROADPHASE_MAX_N else 1024 * n)


@dataclass(frozen=True)
class BoidsLayout:
    """Where the agents of a compiled scene live: ``body`` (n,) body ids, ``mocap`` (n,) their
    mocap indices (rows of ``mocap_pos``/``mocap_quat``), ``types`` (n,), ``box`` side and ``dims``
    (3, or 2 with the agents in the plane ``z = plane_z``), ``edges`` the geom ids of the box's edges."""

    body: np.ndarray
    mocap: np.ndarray
    types: np.ndarray
    box: float
    dims: int
    plane_z: float
    edges: np.ndarray

    @property
    def n(self) -> int:
        return len(self.body)

    @property
    def rows(self) -> slice | np.ndarray:
        """The agents' rows of ``mocap_pos``/``mocap_quat``: a slice when they are consecutive."""
        m = self.mocap
        if len(m) and m[0] >= 0 and np.array_equal(m, np.arange(m[0], m[0] + len(m))):
            return slice(int(m[0]), int(m[0]) + len(m))
        return m

    @property
    def centre(self) -> np.ndarray:
        """Centre of the box (world frame, box units); in 2D the centre of the square, on the plane."""
        L = self.box
        return np.array([L / 2, L / 2, L / 2 if self.dims == 3 else self.plane_z])


def _look_quat(pos, target, up=(0.0, 0.0, 1.0)) -> list[float]:
    """Quaternion of a camera at ``pos`` looking at ``target`` (MuJoCo cameras look along their -z,
    with +y up in the image), its image's up direction as close to ``up`` as possible."""
    f = np.asarray(target, dtype=float) - np.asarray(pos, dtype=float)
    f /= np.linalg.norm(f)
    right = np.cross(f, up)
    right /= np.linalg.norm(right)
    cam_up = np.cross(right, f)
    mat = np.column_stack([right, cam_up, -f]).reshape(-1)
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, mat)
    return q.tolist()


def _edges(box: float, dims: int) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    L = box
    if dims == 2:
        c = [(0.0, 0.0), (L, 0.0), (L, L), (0.0, L)]
        return [((*c[i], 0.0), (*c[(i + 1) % 4], 0.0)) for i in range(4)]
    corners = [(x, y, z) for x in (0.0, L) for y in (0.0, L) for z in (0.0, L)]
    out = []
    for i, a in enumerate(corners):
        for b in corners[i + 1:]:
            if sum(p != q for p, q in zip(a, b)) == 1:
                out.append((a, b))
    return out


def build_scene(n: int, types=None, box: float = 20.0, dims: int = 3, semi_axes=BODY_SEMI_AXES,
                type_colors=None) -> tuple[mujoco.MjModel, BoidsLayout]:
    """Compile a scene of ``n`` agents of the given ``types`` (n ints from 0; default all 0) in the box
    ``[0, box]^dims`` (box units; ``dims`` 3 or 2). ``semi_axes``: the ellipsoid's semi-axes (box
    units; along the velocity first). ``type_colors``: RGBA per type (default: :func:`~lifelike_mj.boids.palette.type_rgba`).
    Agent ``i`` is body ``boid<i>``, its geom ``boid<i>``; the cameras are named in :data:`CAMERAS`.
    Returns ``(model, layout)``; the agents start at the box's centre, pointing along +x: call
    :func:`update` before drawing."""
    if not checks.is_whole(n) or n < 1:
        raise UserError(f"the number of agents must be a whole number of at least 1, got {n!r}.")
    n = int(n)
    if dims not in (2, 3):
        raise UserError(f"dims must be 2 or 3, got {dims!r}.")
    if not checks.is_number(box) or not (
            math.isfinite(box) and box > 0):
        raise UserError(f"the box side must be a positive number, got {box!r}.")
    box = float(box)
    t = np.zeros(n, dtype=np.int64) if types is None else np.asarray(types)
    if t.shape != (n,) or not np.issubdtype(t.dtype, np.integer) or (n and t.min() < 0):
        raise UserError(f"types must be {n} whole numbers >= 0 (one per agent), got shape {t.shape}.")
    t = t.astype(np.int64)
    semi = np.asarray(semi_axes, dtype=float)
    if semi.shape != (3,) or not np.all(np.isfinite(semi) & (semi > 0)):
        raise UserError(f"the body's semi-axes must be three positive lengths, got {semi_axes!r}.")
    n_types = int(t.max()) + 1 if n else 1
    colors = [type_rgba(k) for k in range(n_types)] if type_colors is None else [tuple(c) for c in type_colors]
    if len(colors) < n_types or any(len(c) != 4 for c in colors):
        raise UserError(f"type_colors needs an RGBA colour for each of the {n_types} types.")

    L = box
    plane_z = PLANE_Z_2D if dims == 2 else 0.0
    s = mujoco.MjSpec()
    s.modelname = f"boids_{n}"
    s.memory = scene_memory_bytes(n)
    s.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    vis = s.visual
    vis.quality.shadowsize = 0  # no shadows, no multisampling: ~6x faster software rendering
    vis.quality.offsamples = 0
    # an agent is 10-20 pixels long in a 640 x 480 view of the box: a coarse ellipsoid mesh (120
    # triangles instead of MuJoCo's default 28 x 16) looks the same and renders 3x faster in software
    vis.quality.numslices = 10
    vis.quality.numstacks = 6
    vis.global_.offwidth = 640
    vis.global_.offheight = 480
    vis.global_.fovy = OVERVIEW_FOVY_DEG
    vis.headlight.ambient = [0.45, 0.45, 0.45]
    vis.headlight.diffuse = [0.45, 0.45, 0.45]
    vis.headlight.specular = [0.1, 0.1, 0.1]
    s.stat.center = [L / 2, L / 2, L / 2 if dims == 3 else 0.0]
    s.stat.extent = L

    s.add_texture(name="sky", type=mujoco.mjtTexture.mjTEXTURE_SKYBOX, builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
                  rgb1=[1.0, 1.0, 1.0], rgb2=[0.86, 0.89, 0.93], width=64, height=64)
    s.add_texture(name="floor", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                  rgb1=[0.93, 0.93, 0.93], rgb2=[0.88, 0.88, 0.88], width=64, height=64)
    s.add_material(name="floor", textures=["", "floor"], texrepeat=[L / 4, L / 4], reflectance=0.0)
    s.add_material(name="edge", rgba=[0.25, 0.25, 0.28, 1.0], specular=0.1)
    for k, c in enumerate(colors):
        s.add_material(name=f"type{k}", rgba=list(c), specular=0.3, shininess=0.4)

    w = s.worldbody
    w.add_light(name="sun", type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL, pos=[L / 2, L / 2, 3 * L],
                dir=[0.3, 0.2, -1.0], diffuse=[0.55, 0.55, 0.55], specular=[0.2, 0.2, 0.2], castshadow=False)
    none = {"contype": 0, "conaffinity": 0, "group": 0}
    thick = 0.02
    w.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_BOX, size=[L / 2, L / 2, thick], pos=[L / 2, L / 2, -thick - 0.01],
               material="floor", **none)
    for i, (a, b) in enumerate(_edges(L, dims)):
        w.add_geom(name=f"edge{i}", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[*a, *b], size=[EDGE_RADIUS, 0, 0],
                   material="edge", **none)

    c = np.array([L / 2, L / 2, L / 2 if dims == 3 else 0.0])
    # overview: from above the (x = 0, y = 0) side of the box, the whole box in a 4:3 frame
    view_dir = np.array([-0.45, -1.0, 0.75 if dims == 3 else 1.3])
    view_dir /= np.linalg.norm(view_dir)
    radius = L * (math.sqrt(3.0) if dims == 3 else math.sqrt(2.0)) / 2
    dist = (1.0 if dims == 3 else 0.95) * radius / math.sin(math.radians(OVERVIEW_FOVY_DEG) / 2)  # the whole box in view
    pos = c + dist * view_dir
    w.add_camera(name="overview", pos=pos.tolist(), quat=_look_quat(pos, c), fovy=OVERVIEW_FOVY_DEG)
    ortho = mujoco.mjtProjection.mjPROJ_ORTHOGRAPHIC
    top = [L / 2, L / 2, (L if dims == 3 else 0.0) + 2 * L]
    w.add_camera(name="top", pos=top, quat=[1.0, 0.0, 0.0, 0.0], proj=ortho, fovy=1.08 * L)  # x right, y up
    if dims == 3:
        side = [L / 2, -2 * L, L / 2]
        w.add_camera(name="side", pos=side, quat=_look_quat(side, c), proj=ortho, fovy=1.08 * L)  # x right, z up

    z0 = c[2] if dims == 3 else plane_z
    for i in range(n):
        b = w.add_body(name=f"boid{i}", mocap=True, pos=[L / 2, L / 2, z0])
        b.add_geom(name=f"boid{i}", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID, size=semi.tolist(), material=f"type{t[i]}",
                   **none)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = s.compile()
    body = np.arange(1, n + 1, dtype=np.int64)  # the world is body 0, the agents follow in order
    if n and model.body(f"boid{n - 1}").id != n:
        body = np.array([model.body(f"boid{i}").id for i in range(n)], dtype=np.int64)
    mocap = model.body_mocapid[body].astype(np.int64)
    edges = np.array([model.geom(f"edge{i}").id for i in range(len(_edges(L, dims)))], dtype=np.int64)
    return model, BoidsLayout(body, mocap, t, box, dims, plane_z, edges)


def set_edge_radius(model: mujoco.MjModel, layout: BoidsLayout, radius: float) -> None:
    """Draw the box's edges with capsules of ``radius`` (box units) in this compiled model (without
    multisampling, an edge thinner than a pixel breaks up into dashes: widen it for small images)."""
    model.geom_size[layout.edges, 0] = float(radius)


def velocity_quat(velocities: np.ndarray, previous: np.ndarray | None = None) -> np.ndarray:
    """Unit quaternions (n, 4), MuJoCo's (w, x, y, z), turning the body's x axis to the direction of
    each velocity (n, 2 or 3): a yaw ``psi`` about z, then a pitch ``theta`` about the body's y, so the
    body's y axis stays horizontal (no roll). Rows with a speed below :data:`MIN_SPEED` keep
    ``previous`` (default the identity).

    No trigonometry: ``(cos psi/2, sin psi/2)`` is ``(h + v_x, v_y)`` normalised (``h = |(v_x, v_y)|``),
    or ``(v_y, h - v_x)`` normalised when ``v_x < 0`` (no cancellation; the second form may flip the
    quaternion's sign, the same rotation), and ``(cos theta/2, sin theta/2)`` is ``(|v| + h, -v_z)``
    normalised; the quaternion is ``q_z(psi) q_y(theta)``."""
    v = np.asarray(velocities, dtype=float)
    n = v.shape[0]
    vx, vy = v[:, 0], v[:, 1]
    vz = v[:, 2] if v.shape[1] > 2 else np.zeros(n)
    h = np.hypot(vx, vy)
    speed = np.hypot(h, vz)
    back = vx < 0.0
    a = np.where(back, vy, h + vx)
    b = np.where(back, h - vx, vy)
    r = np.hypot(a, b)
    flat = r == 0.0  # h = 0: straight up or down (or at rest), yaw 0
    r[flat] = 1.0
    a[flat] = 1.0
    cz, sz = a / r, b / r
    c = speed + h
    e = -vz
    r = np.hypot(c, e)
    r[r == 0.0] = 1.0
    cy, sy = c / r, e / r
    q = np.empty((n, 4))
    q[:, 0] = cz * cy
    q[:, 1] = -sz * sy
    q[:, 2] = cz * sy
    q[:, 3] = sz * cy
    still = speed < MIN_SPEED
    if still.any():
        q[still] = (1.0, 0.0, 0.0, 0.0) if previous is None else np.asarray(previous, dtype=float)[still]
    return q


def update(model: mujoco.MjModel, data: mujoco.MjData, layout: BoidsLayout, positions: np.ndarray,
           velocities: np.ndarray) -> None:
    """Place the agents: ``positions`` and ``velocities`` (n, D) in box units (D = ``layout.dims``;
    in 2D the bodies sit in the plane ``z = layout.plane_z``). Writes ``mocap_pos`` and ``mocap_quat``
    (x axis along the velocity; an agent at rest keeps its orientation), then runs ``mj_kinematics``
    (body poses for drawing) and ``mj_camlight`` (the cameras' and lights' poses, which a fixed
    camera needs even though they never move)."""
    x = np.asarray(positions, dtype=float)
    v = np.asarray(velocities, dtype=float)
    n, D = layout.n, layout.dims
    if x.shape != (n, D) or v.shape != (n, D):
        raise ValueError(f"positions and velocities must be ({n}, {D}), got {x.shape} and {v.shape}")
    rows = layout.rows
    if D == 3:
        data.mocap_pos[rows] = x
    else:
        pos = data.mocap_pos[rows]
        pos[:, :2] = x
        pos[:, 2] = layout.plane_z
        data.mocap_pos[rows] = pos
    data.mocap_quat[rows] = velocity_quat(v, data.mocap_quat[rows])
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)


__all__ = ["BODY_SEMI_AXES", "CAMERAS", "EDGE_RADIUS", "PLANE_Z_2D", "BoidsLayout", "build_scene",
           "cameras_for", "scene_memory_bytes", "set_edge_radius", "type_rgba", "update", "velocity_quat"]
