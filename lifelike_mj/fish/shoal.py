"""Measures of fish living together, from their tracks alone: spacing, order, kicks, speed and walls.

Every function reads positions over time (what a video tracker gives of real fish), never the model, so that the
same code scores a simulated tank and a filmed one. Units: SI in and out (m, s, m/s), and body lengths where a name
says ``_bl``. Headings are horizontal (x along the tank, y across): fish in a shallow or wide tank swim mostly level,
and the published order parameters are planar (Couzin et al. 2002; Tunstrom et al. 2013; Calovi et al. 2018).
Distances between fish are three-dimensional.

* **Velocity** (:func:`velocities`): central differences of the positions (one-sided at the ends).
* **Nearest-neighbour distance** (:func:`nearest_neighbour_m`): per fish and sample, the distance to the closest
  other fish's centre, found with a k-d tree (:class:`scipy.spatial.cKDTree`) sample by sample for many fish, so
  that the memory grows with the number of fish, not with its square times the samples.
* **Polarisation** ``O_P = |mean_i h_i|`` (:func:`polarisation`), ``h_i`` the unit horizontal heading: 1 when all
  swim the same way, about ``sqrt(pi / (4 N))`` for ``N`` fish heading independently (0.28 for ten).
* **Milling** ``O_R = |mean_i (r_i x h_i)_z|`` (:func:`milling`), ``r_i`` the unit horizontal vector from the
  group's centroid to fish ``i``: 1 when all circle the centroid the same way. Tunstrom et al. (2013) call a group
  polarised when ``O_P > 0.65`` and ``O_R < 0.35``, milling when ``O_R > 0.65`` and ``O_P < 0.35``, a swarm when
  both are below 0.35.
* **Cohesion** (:func:`cohesion_m`): the mean distance of the fish from their centroid.
* **Spread of depths** (:func:`depth_spread_m`): the standard deviation of the fish's heights, how flat a group is.
* **Kicks** (:func:`kick_times`): the onsets of speed rises. A kick is a local minimum of a fish's speed followed by a
  rise of at least ``rise_bl_s`` body lengths per second before the speed next falls: a burst-and-coast fish's
  kicks, as Calovi et al. (2018) segment their tetras' tracks (heading and speed change at the kick, then a glide).
* **Distance to the wall** (:func:`wall_distance_m`): horizontal, to the nearest side wall of a box tank centred
  on the origin (``tank_m`` = length, depth, height).
* **Neighbour maps** (:func:`neighbour_frame`): where each other fish is in the focal fish's frame (ahead, to its
  left) and how it heads relative to it: the maps Calovi et al. draw.

:func:`group_measures` summarises all of them for a swim.
"""

from __future__ import annotations

import numpy as np

#: A fish slower than this (body lengths per second) has no heading in the order parameters.
MIN_SPEED_BL_S = 0.05
#: A kick is a speed rise of at least this much (body lengths per second) from a local minimum.
KICK_RISE_BL_S = 0.5
#: Above this many fish, the neighbours of a fish are found with a k-d tree (:class:`scipy.spatial.cKDTree`) rather
#: than among all pairs (faster for a few fish); both give the same numbers.
TREE_MIN_FISH = 32
#: The most memory (bytes) that one chunk of pairs of fish may take while a measure is computed: measures over pairs
#: go through the frames (and, for many fish, the fish) in chunks of this size rather than all at once.
PAIR_CHUNK_BYTES = 32 * 2**20


def _positions(positions) -> np.ndarray:
    p = np.asarray(positions, dtype=float)
    if p.ndim == 2:
        p = p[:, None, :]
    if p.ndim != 3 or p.shape[-1] != 3:
        raise ValueError(f"positions must have shape (T, F, 3) or (T, 3), got {p.shape}")
    return p


def velocities(times_s, positions) -> np.ndarray:
    """Velocities (T, F, 3) in m/s of positions (T, F, 3) sampled at ``times_s`` (T,) strictly increasing:
    central differences inside, one-sided at the two ends (``numpy.gradient``)."""
    t = np.asarray(times_s, dtype=float)
    p = _positions(positions)
    if t.ndim != 1 or t.size < 2 or t.size != p.shape[0] or not np.all(np.diff(t) > 0):
        raise ValueError("times_s must be strictly increasing, one time per sample, at least two")
    return np.gradient(p, t, axis=0)


