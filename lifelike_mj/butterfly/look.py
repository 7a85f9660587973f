"""How a butterfly looks when its motion leaves the project: a rig (:mod:`lifelike_mj.export.rig`) per
butterfly of a run, its bones the model's bodies (thorax ``butterfly``, ``abdomen``, ``wing_left``,
``wing_right``, named as in the MJCF) and two antennae, with a textured mesh made here.

* **Wings.** Fore and hind wing surfaces laid over the model's own wing planform, read from the wing geom's
  mesh (today the triangle of Oe 2010, eq. 3: root, and the two ends of the tip chord): each wing is drawn in
  the planform's fan coordinates (the fraction of the span ``r`` and the place across the fan ``s``, -1 at the
  trailing corner, +1 at the leading one), so a new planform carries the outline with it. The forewing fills
  the leading part of the fan to its full span, the hindwing the trailing part to 0.8 of it, with a scalloped
  margin and a swallowtail's tail. Both faces show (a double-sided material); the texture is in the same fan
  coordinates, so veins run radially: one of :data:`PATTERNS`.
  A wing drawn in the model as measured surfaces (the 3D monarch's fore and hind wing: several drawn mesh geoms
  on the wing body) is exported as exactly those outlines (:func:`outline_surfaces`), textured in the wing's own
  plane with a pattern drawn from the outline itself (:func:`outline_texture`): a black margin with white spots,
  black veins from the hinge and along the fore wing's inner margin, the ground colour between.
* **Body.** Thorax, a six-ringed abdomen, head, eyes and clubbed antennae, sized from the model's thorax,
  head and abdomen geoms (capsules or ellipsoids).
* **Antennae** follow the head with a damped lag: each antenna bone turns by a damped oscillator's response
  (:data:`ANTENNA_HZ`, :data:`ANTENNA_ZETA`) to the thorax's acceleration felt in its own frame,
  :data:`ANTENNA_DEG_PER_G` per g. These three numbers are a look, not a measurement (none is published).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.meshes import Piece, assemble, loft, rigid, sheet, sphere, tube
from lifelike_mj.export.rig import (
    Bone,
    Look,
    Rig,
    body_bone,
    creatures,
    damped,
    extra_bone,
    qaxis,
    qconj,
    qmul,
    qrot,
)

#: Wing patterns, each (base, vein and margin, spot, second spot) RGB colours: a swallowtail's pale yellow and
#: black with a blue and orange eyespot, a monarch's orange, a morpho's blue, a cabbage white's.
PATTERNS = {
    "swallowtail": ((250, 226, 120), (25, 22, 20), (70, 110, 200), (235, 110, 40)),
    "monarch": ((235, 120, 20), (20, 18, 16), (250, 250, 245), (250, 250, 245)),
    "morpho": ((40, 110, 230), (15, 20, 40), (245, 245, 240), (245, 245, 240)),
    "white": ((246, 246, 238), (70, 70, 70), (40, 40, 40), (40, 40, 40)),
}
#: The antennae's lag: natural frequency (Hz), damping ratio and deflection per g of felt acceleration (deg).
ANTENNA_HZ, ANTENNA_ZETA, ANTENNA_DEG_PER_G = 8.0, 0.5, 3.0
TEXTURE_PX = 256
_G = 9.81


def forewing_reach(s: np.ndarray) -> np.ndarray:
    """The forewing's outline: the fraction of the span it reaches at fan place ``s`` (-0.05 to 1)."""
    s = np.asarray(s, dtype=float)
    apex = 1.0 - 0.35 * np.clip((s - 0.85) / 0.15, 0, 1) ** 2  # the rounded apex at the leading corner
    inner = 0.78 + 0.22 * np.sin(np.clip((s + 0.05) / 0.55, 0, 1) * np.pi / 2)  # the margin falling back
    return np.minimum(apex, inner)


