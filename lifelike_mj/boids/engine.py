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
are computed from the old state (on parallel threads from :data:`PARALLEL_FROM` agents), then all
agents move. Every sum adds its terms in ascending order of the neighbour's index, as the plain
all-pairs reference :func:`step_reference` does (kept for the tests), so the two agree bit for bit
and the result does not depend on the number of threads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
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
#
# Each force component of agent i is summed exactly as the plain reference sums it: its terms in
# ascending order of the neighbour's index j, one rounding per addition. The engine gets that order
# by turning the loops round. For each column of cells (fixed x and y cell), the agents j of the 3 x 3
# columns around it are listed in ascending index order (the column's "halo", built by one pass over
# the agents in index order), and each j is applied at once to all the column's agents i within one
# cell of it in z. That inner loop over i is branch-free (a term outside its zone is multiplied by 0
# and adds nothing: s + 0 = s exactly, and a sum that starts at +0 never becomes -0), so the compiler
# vectorises it. Separation, a few neighbours per agent, uses a finer grid and sorts each agent's
# separation neighbours by index.

#: The fine grid of the separation zone has at most this many cells, or 2 per agent if more (a
#: bigger grid is mostly empty cells and cache misses at large n).
FINE_CELLS_MIN = 1 << 12


@njit(cache=True)
def _bbox(x, planar):
    """The agents' bounding box: ``(lo, ext)``, each (3,) (z: 0 in 2D)."""
    lo = np.zeros(3)
    hi = np.zeros(3)
    d = 2 if planar else 3
    for a in range(d):
        lo[a] = hi[a] = x[0, a]
    for i in range(1, x.shape[0]):
        for a in range(d):
            lo[a] = min(lo[a], x[i, a])
            hi[a] = max(hi[a], x[i, a])
    return lo, hi - lo


@njit(cache=True)
def _grid(x, lo, ext, size_min, planar, max_cells):
    """A uniform grid over the box ``lo .. lo + ext`` holding the agents, cells at least ``size_min``
    wide (a hair more, so that rounding never puts two agents closer than ``size_min`` two cells
    apart), at most ``max_cells`` cells: ``(ncx, ncy, ncz, cell, start, pos)``. The agents are
    counting-sorted by cell (x, then y, then z), by index within a cell: agent ``i`` is at sorted
    position ``pos[i]``, cell ``c`` holds the sorted positions ``start[c] .. start[c + 1] - 1``."""
    n = x.shape[0]
    inv = np.zeros(3)
    nn = np.ones(3, dtype=np.int64)
    for a in range(2 if planar else 3):
        nn[a] = max(1, int(ext[a] / (size_min * (1.0 + 1e-9))))
    while nn[0] * nn[1] * nn[2] > max_cells:
        nn[np.argmax(nn)] -= 1
    for a in range(2 if planar else 3):
        if ext[a] > 0.0:
            inv[a] = nn[a] / ext[a]
    ncx, ncy, ncz = nn[0], nn[1], nn[2]
    cell = np.empty(n, dtype=np.int64)
    for i in range(n):
        qx = min(int((x[i, 0] - lo[0]) * inv[0]), ncx - 1)
        qy = min(int((x[i, 1] - lo[1]) * inv[1]), ncy - 1)
        qz = 0 if planar else min(int((x[i, 2] - lo[2]) * inv[2]), ncz - 1)
        cell[i] = (qx * ncy + qy) * ncz + qz
    ncells = ncx * ncy * ncz
    start = np.zeros(ncells + 1, dtype=np.int64)
    for i in range(n):
        start[cell[i] + 1] += 1
    for k in range(ncells):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[i] = fill[cell[i]]
        fill[cell[i]] += 1
    return ncx, ncy, ncz, cell, start, pos