def headings(vel, min_speed_m_s: float = 0.0) -> np.ndarray:
    """Unit horizontal headings (T, F, 2) of velocities (T, F, 3); NaN where the horizontal speed is at most
    ``min_speed_m_s`` (or zero)."""
    v = np.asarray(vel, dtype=float)[..., :2]
    s = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        h = v / s
    h[(s[..., 0] <= max(min_speed_m_s, 0.0)) | (s[..., 0] == 0.0)] = np.nan
    return h


def nearest_neighbour_m(positions) -> np.ndarray:
    """Per sample and fish (T, F), the distance (m) to the nearest other fish's centre (NaN for a lone fish).

    Frame by frame (memory grows with ``F``, not ``F^2`` or ``T``): all pairs of a chunk of frames for
    :data:`TREE_MIN_FISH` fish or fewer, a k-d tree (:class:`scipy.spatial.cKDTree`) above; either way the distance
    returned is ``|p_i - p_j|`` computed as the all-pairs distance was, so both give the same numbers. A frame with a
    position that is not finite is measured over all pairs (a NaN makes its frame NaN, as there)."""
    p = _positions(positions)
    T, F, _ = p.shape
    if F < 2:
        return np.full((T, F), np.nan)
    out = np.empty((T, F))
    if F <= TREE_MIN_FISH:
        for a, b in _chunks(T, 24 * F * F):
            d = np.linalg.norm(p[a:b, :, None, :] - p[a:b, None, :, :], axis=-1)
            d[:, np.arange(F), np.arange(F)] = np.inf
            out[a:b] = d.min(axis=2)
        return out
    from scipy.spatial import cKDTree

    me = np.arange(F)
    for k in range(T):
        q = p[k]
        if not np.isfinite(q).all():
            out[k] = _nearest_all_pairs(q)
            continue
        _, j = cKDTree(q).query(q, k=2)
        other = np.where(j[:, 0] == me, j[:, 1], j[:, 0])  # two fish at one place: either is the other's nearest
        out[k] = np.linalg.norm(q[other] - q, axis=-1)
    return out


def _chunks(n: int, bytes_each: int):
    """``(start, stop)`` of chunks of ``n`` items (frames, or rows of fish) of ``bytes_each`` bytes each, every chunk
    within :data:`PAIR_CHUNK_BYTES`."""
    step = max(1, PAIR_CHUNK_BYTES // max(1, bytes_each))
    return ((a, min(a + step, n)) for a in range(0, n, step))


def _nearest_all_pairs(q: np.ndarray) -> np.ndarray:
    """:func:`nearest_neighbour_m` of one frame ``q`` (F, 3) over all pairs, a block of fish at a time."""
    F = q.shape[0]
    out = np.empty(F)
    for a, b in _chunks(F, 24 * F):
        d = np.linalg.norm(q[a:b, None, :] - q[None, :, :], axis=-1)
        d[np.arange(b - a), np.arange(a, b)] = np.inf
        out[a:b] = d.min(axis=1)
    return out


def polarisation(head) -> np.ndarray:
    """``O_P`` per sample (T,): the length of the mean of the unit headings (T, F, 2), over the fish that have one
    (NaN where none has)."""
    h = np.asarray(head, dtype=float)
    ok = np.all(np.isfinite(h), axis=-1)
    n = ok.sum(axis=1)
    s = np.where(ok[..., None], h, 0.0).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.linalg.norm(s, axis=-1) / n, np.nan)


def milling(positions, head) -> np.ndarray:
    """``O_R`` per sample (T,): ``|mean_i (r_i x h_i)_z|`` with ``r_i`` the unit horizontal vector from the centroid
    of all fish to fish ``i`` and ``h_i`` its unit heading, over the fish that have both."""
    p = _positions(positions)[..., :2]
    h = np.asarray(head, dtype=float)
    r = p - p.mean(axis=1, keepdims=True)
    rn = np.linalg.norm(r, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = r / rn
    cross = r[..., 0] * h[..., 1] - r[..., 1] * h[..., 0]
    ok = np.isfinite(cross)
    n = ok.sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.abs(np.where(ok, cross, 0.0).sum(axis=1)) / n, np.nan)