def hindwing_reach(s: np.ndarray) -> np.ndarray:
    """The hindwing's outline (fan place ``s`` -1 to 0.05): 0.8 of the span, scalloped, with a tail."""
    s = np.asarray(s, dtype=float)
    scallops = 0.035 * np.abs(np.sin((s + 1.0) * 6.0 * np.pi))
    tail = 0.22 * np.exp(-(((s + 0.78) / 0.045) ** 2))
    rounded = 0.8 * np.sqrt(np.clip(1.0 - ((s + 0.05) / 1.05) ** 8, 0.05, 1.0))
    near_root = np.clip((s + 1.0) / 0.12, 0.35, 1.0)  # the trailing edge sweeps in to the body
    return rounded * near_root - scallops + tail


def wing_texture(pattern: str = "swallowtail", px: int = TEXTURE_PX) -> np.ndarray:
    """The wing pattern (``(px, px, 4)`` RGBA) in fan coordinates: u = (s + 1) / 2 across, v = r along the span
    (glTF's v runs down the image). Forewing above s = 0, hindwing below; veins radial, a black margin with
    pale lunules, bands on the forewing and eyespots near the hindwing's tail."""
    if pattern not in PATTERNS:
        raise UserError(f"the wing pattern is one of {', '.join(PATTERNS)}, got {pattern!r}.")
    base, dark, spot, spot2 = (np.array(c, dtype=float) for c in PATTERNS[pattern])
    u, v = np.meshgrid((np.arange(px) + 0.5) / px, (np.arange(px) + 0.5) / px)
    s, r = 2.0 * u - 1.0, v
    fore = s >= 0.0
    reach = np.where(fore, forewing_reach(s), hindwing_reach(s))
    edge = reach - r  # distance inside the margin, in span fractions
    img = np.broadcast_to(base, (px, px, 3)).copy()
    shade = 0.85 + 0.15 * r  # darker at the root, as scales over the wing base
    img *= shade[..., None]
    veins = np.abs(np.sin(s * (9 if pattern != "white" else 7) * np.pi / 2)) < (0.07 + 0.05 * (1 - r))
    veins &= r > 0.12
    margin = edge < (0.10 if pattern in ("swallowtail", "monarch", "morpho") else 0.05)
    lunule = margin & (edge > 0.03) & (np.abs(np.sin(s * 14 * np.pi / 2)) > 0.55)
    img[veins | margin] = dark
    if pattern == "swallowtail":
        bands = fore & (np.abs(np.sin(s * 4.2 * np.pi)) > 0.93) & (r < 0.75) & (r > 0.2)
        img[bands] = dark
        img[lunule] = base
        eye = ((s + 0.7) ** 2 / 0.012 + (r - 0.66) ** 2 / 0.004) < 1.0
        img[eye] = spot2
        blue = (~fore) & (edge > 0.1) & (edge < 0.17) & (s < -0.2)
        img[blue] = spot
    elif pattern in ("monarch", "morpho"):
        img[lunule] = spot
        if pattern == "morpho":
            img[~margin] = img[~margin] * (0.75 + 0.45 * np.exp(-((r - 0.5) ** 2) / 0.05))[~margin, None]
    else:
        tip = fore & (s > 0.55) & (r > 0.78)
        img[tip] = dark
        dot = ((s - 0.45) ** 2 / 0.004 + (r - 0.6) ** 2 / 0.003) < 1.0
        img[dot] = spot
    return np.concatenate([np.clip(img, 0, 255), np.full((px, px, 1), 255.0)], axis=-1).astype(np.uint8)


def _geom(model, body: int, suffix: str) -> int | None:
    for g in range(model.ngeom):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
        if model.geom_bodyid[g] == body and name.endswith(suffix) and model.geom_group[g] <= 2:
            return g
    return None


