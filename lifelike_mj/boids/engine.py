"""Heterogeneous boids of Nakamura 2013 (spec/boids.md sections 1-2): a compiled cell-list engine
and a plain all-pairs reference.

Each agent ``i`` (type ``t_i`` of ``k`` types) feels, from the agents ``j`` within the nested
spherical zones ``R_s < R_a < R_c`` (``xi_ij = x_i - x_j``, ``d = |xi_ij|``):

* separation (eq. 3): ``F_s = sum_{d < R_s} w_s f(d) xi_ij / d`` with ``f = 1``, summed, not averaged;
* alignment (eq. 4, 6-7): ``F_a = sum_{d < R_a} W_a[t_i, t_j] (v_j - v_i) / N_a`` (0 without neighbours);
* cohesion (eq. 5, 8-9): ``F_c = sum_{d < R_c} W_c[t_i, t_j] (-xi_ij) / N_c`` (0 without neighbours);

with ``N_a``, ``N_c`` the numbers of neighbours (of any type) in each zone. Walls of the box
``[0, L]^D`` (section 4.1): (1) wall avoidance, a wall closer than ``R_s`` acts like a separation
neighbour, ``w_s`` along the inward normal (the paper gives no weight: our reading); (2) reflecting
walls, an agent that still crosses is mirrored back inside and its normal velocity reversed.
Update (eq. 1-2), semi-implicit Euler with ``m = 1``, ``dt = 1``: ``v += dt/m (F_s + F_a + F_c)``,
then ``x += dt v``. Units are the paper's (lengths in its box units, time in steps).

:func:`step_grid` finds neighbours with a uniform grid of cells no smaller than ``R_c`` (cell
lists, counting sort), so the cost grows linearly with ``n`` at fixed density; forces of all agents
are computed from the old state on parallel threads, then all agents move: the result does not
depend on the number of threads; sums are accumulated in double-double and rounded once, so they do
not depend on the order of the neighbours either. :func:`step_reference` is the same model over all
pairs in plain Python with exactly rounded sums (kept for the tests).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from lifelike_mj.errors import UserError

#: The paper's settings (section 2): zones, separation weight, box side, agents.
R_S, R_A, R_C = 1.0, 2.5, 4.5
W_S = 0.05
BOX = 20.0
N_AGENTS = 300
#: A run has diverged (section 2.2: w_a >= 10 or w_c >= 1) when an agent moves farther than the box
#: side in one step (box units per step, as a multiple of the box side): the walls and zones no
#: longer mean anything. With w_a >= 2 the speeds overflow within a few dozen steps; with w_c = 1
#: the swarm stays finite but agents reach 22-40 box units per step (the fastest agent of the
#: eight patterns, 5b, reaches 18.5 in the worst of 10 seeds).
DIVERGED_BOX_PER_STEP = 1.0


@dataclass(frozen=True)
class BoidParams:
    """Zones (``r_s < r_a < r_c``, box units), separation weight, the ``k x k`` matrices ``W_a``,
    ``W_c`` (row: own type, column: neighbour's type), box side, dimension (3 or 2)."""

    wa: tuple = ((0.5, 0.5), (0.5, 0.5))
    wc: tuple = ((0.01, 0.01), (0.01, 0.01))
    r_s: float = R_S
    r_a: float = R_A
    r_c: float = R_C
    w_s: float = W_S
    box: float = BOX
    dims: int = 3
    dt: float = 1.0
    mass: float = 1.0
    name: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        wa, wc = _matrix("W_a", self.wa), _matrix("W_c", self.wc)
        if wa.shape != wc.shape:
            raise UserError(f"W_a is {wa.shape[0]}x{wa.shape[0]} but W_c is {wc.shape[0]}x{wc.shape[0]}; they must match.")
        object.__setattr__(self, "wa", tuple(map(tuple, wa.tolist())))
        object.__setattr__(self, "wc", tuple(map(tuple, wc.tolist())))
        for k in ("r_s", "r_a", "r_c", "w_s", "box", "dt", "mass"):
            v = getattr(self, k)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise UserError(f"{k} must be a finite number, got {v!r}.")
        if not (0 < self.r_s < self.r_a < self.r_c):
            raise UserError(f"the zones must nest: 0 < R_s < R_a < R_c, got R_s = {self.r_s}, R_a = {self.r_a}, "
                            f"R_c = {self.r_c}.")
        if self.box <= 2 * self.r_c:
            raise UserError(f"the box ({self.box}) must be wider than 2 R_c ({2 * self.r_c}).")
        if self.dims not in (2, 3):
            raise UserError(f"dims must be 2 or 3, got {self.dims!r}.")
        if self.dt <= 0 or self.mass <= 0:
            raise UserError("dt and mass must be positive.")

    @property
    def n_types(self) -> int:
        return len(self.wa)

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(W_a, W_c, consts)`` for the compiled step; consts = r_s, r_a, r_c, w_s, box, dt/m."""
        c = np.array([self.r_s, self.r_a, self.r_c, self.w_s, self.box, self.dt / self.mass, self.dt])
        return np.array(self.wa, dtype=float), np.array(self.wc, dtype=float), c


def _matrix(name: str, m) -> np.ndarray:
    try:
        a = np.array(m, dtype=float)
    except (TypeError, ValueError):
        raise UserError(f"{name} must be a square matrix of numbers, got {m!r}.") from None
    if a.ndim != 2 or a.shape[0] != a.shape[1] or a.shape[0] < 1:
        raise UserError(f"{name} must be a square k x k matrix (one row and column per type), got shape {a.shape}.")
    if not np.all(np.isfinite(a)):
        raise UserError(f"{name} must contain finite numbers.")
    return a


def parse_matrix(text: str, name: str = "matrix") -> tuple:
    """``"a,b;c,d"`` -> ``((a, b), (c, d))`` (rows separated by ``;``)."""
    try:
        rows = [tuple(float(x) for x in r.split(",")) for r in text.split(";")]
    except ValueError:
        raise UserError(f"{name} must look like 'a,b;c,d' (rows separated by ';'), got {text!r}.") from None
    if len({len(r) for r in rows}) != 1:
        raise UserError(f"{name} rows have different lengths in {text!r}.")
    return tuple(rows)


# ---- initial state -------------------------------------------------------------------------------


def initial_state(params: BoidParams, n: int, seed: int, margin: float | None = None,
                  type_probs=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random positions in ``[margin, L - margin]^D`` (default margin ``R_c``: well away from the
    walls), tiny random velocities (uniform in ``[-0.01, 0.01]`` per axis), and types drawn
    independently (each of the ``k`` types equally likely: A or B with probability 0.5 in the
    paper's case). One ``numpy.random.Generator`` seeded with ``seed``."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise UserError(f"the number of agents must be a whole number of at least 2, got {n!r}.")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise UserError(f"seed must be a non-negative whole number, got {seed!r}.")
    rng = np.random.default_rng(seed)
    m = params.r_c if margin is None else margin
    D = params.dims
    x = rng.uniform(m, params.box - m, size=(n, D))
    v = rng.uniform(-0.01, 0.01, size=(n, D))
    k = params.n_types
    p = np.full(k, 1.0 / k) if type_probs is None else np.asarray(type_probs, dtype=float)
    types = rng.choice(k, size=n, p=p).astype(np.int64)
    return x, v, types


# ---- the compiled cell-list step -----------------------------------------------------------------
# Positions and velocities are (n, 3) inside the compiled code; in 2D the z column is 0 and stays 0
# (no force has a z component, the z walls are off, the grid has one layer of cells).


@njit(cache=True)
def _grid(x, box, r_c, planar):
    """Cells no smaller than R_c: ``(ncell_xy, ncell_z, cell_size, order, start, cell)`` with a
    counting sort (agents by cell, by index within a cell)."""
    n = x.shape[0]
    nc = max(1, int(box / r_c))
    nz = 1 if planar else nc
    size = box / nc
    cell = np.empty(n, dtype=np.int64)
    for i in range(n):
        qx = min(max(int(x[i, 0] / size), 0), nc - 1)
        qy = min(max(int(x[i, 1] / size), 0), nc - 1)
        qz = 0 if planar else min(max(int(x[i, 2] / size), 0), nc - 1)
        cell[i] = (qx * nc + qy) * nz + qz
    ncells = nc * nc * nz
    start = np.zeros(ncells + 1, dtype=np.int64)
    for i in range(n):
        start[cell[i] + 1] += 1
    for c in range(ncells):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[fill[cell[i]]] = i
        fill[cell[i]] += 1
    return nc, nz, order, start, cell


@njit(cache=True, inline="always")
def _two_sum(s, c, t):
    """Add ``t`` to the double-double accumulator ``(s, c)`` (Knuth's TwoSum; error-free)."""
    u = s + t
    b = u - s
    return u, c + ((s - (u - b)) + (t - b))


def _forces_py(x, v, types, wa, wc, c, planar, dv):
    """dv = dt/m (F_s + F_a + F_c) of every agent (eq. 1-9), on parallel threads.

    Each force component is a sum over neighbours accumulated in double-double arithmetic and
    rounded once: its value does not depend on the order in which the neighbours are visited
    (cells, threads), and equals the all-pairs reference, which sums the same terms exactly
    (``math.fsum``), except when the exact sum lies within ~1e-27 (relative) of a rounding
    boundary. The agents are copied in cell order first, so that a cell's agents are contiguous."""
    n = x.shape[0]
    r_s, r_a, r_c, w_s, box, dt_m = c[0], c[1], c[2], c[3], c[4], c[5]
    r_s2, r_a2, r_c2 = r_s * r_s, r_a * r_a, r_c * r_c
    nc, nz, order, start, cell = _grid(x, box, r_c, planar)
    xs = np.empty((n, 3))
    vs = np.empty((n, 3))
    ts = np.empty(n, dtype=np.int64)
    for q in range(n):
        j = order[q]
        for a in range(3):
            xs[q, a] = x[j, a]
            vs[q, a] = v[j, a]
        ts[q] = types[j]
    for p in prange(n):
        i = order[p]
        sx = sy = sz = ax = ay = az = cx = cy = cz = 0.0  # separation, alignment, cohesion sums
        esx = esy = esz = eax = eay = eaz = ecx = ecy = ecz = 0.0  # their error terms
        na = 0
        nci = 0
        ti = ts[p]
        xi0, xi1, xi2 = xs[p, 0], xs[p, 1], xs[p, 2]
        vi0, vi1, vi2 = vs[p, 0], vs[p, 1], vs[p, 2]
        ci = cell[i]
        qz = ci % nz
        qy = (ci // nz) % nc
        qx = ci // (nz * nc)
        for dxc in range(-1, 2):
            bx = qx + dxc
            if bx < 0 or bx >= nc:
                continue
            for dyc in range(-1, 2):
                by = qy + dyc
                if by < 0 or by >= nc:
                    continue
                z0 = max(qz - 1, 0)
                z1 = min(qz + 1, nz - 1)
                # the cells (bx, by, z0..z1) are consecutive: one contiguous run of agents
                c0 = (bx * nc + by) * nz
                for q in range(start[c0 + z0], start[c0 + z1 + 1]):
                    ex = xi0 - xs[q, 0]
                    ey = xi1 - xs[q, 1]
                    ez = xi2 - xs[q, 2]
                    d2 = ex * ex + ey * ey + ez * ez
                    if d2 >= r_c2 or q == p:
                        continue
                    nci += 1
                    w = wc[ti, ts[q]]
                    cx, ecx = _two_sum(cx, ecx, -(w * ex))
                    cy, ecy = _two_sum(cy, ecy, -(w * ey))
                    cz, ecz = _two_sum(cz, ecz, -(w * ez))
                    if d2 < r_a2:
                        na += 1
                        w = wa[ti, ts[q]]
                        ax, eax = _two_sum(ax, eax, w * (vs[q, 0] - vi0))
                        ay, eay = _two_sum(ay, eay, w * (vs[q, 1] - vi1))
                        az, eaz = _two_sum(az, eaz, w * (vs[q, 2] - vi2))
                        if d2 < r_s2 and d2 > 0.0:
                            w = w_s / math.sqrt(d2)
                            sx, esx = _two_sum(sx, esx, w * ex)
                            sy, esy = _two_sum(sy, esy, w * ey)
                            sz, esz = _two_sum(sz, esz, w * ez)
        # wall avoidance: a wall closer than R_s pushes w_s along its inward normal (a term of F_s)
        if xi0 < r_s:
            sx, esx = _two_sum(sx, esx, w_s)
        if box - xi0 < r_s:
            sx, esx = _two_sum(sx, esx, -w_s)
        if xi1 < r_s:
            sy, esy = _two_sum(sy, esy, w_s)
        if box - xi1 < r_s:
            sy, esy = _two_sum(sy, esy, -w_s)
        if not planar:
            if xi2 < r_s:
                sz, esz = _two_sum(sz, esz, w_s)
            if box - xi2 < r_s:
                sz, esz = _two_sum(sz, esz, -w_s)
        fx, fy, fz = sx + esx, sy + esy, sz + esz
        if na > 0:
            fx += (ax + eax) / na
            fy += (ay + eay) / na
            fz += (az + eaz) / na
        if nci > 0:
            fx += (cx + ecx) / nci
            fy += (cy + ecy) / nci
            fz += (cz + ecz) / nci
        dv[i, 0] = dt_m * fx
        dv[i, 1] = dt_m * fy
        dv[i, 2] = dt_m * fz


#: Below this many agents one thread is faster (no fork-join per step) and robust to a busy machine.
PARALLEL_FROM = 2000
_forces_par = njit(cache=True, parallel=True)(_forces_py)
_forces_ser = njit(cache=True)(_forces_py)


@njit(cache=True)
def _advance(x, v, dv, c):
    """Semi-implicit update (eq. 1-2) and reflecting walls; an agent is never left outside the box
    (a reflection that would still land outside, possible only in a diverging run, is clamped)."""
    n = x.shape[0]
    box, dt = c[4], c[6]
    for i in range(n):
        for a in range(3):
            v[i, a] += dv[i, a]
            x[i, a] += dt * v[i, a]
            if x[i, a] < 0.0:
                x[i, a] = -x[i, a]
                v[i, a] = -v[i, a]
            elif x[i, a] > box:
                x[i, a] = 2.0 * box - x[i, a]
                v[i, a] = -v[i, a]
            if not (0.0 <= x[i, a] <= box):
                x[i, a] = min(max(x[i, a], 0.0), box) if x[i, a] == x[i, a] else 0.0


@njit(cache=True)
def _run(x, v, types, wa, wc, c, planar, n_steps, record_every, out_x, out_v, vmax):
    """``n_steps`` steps; records every ``record_every`` steps into ``out_x``/``out_v``; returns the
    first step (1-based) at which a speed exceeded ``vmax`` or became NaN, else 0. The forces run on
    all threads from :data:`PARALLEL_FROM` agents on (same result: sums do not depend on order)."""
    n = x.shape[0]
    dv = np.empty((n, 3))
    r = 0
    par = n >= PARALLEL_FROM
    for k in range(n_steps):
        if par:
            _forces_par(x, v, types, wa, wc, c, planar, dv)
        else:
            _forces_ser(x, v, types, wa, wc, c, planar, dv)
        _advance(x, v, dv, c)
        for i in range(n):
            s = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
            if not (s <= vmax * vmax):
                return k + 1
        if record_every > 0 and (k + 1) % record_every == 0:
            out_x[r] = x
            out_v[r] = v
            r += 1
    return 0


def _as3(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a if a.shape[1] == 3 else np.concatenate([a, np.zeros((a.shape[0], 3 - a.shape[1]))], axis=1)


def step_grid(x: np.ndarray, v: np.ndarray, types: np.ndarray, params: BoidParams, n_steps: int = 1) -> None:
    """Advance ``x``, ``v`` (arrays (n, D), updated in place) by ``n_steps`` steps with the cell-list
    engine. Raises :class:`UserError` when the run diverges."""
    x3, v3 = _as3(x), _as3(v)
    wa, wc, c = params.arrays()
    empty = np.zeros((0, x3.shape[0], 3))
    bad = _run(x3, v3, np.asarray(types, dtype=np.int64), wa, wc, c, params.dims == 2, int(n_steps), 0, empty, empty,
               diverged_speed(params))
    x[...] = x3[:, : x.shape[1]]
    v[...] = v3[:, : v.shape[1]]
    if bad:
        raise UserError(divergence_message(params, bad))


def diverged_speed(params: BoidParams) -> float:
    """The speed (box units per step) above which a run counts as diverged."""
    return DIVERGED_BOX_PER_STEP * params.box / params.dt


def divergence_message(params: BoidParams, step: int) -> str:
    wa, wc = np.array(params.wa), np.array(params.wc)
    return (f"the run diverged at step {step}: an agent moved farther than the box side ({params.box:g}) in one step; "
            f"the weights are too large (largest W_a entry {np.max(np.abs(wa)):g}, largest W_c entry "
            f"{np.max(np.abs(wc)):g}; the paper finds divergence from w_a >= 10 or w_c >= 1).")


# ---- the plain all-pairs reference -----------------------------------------------------------------


def step_reference(x: np.ndarray, v: np.ndarray, types: np.ndarray, params: BoidParams) -> None:
    """One step over all pairs in plain Python: the definition the engine is tested against. Each
    force component is the exactly rounded sum (``math.fsum``) of its terms (eq. 3-5, 7, 9, and the
    walls as separation terms)."""
    n, D = x.shape
    wa, wc = np.array(params.wa), np.array(params.wc)
    dv = np.zeros((n, D))
    for i in range(n):
        fs, fa, fc = [[] for _ in range(D)], [[] for _ in range(D)], [[] for _ in range(D)]
        na = nc = 0
        for j in range(n):
            if j == i:
                continue
            xi = [float(x[i, a] - x[j, a]) for a in range(D)]
            d2 = 0.0
            for e in xi:
                d2 += e * e
            if d2 < params.r_c * params.r_c:
                nc += 1
                w = wc[types[i], types[j]]
                for a in range(D):
                    fc[a].append(-(w * xi[a]))
                if d2 < params.r_a * params.r_a:
                    na += 1
                    w = wa[types[i], types[j]]
                    for a in range(D):
                        fa[a].append(w * (v[j, a] - v[i, a]))
                    if 0.0 < d2 < params.r_s * params.r_s:
                        w = params.w_s / math.sqrt(d2)
                        for a in range(D):
                            fs[a].append(w * xi[a])
        for a in range(D):
            if x[i, a] < params.r_s:
                fs[a].append(params.w_s)
            if params.box - x[i, a] < params.r_s:
                fs[a].append(-params.w_s)
        for a in range(D):
            f = math.fsum(fs[a])
            if na:
                f += math.fsum(fa[a]) / na
            if nc:
                f += math.fsum(fc[a]) / nc
            dv[i, a] = params.dt / params.mass * f
    v += dv
    x += params.dt * v
    low, high = x < 0.0, x > params.box
    x[low] = -x[low]
    v[low] = -v[low]
    x[high] = 2.0 * params.box - x[high]
    v[high] = -v[high]


# ---- runs ----------------------------------------------------------------------------------------


@dataclass
class BoidRun:
    """A run's record: ``positions``/``velocities`` (T, n, D) at ``steps`` (T,), the agents'
    ``types`` (n,), and the parameters, seed and wall time."""

    params: BoidParams
    seed: int
    types: np.ndarray
    steps: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    wall_time_s: float = 0.0

    @property
    def n(self) -> int:
        return len(self.types)


def simulate(params: BoidParams, n: int = N_AGENTS, n_steps: int = 3000, seed: int = 0, record_every: int = 1,
             record_from: int = 0, progress: bool = False, extra_steps=()) -> BoidRun:
    """Run ``n_steps`` steps from :func:`initial_state`; record the state every ``record_every``
    steps from step ``record_from`` on (step 0 = the initial state), and at the ``extra_steps``.
    Raises :class:`UserError` if the run diverges (section 2.2: w_a >= 10 or w_c >= 1)."""
    import time

    if isinstance(n_steps, bool) or not isinstance(n_steps, (int, np.integer)) or n_steps < 1:
        raise UserError(f"the number of steps must be a whole number of at least 1, got {n_steps!r}.")
    if record_every < 1:
        raise UserError(f"record_every must be at least 1, got {record_every}.")
    t0 = time.perf_counter()
    x, v, types = initial_state(params, n, seed)
    x3, v3 = _as3(x), _as3(v)
    wa, wc, c = params.arrays()
    planar = params.dims == 2
    D = params.dims
    rec_steps = sorted({s for s in range(0, int(n_steps) + 1, record_every) if s >= record_from}
                       | {int(s) for s in extra_steps if 0 <= s <= n_steps})
    X = np.empty((len(rec_steps), n, 3))
    V = np.empty((len(rec_steps), n, 3))
    r = 0
    if rec_steps and rec_steps[0] == 0:
        X[0], V[0] = x3, v3
        r = 1
    done = 0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=int(n_steps), unit="step", desc="boids", leave=False)
    try:
        while done < n_steps:
            target = rec_steps[r] if r < len(rec_steps) else int(n_steps)
            k = target - done
            empty = np.zeros((0, n, 3))
            bad = _run(x3, v3, types, wa, wc, c, planar, k, 0, empty, empty, diverged_speed(params))
            if bad:
                raise UserError(divergence_message(params, done + bad))
            done += k
            if r < len(rec_steps) and done == rec_steps[r]:
                X[r], V[r] = x3, v3
                r += 1
            if bar is not None:
                bar.update(k)
    finally:
        if bar is not None:
            bar.close()
    return BoidRun(params, int(seed), types, np.array(rec_steps), X[:, :, :D].copy(), V[:, :, :D].copy(),
                   time.perf_counter() - t0)