def cohesion_m(positions) -> np.ndarray:
    """Per sample (T,), the mean distance (m) of the fish from their centroid."""
    p = _positions(positions)
    return np.linalg.norm(p - p.mean(axis=1, keepdims=True), axis=-1).mean(axis=1)


def depth_spread_m(positions) -> np.ndarray:
    """Per sample (T,), the standard deviation (m) of the fish's depths: how flat the group is."""
    return np.std(_positions(positions)[..., 2], axis=1)


def kick_times(times_s, speed, rise_m_s: float) -> np.ndarray:
    """The kicks of one fish: the times (s) of the local minima of ``speed`` (m/s, one per time in ``times_s``) from
    which the speed rises by at least ``rise_m_s`` before it next falls. A flat stretch counts as one minimum, at its
    start."""
    t = np.asarray(times_s, dtype=float)
    v = np.asarray(speed, dtype=float)
    if v.size < 3:
        return np.zeros(0)
    dv = np.diff(v)
    sign = np.sign(dv)
    # carry the last non-zero slope over flat stretches, so that a plateau is not a turning point
    for i in range(1, sign.size):
        if sign[i] == 0:
            sign[i] = sign[i - 1]
    kicks = []
    i, n = 0, v.size
    while i < n - 1:
        if sign[i] > 0 and (i == 0 or sign[i - 1] < 0):
            j = i
            while j < n - 1 and sign[j] >= 0:
                j += 1
            if v[j] - v[i] >= rise_m_s:
                kicks.append(t[i])
            i = j
        else:
            i += 1
    return np.asarray(kicks)


def kick_intervals_s(times_s, speed, rise_m_s: float) -> np.ndarray:
    """The intervals (s) between consecutive kicks (:func:`kick_times`) of each fish, pooled over the fish (an
    interval never spans two fish); ``speed`` (T, F) m/s, one row per time in ``times_s``."""
    v = np.asarray(speed, dtype=float).reshape(len(times_s), -1)
    return np.concatenate([np.zeros(0)] + [np.diff(kick_times(times_s, v[:, f], rise_m_s)) for f in range(v.shape[1])])


def wall_distance_m(positions, tank_m) -> np.ndarray:
    """Per sample and fish (T, F), the horizontal distance (m) to the nearest side wall of a box tank of
    ``tank_m = (length, depth, height)`` centred on the origin in x and y."""
    p = _positions(positions)
    L, D = float(tank_m[0]), float(tank_m[1])
    return np.minimum(L / 2 - np.abs(p[..., 0]), D / 2 - np.abs(p[..., 1]))


def neighbour_frame(positions, head) -> tuple[np.ndarray, np.ndarray]:
    """Where the other fish are as each fish sees them: ``(rel, dphi)`` with ``rel`` (M, 2), a neighbour's horizontal
    position in the focal fish's frame (m: ahead, to its left) and ``dphi`` (M,) its heading less the focal fish's
    (rad, in ``(-pi, pi]``), for every sample and ordered pair whose two headings exist (sample by sample, then pair
    by pair: ``M`` is up to ``T F (F - 1)``, and the work goes through the frames in chunks of
    :data:`PAIR_CHUNK_BYTES`)."""
    p = _positions(positions)[..., :2]
    h = np.asarray(head, dtype=float)
    T, F, _ = p.shape
    if F < 2:
        return np.zeros((0, 2)), np.zeros(0)
    i, j = np.nonzero(~np.eye(F, dtype=bool))
    rels, dphis = [np.zeros((0, 2))], [np.zeros(0)]
    for a, b in _chunks(T, 128 * i.size):
        d = p[a:b, j] - p[a:b, i]  # (frames, P, 2)
        hi, hj = h[a:b, i], h[a:b, j]
        ahead = d[..., 0] * hi[..., 0] + d[..., 1] * hi[..., 1]
        left = -d[..., 0] * hi[..., 1] + d[..., 1] * hi[..., 0]
        dphi = np.arctan2(hi[..., 0] * hj[..., 1] - hi[..., 1] * hj[..., 0],
                          hi[..., 0] * hj[..., 0] + hi[..., 1] * hj[..., 1])
        ok = np.isfinite(ahead) & np.isfinite(dphi)
        rels.append(np.stack([ahead[ok], left[ok]], axis=-1))
        dphis.append(dphi[ok])
    return np.concatenate(rels), np.concatenate(dphis)