def planform(model, wing_body: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The wing planform's root and its tip chord's leading and trailing ends, in the wing body's frame (m),
    from the wing geom's mesh: the vertex nearest the hinge, and of the two farthest from it, the one further
    forward (+x) leads."""
    g = next((g for g in range(model.ngeom) if model.geom_bodyid[g] == wing_body
              and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and model.geom_group[g] <= 2), None)
    if g is None:
        raise UserError("a butterfly wing needs a drawn mesh geom for its planform.")
    mesh = int(model.geom_dataid[g])
    v = model.mesh_vert[model.mesh_vertadr[mesh]: model.mesh_vertadr[mesh] + model.mesh_vertnum[mesh]].astype(float)
    R = np.empty(9)
    mujoco.mju_quat2Mat(R, model.geom_quat[g])
    v = v @ R.reshape(3, 3).T + model.geom_pos[g]
    v[:, 2] = 0.0  # the planform's plane (the mesh is a thin slab: its two faces fall together)
    v = np.unique(np.round(v, 9), axis=0)
    d = np.linalg.norm(v[:, :2], axis=1)
    root = v[np.argmin(d)]
    far = v[np.argsort(d)[-2:]]
    lead, trail = (far[0], far[1]) if far[0, 0] > far[1, 0] else (far[1], far[0])
    if np.linalg.norm(lead - trail) < 1e-9:
        raise UserError("a butterfly wing's planform needs a tip chord.")
    return root, lead, trail


def outline_surfaces(model, wing_body: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The drawn surfaces of a wing whose model draws its measured outline (more than one drawn mesh geom, or a
    mesh with more than a triangle's six slab vertices), each as ``(vertices (V, 3), triangles (T, 3), boundary
    edges (E, 2, 2))`` in the wing body's frame (m), its plane ``z = 0``: the slab's upper face. Empty for the
    paper's triangle."""
    geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == wing_body
             and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and model.geom_group[g] <= 2]
    meshes = [int(model.geom_dataid[g]) for g in geoms]
    if len(geoms) < 2 and all(model.mesh_vertnum[k] <= 6 for k in meshes):
        return []
    out = []
    for g, k in zip(geoms, meshes):
        v = model.mesh_vert[model.mesh_vertadr[k]: model.mesh_vertadr[k] + model.mesh_vertnum[k]].astype(float)
        f = model.mesh_face[model.mesh_faceadr[k]: model.mesh_faceadr[k] + model.mesh_facenum[k]].astype(np.int64)
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, model.geom_quat[g])
        v = v @ R.reshape(3, 3).T + model.geom_pos[g]
        top = v[:, 2] > 0.0
        tris = f[top[f].all(axis=1)]
        keep = np.unique(tris)
        new = -np.ones(len(v), dtype=np.int64)
        new[keep] = np.arange(len(keep))
        verts = v[keep].copy()
        verts[:, 2] = 0.0
        tris = new[tris]
        edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
        uniq, counts = np.unique(edges, axis=0, return_counts=True)
        out.append((verts, tris, verts[uniq[counts == 1]][:, :, :2]))
    return out


