"""Measures of how the types of heterogeneous boids mix, and a hand-written classifier of the eight
patterns of Nakamura 2013 (docs/models/boids.md: the paper's missing "objective index").

Every measure is a function of one frame ``(positions, velocities, types)`` (:func:`frame_measures`);
:func:`measures` evaluates it on the recorded frames of a late window of a run and averages it over
the frames (counts: the per-frame majority, plus the mean), and adds a few features of the time
series over the window (:func:`series_features`). :func:`classify` maps the averaged measures to one
of the eight patterns (or ``"other"``) with a small decision tree whose thresholds are the module
constants below, and says which measures and thresholds decided.

Definitions (``n`` agents, ``n_I`` of type ``I``, ``k`` types; "random mix" means the types shuffled
over the same positions):

* **same-type neighbour fraction** ``f_s``: mean over agents of the fraction of its ``K_NEIGHBOURS``
  nearest neighbours that share its type. This is the like-neighbour fraction used as a segregation
  parameter in the cell-sorting literature (Belmonte, Thomas, Brunnet, de Almeida & Chate 2008, PRL
  100, 248702, there with Voronoi neighbours in 2D; Schelling 1971 for its origin), here with ``k``
  nearest neighbours in 3D.
* **segregation index** ``S = (f_s - E) / (1 - E)`` with ``E = sum_I n_I (n_I - 1) / (n (n - 1))``,
  the same-type fraction expected in a random mix: 0 for a random mix, 1 when every agent's
  neighbours are all of its type, negative when the types alternate (our normalisation, the
  chance-corrected form of Cohen's kappa).
* **heterotypic contact ratio**: contacts are the pairs closer than ``CONTACT_RADIUS`` (``R_a``, the
  alignment zone); the fraction of contacts that join two different types, divided by its random-mix
  expectation ``1 - E``. 1 = mixed, 0 = no contact between types. It is the particle analogue of the
  heterotypic boundary length of Graner & Glazier 1992 (PRL 69, 2013), normalised.
* **centroid distance**: distance between the two types' centroids (box units; for ``k`` types the
  largest pairwise distance); ``centroid_distance_rel`` divides it by the radius of gyration of all
  agents, ``R_g = sqrt(mean |x_i - c|^2)`` (the standard polymer-physics radius of gyration).
* **radii of gyration** per type about the type's own centroid (``rg_type``), and the rms distance of
  each type from the common centroid ``c`` of all agents (``radial_rms_type``).
* ``radius_ratio`` = smallest / largest ``radial_rms_type`` (<= 1). A core of radius ``R`` inside a
  shell of equal number reaches ~0.65-0.7, and sets of the same shape at the same place (a mix, two
  hemispheres, two groups side by side) give ~1. ``inner_type`` is the type with the smallest value.
* ``radial_sorting_error``: with ``r_i = |x_i - c|``, ``P = P(r_i < r_j)`` for ``i`` of one type and
  ``j`` of the other (the Mann-Whitney U statistic divided by ``n_A n_B``; Mann & Whitney 1947, i.e.
  the area under the ROC curve of ``r`` as a classifier of the type), ``error = 2 min(P, 1 - P)``:
  0 = one type entirely inside the other, 1 = no radial order (for ``k`` types the mean over pairs).
* ``plane_split``: the best plane through the common centroid of two types, as the fraction of their
  agents on their type's side; the normals tried are the centroid-difference direction and Fisher's
  linear discriminant ``S_w^-1 (c_A - c_B)`` (Fisher 1936). 1 = perfect hemispheres or separate
  groups, ~0.5 = mixed (for ``k`` types the mean over pairs).
* **groups**: connected components of the graph joining agents closer than ``GROUP_RADIUS`` (``R_c``,
  the cohesion zone), counting components of at least ``MIN_GROUP_FRACTION`` of the agents
  (``n_groups``); ``n_groups_type`` does the same within each type (edges between same-type agents
  only, the size threshold a fraction of that type). ``largest_group_fraction``: agents in the largest
  component. Components of a neighbourhood graph as flocks: e.g. Vicsek & Zafeiris 2012, Phys. Rep.
  517, 71 (cluster analysis), the usual definition.
* **polarisation** ``phi = |mean_i v_i / |v_i||`` (the order parameter of Vicsek, Czirok, Ben-Jacob,
  Cohen & Shochet 1995, PRL 75, 1226), for all agents and per type; ``heading_cos`` is the cosine
  between the mean headings of the two types (1 = same direction, -1 = opposite); ``speed`` the mean
  speed ``|v_i|`` (box units per step). ``contact_alignment_same`` / ``_cross``: the mean cosine
  between the headings of contact pairs of the same / of different types (local alignment);
  ``interface_fraction``: agents with a contact of another type.
* **shape**: the eigenvalues ``l1 >= l2 >= l3`` of the gyration tensor of all agents;
  ``elongation = sqrt(l1 / l3)`` (1 for a sphere, ~2 for two touching equal spheres) and the
  relative shape anisotropy ``kappa^2 = 1 - 3 (l1 l2 + l2 l3 + l3 l1) / (l1 + l2 + l3)^2``
  (Theodorou & Suter 1985, Macromolecules 18, 1206).
* ``wall_fraction``: agents closer than ``R_s`` to a wall (the wall-avoidance zone).
* ``nn_distance``: mean distance to the nearest neighbour (how loose a swarm is).

Time-series features over the window (:func:`series_features`): the coefficient of variation
(std/mean over frames) of the mean speed and of the centroid distance, the range of the centroid
distance relative to its mean, the fraction of frames in which the types' mean headings point
apart (``heading_cos < 0``), and the peak wall fraction.

Cost: each frame compares all pairs (in blocks of 1024 rows, so memory stays ~1024 n), O(n^2) time:
~10-30 ms a frame at n = 300; the classifier's window has 100 frames.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np

from lifelike_mj.boids.engine import BOX, R_A, R_C, R_S

# ---- measure settings ------------------------------------------------------------------------------

#: Nearest neighbours for the same-type fraction (about the first shell of a dense 3D flock).
K_NEIGHBOURS = 6
#: Contact radius for A-B contacts: the alignment zone R_a.
CONTACT_RADIUS = R_A
#: Radius of the group graph: the cohesion zone R_c (agents that feel each other's cohesion).
GROUP_RADIUS = R_C
#: A group (connected component) counts when it holds at least this fraction of the agents (or, per
#: type, of that type's agents).
MIN_GROUP_FRACTION = 0.05
#: Distance to a wall below which an agent counts as at the wall: the separation zone R_s.
WALL_DISTANCE = R_S

#: Run length (steps) and window (the last ``WINDOW_STEPS`` steps of the run, one frame every
#: ``RECORD_EVERY`` steps) used to classify. The paper gives no run length. At n = 300 the shell (4c),
#: the mix (5a) and 4d's flock settle within ~500 steps, 5c and 5d within ~2000-3000, the half-split of
#: 5b within ~3000 (its S still creeps up by ~0.1 until ~10000), but sorting by differential cohesion
#: is slow: 4b's two groups form (S >= 0.75) between ~1800 and ~5200 steps depending on the seed
#: (seeds 10-14), 4a's at ~5200 for one seed in five and not at all for the others (an arrested
#: partial sort, unchanged up to 30000 steps). 10000 steps, measured over 8000-10000, leave the
#: slowest 4b sort ~3000 steps of margin.
RUN_STEPS = 10000
WINDOW_STEPS = 2000
RECORD_EVERY = 20


# ---- geometry helpers --------------------------------------------------------------------------------


def _pair_d2_chunks(x: np.ndarray, chunk: int = 1024):
    """Yield ``(i0, d2)`` with ``d2`` the squared distances of agents ``i0 .. i0 + len(d2)`` to all
    agents (memory bounded by ``chunk * n``)."""
    sq = np.einsum("ij,ij->i", x, x)
    n = len(x)
    for i0 in range(0, n, chunk):
        xi = x[i0:i0 + chunk]
        d2 = sq[i0:i0 + chunk, None] + sq[None, :] - 2.0 * (xi @ x.T)
        np.maximum(d2, 0.0, out=d2)
        d2[np.arange(len(xi)), np.arange(i0, i0 + len(xi))] = np.inf
        yield i0, d2


#: Above this many agents the neighbour measures search a k-d tree (``scipy.spatial.cKDTree``: time and memory
#: about linear in n) instead of the chunked all-pairs distances (time in n^2), which give the same neighbours and
#: are kept below it so that the paper's runs measure bit for bit as before (``tests/boids/test_boids_metrics.py``
#: checks that both agree).
DENSE_MAX = 4096


def knn(x: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices (n, k) and distances (n, k) of each agent's ``k`` nearest other agents (unsorted)."""
    n = len(x)
    k = min(k, n - 1)
    if n > DENSE_MAX:
        from scipy.spatial import cKDTree

        dist, idx = cKDTree(x).query(x, k=k + 1)  # the first is the agent itself (or a twin at distance 0)
        own = idx == np.arange(n)[:, None]
        keep = ~own
        keep[~own.any(axis=1), -1] = False  # a twin listed before the agent: drop the farthest instead
        return idx[keep].reshape(n, k).astype(np.int64), dist[keep].reshape(n, k)
    idx = np.empty((n, k), dtype=np.int64)
    dist = np.empty((n, k))
    for i0, d2 in _pair_d2_chunks(x):
        part = np.argpartition(d2, k - 1, axis=1)[:, :k]
        idx[i0:i0 + len(d2)] = part
        dist[i0:i0 + len(d2)] = np.sqrt(np.take_along_axis(d2, part, axis=1))
    return idx, dist