def _pair_distances_m(positions: np.ndarray, head: np.ndarray) -> np.ndarray:
    """The 3D distances (m) between the centres of every ordered pair of fish whose two headings exist, sample by
    sample (as :func:`neighbour_frame` orders them), in chunks of frames."""
    T, F, _ = positions.shape
    i, j = np.nonzero(~np.eye(F, dtype=bool))
    out = [np.zeros(0)]
    for a, b in _chunks(T, 64 * i.size):
        d3 = np.linalg.norm(positions[a:b, j] - positions[a:b, i], axis=-1)  # (frames, P)
        ok = np.isfinite(head[a:b, i, 0]) & np.isfinite(head[a:b, j, 0])
        out.append(d3[ok])
    return np.concatenate(out)


def _stats(x: np.ndarray) -> dict:
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if not x.size:
        nan = float("nan")
        return {"mean": nan, "median": nan, "p5": nan, "p95": nan}
    return {"mean": float(x.mean()), "median": float(np.median(x)), "p5": float(np.percentile(x, 5)),
            "p95": float(np.percentile(x, 95))}


def group_measures(times_s, positions, body_length_m: float, tank_m=None, *, skip_s: float = 0.0,
                   kick_rise_bl_s: float = KICK_RISE_BL_S, min_speed_bl_s: float = MIN_SPEED_BL_S) -> dict:
    """The measures of the module docstring for a swim: ``times_s`` (T,), ``positions`` (T, F, 3) m, the fish's
    ``body_length_m``, the box tank ``tank_m`` (length, depth, height; None: no wall distance). Samples before
    ``skip_s`` (s after the first) are left out (the start from rest). Returns a JSON-ready dict:

    * ``nn_distance_bl``: the nearest-neighbour distance's mean, median, 5th and 95th percentiles over fish and
      samples (body lengths), and ``near_fraction_2bl``: the fraction of fish and samples with a neighbour within
      2 body lengths;
    * ``polarisation`` and ``milling``: their means over samples, and the fractions of samples polarised, milling
      or swarming by Tunstrom et al.'s thresholds;
    * ``cohesion_bl``: the mean distance from the centroid (body lengths), its mean over samples;
    * ``depth_spread_bl``: the standard deviation of the fish's depths (body lengths), its mean over samples: how
      flat the group is (neighbours in real schools keep to a similar depth, Partridge et al. 1980);
    * ``kick_interval_s``: the intervals between a fish's consecutive kicks, pooled: mean, CV (standard deviation over
      mean), minimum, 5th percentile, median and count;
    * ``speed_bl_s``: the speed's mean, median, 5th and 95th percentiles (body lengths per second);
    * ``wall_distance_bl``: the distance to the nearest side wall's mean, median, 5th and 95th percentiles."""
    t = np.asarray(times_s, dtype=float)
    p = _positions(positions)
    if not body_length_m > 0:
        raise ValueError("body_length_m must be positive")
    vel = velocities(t, p)
    keep = t >= t[0] + skip_s
    t, p, vel = t[keep], p[keep], vel[keep]
    bl = float(body_length_m)
    head = headings(vel, min_speed_bl_s * bl)
    speed = np.linalg.norm(vel, axis=-1)
    nan = float("nan")
    out: dict = {"fish": int(p.shape[1]), "samples": int(p.shape[0]), "body_length_m": bl, "skip_s": float(skip_s)}
    nn = nearest_neighbour_m(p) / bl
    out["nn_distance_bl"] = _stats(nn)
    out["near_fraction_2bl"] = float(np.mean(nn[np.isfinite(nn)] <= 2.0)) if np.isfinite(nn).any() else nan
    op, orr = polarisation(head), milling(p, head)
    ok = np.isfinite(op) & np.isfinite(orr)
    out["polarisation"] = float(np.nanmean(op)) if ok.any() else nan
    out["milling"] = float(np.nanmean(orr)) if ok.any() else nan
    out["state_fractions"] = {
        "polarised": float(np.mean((op[ok] > 0.65) & (orr[ok] < 0.35))) if ok.any() else nan,
        "milling": float(np.mean((orr[ok] > 0.65) & (op[ok] < 0.35))) if ok.any() else nan,
        "swarm": float(np.mean((op[ok] < 0.35) & (orr[ok] < 0.35))) if ok.any() else nan}
    out["cohesion_bl"] = float(cohesion_m(p).mean() / bl)
    out["depth_spread_bl"] = float(depth_spread_m(p).mean() / bl)
    iv = kick_intervals_s(t, speed, kick_rise_bl_s * bl)
    out["kick_interval_s"] = {
        "count": int(iv.size), "mean": float(iv.mean()) if iv.size else nan,
        "cv": float(iv.std() / iv.mean()) if iv.size > 1 and iv.mean() > 0 else nan,
        "min": float(iv.min()) if iv.size else nan, "p5": float(np.percentile(iv, 5)) if iv.size else nan,
        "median": float(np.median(iv)) if iv.size else nan}
    out["speed_bl_s"] = _stats(speed / bl)
    out["wall_distance_bl"] = _stats(wall_distance_m(p, tank_m) / bl) if tank_m is not None else None
    return out


