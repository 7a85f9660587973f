"""Objective life-likeness measures of fish tracks, in place of the questionnaire of Satoi et al. 2015.

Satoi, Nakadai & Hoshino 2015 generate life-like tropical-fish motion from the "burstiness" and
"diversity" of motion: each fish switches among four motion units (MU 0 accelerate, 1 coast,
2 cruise, 3 brake) chosen by a Markov chain, and the result was judged by a questionnaire. Here
we score the generated motion with measures computed on the TRACKS ALONE (positions over time),
the way a video analysis of a real fish would (the paper analysed its videos at 24 fps), so that
the same code scores a real fish's track:

* acceleration events: video frames whose tangential acceleration exceeds a fixed threshold in
  body lengths per s^2 (a visible speed-up); bursts: trains of consecutive events (their onsets);
* burstiness of the intervals between events (Goh & Barabasi 2008, with the finite-size
  correction of Kim & Jo 2016): trains of events separated by long quiet coasts give B > 0,
  evenly spread small pushes give B near 0 or below;
* the shape of the acceleration distribution (excess kurtosis, skewness, histogram mode);
* the diversity of heading changes (Shannon entropy of the turning angles over a window).

Only :func:`mu_entropy_rate` and :func:`mu_dwell_times` read the MU log (the model's own
choices); nothing here reads model parameters.

Conventions: SI units (m, s, m/s, m/s^2) unless a name says body lengths (``_bl``,
``body_lengths``); world coordinates have x horizontal along the tank, y depth (toward the
camera) and z up, so the side view seen by the camera is (x, z). Statistics use population
moments (divide by N) and ignore non-finite samples. NumPy only.

References
----------
* Satoi, Nakadai & Hoshino 2015, life-like tropical-fish animation from burstiness and diversity
  of motion (the model and its 24 fps video analysis).
* Goh & Barabasi 2008, "Burstiness and memory in complex systems", EPL 81, 48002.
* Kim & Jo 2016, "Measuring burstiness for finite event sequences", Phys. Rev. E 94, 032311.
* Karsai, Kaski, Barabasi & Kertesz 2012, Sci. Rep. 2, 397 (bursty trains of events).
* Cover & Thomas, "Elements of Information Theory", ch. 4 (entropy rate of a Markov chain).
"""

from __future__ import annotations

import math

import numpy as np

#: Names of the four motion units of Satoi et al. 2015, indexed by MU number.
MU_NAMES: tuple[str, ...] = ("accelerate", "coast", "cruise", "brake")
#: Frame rate of the paper's video analysis, frames/s.
VIDEO_FPS: float = 24.0
#: Tolerance, in bin widths, under which an angle is taken to lie on a bin edge (see turn_entropy).
_EDGE_TOL_BINS: float = 1e-9


def _finite(x) -> np.ndarray:
    a = np.asarray(x, dtype=float).ravel()
    return a[np.isfinite(a)]


# --------------------------------------------------------------------------------------------
# Tracks
# --------------------------------------------------------------------------------------------


def side_view(positions_xyz: np.ndarray) -> np.ndarray:
    """Project world positions onto the camera's side view: (x, y, z) -> (x, z), in m.

    ``positions_xyz`` has shape (T, 3) or (T, F, 3) (F fish), world coordinates with x along the
    tank, y depth toward the camera and z up. Returns shape (T, 2) or (T, F, 2).
    """
    p = np.asarray(positions_xyz, dtype=float)
    if p.ndim not in (2, 3) or p.shape[-1] != 3:
        raise ValueError(f"positions must have shape (T, 3) or (T, F, 3), got {p.shape}")
    return p[..., [0, 2]].copy()