def pairs_within(x: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    """All pairs ``i < j`` with ``|x_i - x_j| < r``."""
    if len(x) > DENSE_MAX:
        from scipy.spatial import cKDTree

        pairs = cKDTree(x).query_pairs(r, output_type="ndarray")  # |d| <= r; the strict bound below
        i, j = pairs[:, 0].astype(np.int64), pairs[:, 1].astype(np.int64)
        d = x[i] - x[j]
        inside = np.einsum("ij,ij->i", d, d) < r * r
        order = np.lexsort((j[inside], i[inside]))
        return i[inside][order], j[inside][order]
    ii, jj = [], []
    for i0, d2 in _pair_d2_chunks(x):
        a, b = np.nonzero(d2 < r * r)
        a = a + i0
        keep = a < b
        ii.append(a[keep])
        jj.append(b[keep])
    if not ii:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    return np.concatenate(ii), np.concatenate(jj)


def components(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Connected-component labels (n,) of the graph with edges ``(i, j)``: min-label propagation
    with pointer jumping. Labels are the smallest agent index of each component."""
    lab = np.arange(n)
    if len(i) == 0:
        return lab
    while True:
        new = lab.copy()
        np.minimum.at(new, i, lab[j])
        np.minimum.at(new, j, lab[i])
        while True:  # pointer jumping: follow labels to their roots
            nxt = new[new]
            if np.array_equal(nxt, new):
                break
            new = nxt
        if np.array_equal(new, lab):
            return lab
        lab = new


def _group_sizes(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    return np.sort(np.bincount(components(n, i, j), minlength=n))[::-1]


def _nan() -> float:
    return float("nan")


# ---- one frame -------------------------------------------------------------------------------------


def frame_measures(x: np.ndarray, v: np.ndarray, types: np.ndarray, *, k: int = K_NEIGHBOURS,
                   contact_radius: float = CONTACT_RADIUS, group_radius: float = GROUP_RADIUS,
                   min_group_fraction: float = MIN_GROUP_FRACTION, box: float | None = BOX,
                   wall_distance: float = WALL_DISTANCE) -> dict:
    """The measures of one frame (see the module docstring): ``x``, ``v`` (n, D), ``types`` (n,)
    integers ``0 .. k-1``. ``box`` is the side of the box ``[0, box]^D`` for the wall fraction (None:
    no walls). Values that do not exist (a single type present) are NaN."""
    x = np.asarray(x, dtype=float)
    v = np.asarray(v, dtype=float)
    types = np.asarray(types, dtype=np.int64)
    n, D = x.shape
    labels = np.unique(types)
    nt = int(types.max()) + 1 if n else 0
    counts = np.bincount(types, minlength=nt)
    present = [int(t) for t in labels]
    out: dict = {}

    # -- neighbour types
    idx, dist = knn(x, k)
    same = (types[idx] == types[:, None]).mean(axis=1)
    f_s = float(same.mean())
    E = float(np.sum(counts * (counts - 1.0)) / (n * (n - 1.0)))
    out["same_type_fraction"] = f_s
    out["same_type_expected"] = E
    out["segregation_index"] = (f_s - E) / (1.0 - E) if E < 1.0 else _nan()
    out["nn_distance"] = float(dist.min(axis=1).mean())
    for t in present:
        out[f"same_type_fraction_{t}"] = float(same[types == t].mean())

    # -- contacts
    ci, cj = pairs_within(x, contact_radius)
    out["contacts_per_agent"] = 2.0 * len(ci) / n
    if len(ci) and E < 1.0:
        het = float(np.mean(types[ci] != types[cj]))
        out["heterotypic_contact_fraction"] = het
        out["contact_ratio"] = het / (1.0 - E)
    else:
        out["heterotypic_contact_fraction"] = _nan()
        out["contact_ratio"] = _nan()

    # -- centroids and radii
    c = x.mean(axis=0)
    rel = x - c
    rg_all = float(np.sqrt(np.mean(np.sum(rel * rel, axis=1))))
    out["rg_all"] = rg_all
    cents = {t: x[types == t].mean(axis=0) for t in present}
    r = np.sqrt(np.sum(rel * rel, axis=1))
    radial = {}
    for t in present:
        xt = x[types == t]
        out[f"rg_{t}"] = float(np.sqrt(np.mean(np.sum((xt - cents[t]) ** 2, axis=1))))
        radial[t] = float(np.sqrt(np.mean(r[types == t] ** 2)))
        out[f"radial_rms_{t}"] = radial[t]
    pairs = [(a, b) for ia, a in enumerate(present) for b in present[ia + 1:]]
    if pairs:
        dists = [float(np.linalg.norm(cents[a] - cents[b])) for a, b in pairs]
        out["centroid_distance"] = max(dists)
        out["centroid_distance_rel"] = max(dists) / rg_all if rg_all > 0 else _nan()
        inner = min(radial, key=radial.get)
        out["radius_ratio"] = radial[inner] / max(radial.values()) if max(radial.values()) > 0 else _nan()
        out["inner_type"] = inner
        errs, splits = [], []
        for a, b in pairs:
            errs.append(_radial_sorting_error(r[types == a], r[types == b]))
            splits.append(_plane_split(x[types == a], x[types == b]))
        out["radial_sorting_error"] = float(np.mean(errs))
        out["plane_split"] = float(np.mean(splits))
    else:
        for key in ("centroid_distance", "centroid_distance_rel", "radius_ratio", "radial_sorting_error", "plane_split"):
            out[key] = _nan()
        out["inner_type"] = present[0] if present else -1

    # -- shape of the whole set
    if n > D:
        ev = np.sort(np.linalg.eigvalsh(rel.T @ rel / n))[::-1]
        ev = np.maximum(ev, 1e-12)
        out["elongation"] = float(np.sqrt(ev[0] / ev[-1]))
        if D == 3:
            out["anisotropy"] = float(1.0 - 3.0 * (ev[0] * ev[1] + ev[1] * ev[2] + ev[2] * ev[0]) / np.sum(ev) ** 2)
        else:
            out["anisotropy"] = float(1.0 - 4.0 * ev[0] * ev[1] / np.sum(ev) ** 2)
    else:
        out["elongation"] = out["anisotropy"] = _nan()

    # -- groups
    gi, gj = pairs_within(x, group_radius)
    sizes = _group_sizes(n, gi, gj)
    out["n_groups"] = int(np.sum(sizes >= max(1.0, min_group_fraction * n)))
    out["largest_group_fraction"] = float(sizes[0] / n)
    for t in present:
        sel = np.nonzero(types == t)[0]
        m = len(sel)
        pos = np.full(n, -1)
        pos[sel] = np.arange(m)
        keep = (types[gi] == t) & (types[gj] == t)
        st = _group_sizes(m, pos[gi[keep]], pos[gj[keep]])
        out[f"n_groups_{t}"] = int(np.sum(st >= max(1.0, min_group_fraction * m)))
        out[f"largest_group_fraction_{t}"] = float(st[0] / m)

    # -- motion
    speed = np.sqrt(np.sum(v * v, axis=1))
    out["speed"] = float(speed.mean())
    heads = v / np.where(speed > 0, speed, 1.0)[:, None]
    out["polarisation"] = float(np.linalg.norm(heads.mean(axis=0)))
    mh = {}
    for t in present:
        mh[t] = heads[types == t].mean(axis=0)
        out[f"polarisation_{t}"] = float(np.linalg.norm(mh[t]))
        out[f"speed_{t}"] = float(speed[types == t].mean())
    if pairs:
        cs = []
        for a, b in pairs:
            na, nb = np.linalg.norm(mh[a]), np.linalg.norm(mh[b])
            cs.append(float(mh[a] @ mh[b] / (na * nb)) if na > 0 and nb > 0 else _nan())
        out["heading_cos"] = float(np.mean(cs))
    else:
        out["heading_cos"] = _nan()

    # -- local alignment: mean cosine between the headings of contact pairs, same type / two types
    if len(ci):
        cosp = np.sum(heads[ci] * heads[cj], axis=1)
        st = types[ci] == types[cj]
        out["contact_alignment_same"] = float(cosp[st].mean()) if np.any(st) else _nan()
        out["contact_alignment_cross"] = float(cosp[~st].mean()) if np.any(~st) else _nan()
        touch = np.zeros(n, dtype=bool)
        touch[ci[~st]] = True
        touch[cj[~st]] = True
        out["interface_fraction"] = float(touch.mean())
    else:
        out["contact_alignment_same"] = out["contact_alignment_cross"] = _nan()
        out["interface_fraction"] = 0.0

    # -- walls
    if box is not None:
        dw = np.minimum(x, box - x).min(axis=1)
        out["wall_fraction"] = float(np.mean(dw < wall_distance))
    else:
        out["wall_fraction"] = _nan()
    return out


def _radial_sorting_error(ra: np.ndarray, rb: np.ndarray) -> float:
    """``2 min(P, 1 - P)`` with ``P = P(r_a < r_b)`` (ties count 1/2): the Mann-Whitney U of the two
    samples divided by ``len(ra) len(rb)``, computed from ranks."""
    na, nb = len(ra), len(rb)
    if na == 0 or nb == 0:
        return _nan()
    allr = np.concatenate([ra, rb])
    order = np.argsort(allr, kind="mergesort")
    ranks = np.empty(len(allr))
    ranks[order] = np.arange(1, len(allr) + 1)
    # average ranks of ties
    sv = allr[order]
    _, first, cnt = np.unique(sv, return_index=True, return_counts=True)
    if np.any(cnt > 1):
        avg = first + (cnt + 1) / 2.0
        ranks[order] = np.repeat(avg, cnt)
    u_b = ranks[na:].sum() - nb * (nb + 1) / 2.0  # pairs with r_b > r_a (b outside a)
    p = u_b / (na * nb)
    return float(2.0 * min(p, 1.0 - p))


def _plane_split(xa: np.ndarray, xb: np.ndarray) -> float:
    """Best fraction of agents of two types on their type's side of a plane through their common
    centroid, over the normals ``c_a - c_b`` and Fisher's discriminant ``S_w^-1 (c_a - c_b)``."""
    if len(xa) == 0 or len(xb) == 0:
        return _nan()
    ca, cb = xa.mean(axis=0), xb.mean(axis=0)
    c = np.concatenate([xa, xb]).mean(axis=0)
    d = ca - cb
    normals = [d]
    sw = np.cov((xa - ca).T, bias=True) * len(xa) + np.cov((xb - cb).T, bias=True) * len(xb)
    sw = np.atleast_2d(sw)
    try:
        normals.append(np.linalg.solve(sw + 1e-9 * np.trace(sw) * np.eye(len(d)), d))
    except np.linalg.LinAlgError:
        pass
    best = 0.5
    for w in normals:
        if not np.any(w):
            continue
        sa = (xa - c) @ w
        sb = (xb - c) @ w
        f = (np.sum(sa > 0) + np.sum(sb < 0)) / (len(xa) + len(xb))
        best = max(best, float(f), float(1.0 - f))
    return best


# ---- a window of frames ----------------------------------------------------------------------------


def series_features(frames: list[dict]) -> dict:
    """Features of the time series of per-frame measures over the window (module docstring)."""
    out: dict = {}

    def arr(key):
        return np.array([f.get(key, np.nan) for f in frames], dtype=float)

    sp = arr("speed")
    out["speed_cv"] = float(np.std(sp) / np.mean(sp)) if np.mean(sp) > 0 else _nan()
    cd = arr("centroid_distance")
    if np.all(np.isfinite(cd)) and np.mean(cd) > 0:
        out["centroid_distance_cv"] = float(np.std(cd) / np.mean(cd))
        out["centroid_distance_range"] = float((np.max(cd) - np.min(cd)) / np.mean(cd))
    else:
        out["centroid_distance_cv"] = out["centroid_distance_range"] = _nan()
    hc = arr("heading_cos")
    out["heading_apart_fraction"] = float(np.mean(hc[np.isfinite(hc)] < 0)) if np.any(np.isfinite(hc)) else _nan()
    wf = arr("wall_fraction")
    out["wall_fraction_max"] = float(np.nanmax(wf)) if np.any(np.isfinite(wf)) else _nan()
    return out


def window_frames(steps: np.ndarray, window: int | None) -> np.ndarray:
    """Indices of the recorded frames in the last ``window`` steps (``steps > last - window``); all
    frames for ``window=None``."""
    steps = np.asarray(steps)
    if window is None:
        return np.arange(len(steps))
    return np.nonzero(steps > steps[-1] - window)[0]


def measures_from_frames(positions: np.ndarray, velocities: np.ndarray, types: np.ndarray,
                         box: float | None = BOX, **kw) -> dict:
    """Average :func:`frame_measures` over frames (T, n, D) (all of them), add the majority of the
    counts and :func:`series_features`; plain JSON-able values (NaN -> None)."""
    positions = np.asarray(positions, dtype=float)
    velocities = np.asarray(velocities, dtype=float)
    if positions.ndim == 2:
        positions, velocities = positions[None], velocities[None]
    frames = [frame_measures(positions[f], velocities[f], types, box=box, **kw) for f in range(len(positions))]
    keys = list(dict.fromkeys(k for f in frames for k in f))
    out: dict = {"n_frames": len(frames), "n_agents": int(positions.shape[1]),
                 "type_counts": [int(c) for c in np.bincount(np.asarray(types, dtype=np.int64))]}
    for key in keys:
        vals = np.array([f.get(key, np.nan) for f in frames], dtype=float)
        if key == "inner_type":
            out[key] = int(Counter(int(v) for v in vals).most_common(1)[0][0])
            out["inner_type_fraction"] = float(np.mean(vals == out[key]))
            continue
        if key.startswith("n_groups"):
            out[key] = _majority(vals)
            out[key + "_mean"] = float(np.mean(vals))
            continue
        fin = vals[np.isfinite(vals)]
        out[key] = float(fin.mean()) if len(fin) else None
    for key, val in series_features(frames).items():
        out[key] = val if val is None or math.isfinite(val) else None
    return out


def _majority(vals: np.ndarray) -> int:
    """The most frequent value; ties go to the smaller count."""
    c = Counter(int(v) for v in vals)
    top = max(c.values())
    return min(v for v, m in c.items() if m == top)


def measures(run, window: int | None = WINDOW_STEPS, **kw) -> dict:
    """Measures of a :class:`~lifelike_mj.boids.engine.BoidRun` averaged over its recorded frames in
    the last ``window`` steps (None: all recorded frames). Keyword arguments go to
    :func:`frame_measures`. Returns plain floats/ints (None where undefined)."""
    sel = window_frames(run.steps, window)
    out = measures_from_frames(run.positions[sel], run.velocities[sel], run.types, box=run.params.box, **kw)
    out["window_steps"] = [int(run.steps[sel[0]]), int(run.steps[sel[-1]])]
    return out


# ---- the classifier ----------------------------------------------------------------------------------
# Thresholds, tuned by hand on seeds 10-14 of the eight presets at n = 300 (RUN_STEPS steps, measures
# averaged over the last WINDOW_STEPS steps); the values the presets reach there are quoted.

#: Mean speed (box units per step) above which the flock is "fast": the 5b groups that accelerate
#: towards each other, pass and hit the walls reach 0.3-0.6; every other state stays below 0.11.
FAST_SPEED = 0.15
#: A shell (4c): the radial order of the types is nearly perfect (4c: error 0.000-0.002; a mix or
#: two hemispheres: 0.7-1.0) ...
SHELL_SORTING_ERROR = 0.25
#: ... and the inner type's rms radius is clearly smaller (4c: 0.57-0.60; everything else >= 0.85) ...
SHELL_RADIUS_RATIO = 0.8
#: ... and the two types are concentric: centroid distance over R_g of all agents at most this (4c:
#: 0.010-0.014). Added after the held-out seeds 0-4: two separate groups of unequal size (5c seed 0)
#: look radially sorted about the common centroid, which lies inside the larger group (1.97 there).
SHELL_CENTROID_REL = 0.3
#: Separate groups (5c): the types are fully segregated (5c: S = 0.985-1.000) ...
SEPARATE_SEGREGATION = 0.9
#: ... and hardly ever touch: heterotypic contacts (pairs within R_a) at most this fraction of the
#: random-mix expectation (5c: 0.000-0.024; touching groups 4a, 4b: ~0.27).
SEPARATE_CONTACT_RATIO = 0.1
#: A loose swarm (5d): mean nearest-neighbour distance above this (5d: 1.31-1.34; the compact flocks
#: pack at the separation radius: 0.64-0.99).
LOOSE_NN_DISTANCE = 1.15
#: Segregated: the same-type neighbour fraction is this far from the random mix towards complete
#: segregation (sorted 4a: 0.84-0.87, 4b: 0.89; half-split 5b: 0.42-0.64).
SEGREGATED = 0.75
#: Partly segregated: a flock with S above this is sorting or split (arrested 4a: 0.09-0.25, 4d:
#: -0.03-0.29, half-split 5b: 0.42-0.64); below it the types are mixed (5a: -0.04-0.02).
PARTLY_SEGREGATED = 0.07
#: Half-segregated: S above this in an agitated flock is the half-split of 5b (0.42-0.64), below
#: it the weak split of 4d (up to 0.29).
HALF_SEGREGATED = 0.3
#: Two hemispheres of one round flock (the paper's 4d picture) rather than two groups side by side
#: (4a, 4b): the whole is round (elongation sqrt(l1/l3) below this; two touching balls ~2, sorted
#: 4a/4b 1.45-1.56, one ball 1.0) ...
ROUND_ELONGATION = 1.25
#: ... and the type centroids are close relative to R_g of all agents (hemispheres of a ball 0.97,
#: sorted 4a/4b 1.2-1.26, two touching balls 1.58).
HEMISPHERE_CENTROID_REL = 1.1
#: Swarm speed of a segregated pair: 4b's types do not align with their own type (W_a diagonal 0)
#: and jitter at 0.10; 4a's aligned types at 0.05.
SWARM_SPEED = 0.075
#: Agitated flock: a single compact flock above this mean speed has cross-type anti-alignment
#: (4d: 0.063-0.065, half-split 5b: 0.058-0.062); below it the types align with each other or not at
#: all (5a: 0.054-0.055, 4a: 0.046-0.050). A kinematic signature, not a shape: see classify().
AGITATED_SPEED = 0.057

PATTERN_LABELS = ("4a", "4b", "4c", "4d", "5a", "5b", "5c", "5d", "other")


def classify(m: dict) -> tuple[str, dict]:
    """The pattern (``"4a"`` ... ``"5d"`` or ``"other"``) of averaged measures ``m`` (:func:`measures`)
    and the reasons: ``{"rule": ..., "state": what was seen, "paper_picture": whether it is the
    picture the paper draws for that label, "tests": [(measure, value, op, threshold, passed)]}``.

    The decision tree (thresholds: module constants):

    1. ``speed >= FAST_SPEED`` -> **5b** (fast groups that collide and hit the walls).
    2. ``radial_sorting_error <= SHELL_SORTING_ERROR``, ``radius_ratio <= SHELL_RADIUS_RATIO`` and
       ``centroid_distance_rel <= SHELL_CENTROID_REL`` -> **4c** (one type a concentric shell around
       the other).
    3. ``segregation_index >= SEPARATE_SEGREGATION`` and ``contact_ratio <= SEPARATE_CONTACT_RATIO``
       -> **5c** (groups of one type each that do not touch).
    4. ``nn_distance >= LOOSE_NN_DISTANCE`` -> **5d** if ``segregation_index >= HALF_SEGREGATED``
       (loose unmixed groups), else *other*.
    5. ``n_groups >= 2`` (several groups not sorted by type) -> *other*.
    6. ``segregation_index >= SEGREGATED`` (two halves of one flock): **4d** if the whole is round and
       the centroids close (``elongation < ROUND_ELONGATION`` and ``centroid_distance_rel <
       HEMISPHERE_CENTROID_REL``: hemispheres); else **4b** if ``speed >= SWARM_SPEED`` (swarms
       with a wide interface), else **4a** (two groups side by side).
    7. One compact flock, not fully segregated, told apart by its agitation (mean speed), since its
       shape alone does not separate the presets at n = 300 in this engine:
       ``speed >= AGITATED_SPEED`` (cross-type anti-alignment): **5b** if ``segregation_index >=
       HALF_SEGREGATED`` (the flock split in two halves with a mixed interface: the state the 5b
       weights reach when the two groups never separate), else **4d** if ``segregation_index >=
       PARTLY_SEGREGATED`` (a weak split into two halves), else **5a** (mixed); calm: **4a** if
       ``segregation_index >= PARTLY_SEGREGATED`` (sorting under way or arrested), else **5a**.

    ``paper_picture`` is False for the labels of rule 7 other than 5a: those states are not the
    pictures the paper draws (4a: two groups side by side; 4d: clean hemispheres; 5b: fast colliding
    groups) but the states the presets' weights reach instead in this engine at n = 300, told apart
    by agitation and partial segregation.
    """
    tests: list = []

    def t(key, op, thr):
        val = m.get(key)
        ok = val is not None and (val >= thr if op == ">=" else val <= thr if op == "<=" else val < thr)
        tests.append((key, None if val is None else round(float(val), 4), op, thr, bool(ok)))
        return ok

    def done(label, rule, state, picture):
        return label, {"rule": rule, "state": state, "paper_picture": picture, "tests": tests}

    if m.get("segregation_index") is None:
        tests.append(("segregation_index", None, "defined", None, False))
        return done("other", "0", "fewer than two types", False)
    if t("speed", ">=", FAST_SPEED):
        return done("5b", "1", "fast groups colliding and hitting the walls", True)
    if (t("radial_sorting_error", "<=", SHELL_SORTING_ERROR) & t("radius_ratio", "<=", SHELL_RADIUS_RATIO)
            & t("centroid_distance_rel", "<=", SHELL_CENTROID_REL)):
        return done("4c", "2", f"type {m.get('inner_type')} inside a shell of the other", True)
    if t("segregation_index", ">=", SEPARATE_SEGREGATION) & t("contact_ratio", "<=", SEPARATE_CONTACT_RATIO):
        return done("5c", "3", "separate groups of one type each, hardly touching", True)
    if t("nn_distance", ">=", LOOSE_NN_DISTANCE):
        if t("segregation_index", ">=", HALF_SEGREGATED):
            return done("5d", "4", "loose swarm, types unmixed", True)
        return done("other", "4", "loose swarm, types mixed", False)
    if t("n_groups", ">=", 2):
        return done("other", "5", "several groups, not sorted by type", False)
    if t("segregation_index", ">=", SEGREGATED):
        if t("elongation", "<", ROUND_ELONGATION) & t("centroid_distance_rel", "<", HEMISPHERE_CENTROID_REL):
            return done("4d", "6", "one round flock split into two hemispheres", True)
        if t("speed", ">=", SWARM_SPEED):
            return done("4b", "6", "two segregated swarms with a wide interface", True)
        return done("4a", "6", "two segregated groups side by side", True)
    if t("speed", ">=", AGITATED_SPEED):
        if t("segregation_index", ">=", HALF_SEGREGATED):
            return done("5b", "7", "one round flock split in two halves with a mixed interface (agitated)", False)
        if t("segregation_index", ">=", PARTLY_SEGREGATED):
            return done("4d", "7", "one round flock, types weakly split (agitated)", False)
        return done("5a", "7", "one mixed flock (agitated)", True)
    if t("segregation_index", ">=", PARTLY_SEGREGATED):
        return done("4a", "7", "one flock, types partly sorted (calm)", False)
    return done("5a", "7", "one mixed flock", True)


# One type (the homogeneous boids of Nakamura 2013 Fig. 2). Thresholds set by hand on the 16 cells of
# Fig. 2's grid, seeds 0 and 1, n = 300 (docs/results.md): every cell got the same label on both seeds,
# and every threshold lies in a gap between the cells' values.
#: Aligned lattice: polarisation at least this (w_c = 0, w_a >= 0.1: 0.85-1.00; every other cell <= 0.59).
ALIGNED_POLARISATION = 0.8
#: Compact flock: mean nearest-neighbour distance at most this (w_c = 0.1, w_a >= 0.01: 0.21-0.53; others >= 0.85).
COMPACT_NN_DISTANCE = 0.6
#: Spread: RMS distance from the centroid above this, box units (no flock: 5.0-9.7; one cloud: 1.8-3.6).
SPREAD_RADIUS = 4.3
#: Lattice (a slow cloud spaced at about R_s) below this mean speed per step, swarm above it
#: (w_c = 0.001, w_a >= 0.1: 0.012-0.030; w_c = 0.01, w_a >= 0.01: 0.066-0.153).
LATTICE_SPEED = 0.05
HOMOGENEOUS_LABELS = ("aligned lattice", "lattice", "compact flock", "swarm", "spread")


def classify_homogeneous(m: dict) -> tuple[str, dict]:
    """The regime of a one-type run (Nakamura 2013 Fig. 2, section 2.2) from its averaged measures ``m``
    (:func:`measures`), and the reasons (as :func:`classify`'s):

    1. ``polarisation >= ALIGNED_POLARISATION`` -> **aligned lattice** (every agent heading the same way).
    2. ``nn_distance <= COMPACT_NN_DISTANCE`` -> **compact flock**.
    3. ``radial_rms_0 > SPREAD_RADIUS`` -> **spread** (no flock: the agents fill much of the box).
    4. ``speed < LATTICE_SPEED`` -> **lattice** (one slow cloud, agents about R_s apart: the paper's
       "lattice-like" spacing).
    5. else **swarm** (one agitated, unaligned cloud: the paper's midge-like swarm).

    A run that diverges (w_a >= 10 or w_c >= 1) is labelled ``diverged`` by the caller.
    """
    tests: list = []

    def t(key, op, thr):
        val = m.get(key)
        ok = val is not None and (val >= thr if op == ">=" else val <= thr if op == "<=" else
                                  val > thr if op == ">" else val < thr)
        tests.append((key, None if val is None else round(float(val), 4), op, thr, bool(ok)))
        return ok

    def done(label, rule, state):
        return label, {"rule": rule, "state": state, "paper_picture": True, "tests": tests}

    if t("polarisation", ">=", ALIGNED_POLARISATION):
        return done("aligned lattice", "1", "every agent heading the same way")
    if t("nn_distance", "<=", COMPACT_NN_DISTANCE):
        return done("compact flock", "2", "a dense flock")
    if t("radial_rms_0", ">", SPREAD_RADIUS):
        return done("spread", "3", "agents spread over the box, no flock")
    if t("speed", "<", LATTICE_SPEED):
        return done("lattice", "4", "one slow cloud, agents about R_s apart")
    return done("swarm", "5", "one agitated, unaligned cloud")


def simulate_and_measure(params, seed: int, n: int | None = None, n_steps: int = RUN_STEPS,
                         window: int = WINDOW_STEPS, record_every: int = RECORD_EVERY) -> dict:
    """Run ``params`` (:class:`~lifelike_mj.boids.engine.BoidParams`) for ``n_steps`` steps, recording
    only the last ``window`` steps, and return :func:`measures` over that window."""
    from lifelike_mj.boids.engine import N_AGENTS
    from lifelike_mj.boids.sim import simulate

    run = simulate(params, n=N_AGENTS if n is None else n, n_steps=n_steps, seed=seed, record_every=record_every,
                   record_from=max(0, n_steps - window + 1))
    return measures(run, window=window)