def wall_angle_rad(positions, head, tank_m) -> np.ndarray:
    """Per sample and fish (T, F), the angle (rad, in ``[0, pi]``) between a fish's horizontal heading and the outward
    normal of the nearest side wall of a box tank (``tank_m`` as in :func:`wall_distance_m`): 0 swimming straight at
    the wall, ``pi / 2`` along it, ``pi`` straight away. Calovi et al. (2018)'s ``theta_w`` in a circular tank, read
    in a box; NaN where a fish has no heading."""
    p = _positions(positions)
    h = np.asarray(head, dtype=float)
    L, D = float(tank_m[0]), float(tank_m[1])
    gx, gy = L / 2 - np.abs(p[..., 0]), D / 2 - np.abs(p[..., 1])
    nx = np.where(gx <= gy, np.sign(p[..., 0]), 0.0)
    ny = np.where(gx <= gy, 0.0, np.sign(p[..., 1]))
    return np.arccos(np.clip(h[..., 0] * nx + h[..., 1] * ny, -1.0, 1.0))


def kick_segments(times_s, positions, body_length_m: float, *, kick_rise_bl_s: float = KICK_RISE_BL_S
                  ) -> dict:
    """Each fish's track cut at its kicks (:func:`kick_times`), pooled over the fish: ``duration_s`` (from one kick's
    onset to the next), ``length_m`` (the path swum in that time), and ``glide_tau_s`` with ``glide_power``: how the
    speed decays after the kick's peak, fitted on each segment with at least 6 samples of falling speed.

    ``glide_tau_s`` is the time constant ``tau`` of an exponential decay ``v = v_k exp(-t / tau)`` (Calovi et al.'s
    glide, linear drag), fitted to ``ln v``; ``glide_power`` says which law fits the segment better, 1 for the
    exponential and 2 for the hyperbolic decay ``v = v_k / (1 + t / t_h)`` of quadratic drag (a straight line in
    ``1 / v``), by the smaller root-mean-square residual in speed."""
    t = np.asarray(times_s, dtype=float)
    p = _positions(positions)
    vel = velocities(t, p)
    speed = np.linalg.norm(vel, axis=-1)
    step = np.linalg.norm(np.diff(p, axis=0), axis=-1)  # (T-1, F)
    dur, length, taus, power = [], [], [], []
    for f in range(p.shape[1]):
        kt = kick_times(t, speed[:, f], kick_rise_bl_s * body_length_m)
        idx = np.searchsorted(t, kt)
        for a, b in zip(idx[:-1], idx[1:], strict=True):
            dur.append(t[b] - t[a])
            length.append(step[a:b, f].sum())
            v = speed[a:b + 1, f]
            k = int(np.argmax(v))
            g, tg = v[k:], t[a + k:b + 1] - t[a + k]
            if g.size < 6 or g.min() <= 0.0:
                continue
            slope, icpt = np.polyfit(tg, np.log(g), 1)
            if slope >= 0.0:
                continue
            taus.append(-1.0 / slope)
            res_exp = np.sqrt(np.mean((np.exp(icpt + slope * tg) - g) ** 2))
            s2, i2 = np.polyfit(tg, 1.0 / g, 1)
            fit2 = i2 + s2 * tg
            res_hyp = np.sqrt(np.mean((1.0 / fit2 - g) ** 2)) if np.all(fit2 > 0) else np.inf
            power.append(1 if res_exp <= res_hyp else 2)
    return {"duration_s": np.asarray(dur), "length_m": np.asarray(length), "glide_tau_s": np.asarray(taus),
            "glide_power": np.asarray(power, dtype=int)}