def _distance_to_edges(pts: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Each point's distance (m) to the nearest of the segments ``edges`` ``(E, 2, 2)``."""
    a, b = edges[:, 0], edges[:, 1]
    ab = b - a
    t = np.clip(np.einsum("pek,ek->pe", pts[:, None, :] - a[None], ab) / np.maximum(np.sum(ab * ab, 1), 1e-18), 0, 1)
    near = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(pts[:, None, :] - near, axis=2).min(axis=1)


def outline_texture(surfaces, box: tuple[float, float, float, float], pattern: str = "monarch",
                    px: int = TEXTURE_PX) -> np.ndarray:
    """A wing pattern ``(px, px, 4)`` over the wing's plane (``box``: x and y ranges the texture spans, m; u along
    x, v along y from the hinge), drawn from the outline: the ground colour, a black margin (6 % of the span)
    with two rows of white spots, black veins fanning from the hinge, and the fore wing's inner margin black."""
    if pattern not in PATTERNS:
        raise UserError(f"the wing pattern is one of {', '.join(PATTERNS)}, got {pattern!r}.")
    base, dark, spot, _ = (np.array(c, dtype=float) for c in PATTERNS[pattern])
    x0, x1, y0, y1 = box
    u, v = np.meshgrid((np.arange(px) + 0.5) / px, (np.arange(px) + 0.5) / px)
    pts = np.stack([x0 + u * (x1 - x0), y0 + v * (y1 - y0)], axis=-1).reshape(-1, 2)
    span = y1 - y0
    edges = np.concatenate([e for _, _, e in surfaces])
    keyed = np.round(np.sort(edges.reshape(-1, 4).reshape(-1, 2, 2), axis=1).reshape(-1, 4), 9)
    uniq, counts = np.unique(keyed, axis=0, return_counts=True)
    outer = uniq[counts == 1].reshape(-1, 2, 2)  # the union's outline: edges of one surface only
    inner = uniq[counts > 1].reshape(-1, 2, 2)  # shared: the fore wing's inner margin
    d_out = _distance_to_edges(pts, outer) / span
    img = np.broadcast_to(base, (len(pts), 3)).copy()
    img *= (0.85 + 0.15 * np.clip(pts[:, 1] / span, 0, 1))[:, None]
    angle = np.arctan2(pts[:, 0], np.maximum(pts[:, 1], 1e-9))
    r = np.hypot(pts[:, 0], pts[:, 1]) / span
    veins = (np.abs(np.sin(angle * 9.0)) < 0.06 + 0.04 * (1 - r)) & (r > 0.1)
    margin = d_out < 0.06
    img[veins | margin] = dark
    if len(inner):
        img[_distance_to_edges(pts, inner) / span < 0.012] = dark
    along = np.sin(angle * 26.0)
    img[margin & (np.abs(d_out - 0.02) < 0.008) & (along > 0.6)] = spot
    img[margin & (np.abs(d_out - 0.042) < 0.007) & (along < -0.6)] = spot
    img = img.reshape(px, px, 3)
    return np.concatenate([np.clip(img, 0, 255), np.full((px, px, 1), 255.0)], axis=-1).astype(np.uint8)


def _outline_box(surfaces) -> tuple[float, float, float, float]:
    """The chord range and the span range ``(0, R)`` a measured wing's texture spans (m; either wing: the span's
    size)."""
    allv = np.concatenate([v for v, _, _ in surfaces])
    return float(allv[:, 0].min()), float(allv[:, 0].max()), 0.0, float(np.abs(allv[:, 1]).max())


def _outline_pieces(surfaces, look: Look, bone: int) -> list[Piece]:
    """The measured wing's surfaces as mesh pieces bound to ``bone``, drawn on both faces, fore wing above; texture
    coordinates over :func:`_outline_box` (the right wing mirrors the left's)."""
    x0, x1, _, y1 = _outline_box(surfaces)
    pieces = []
    for k, (v, t, _) in enumerate(surfaces):
        pos = v.copy()
        pos[:, 2] = 0.00012 if k == 0 else -0.00012
        uv = np.stack([(v[:, 0] - x0) / (x1 - x0), np.abs(v[:, 1]) / y1], axis=1)
        nrm = np.tile([0.0, 0.0, 1.0], (len(v), 1))
        j, w = rigid(len(v), bone)
        pieces.append(Piece(pos, nrm, uv, t, j, w, look))  # the slabs' upper faces run counter-clockwise
    return pieces


def _wing(root, lead, trail, look: Look, bone: int, fore: bool, lift: float) -> Piece:
    """One wing surface over the planform (module docstring)."""
    n_s, n_r = (22, 12)
    s = np.linspace(-0.05, 1.0, n_s) if fore else np.linspace(-1.0, 0.05, n_s)
    reach = forewing_reach(s) if fore else hindwing_reach(s)
    r = np.linspace(0.0, 1.0, n_r)[:, None] * reach[None, :]
    a = ((1 + s) / 2)[None, :, None]
    tip = a * lead + (1 - a) * trail  # (1, n_s, 3)
    pts = root + r[..., None] * (tip - root)
    pts[..., 2] += lift
    uv = np.stack([np.broadcast_to((s + 1) / 2, r.shape), r], axis=-1)
    return sheet(pts, uv, look, rigid(1, bone))


def butterfly_rig(poses, root: int, indices: list[int], pattern: str = "swallowtail") -> Rig:
    """The rig of the butterfly whose root body is ``root`` (module docstring): its bodies ``indices`` in
    ``poses``, its wings in ``pattern``."""
    m = poses.model
    bones: list[Bone] = []
    index: dict[int, int] = {}
    for i in indices:
        body = int(poses.body_ids[i])
        parent = index.get(int(m.body_parentid[body]), -1) if body != root else -1
        index[body] = len(bones)
        bones.append(body_bone(poses, i, parent))
    rname = poses.body_names[indices[0]]
    pattern = _species_pattern(m, pattern)
    prefix = rname[: -len("butterfly")] if rname.endswith("butterfly") else ""
    wing_ids = {side: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{prefix}wing_{side}") for side in ("left", "right")}
    wings = {side: index.get(w) for side, w in wing_ids.items()}
    abdomen_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{prefix}abdomen")
    abdomen = index.get(abdomen_id)
    # body sizes from the model's geoms
    thorax_g, head_g = _geom(m, root, "thorax"), _geom(m, root, "head")
    half, radius = _half_and_radius(m, thorax_g, 0.005, 0.003)
    head_x = float(m.geom_pos[head_g, 0]) if head_g is not None else half + 0.002
    head_r = float(m.geom_size[head_g, 0]) if head_g is not None else 0.002
    # antennae: from the top of the head, forward and up, with a damped lag of the thorax's felt acceleration
    t = poses.t_s
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    thorax = bones[0]
    acc = np.gradient(np.gradient(thorax.position_m, t, axis=0), t, axis=0) if len(t) > 2 else \
        np.zeros_like(thorax.position_m)
    felt = qrot(qconj(thorax.quat_wxyz), acc + np.array([0.0, 0.0, _G])) / _G - np.array([0.0, 0.0, 1.0])
    lag = damped(felt, dt, ANTENNA_HZ, ANTENNA_ZETA) * math.radians(ANTENNA_DEG_PER_G)
    if wings["left"] is not None:  # antennae about 0.4 of the wing's span long
        root_pt, lead, _ = planform(m, wing_ids["left"])
        length = 0.4 * float(np.linalg.norm(lead - root_pt))
    else:
        length = 0.018
    for side, sign in (("left", 1.0), ("right", -1.0)):
        pitch = -lag[:, 0] + lag[:, 2]  # pushed back when the body speeds up, down when it rises
        turn = _turns(pitch, -lag[:, 1])  # pushed to the side opposite a sideways acceleration
        rest = _rest_antenna(sign)
        bones.append(extra_bone(f"{rname}/antenna_{side}", 0, bones, (head_x + 0.3 * head_r, sign * 0.4 * head_r,
                                                                       0.7 * head_r), turn, rest))
    # the mesh
    wing_look = Look("wing", (1.0, 1.0, 1.0, 1.0), wing_texture(pattern), double_sided=True, roughness=0.8)
    outline_look = None  # one texture for both measured wings, made from the first in the left wing's frame
    body_look = Look("body", (0.12, 0.10, 0.08, 1.0), roughness=0.9)
    eye_look = Look("eye", (0.03, 0.03, 0.03, 1.0), roughness=0.3)
    pieces: list[Piece] = []
    xs = np.linspace(-half - radius, half + radius, 9)
    prof = np.sqrt(np.clip(1.0 - ((xs - 0.0) / (half + radius)) ** 2, 0.0, 1.0))
    pieces.append(loft(xs, radius * 1.05 * prof, radius * 1.15 * prof, body_look, rigid(1, 0)))
    pieces.append(sphere((head_x, 0.0, 0.0), head_r, body_look, rigid(1, 0)))
    for sign in (1.0, -1.0):
        pieces.append(sphere((head_x + 0.35 * head_r, sign * 0.7 * head_r, 0.15 * head_r), 0.55 * head_r, eye_look,
                             rigid(1, 0), segments=8))
    if abdomen is not None:
        ab_g = _geom(m, abdomen_id, "abdomen")
        ab_half, ab_r = _half_and_radius(m, ab_g, 0.005, 0.0025)
        ab_len = 2 * ab_half
        base = bones[abdomen].bind[:3, 3]
        u = np.linspace(0.0, 1.0, 25)
        rings = 1.0 - 0.09 * np.abs(np.sin(u * 6 * np.pi))
        taper = np.sqrt(np.clip(1.0 - u ** 4, 0.0, 1.0)) * np.clip(0.75 + u * 2, 0, 1)
        xs = base[0] - u * (ab_len + ab_r)
        pieces.append(loft(xs, ab_r * rings * taper, ab_r * 1.1 * rings * taper, body_look, rigid(1, abdomen),
                           centre_z=np.full(len(u), base[2])))
    for side, sign in (("left", 1.0), ("right", -1.0)):
        b = len(bones) - (2 if side == "left" else 1)
        path = np.stack([np.linspace(0, 1, 10), np.zeros(10), np.zeros(10)], axis=1) * length
        path = qrot(np.asarray(_rest_antenna(sign)), path) + bones[b].bind[:3, 3]
        rad = np.full(10, 0.00018)
        rad[-3:] = [0.00035, 0.00045, 0.0002]
        pieces.append(tube(path, rad, body_look, rigid(1, b)))
        w = wings[side]
        if w is None:
            continue
        measured = outline_surfaces(m, wing_ids[side])
        if measured:
            if outline_look is None:
                left = [(v * [1, sign, 1], t, e * [1, sign]) for v, t, e in measured]
                outline_look = Look("wing", (1.0, 1.0, 1.0, 1.0), outline_texture(left, _outline_box(measured), pattern),
                                    double_sided=True, roughness=0.8)
            for piece in _outline_pieces(measured, outline_look, w):
                piece.positions = piece.positions @ bones[w].bind[:3, :3].T + bones[w].bind[:3, 3]
                piece.normals = piece.normals @ bones[w].bind[:3, :3].T
                pieces.append(piece)
            continue
        root_pt, lead, trail = planform(m, wing_ids[side])
        for fore, lift in ((True, 0.00012), (False, -0.00012)):
            piece = _wing(root_pt, lead, trail, wing_look, w, fore, lift)
            piece.positions = piece.positions @ bones[w].bind[:3, :3].T + bones[w].bind[:3, 3]
            piece.normals = piece.normals @ bones[w].bind[:3, :3].T
            pieces.append(piece)
    return Rig(rname, bones, assemble(f"{rname} ({pattern})", pieces), {"pattern": pattern})


def _species_pattern(m, pattern: str) -> str:
    """A model that names its species in its wings' material (the 3D monarch's ``monarch_0``) is drawn in that
    species' pattern, whatever ``pattern`` asks."""
    for g in range(m.ngeom):
        mat = int(m.geom_matid[g])
        name = (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_MATERIAL, mat) or "") if mat >= 0 else ""
        species = name.rsplit("/", 1)[-1].split("_")[0]
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH and species in PATTERNS and species != "wing":
            return species
    return pattern


def _half_and_radius(m, g, half: float, radius: float) -> tuple[float, float]:
    """A body part's half length less its radius, and its radius (m), from its drawn capsule or ellipsoid."""
    if g is None:
        return half, radius
    size = m.geom_size[g]
    if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_ELLIPSOID:
        return float(size[0] - size[1]), float(size[1])
    return float(size[1]), float(size[0])


def _rest_antenna(sign: float) -> np.ndarray:
    """An antenna's rest turn: from the body's +x, 35 deg up and 20 deg out to its side."""
    return qmul(qaxis((0.0, 0.0, 1.0), sign * math.radians(20.0)), qaxis((0.0, 1.0, 0.0), -math.radians(35.0)))


def _turns(pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    return qmul(qaxis((0.0, 0.0, 1.0), yaw), qaxis((0.0, 1.0, 0.0), pitch))


def rigs(poses, patterns: tuple[str, ...] = ("swallowtail", "monarch", "morpho", "white")) -> list:
    """One rig per butterfly of the run (each a root body carrying a thorax), the first in ``patterns[0]``, the
    next in the next pattern, and so on around."""
    out = []
    for k, (root, idx) in enumerate(creatures(poses).items()):
        out.append(butterfly_rig(poses, root, idx, patterns[k % len(patterns)]))
    return out