def resample(times_s: np.ndarray, positions: np.ndarray, fps: float = VIDEO_FPS) -> tuple[np.ndarray, np.ndarray]:
    """Linearly interpolate a track onto a uniform grid at ``fps`` frames/s.

    ``times_s`` (T,) strictly increasing, in s; ``positions`` (T, ...) any trailing shape. The
    grid is ``times_s[0] + k / fps`` for k = 0 .. floor((times_s[-1] - times_s[0]) * fps), so it
    starts at the first sample and never extrapolates past the last. Returns ``(t, p)`` with
    ``t`` (N,) in s and ``p`` (N, ...). The paper's video analysis used 24 fps.
    """
    t = np.asarray(times_s, dtype=float)
    p = np.asarray(positions, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError("times_s must be 1-D with at least 2 samples")
    if p.shape[0] != t.size:
        raise ValueError(f"positions has {p.shape[0]} samples but times_s has {t.size}")
    if not np.all(np.diff(t) > 0):
        raise ValueError("times_s must be strictly increasing")
    if not fps > 0:
        raise ValueError("fps must be positive")
    n = int(math.floor((t[-1] - t[0]) * fps + 1e-9)) + 1
    grid = t[0] + np.arange(n) / fps
    grid[-1] = min(grid[-1], t[-1])  # guard the 1e-9 slack: never extrapolate
    i = np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 2)
    w = (grid - t[i]) / (t[i + 1] - t[i])
    w = w.reshape((-1,) + (1,) * (p.ndim - 1))
    return grid, (1.0 - w) * p[i] + w * p[i + 1]