def pair_quantities(times_s, positions, body_length_m: float, tank_m, *, skip_s: float = 0.0,
                    kick_rise_bl_s: float = KICK_RISE_BL_S, min_speed_bl_s: float = MIN_SPEED_BL_S) -> dict:
    """The quantities whose distributions Calovi et al. (2018) report for one and for two fish, for every sample
    (after ``skip_s``) and fish, as arrays (units in the names): ``wall_distance_bl``, ``wall_angle_deg``
    (:func:`wall_angle_rad`), ``speed_bl_s``; for two fish or more, over the ordered pairs, ``distance_bl`` (3D,
    between centres), ``heading_difference_deg`` (``|dphi|``, 0 swimming the same way) and ``viewing_angle_deg``
    (``|psi|``, where the neighbour lies from the focal fish's heading: 0 ahead, 180 behind); and from the kicks
    (:func:`kick_segments`), ``kick_duration_s``, ``kick_length_bl``, ``glide_tau_s`` and ``glide_power``."""
    t = np.asarray(times_s, dtype=float)
    p = _positions(positions)
    bl = float(body_length_m)
    vel = velocities(t, p)
    keep = t >= t[0] + skip_s
    t, p, vel = t[keep], p[keep], vel[keep]
    head = headings(vel, min_speed_bl_s * bl)
    out = {"wall_distance_bl": (wall_distance_m(p, tank_m) / bl).ravel(),
           "wall_angle_deg": np.degrees(wall_angle_rad(p, head, tank_m)).ravel(),
           "speed_bl_s": (np.linalg.norm(vel, axis=-1) / bl).ravel()}
    out["wall_angle_deg"] = out["wall_angle_deg"][np.isfinite(out["wall_angle_deg"])]
    if p.shape[1] >= 2:
        rel, dphi = neighbour_frame(p, head)
        out["distance_bl"] = _pair_distances_m(p, head) / bl
        out["heading_difference_deg"] = np.degrees(np.abs(dphi))
        out["viewing_angle_deg"] = np.degrees(np.abs(np.arctan2(rel[:, 1], rel[:, 0])))
    seg = kick_segments(t, p, bl, kick_rise_bl_s=kick_rise_bl_s)
    out.update(kick_duration_s=seg["duration_s"], kick_length_bl=seg["length_m"] / bl,
               glide_tau_s=seg["glide_tau_s"], glide_power=seg["glide_power"])
    return out


def pair_measures(times_s, positions, body_length_m: float, tank_m, **kwargs) -> dict:
    """:func:`pair_quantities` summarised for JSON: each array's mean, median, 5th and 95th percentiles, and for the
    glides the fraction that the exponential fits better (``glide_exponential_fraction``); ``kwargs`` as there."""
    q = pair_quantities(times_s, positions, body_length_m, tank_m, **kwargs)
    out = {k: _stats(v) for k, v in q.items() if k != "glide_power"}
    gp = q["glide_power"]
    out["kick_duration_s"]["cv"] = (float(q["kick_duration_s"].std() / q["kick_duration_s"].mean())
                                    if q["kick_duration_s"].size > 1 else float("nan"))
    out["glide_exponential_fraction"] = float(np.mean(gp == 1)) if gp.size else float("nan")
    out["kicks"] = int(q["kick_duration_s"].size)
    return out