@njit(cache=True)
def _fill_chunk(k, nchunks, cols, x, v, types, wa, wc, nz, cell, pos, order, naround, around, hstart,
                fcell, forder, xs, vs, cs, zs, ts, wcs, was, halo, fxs, fcs, fine):
    """Part ``k`` of ``nchunks`` of the copies in sorted order (gathered: sequential writes, much
    faster than scattering at large n) and of the halo lists (columns ``cols[k] .. cols[k + 1] - 1``,
    filled by one pass over the agents in index order)."""
    n = x.shape[0]
    for p in range(k * n // nchunks, (k + 1) * n // nchunks):
        i = order[p]
        for a in range(3):
            xs[a, p] = x[i, a]
            vs[a, p] = v[i, a]
        cs[p] = cell[i]
        zs[p] = cell[i] % nz
        ts[p] = types[i]
        for t in range(wa.shape[0]):
            wcs[t, p] = wc[types[i], t]
            was[t, p] = wa[types[i], t]
        if fine:
            i = forder[p]
            fcs[p] = fcell[i]
            for a in range(3):
                fxs[a, p] = x[i, a]
    q0, q1 = cols[k], cols[k + 1]
    fill = hstart[q0:q1].copy()
    for i in range(n):
        q = cell[i] // nz
        for s in range(naround[q]):
            b = around[q, s]
            if q0 <= b < q1:
                halo[fill[b - q0]] = pos[i]
                fill[b - q0] += 1


@njit(cache=True, parallel=True)
def _fill_parallel(nchunks, cols, x, v, types, wa, wc, nz, cell, pos, order, naround, around, hstart,
                   fcell, forder, xs, vs, cs, zs, ts, wcs, was, halo, fxs, fcs, fine):
    """:func:`_fill_chunk`, part ``k`` on thread ``k``."""
    for k in prange(nchunks):
        _fill_chunk(k, nchunks, cols, x, v, types, wa, wc, nz, cell, pos, order, naround, around, hstart,
                    fcell, forder, xs, vs, cs, zs, ts, wcs, was, halo, fxs, fcs, fine)


@njit(cache=True)
def _prepare(x, v, types, wa, wc, c, planar, nchunks):
    """Everything the pair loops read: the R_c grid, the agents' state in sorted order (rows x, y, z),
    per-position weight columns (``wcs[t, p]``: the weight of the agent at ``p`` for a neighbour of
    type ``t``), the halo lists, ``nchunks`` ranges of sorted positions of about equal work, and the
    fine grid of the separation zone."""
    n = x.shape[0]
    lo, ext = _bbox(x, planar)
    ncx, ncy, nz, cell, start, pos = _grid(x, lo, ext, c[2], planar, 1 << 40)
    k = wa.shape[0]
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[pos[i]] = i
    # halo lists: for each occupied column (fixed x and y cell), the sorted positions of the agents
    # of the occupied columns around it (3 x 3), in ascending agent index (the order of the sums)
    ncol = ncx * ncy
    occupied = np.zeros(ncol, dtype=np.int64)
    for i in range(n):
        occupied[cell[i] // nz] += 1
    around = np.empty((ncol, 9), dtype=np.int64)  # the occupied columns around each column
    naround = np.zeros(ncol, dtype=np.int64)
    hstart = np.zeros(ncol + 1, dtype=np.int64)
    for q in range(ncol):
        if occupied[q] == 0:
            continue
        qx, qy = q // ncy, q % ncy
        for bx in range(max(qx - 1, 0), min(qx + 2, ncx)):
            for by in range(max(qy - 1, 0), min(qy + 2, ncy)):
                b = bx * ncy + by
                if occupied[b] > 0:
                    around[q, naround[q]] = b
                    naround[q] += 1
                    hstart[b + 1] += occupied[q]
    for q in range(ncol):
        hstart[q + 1] += hstart[q]
    # chunks of equal work: an agent's work is its column's halo length; the halo lists are
    # filled in chunks of columns of equal length
    total = 0
    for q in range(ncol):
        total += occupied[q] * (hstart[q + 1] - hstart[q])
    cols = np.full(nchunks + 1, ncol, dtype=np.int64)
    cols[0] = 0
    kk = 1
    for q in range(ncol):
        while kk < nchunks and hstart[q] * nchunks >= kk * hstart[ncol]:
            cols[kk] = q
            kk += 1
    # sparse (runs of agents shorter than SHORT_RUN on average): every pass takes the plain loop,
    # which adds the separation terms too; else the separation runs on a fine grid
    ncells_occupied = 0
    for q in range(ncol * nz):
        if start[q + 1] > start[q]:
            ncells_occupied += 1
    sparse = n * min(3, nz) < SHORT_RUN * ncells_occupied
    # the fine grid of the separation zone, its agents in fine cell order (none if sparse)
    nf = 0 if sparse else n
    fx = fy = fz = 1
    fcell = np.zeros(nf, dtype=np.int64)
    fstart = np.zeros(2, dtype=np.int64)
    forder = np.empty(nf, dtype=np.int64)
    if not sparse:
        fx, fy, fz, fcell, fstart, fpos = _grid(x, lo, ext, c[0], planar, max(FINE_CELLS_MIN, 2 * n))
        for i in range(n):
            forder[fpos[i]] = i
    xs = np.empty((3, n))
    vs = np.empty((3, n))
    cs = np.empty(n, dtype=np.int64)
    zs = np.empty(n, dtype=np.int64)
    ts = np.empty(n, dtype=np.int64)
    wcs = np.empty((k, n))
    was = np.empty((k, n))
    halo = np.empty(hstart[ncol], dtype=np.int64)
    fxs = np.empty((3, nf))
    fcs = np.empty(nf, dtype=np.int64)
    if nchunks > 1:
        _fill_parallel(nchunks, cols, x, v, types, wa, wc, nz, cell, pos, order, naround, around, hstart,
                       fcell, forder, xs, vs, cs, zs, ts, wcs, was, halo, fxs, fcs, not sparse)
    else:
        _fill_chunk(0, 1, cols, x, v, types, wa, wc, nz, cell, pos, order, naround, around, hstart,
                    fcell, forder, xs, vs, cs, zs, ts, wcs, was, halo, fxs, fcs, not sparse)
    bounds = np.full(nchunks + 1, n, dtype=np.int64)
    bounds[0] = 0
    done = 0
    kk = 1
    for p in range(n):
        while kk < nchunks and done * nchunks >= kk * total:
            bounds[kk] = p
            kk += 1
        q = cs[p] // nz
        done += hstart[q + 1] - hstart[q]
    return (sparse, nz, start, order, cs, zs, ts, xs, vs, wcs, was, hstart, halo, bounds,
            fx, fy, fz, fcs, fstart, forder, fxs)


#: Runs of fewer agents than this take a plain loop: the vector loop's set-up (run-time alias checks
#: of its 16 arrays) costs more than it saves on a short run (measured; docs/performance.md).
SHORT_RUN = 24


@njit(cache=True)
def _pairs_chunk(p0, p1, nz, start, cs, zs, ts, hstart, halo, xs, vs, wcs, was, r_c2, r_a2, acc, sparse, r_s2,
                 w_s):
    """Cohesion and alignment sums and neighbour counts of the agents at sorted positions ``p0 ..
    p1 - 1`` (chunks on parallel threads write disjoint positions). ``acc`` rows: cohesion x, y, z,
    alignment x, y, z, N_c + 1, N_a + 1 (an agent meets itself once, with zero terms), and, if
    ``sparse``, separation x, y, z (every pass then takes the plain loop, which adds them too).

    A neighbour j is applied to the agents of the column in its own and the adjacent z cells. Two
    consecutive halo agents j < k in the same or adjacent z cells are applied in one pass (first
    j's term, then k's: the order of the sums is kept), which halves the loads and stores of the
    sums. A run of agents may be lengthened within the column (to a multiple of 8, for whole vector
    iterations): an agent out of j's zones gets zero terms, in its right place in the order."""
    xs0, xs1, xs2 = xs[0], xs[1], xs[2]
    vs0, vs1, vs2 = vs[0], vs[1], vs[2]
    cx, cy, cz, ax, ay, az, ncn, nan = acc[0], acc[1], acc[2], acc[3], acc[4], acc[5], acc[6], acc[7]
    sx, sy, sz = acc[8], acc[9], acc[10]
    if p0 < p1:
        for q in range(cs[p0] // nz, cs[p1 - 1] // nz + 1):
            a = max(start[q * nz], p0)
            b = min(start[q * nz + nz], p1)
            if a >= b:
                continue
            h = hstart[q]
            h1 = hstart[q + 1]
            while h < h1:
                pj = halo[h]
                qj = zs[pj]
                pk = pj
                qk = qj
                on = 0.0  # 1 when a second agent k is applied in this pass
                if h + 1 < h1 and abs(zs[halo[h + 1]] - qj) <= 1:
                    pk = halo[h + 1]
                    qk = zs[pk]
                    on = 1.0
                h += 2 if on > 0.0 else 1
                r0 = max(start[q * nz + max(min(qj, qk) - 1, 0)], a)
                r1 = min(start[q * nz + min(max(qj, qk) + 1, nz - 1) + 1], b)
                if r0 >= r1:
                    continue
                xj0, xj1, xj2 = xs0[pj], xs1[pj], xs2[pj]
                xk0, xk1, xk2 = xs0[pk], xs1[pk], xs2[pk]
                vj0, vj1, vj2 = vs0[pj], vs1[pj], vs2[pj]
                vk0, vk1, vk2 = vs0[pk], vs1[pk], vs2[pk]
                tj, tk = ts[pj], ts[pk]  # (rows of wcs/was indexed in place: a row view costs reference counting)
                if sparse or r1 - r0 < SHORT_RUN:
                    # a short run (sparse cells): a plain loop, whose set-up costs less than the
                    # vector loop's (signed indices keep the compiler from vectorising it)
                    for p in range(r0, r1):
                        for u in range(2 if on > 0.0 else 1):  # j's terms, then k's
                            if u == 0:
                                y0, y1, y2, u0, u1, u2, tu = xj0, xj1, xj2, vj0, vj1, vj2, tj
                            else:
                                y0, y1, y2, u0, u1, u2, tu = xk0, xk1, xk2, vk0, vk1, vk2, tk
                            ex = xs0[p] - y0
                            ey = xs1[p] - y1
                            ez = xs2[p] - y2
                            d2 = ex * ex + ey * ey + ez * ez
                            if d2 < r_c2:
                                ncn[p] += 1.0
                                w = wcs[tu, p]
                                cx[p] += -(w * ex)
                                cy[p] += -(w * ey)
                                cz[p] += -(w * ez)
                                if d2 < r_a2:
                                    nan[p] += 1.0
                                    w = was[tu, p]
                                    ax[p] += w * (u0 - vs0[p])
                                    ay[p] += w * (u1 - vs1[p])
                                    az[p] += w * (u2 - vs2[p])
                                    if sparse and d2 < r_s2 and d2 > 0.0:
                                        w = w_s / math.sqrt(d2)
                                        sx[p] += w * ex
                                        sy[p] += w * ey
                                        sz[p] += w * ez
                    continue
                r1 = min(r1 + (r0 - r1) % 8, b)
                r0 = max(r0 - (r0 - r1) % 8, a)
                # unsigned indices (no negative-index wraparound) let the loops vectorise; cohesion and
                # alignment stay two loops (fewer arrays each): one fused loop measured slower
                for p in range(np.uint64(r0), np.uint64(r1)):
                    ex = xs0[p] - xj0
                    ey = xs1[p] - xj1
                    ez = xs2[p] - xj2
                    fx = xs0[p] - xk0
                    fy = xs1[p] - xk1
                    fz = xs2[p] - xk2
                    m = 1.0 if ex * ex + ey * ey + ez * ez < r_c2 else 0.0
                    mk = on if fx * fx + fy * fy + fz * fz < r_c2 else 0.0
                    ncn[p] += m + mk
                    w = wcs[tj, p] * m
                    wk = wcs[tk, p] * mk
                    cx[p] = (cx[p] + -(w * ex)) + -(wk * fx)
                    cy[p] = (cy[p] + -(w * ey)) + -(wk * fy)
                    cz[p] = (cz[p] + -(w * ez)) + -(wk * fz)
                for p in range(np.uint64(r0), np.uint64(r1)):
                    ex = xs0[p] - xj0
                    ey = xs1[p] - xj1
                    ez = xs2[p] - xj2
                    fx = xs0[p] - xk0
                    fy = xs1[p] - xk1
                    fz = xs2[p] - xk2
                    m = 1.0 if ex * ex + ey * ey + ez * ez < r_a2 else 0.0
                    mk = on if fx * fx + fy * fy + fz * fz < r_a2 else 0.0
                    nan[p] += m + mk
                    w = was[tj, p] * m
                    wk = was[tk, p] * mk
                    vp = vs0[p]
                    ax[p] = (ax[p] + w * (vj0 - vp)) + wk * (vk0 - vp)
                    vp = vs1[p]
                    ay[p] = (ay[p] + w * (vj1 - vp)) + wk * (vk1 - vp)
                    vp = vs2[p]
                    az[p] = (az[p] + w * (vj2 - vp)) + wk * (vk2 - vp)


@njit(cache=True)
def _separation_chunk(s0, s1, fncx, fncy, fncz, fcs, fstart, forder, fxs, r_s, w_s, sep):
    """Separation sums (eq. 3 with f = 1, summed) of the agents at fine sorted positions ``s0 .. s1 -
    1``: each agent's neighbours within R_s, found on the fine grid, are sorted by index and their
    terms summed in that order. Cell by cell: the (at most 9) runs of neighbouring cells are found
    once per cell."""
    r_s2 = r_s * r_s
    n = fxs.shape[1]
    buf = np.empty(n, dtype=np.int64)  # fine positions of one agent's separation neighbours
    lo = np.empty(9, dtype=np.int64)
    hi = np.empty(9, dtype=np.int64)
    if s0 >= s1:
        return
    for q in range(fcs[s0], fcs[s1 - 1] + 1):
        a0 = max(fstart[q], s0)
        a1 = min(fstart[q + 1], s1)
        if a0 >= a1:
            continue
        qz = q % fncz
        qy = (q // fncz) % fncy
        qx = q // (fncz * fncy)
        nr = 0
        for bx in range(max(qx - 1, 0), min(qx + 2, fncx)):
            for by in range(max(qy - 1, 0), min(qy + 2, fncy)):
                c0 = (bx * fncy + by) * fncz
                lo[nr] = fstart[c0 + max(qz - 1, 0)]
                hi[nr] = fstart[c0 + min(qz + 1, fncz - 1) + 1]
                nr += 1
        for pa in range(a0, a1):
            i = forder[pa]
            xi0, xi1, xi2 = fxs[0, pa], fxs[1, pa], fxs[2, pa]
            m = 0
            for r in range(nr):
                for pb in range(lo[r], hi[r]):
                    ex = xi0 - fxs[0, pb]
                    ey = xi1 - fxs[1, pb]
                    ez = xi2 - fxs[2, pb]
                    d2 = ex * ex + ey * ey + ez * ez
                    if 0.0 < d2 < r_s2:
                        # insertion into buf[0:m], kept in ascending agent index
                        j = forder[pb]
                        s = m
                        while s > 0 and forder[buf[s - 1]] > j:
                            buf[s] = buf[s - 1]
                            s -= 1
                        buf[s] = pb
                        m += 1
            sx = sy = sz = 0.0
            for s in range(m):
                pb = buf[s]
                ex = xi0 - fxs[0, pb]
                ey = xi1 - fxs[1, pb]
                ez = xi2 - fxs[2, pb]
                w = w_s / math.sqrt(ex * ex + ey * ey + ez * ez)
                sx += w * ex
                sy += w * ey
                sz += w * ez
            sep[0, i] = sx
            sep[1, i] = sy
            sep[2, i] = sz


@njit(cache=True)
def _combine(xs, order, acc, sep, c, planar, dv, sparse):
    """dv = dt/m (F_s + F_a + F_c) (eq. 1-2): separation plus wall avoidance (a wall closer than
    R_s adds w_s along its inward normal, after the neighbours' terms), then the alignment and
    cohesion averages (eq. 6-9). In sorted order (``xs``: positions in sorted order, ``order[p]``: the
    agent at sorted position p)."""
    n = xs.shape[1]
    r_s, w_s, box, dt_m = c[0], c[3], c[4], c[5]
    for p in range(n):
        i = order[p]
        na = acc[7, p] - 1.0
        nc = acc[6, p] - 1.0
        for a in range(3):
            f = acc[8 + a, p] if sparse else sep[a, i]
            if a < 2 or not planar:
                if xs[a, p] < r_s:
                    f += w_s
                if box - xs[a, p] < r_s:
                    f += -w_s
            if na > 0.0:
                f += acc[3 + a, p] / na
            if nc > 0.0:
                f += acc[a, p] / nc
            dv[i, a] = dt_m * f


#: Below this many agents one thread is as fast (see docs/performance.md) and robust to a busy machine.
PARALLEL_FROM = 2000


@njit(cache=True, parallel=True)
def _chunks_parallel(bounds, nz, start, cs, zs, ts, hstart, halo, xs, vs, wcs, was, r_c2, r_a2, acc, sparse,
                     fncx, fncy, fncz, fcs, fstart, forder, fxs, r_s, w_s, sep):
    """The pair and separation sums, chunk ``k`` of each on thread ``k``."""
    nchunks = bounds.shape[0] - 1
    n = fxs.shape[1]
    for k in prange(nchunks):
        _pairs_chunk(bounds[k], bounds[k + 1], nz, start, cs, zs, ts, hstart, halo, xs, vs, wcs, was, r_c2, r_a2,
                     acc, sparse, r_s * r_s, w_s)
        if not sparse:
            _separation_chunk(k * n // nchunks, (k + 1) * n // nchunks, fncx, fncy, fncz, fcs, fstart, forder, fxs,
                              r_s, w_s, sep)


@njit(cache=True)
def _forces(x, v, types, wa, wc, c, planar, dv, nchunks):
    """dv = dt/m (F_s + F_a + F_c) of every agent (eq. 1-9), split into ``nchunks`` parts on parallel
    threads if ``nchunks > 1`` (the result is the same: each sum's order is fixed by the agents'
    indices)."""
    n = x.shape[0]
    (sparse, nz, start, order, cs, zs, ts, xs, vs, wcs, was, hstart, halo, bounds,
     fx, fy, fz, fcs, fstart, forder, fxs) = _prepare(x, v, types, wa, wc, c, planar, nchunks)
    acc = np.zeros((11, n))
    sep = np.empty((3, n))
    r_c2, r_a2 = c[2] * c[2], c[1] * c[1]
    if nchunks > 1:
        _chunks_parallel(bounds, nz, start, cs, zs, ts, hstart, halo, xs, vs, wcs, was, r_c2, r_a2, acc, sparse,
                         fx, fy, fz, fcs, fstart, forder, fxs, c[0], c[3], sep)
    else:
        _pairs_chunk(0, n, nz, start, cs, zs, ts, hstart, halo, xs, vs, wcs, was, r_c2, r_a2, acc, sparse,
                     c[0] * c[0], c[3])
        if not sparse:
            _separation_chunk(0, n, fx, fy, fz, fcs, fstart, forder, fxs, c[0], c[3], sep)
    _combine(xs, order, acc, sep, c, planar, dv, sparse)


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
def _run(x, v, types, wa, wc, c, planar, n_steps, vmax, nchunks):
    """``n_steps`` steps; returns the first step (1-based) at which a speed exceeded ``vmax`` or
    became NaN, else 0. The forces are split into ``nchunks`` parts on parallel threads."""
    n = x.shape[0]
    dv = np.empty((n, 3))
    for k in range(n_steps):
        _forces(x, v, types, wa, wc, c, planar, dv, nchunks)
        _advance(x, v, dv, c)
        for i in range(n):
            s = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
            if not (s <= vmax * vmax):
                return k + 1
    return 0


def _nchunks(n: int) -> int:
    """One part below :data:`PARALLEL_FROM` agents, else one per numba thread."""
    return 1 if n < PARALLEL_FROM else max(1, numba.get_num_threads())


def _as3(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a if a.shape[1] == 3 else np.concatenate([a, np.zeros((a.shape[0], 3 - a.shape[1]))], axis=1)


def step_grid(x: np.ndarray, v: np.ndarray, types: np.ndarray, params: BoidParams, n_steps: int = 1) -> None:
    """Advance ``x``, ``v`` (arrays (n, D), updated in place) by ``n_steps`` steps with the cell-list
    engine. Raises :class:`UserError` when the run diverges."""
    x3, v3 = _as3(x), _as3(v)
    wa, wc, c = params.arrays()
    bad = _run(x3, v3, np.asarray(types, dtype=np.int64), wa, wc, c, params.dims == 2, int(n_steps),
               diverged_speed(params), _nchunks(len(x3)))
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
    force component is the plain floating-point sum of its terms, neighbours in ascending index
    order, then the wall terms (eq. 3-5, 7, 9)."""
    n, D = x.shape
    wa, wc = np.array(params.wa), np.array(params.wc)
    dv = np.zeros((n, D))
    for i in range(n):
        fs, fa, fc = [0.0] * D, [0.0] * D, [0.0] * D
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
                    fc[a] += -(w * xi[a])
                if d2 < params.r_a * params.r_a:
                    na += 1
                    w = wa[types[i], types[j]]
                    for a in range(D):
                        fa[a] += w * (v[j, a] - v[i, a])
                    if 0.0 < d2 < params.r_s * params.r_s:
                        w = params.w_s / math.sqrt(d2)
                        for a in range(D):
                            fs[a] += w * xi[a]
        for a in range(D):
            if x[i, a] < params.r_s:
                fs[a] += params.w_s
            if params.box - x[i, a] < params.r_s:
                fs[a] += -params.w_s
        for a in range(D):
            f = fs[a]
            if na:
                f += fa[a] / na
            if nc:
                f += fc[a] / nc
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
            bad = _run(x3, v3, types, wa, wc, c, planar, k, diverged_speed(params), _nchunks(n))
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