def speed_and_accel(p2d: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Speed (m/s) and signed tangential acceleration (m/s^2) of a 2-D track sampled at ``fps``.

    ``p2d`` has shape (T, 2) or (T, F, 2), in m. ``speed[i] = |p[i+1] - p[i]| * fps`` (T-1
    values, belonging to the midpoint time of samples i and i+1); ``accel[i] = (speed[i+1] -
    speed[i]) * fps`` (T-2 values, centred on sample i+1); negative means deceleration. For
    (T, F, 2) the outputs are (T-1, F) and (T-2, F).
    """
    p = np.asarray(p2d, dtype=float)
    if p.ndim not in (2, 3) or p.shape[-1] != 2:
        raise ValueError(f"p2d must have shape (T, 2) or (T, F, 2), got {p.shape}")
    speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * fps
    accel = np.diff(speed, axis=0) * fps
    return speed, accel


# --------------------------------------------------------------------------------------------
# Acceleration distribution
# --------------------------------------------------------------------------------------------


def accel_histogram(accel: np.ndarray, bins: int = 41, limit: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Histogram of accelerations over the symmetric range [-limit, limit].

    ``accel`` any shape (flattened; non-finite samples ignored), in m/s^2 (or any unit: the
    edges come in the same unit). ``limit`` defaults to the 99th percentile of |accel| (robust
    to a few extreme frames; 1.0 when that is 0 or there is no data); samples outside the range
    are not counted (as ``np.histogram``). An odd ``bins`` (default 41) puts a bin centred on 0.
    Returns ``(counts, edges)`` with ``bins`` counts and ``bins + 1`` edges.
    """
    a = _finite(accel)
    if limit is None:
        limit = float(np.percentile(np.abs(a), 99.0)) if a.size else 0.0
        if not limit > 0:
            limit = 1.0
    if not limit > 0:
        raise ValueError("limit must be positive")
    return np.histogram(a, bins=bins, range=(-limit, limit))


def _centred(x: np.ndarray, min_n: int) -> tuple[np.ndarray, float] | None:
    """The finite samples' deviations from their mean and the population variance m2; None for
    fewer than ``min_n`` samples or no spread."""
    a = _finite(x)
    if a.size < min_n:
        return None
    d = a - a.mean()
    m2 = float(np.mean(d * d))
    return (d, m2) if m2 > 0 else None


def skewness(x: np.ndarray) -> float:
    """Sample skewness g1 = m3 / m2^1.5 with population central moments; nan for < 3 samples or no spread."""
    c = _centred(x, 3)
    if c is None:
        return float("nan")
    d, m2 = c
    return float(np.mean(d**3) / m2**1.5)


def histogram_summary(accel: np.ndarray, bins: int = 41, limit: float | None = None) -> dict[str, float]:
    """Summary of an acceleration distribution (units of ``accel``, e.g. m/s^2).

    Keys: ``mode`` (centre of the fullest bin of :func:`accel_histogram` with the same ``bins``
    and ``limit``; the first on ties), ``skewness`` (g1, population moments), ``fraction_positive``
    (share of samples > 0), ``mean``, ``median``, ``p5`` and ``p95`` (5th/95th percentiles).
    All values are Python floats; nan where there is no data.
    """
    a = _finite(accel)
    nan = float("nan")
    if a.size == 0:
        return {k: nan for k in ("mode", "skewness", "fraction_positive", "mean", "median", "p5", "p95")}
    counts, edges = accel_histogram(a, bins=bins, limit=limit)
    k = int(np.argmax(counts))
    mode = 0.5 * (edges[k] + edges[k + 1]) if counts[k] > 0 else nan
    return {
        "mode": float(mode),
        "skewness": skewness(a),
        "fraction_positive": float(np.mean(a > 0)),
        "mean": float(a.mean()),
        "median": float(np.median(a)),
        "p5": float(np.percentile(a, 5.0)),
        "p95": float(np.percentile(a, 95.0)),
    }


def kurtosis(x: np.ndarray) -> float:
    """Excess kurtosis (Fisher: normal = 0, Laplace = 3) from population moments, m4 / m2^2 - 3.

    Non-finite samples are ignored; nan for fewer than 4 samples or zero variance. Heavy-tailed
    acceleration (rare bursts among long coasts) gives large positive values.
    """
    c = _centred(x, 4)
    if c is None:
        return float("nan")
    d, m2 = c
    return float(np.mean(d**4) / (m2 * m2) - 3.0)


# --------------------------------------------------------------------------------------------
# Bursts and burstiness
# --------------------------------------------------------------------------------------------


def accel_events(accel: np.ndarray, fps: float, threshold: float, t0: float = 0.0) -> np.ndarray:
    """Times (s) of the samples of a 1-D acceleration series (sampled at ``fps``) with
    ``accel > threshold`` (strictly): the events whose intervals :func:`burstiness` scores.
    Sample ``i`` is at ``t0 + i / fps``."""
    a = np.asarray(accel, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"accel must be 1-D, got shape {a.shape}")
    return t0 + np.flatnonzero(a > threshold) / fps


def bursts(accel: np.ndarray, fps: float, threshold: float, t0: float = 0.0) -> np.ndarray:
    """Onset times (s) of bursts in a 1-D acceleration series sampled at ``fps``.

    A burst is a maximal run of consecutive samples with ``accel > threshold`` (strictly; a
    non-finite sample ends a run); its onset is the first sample of the run, at time
    ``t0 + i / fps``. A run already in progress at sample 0 counts, with onset ``t0`` (its true
    onset is unknown: left-censored).
    """
    a = np.asarray(accel, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"accel must be 1-D, got shape {a.shape}")
    above = a > threshold
    start = above & ~np.concatenate(([False], above[:-1]))
    return t0 + np.flatnonzero(start) / fps


def burstiness(intervals: np.ndarray, finite_size_correction: bool = True) -> float:
    """Burstiness of inter-event intervals, in [-1, 1]: -1 periodic, ~0 Poisson, -> 1 bursty.

    Goh & Barabasi 2008: ``B = (sigma - mu) / (sigma + mu) = (r - 1) / (r + 1)`` with
    ``r = sigma / mu`` the coefficient of variation of the intervals. With
    ``finite_size_correction`` (default) returns Kim & Jo 2016 (PRE 94, 032311) eq. for A_n::

        A_n = (sqrt(n+1) r - sqrt(n-1)) / ((sqrt(n+1) - 2) r + sqrt(n-1))

    What n is: Kim & Jo put n events in a period with periodic boundaries, so n events give n
    inter-event times, and their derivation uses n values summing to the total time. In the
    formula n is therefore the NUMBER OF INTERVALS used, and that is what we pass:
    ``n = len(intervals)`` (for an open sequence of N onsets, n = N - 1). Only with this n do
    the fixed points hold: A_n = -1 at r = 0 (periodic), A_n = 1 at the largest possible
    r = sqrt(n-1) (all time in one interval), and A_n = 0 at r = sqrt((n-1)/(n+1)), which is the
    exact mean of r^2 for n i.i.d. exponential (Poisson) intervals. ``sigma`` is the POPULATION
    standard deviation (divide by n), as in Kim & Jo (their sigma^2 = <tau^2> - <tau>^2); the
    r_max = sqrt(n-1) bound needs it.

    Intervals must be >= 0 (s, or any unit: B is scale-free). Returns nan for fewer than 3
    intervals or a zero mean. The result is clipped to [-1, 1] against rounding only.
    """
    x = np.asarray(intervals, dtype=float).ravel()
    if x.size < 3:
        return float("nan")
    if not np.all(np.isfinite(x)) or np.any(x < 0):
        raise ValueError("intervals must be finite and non-negative")
    mu = float(x.mean())
    if mu <= 0:
        return float("nan")
    r = float(x.std()) / mu  # population standard deviation (ddof=0)
    if finite_size_correction:
        n = x.size
        sp, sm = math.sqrt(n + 1), math.sqrt(n - 1)
        b = (sp * r - sm) / ((sp - 2.0) * r + sm)
    else:
        b = (r - 1.0) / (r + 1.0)
    return float(min(1.0, max(-1.0, b)))


# --------------------------------------------------------------------------------------------
# Turning
# --------------------------------------------------------------------------------------------


def turning_angles(track: np.ndarray, min_speed: float, fps: float = VIDEO_FPS, window: int = 1) -> np.ndarray:
    """Unsigned turning angles (rad, in [0, pi]) of a 2-D or 3-D track sampled at ``fps``.

    ``track`` (T, 2) or (T, 3) in m. With displacements over ``window`` frames,
    ``d_k = p[k + window] - p[k]``, angle k is the angle between ``d_k`` and ``d_{k + window}``
    (the heading change over ``window / fps`` s; ``window = 1``: frame to frame). Pairs where
    either displacement's speed ``|d| fps / window`` is below ``min_speed`` (m/s) are skipped: the
    heading of a nearly still fish is undefined. Unsigned, so that 2-D and 3-D tracks are scored
    alike. Returns a 1-D array (at most ``T - 2 window`` values).
    """
    p = np.asarray(track, dtype=float)
    if p.ndim != 2 or p.shape[1] not in (2, 3):
        raise ValueError(f"track must have shape (T, 2) or (T, 3), got {p.shape}")
    w = int(window)
    if w < 1:
        raise ValueError("window must be a positive number of frames")
    if p.shape[0] < 2 * w + 1:
        return np.zeros(0)
    d = p[w:] - p[:-w]
    a, b = d[:-w], d[w:]
    na, nb = np.linalg.norm(a, axis=1), np.linalg.norm(b, axis=1)
    keep = (na * fps / w >= min_speed) & (nb * fps / w >= min_speed) & (na > 0) & (nb > 0)
    cos = np.sum(a[keep] * b[keep], axis=1) / (na[keep] * nb[keep])
    return np.arccos(np.clip(cos, -1.0, 1.0))


def turn_entropy(angles: np.ndarray, bins: int = 36) -> float:
    """Shannon entropy (bits) of the histogram of unsigned turning angles over [0, pi] in ``bins``
    equal bins (36: 5 degrees each).

    0 when every turn falls in one bin (a straight swim), log2(bins) when turns are uniform over
    [0, pi] (random headings). Bins are [e_k, e_{k+1}), the last one closed; an angle within 1e-9
    bin widths below an edge counts as on it (rounding noise). Plug-in estimate (biased low by
    about (bins - 1) / (2 N ln 2) bits for N angles). nan with no angles.
    """
    a = _finite(angles)
    if a.size == 0:
        return float("nan")
    w = np.pi / bins
    idx = np.clip(np.floor(a / w + _EDGE_TOL_BINS).astype(np.int64), 0, bins - 1)
    counts = np.bincount(idx, minlength=bins)
    p = counts[counts > 0] / a.size
    return float(max(0.0, -np.sum(p * np.log2(p))))


# --------------------------------------------------------------------------------------------
# Motion-unit log (the model's choices; not available for a real fish)
# --------------------------------------------------------------------------------------------


def _mu_columns(mu_log: np.ndarray) -> np.ndarray:
    m = np.asarray(mu_log)
    if m.ndim == 1:
        m = m[:, None]
    if m.ndim != 2:
        raise ValueError(f"mu_log must have shape (T,) or (T, F), got {m.shape}")
    if m.size and (not np.all(m == np.round(m)) or m.min() < 0 or m.max() >= len(MU_NAMES)):
        raise ValueError("mu_log must hold integers 0..3")
    return m.astype(np.int64)


def mu_dwell_times(mu_log: np.ndarray, dt: float, drop_censored: bool = False) -> dict[int, np.ndarray]:
    """Dwell times (s) of each motion unit: lengths of maximal runs of one MU, times ``dt`` (s).

    ``mu_log`` (T,) or (T, F) of ints 0..3 sampled every ``dt`` s; runs are taken along time
    within each fish (column) and never join across fish. Returns ``{mu: array of seconds}`` for
    mu = 0..3 (empty arrays for absent MUs), runs in time order, fish by fish. Runs touching the
    first or last sample are cut by the log's ends; ``drop_censored=True`` leaves them out.
    """
    m = _mu_columns(mu_log)
    out: dict[int, list[float]] = {k: [] for k in range(len(MU_NAMES))}
    for col in m.T:
        if col.size == 0:
            continue
        change = np.flatnonzero(col[1:] != col[:-1]) + 1
        starts = np.concatenate(([0], change))
        ends = np.concatenate((change, [col.size]))
        for s, e in zip(starts, ends):
            if drop_censored and (s == 0 or e == col.size):
                continue
            out[int(col[s])].append((e - s) * dt)
    return {k: np.asarray(v, dtype=float) for k, v in out.items()}


def mu_entropy_rate(mu_log: np.ndarray) -> float:
    """Entropy rate (bits/step) of the empirical first-order Markov chain of a MU log.

    ``H = -sum_i pi_i sum_j P_ij log2 P_ij`` (Cover & Thomas ch. 4) with ``P_ij = C_ij / C_i``
    from the transition counts ``C_ij`` (i at step t, j at step t+1; pooled over fish for a
    (T, F) log, never across fish) and ``pi_i = C_i / sum C`` the empirical frequency of i among
    the "from" states. 0 for a deterministic sequence, log2(4) = 2 for i.i.d. uniform MUs.
    Plug-in estimate; nan when there is no transition.
    """
    m = _mu_columns(mu_log)
    k = len(MU_NAMES)
    if m.shape[0] < 2:
        return float("nan")
    frm, to = m[:-1].ravel(), m[1:].ravel()
    counts = np.bincount(frm * k + to, minlength=k * k).reshape(k, k).astype(float)
    total = counts.sum()
    row = counts.sum(axis=1, keepdims=True)
    nz = counts > 0
    p = np.divide(counts, row, out=np.zeros_like(counts), where=row > 0)
    return float(max(0.0, -np.sum(counts[nz] / total * np.log2(p[nz]))))


# --------------------------------------------------------------------------------------------
# The whole analysis
# --------------------------------------------------------------------------------------------


def track_measures(
    times_s: np.ndarray,
    positions_xyz: np.ndarray,
    body_length_m: float,
    fps: float = VIDEO_FPS,
    burst_threshold_bl_s2: float = 4.0,
    turn_window_s: float = 0.25,
    turn_bins: int = 36,
    min_speed_bl_s: float = 0.2,
    mu_log: np.ndarray | None = None,
    control_dt: float | None = None,
) -> dict:
    """Life-likeness measures of a tank of fish, from their tracks alone (plus the MU log if given).

    ``times_s`` (T,) strictly increasing, s; ``positions_xyz`` (T, F, 3) (or (T, 3) for one fish)
    world positions in m (x along the tank, y depth, z up); ``body_length_m`` scales the
    body-length outputs and thresholds. For each fish, as a video analysis would (the paper's:
    side view, 24 fps): side view (x, z) -> :func:`resample` at ``fps`` -> :func:`speed_and_accel`
    -> events (:func:`accel_events`: frames with ``accel > burst_threshold_bl_s2`` body lengths/s^2)
    and bursts (:func:`bursts`: onsets of trains of consecutive events) -> intervals between
    consecutive events and between consecutive burst onsets; :func:`turning_angles` of the side
    view over ``turn_window_s`` (rounded to frames) with ``min_speed = min_speed_bl_s`` body
    lengths/s. Accel sample i is placed at grid time ``t[i + 1]`` (it is centred there).

    Pooled over fish (intervals never span two fish): event intervals -> ``burstiness`` (Kim & Jo's
    A_n, n = the pooled number of intervals); burst-onset intervals -> ``burst_interval_mean_s``,
    ``burst_interval_median_s``; all accel samples -> ``accel_kurtosis``, ``accel_skewness``,
    ``accel_mode_bl_s2`` (histogram mode of accel / body length, :func:`accel_histogram` defaults);
    all angles -> ``turn_entropy`` (``turn_bins`` bins over [0, pi]); all speeds ->
    ``mean_speed_body_lengths_s``, ``max_speed_body_lengths_s``. ``bursts_per_s`` = bursts per fish
    per second = n_bursts / (F * (times_s[-1] - times_s[0])).

    With ``mu_log`` ((T_c,) or (T_c, F) ints 0..3, one row per control step of ``control_dt`` s;
    ``control_dt`` is then required) also ``mu_entropy_rate`` (bits/step) and ``mu_dwell_mean_s``
    ({"accelerate" | "coast" | "cruise" | "brake": mean dwell in s, nan if never used}).

    Returns a plain JSON-serialisable dict of Python floats (nan where undefined) and ints.
    """
    t = np.asarray(times_s, dtype=float)
    pos = np.asarray(positions_xyz, dtype=float)
    if pos.ndim == 2:
        pos = pos[:, None, :]
    if pos.ndim != 3 or pos.shape[-1] != 3:
        raise ValueError(f"positions_xyz must have shape (T, F, 3) or (T, 3), got {pos.shape}")
    if not body_length_m > 0:
        raise ValueError("body_length_m must be positive")
    n_fish = pos.shape[1]
    tg, p2d = resample(t, side_view(pos), fps)  # (N,), (N, F, 2)
    speed, accel = speed_and_accel(p2d, fps)  # (N-1, F), (N-2, F)
    min_speed = min_speed_bl_s * body_length_m

    threshold = burst_threshold_bl_s2 * body_length_m
    window = max(1, int(round(turn_window_s * fps)))
    t0 = float(tg[1]) if tg.size > 1 else 0.0
    intervals: list[np.ndarray] = []
    event_intervals: list[np.ndarray] = []
    angles: list[np.ndarray] = []
    n_bursts = 0
    for f in range(n_fish):
        a = accel[:, f]
        onsets = bursts(a, fps, threshold, t0=t0)
        n_bursts += int(onsets.size)
        intervals.append(np.diff(onsets))
        event_intervals.append(np.diff(accel_events(a, fps, threshold, t0=t0)))
        angles.append(turning_angles(p2d[:, f, :], min_speed, fps, window))
    iv = np.concatenate(intervals) if intervals else np.zeros(0)
    ev = np.concatenate(event_intervals) if event_intervals else np.zeros(0)
    ang = np.concatenate(angles) if angles else np.zeros(0)
    acc = _finite(accel)
    spd = _finite(speed)
    duration = float(t[-1] - t[0])
    nan = float("nan")

    out: dict = {
        "burst_interval_mean_s": float(iv.mean()) if iv.size else nan,
        "burst_interval_median_s": float(np.median(iv)) if iv.size else nan,
        "bursts_per_s": float(n_bursts / (n_fish * duration)) if duration > 0 and n_fish else nan,
        "burstiness": burstiness(ev),
        "accel_kurtosis": kurtosis(acc),
        "accel_skewness": skewness(acc),
        "accel_mode_bl_s2": histogram_summary(acc / body_length_m)["mode"],
        "turn_entropy": turn_entropy(ang, bins=turn_bins),
        "mean_speed_body_lengths_s": float(spd.mean() / body_length_m) if spd.size else nan,
        "max_speed_body_lengths_s": float(spd.max() / body_length_m) if spd.size else nan,
        "n_bursts": int(n_bursts),
    }
    if mu_log is not None:
        if control_dt is None or not control_dt > 0:
            raise ValueError("control_dt (s) is required with mu_log")
        dwell = mu_dwell_times(mu_log, control_dt)
        out["mu_entropy_rate"] = mu_entropy_rate(mu_log)
        out["mu_dwell_mean_s"] = {name: float(dwell[i].mean()) if dwell[i].size else nan for i, name in enumerate(MU_NAMES)}
    return out