def largest_group(positions, link_m: float) -> np.ndarray:
    """The fish of the largest group at one moment: ``positions`` (F, 3) m; two fish are in one group when a chain of
    fish, each within ``link_m`` of the next, joins them. Returns the group's fish indices, sorted (ties: the group
    of the lowest index). The pairs within ``link_m`` come from a k-d tree above :data:`TREE_MIN_FISH` fish (memory
    that grows with the pairs found, not with ``F^2``), their distances computed as over all pairs."""
    p = np.asarray(positions, dtype=float).reshape(-1, 3)
    F = p.shape[0]
    a, b = _pairs_within(p, link_m)
    # each group labelled by its lowest index (what a search from each unlabelled fish in turn gives)
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    _, comp = connected_components(coo_matrix((np.ones(a.size, dtype=bool), (a, b)), shape=(F, F)), directed=False)
    lowest = np.full(comp.max() + 1, F)
    np.minimum.at(lowest, comp, np.arange(F))
    label = lowest[comp]
    sizes = np.bincount(label, minlength=F)
    return np.flatnonzero(label == int(np.argmax(sizes)))


def _pairs_within(p: np.ndarray, link_m: float) -> tuple[np.ndarray, np.ndarray]:
    """The pairs ``(a, b)`` of fish (``a < b``) whose centres ``p`` (F, 3) lie within ``link_m`` of each other, by
    ``|p_a - p_b| <= link_m``: from a k-d tree (candidates a hair beyond ``link_m``, then that test) above
    :data:`TREE_MIN_FISH` fish with finite positions, else over all pairs, a block of fish at a time."""
    F = p.shape[0]
    none = np.zeros(0, dtype=np.int64)
    if not link_m >= 0.0:
        return none, none
    if F > TREE_MIN_FISH and np.isfinite(p).all():
        from scipy.spatial import cKDTree

        cand = cKDTree(p).query_pairs(float(link_m) * (1.0 + 1e-9), output_type="ndarray").astype(np.int64)
        if not cand.size:
            return none, none
        keep = np.linalg.norm(p[cand[:, 1]] - p[cand[:, 0]], axis=-1) <= link_m
        return cand[keep, 0], cand[keep, 1]
    A, B = [none], [none]
    for lo, hi in _chunks(F, 24 * F):
        near = np.linalg.norm(p[lo:hi, None, :] - p[None, :, :], axis=-1) <= link_m
        r, c = np.nonzero(near)
        r = r + lo
        A.append(r[r < c])
        B.append(c[r < c])
    return np.concatenate(A), np.concatenate(B)


def front_of_group(positions, vel, link_m: float) -> tuple[int, np.ndarray]:
    """The fish at the front of the largest group (:func:`largest_group`) and the group: the member farthest along the
    group's mean horizontal velocity (``vel`` (F, 3) m/s)."""
    p = np.asarray(positions, dtype=float).reshape(-1, 3)
    g = largest_group(p, link_m)
    v = np.asarray(vel, dtype=float).reshape(-1, 3)[g, :2].mean(axis=0)
    return int(g[int(np.argmax(p[g, :2] @ v))]), g


def is_school(positions, vel, link_m: float, min_fish: int, min_polarisation: float = 0.8) -> bool:
    """Whether fish at one moment (``positions``, velocities ``vel`` (F, 3)) swim as a school: the largest group
    (:func:`largest_group`) holds at least ``min_fish`` fish, and their horizontal headings' polarisation exceeds
    ``min_polarisation``."""
    g = largest_group(positions, link_m)
    if len(g) < min_fish:
        return False
    head = headings(np.asarray(vel, dtype=float).reshape(-1, 3)[g][None], 0.0)
    return bool(polarisation(head)[0] > min_polarisation)
