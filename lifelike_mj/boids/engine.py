"""Heterogeneous boids of Nakamura 2013 (docs/models/boids.md): a compiled cell-list engine
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
agents move. Every sum is an exact sum of 64-bit fixed-point values (positions, velocities and
separation terms rounded to a power-of-two quantum chosen so that nothing can overflow: for the
paper's 300 agents, the float64 spacing of the largest values), so its value does not depend on the
order of its terms: the engine adds them in the order that vectorises, on any number of threads,
and equals the plain all-pairs reference :func:`step_reference` (kept for the tests) bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np
from numba import njit, prange

from lifelike_mj import checks
from lifelike_mj.errors import UserError

#: The paper's settings (section 2): zones, separation weight, box side, agents.
R_S, R_A, R_C = 1.0, 2.5, 4.5
W_S = 0.05
BOX = 20.0
#: Widest box, in multiples of R_c (the neighbour grid holds (box / R_c)^3 cells: 200^3 = 8 million).
MAX_BOX_ZONES = 200
N_AGENTS = 300
#: A run has diverged (section 2.2: w_a >= 10 or w_c >= 1) when an agent moves farther than the box
#: side in one step (box units per step, as a multiple of the box side): the walls and zones no
#: longer mean anything. With w_a >= 2 the speeds overflow within a few dozen steps; with w_c = 1
#: the swarm stays finite but agents pass 20 box units per step within 35-500 steps. Anti-alignment
#: (a negative W_a entry, as in 5b) can throw a lone agent past it too (5b seed 2, at step 626).
DIVERGED_BOX_PER_STEP = 1.0
#: The most agent types, and the largest weight (in size) of a W_a or W_c entry: far beyond the paper's (types 2,
#: weights below 1, runs diverging from w_a = 10 or w_c = 1) and keeping every number of the compiled step finite.
MAX_TYPES = 64
MAX_WEIGHT = 1.0e3
#: The largest zone radius (box units).
MAX_RADIUS = 1.0e3


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
            if not checks.is_number(v) or not math.isfinite(v):
                raise UserError(f"{k} must be a finite number, got {v!r}.")
        for k in ("r_s", "r_a", "r_c"):
            checks.number(k, getattr(self, k), hi=MAX_RADIUS, unit="box units")
        checks.number("w_s", self.w_s, -MAX_WEIGHT, MAX_WEIGHT)
        if not (0 < self.r_s < self.r_a < self.r_c):
            raise UserError(f"the zones must nest: 0 < R_s < R_a < R_c, got R_s = {self.r_s}, R_a = {self.r_a}, "
                            f"R_c = {self.r_c}.")
        if self.box <= 2 * self.r_c:
            raise UserError(f"the box ({self.box}) must be wider than 2 R_c ({2 * self.r_c}).")
        if self.box > MAX_BOX_ZONES * self.r_c:
            raise UserError(f"the box ({self.box:g}) may be at most {MAX_BOX_ZONES} R_c ({MAX_BOX_ZONES * self.r_c:g}) "
                            "wide: the neighbour grid has (box / R_c)^3 cells.")
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
    if a.ndim != 2 or a.shape[0] != a.shape[1] or not 1 <= a.shape[0] <= MAX_TYPES:
        raise UserError(f"{name} must be a square k x k matrix (one row and column per type, at most {MAX_TYPES} "
                        f"types), got shape {a.shape}.")
    if not np.all(np.isfinite(a)) or np.any(np.abs(a) > MAX_WEIGHT):
        raise UserError(f"{name} must contain finite numbers within +-{MAX_WEIGHT:g}, got {a.tolist()!r}.")
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


#: The most neighbour visits (each agent's neighbours within R_c, summed over the agents and the steps) one run may
#: ask for: about half an hour of the compiled engine on two cores (measured: 6-8 x 10^7 visits per second on one
#: core, 10,000-30,000 agents in the paper's box). The agent-steps bound alone does not hold the cost: in the paper's
#: fixed box the neighbours grow with the agents, so a million agents there see about 48,000 each.
MAX_NEIGHBOUR_VISITS = 1.0e11


def neighbours_each(params: BoidParams, n: int) -> float:
    """The neighbours within ``R_c`` each of ``n`` agents has when they fill ``params``' box evenly (as they start:
    :func:`initial_state`): ``(n - 1)`` times the zone's share of the box (a sphere of radius ``R_c`` in a cube, or
    a disc in a square in 2D), at most ``n - 1``. A cohesive pattern gathers them closer, so this is the least."""
    import math

    d = int(params.dims)
    zone = 4.0 / 3.0 * math.pi * params.r_c**3 if d == 3 else math.pi * params.r_c**2
    return (n - 1) * min(1.0, zone / float(params.box) ** d)


def check_cost(params: BoidParams, n: int, steps: int, what: str, limit: float = MAX_NEIGHBOUR_VISITS) -> float:
    """Before any work: the neighbour visits of ``n`` agents over ``steps`` steps (:func:`neighbours_each`, at least
    one per agent-step), or a :class:`~lifelike_mj.errors.UserError` naming ``what``, the neighbours each agent sees
    and :data:`MAX_NEIGHBOUR_VISITS`."""
    each = neighbours_each(params, n)
    visits = float(n) * max(each, 1.0) * float(steps)
    if visits > limit:
        raise UserError(f"{what}: {n:,} agents in a box {float(params.box):g} units wide see about {each:,.0f} "
                        f"neighbours each, {visits:.3g} neighbour visits over {steps:,} step{'s' if steps != 1 else ''}; at most "
                        f"{limit:.3g} "
                        "are allowed (fewer agents or steps, or a wider box: a preset's \"box\").")
    return visits


def initial_state(params: BoidParams, n: int, seed: int, margin: float | None = None,
                  type_probs=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random positions in ``[margin, L - margin]^D`` (default margin ``R_c``: well away from the
    walls), tiny random velocities (uniform in ``[-0.01, 0.01]`` per axis), and types drawn
    independently (each of the ``k`` types equally likely: A or B with probability 0.5 in the
    paper's case). One ``numpy.random.Generator`` seeded with ``seed``."""
    if not checks.is_whole(n) or n < 2:
        raise UserError(f"the number of agents must be a whole number of at least 2, got {n!r}.")
    if not checks.is_whole(seed) or seed < 0:
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
# Every sum of a force (eq. 3, 7, 9) is accumulated in 64-bit fixed point, so that its value does not
# depend on the order of its terms: the engine may add them in whatever order is fastest (vectorised,
# on any number of threads) and still equal the all-pairs reference bit for bit. A value y enters a
# sum as the integer Q(y) = trunc(y * s), s a power of two chosen by :func:`_scale` from the largest
# |y| and n so that no sum can overflow. For the paper's n = 300 the quantum 1 / s is the float64
# spacing of the largest values (2^-48 box units for positions in a box of 20: nothing is lost at
# 16-20); the difference from plain floating-point sums is at the level of their own rounding
# (tested: a few float64 epsilons after one step).
#
# The alignment and cohesion sums are kept per neighbour type t: ``S_t = sum Q(y_j)`` over the
# neighbours of type t in the zone and their number ``N_t``; ``sum_j (y_j - y_i)`` over them is then
# the exact integer ``S_t - N_t Q(y_i)``, weighted by ``W[t_i, t]`` after conversion (eq. 6-9).
# The agents are sorted by (column of R_c cells, type, z cell): the agents of one type in three
# adjacent z cells of a column are one contiguous run, and each agent's neighbours are at most 9 k
# runs, which the compiler vectorises (a branch-free loop: a term outside its zone is masked to 0).
# Separation (a few neighbours each) runs on a finer grid of cells of R_s, each pair once.

#: The fine grid of the separation zone has at most this many cells, or 2 per agent if more (a
#: bigger grid is mostly empty cells and cache misses at large n).
FINE_CELLS_MIN = 1 << 12


@njit(cache=True)
def _scale(top, n):
    """The fixed-point scale of a sum of at most ``n`` terms of magnitude at most ``top``: the power of
    two ``s = 2^(min(53, 62 - b) - e)``, where ``2^(e-1) <= top < 2^e`` and ``2^(b-1) <= n < 2^b``.
    Then ``top * s < 2^53`` (below n = 512 agents the quantum ``1 / s`` is the float64 spacing of
    the largest values: nothing is lost) and ``n * top * s < 2^62`` (no sum of n terms, nor the
    difference of two, reaches 2^63)."""
    if not top > 0.0:
        return 1.0
    e = math.frexp(top)[1]
    b = 0
    while n >> b:
        b += 1
    return math.ldexp(1.0, min(53, 62 - b) - e)


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
def _grid(x, types, k, lo, ext, size_min, planar, max_cells):
    """A uniform grid over the box ``lo .. lo + ext`` holding the agents, cells at least ``size_min``
    wide (a hair more, so that rounding never puts two agents closer than ``size_min`` two cells
    apart), at most ``max_cells`` cells: ``(ncx, ncy, ncz, start, pos)``. The agents are
    counting-sorted by the key (x cell, y cell, type, z cell) (``k = 1``: no type), by index within a
    key: agent ``i`` is at sorted position ``pos[i]``, key ``c`` holds the sorted positions
    ``start[c] .. start[c + 1] - 1``."""
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
    key = np.empty(n, dtype=np.int64)
    for i in range(n):
        qx = min(int((x[i, 0] - lo[0]) * inv[0]), ncx - 1)
        qy = min(int((x[i, 1] - lo[1]) * inv[1]), ncy - 1)
        qz = 0 if planar else min(int((x[i, 2] - lo[2]) * inv[2]), ncz - 1)
        t = types[i] if k > 1 else 0
        key[i] = ((qx * ncy + qy) * k + t) * ncz + qz
    nkeys = ncx * ncy * k * ncz
    start = np.zeros(nkeys + 1, dtype=np.int64)
    for i in range(n):
        start[key[i] + 1] += 1
    for c in range(nkeys):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    pos = np.empty(n, dtype=np.int64)
    for i in range(n):
        pos[i] = fill[key[i]]
        fill[key[i]] += 1
    return ncx, ncy, ncz, start, pos


@njit(cache=True)
def _max_abs(a):
    m = 0.0
    for i in range(a.shape[0]):
        for b in range(a.shape[1]):
            m = max(m, abs(a[i, b]))
    return m


@njit(cache=True)
def _scales(x, v, w_s):
    """The fixed-point scales of the cohesion (positions), alignment (velocities) and separation
    (terms at most |w_s|) sums of this state."""
    n = x.shape[0]
    return _scale(_max_abs(x), n), _scale(_max_abs(v), n), _scale(abs(w_s), n)


@njit(cache=True)
def _prepare(x, v, types, k, c, planar, nchunks, s_x, s_v):
    """Everything the sum loops read: the R_c grid (sorted by column, type, z), the agents' state in
    sorted order (``xs`` rows x, y, z; ``qx``, ``qv`` the fixed-point positions and velocities), the
    fine grid of the separation zone (``fmain``: fine order -> sorted order, ``fxs``: positions in fine
    order), and ``nchunks`` ranges of R_c cells (column-major, z minor) of about equal numbers of
    agents."""
    n = x.shape[0]
    lo, ext = _bbox(x, planar)
    ncx, ncy, nz, start, pos = _grid(x, types, k, lo, ext, c[2], planar, 1 << 40)
    order = np.empty(n, dtype=np.int64)
    for i in range(n):
        order[pos[i]] = i
    xs = np.empty((3, n))
    qx = np.empty((3, n), dtype=np.int64)
    qv = np.empty((3, n), dtype=np.int64)
    ts = np.empty(n, dtype=np.int64)
    for p in range(n):
        i = order[p]
        ts[p] = types[i]
        for a in range(3):
            xs[a, p] = x[i, a]
            qx[a, p] = np.int64(x[i, a] * s_x)
            qv[a, p] = np.int64(v[i, a] * s_v)
    fx, fy, fz, fstart, fpos = _grid(x, types, 1, lo, ext, c[0], planar, max(FINE_CELLS_MIN, 2 * n))
    fmain = np.empty(n, dtype=np.int64)  # fine position -> sorted position
    for i in range(n):
        fmain[fpos[i]] = pos[i]
    fxs = np.empty((3, n))
    for f in range(n):
        p = fmain[f]
        for a in range(3):
            fxs[a, f] = xs[a, p]
    # chunks: cells (col, z), col = (x cell, y cell), of about n / nchunks agents each
    ncells = ncx * ncy * nz
    cells = np.full(nchunks + 1, ncells, dtype=np.int64)
    cells[0] = 0
    kk = 1
    done = 0
    for cc in range(ncells):
        while kk < nchunks and done * nchunks >= kk * n:
            cells[kk] = cc
            kk += 1
        col = cc // nz
        z = cc - col * nz
        for t in range(k):
            q = (col * k + t) * nz + z
            done += start[q + 1] - start[q]
    return ncx, ncy, nz, start, order, xs, qx, qv, ts, fx, fy, fz, fstart, fmain, fxs, cells


@njit(cache=True)
def _sums_chunk(c0, c1, ncx, ncy, nz, k, start, xs, qx, qv, r_c2, r_a2, sums):
    """Alignment and cohesion sums of the agents in R_c cells ``c0 .. c1 - 1`` (each chunk of cells
    writes its own agents). ``sums[p, 8 t + r]`` for neighbour type t: r = 0-2 sum of Q(x_j), 3-5
    sum of Q(v_j), 6 N_c, 7 N_a (the agent itself included, with equal and opposite terms). The
    candidates of a cell are at most 9 k runs (a neighbouring column, one type, three z cells)."""
    x0, x1, x2 = xs[0], xs[1], xs[2]
    q0, q1, q2 = qx[0], qx[1], qx[2]
    u0, u1, u2 = qv[0], qv[1], qv[2]
    rlo = np.empty(9 * k, dtype=np.int64)
    rhi = np.empty(9 * k, dtype=np.int64)
    rend = np.empty(k, dtype=np.int64)  # the runs of type t are rlo/rhi[rend[t - 1] .. rend[t] - 1]
    for cc in range(c0, c1):
        col = cc // nz
        z = cc - col * nz
        here = 0  # agents in this cell
        for t in range(k):
            here += start[(col * k + t) * nz + z + 1] - start[(col * k + t) * nz + z]
        if here == 0:
            continue
        cx, cy = col // ncy, col % ncy
        za, zb = max(z - 1, 0), min(z + 1, nz - 1)
        nr = 0
        for t in range(k):
            for bx in range(max(cx - 1, 0), min(cx + 2, ncx)):
                for by in range(max(cy - 1, 0), min(cy + 2, ncy)):
                    b = (bx * ncy + by) * k + t
                    lo = start[b * nz + za]
                    hi = start[b * nz + zb + 1]
                    if hi > lo:
                        rlo[nr] = lo
                        rhi[nr] = hi
                        nr += 1
            rend[t] = nr
        for tr in range(k):
            q = (col * k + tr) * nz + z
            for p in range(start[q], start[q + 1]):
                xi0, xi1, xi2 = x0[p], x1[p], x2[p]
                r = 0
                for t in range(k):
                    s0 = s1 = s2 = a0 = a1 = a2 = nc = na = np.int64(0)
                    while r < rend[t]:
                        # unsigned indices (no negative-index wraparound) let the loop vectorise
                        for j in range(np.uint64(rlo[r]), np.uint64(rhi[r])):
                            e0 = xi0 - x0[j]
                            e1 = xi1 - x1[j]
                            e2 = xi2 - x2[j]
                            d2 = e0 * e0 + e1 * e1 + e2 * e2
                            m = np.int64(-1) if d2 < r_c2 else np.int64(0)
                            g = np.int64(-1) if d2 < r_a2 else np.int64(0)
                            s0 += q0[j] & m
                            s1 += q1[j] & m
                            s2 += q2[j] & m
                            nc -= m
                            a0 += u0[j] & g
                            a1 += u1[j] & g
                            a2 += u2[j] & g
                            na -= g
                        r += 1
                    o = 8 * t
                    sums[p, o] = s0
                    sums[p, o + 1] = s1
                    sums[p, o + 2] = s2
                    sums[p, o + 3] = a0
                    sums[p, o + 4] = a1
                    sums[p, o + 5] = a2
                    sums[p, o + 6] = nc
                    sums[p, o + 7] = na


@njit(cache=True)
def _separation_chunk(s0, s1, fncx, fncy, fncz, fstart, fmain, fxs, r_s, w_s, s_s, sep):
    """Separation sums (eq. 3 with f = 1), fixed point, of the pairs whose first agent is at fine
    sorted position ``s0 .. s1 - 1``: each pair once (its own cell after it, and 13 of the 26
    neighbouring cells), the term Q(w_s xi / d) added to one agent's sum and subtracted from the
    other's (Q(-y) = -Q(y)). ``sep[a, p]``: component a of the agent at (R_c grid) sorted position p;
    ``fmain[f]``: the sorted position of the agent at fine position f."""
    r_s2 = r_s * r_s
    if s0 >= s1:
        return
    lo = np.empty(5, dtype=np.int64)
    hi = np.empty(5, dtype=np.int64)
    f = w_s * s_s
    q = np.searchsorted(fstart, s0, side="right") - 1
    nq = fncx * fncy * fncz
    while q < nq and fstart[q] < s1:
        a0 = max(fstart[q], s0)
        a1 = min(fstart[q + 1], s1)
        if a0 < a1:
            qz = q % fncz
            qy = (q // fncz) % fncy
            qx = q // (fncz * fncy)
            za, zb = max(qz - 1, 0), min(qz + 1, fncz - 1)
            # run 0: this column from the agent on (this cell, then the cell above); runs 1-4: the
            # columns (x, y + 1), (x + 1, y - 1), (x + 1, y), (x + 1, y + 1), three z cells each
            hi[0] = fstart[(qx * fncy + qy) * fncz + zb + 1]
            nr = 1
            for d in range(4):
                bx = qx + (0 if d == 0 else 1)
                by = qy + (1 if d == 0 else d - 2)
                if bx < fncx and 0 <= by < fncy:
                    c0 = (bx * fncy + by) * fncz
                    lo[nr] = fstart[c0 + za]
                    hi[nr] = fstart[c0 + zb + 1]
                    nr += 1
            for pa in range(a0, a1):
                xi0, xi1, xi2 = fxs[0, pa], fxs[1, pa], fxs[2, pa]
                i = fmain[pa]
                lo[0] = pa + 1
                for r in range(nr):
                    for pb in range(lo[r], hi[r]):
                        ex = xi0 - fxs[0, pb]
                        ey = xi1 - fxs[1, pb]
                        ez = xi2 - fxs[2, pb]
                        d2 = ex * ex + ey * ey + ez * ez
                        if 0.0 < d2 < r_s2:
                            w = f / math.sqrt(d2)
                            j = fmain[pb]
                            y = np.int64(w * ex)
                            sep[0, i] += y
                            sep[0, j] -= y
                            y = np.int64(w * ey)
                            sep[1, i] += y
                            sep[1, j] -= y
                            y = np.int64(w * ez)
                            sep[2, i] += y
                            sep[2, j] -= y
        q += 1


@njit(cache=True)
def _combine(p0, p1, xs, qx, qv, ts, order, sums, sep, wa, wc, c, planar, s_x, s_v, s_s, dv):
    """dv = dt/m (F_s + F_a + F_c) (eq. 1-9), as :func:`step_reference` computes it from the exact
    sums: separation, plus wall avoidance (a wall closer than R_s adds w_s along its inward normal),
    then the alignment and cohesion averages, each the sum over neighbour types t of
    ``W[t_i, t] * (S_t - N_t Q(y_i)) / s`` divided by the number of neighbours. In sorted order
    (``order[p]``: the agent at sorted position p), positions ``p0 .. p1 - 1``; ``sep[h]``: chunk h's
    separation sums."""
    k = wa.shape[0]
    r_s, w_s, box, dt_m = c[0], c[3], c[4], c[5]
    ix, iv, i_s = 1.0 / s_x, 1.0 / s_v, 1.0 / s_s
    for p in range(p0, p1):
        i = order[p]
        ti = ts[p]
        nc = -1
        na = -1
        for t in range(k):
            nc += sums[p, 8 * t + 6]
            na += sums[p, 8 * t + 7]
        for a in range(3):
            ss = np.int64(0)
            for h in range(sep.shape[0]):
                ss += sep[h, a, p]
            f = float(ss) * i_s
            if a < 2 or not planar:
                if xs[a, p] < r_s:
                    f += w_s
                if box - xs[a, p] < r_s:
                    f += -w_s
            if na > 0:
                g = 0.0
                for t in range(k):
                    g += wa[ti, t] * (float(sums[p, 8 * t + 3 + a] - sums[p, 8 * t + 7] * qv[a, p]) * iv)
                f += g / na
            if nc > 0:
                g = 0.0
                for t in range(k):
                    g += wc[ti, t] * (float(sums[p, 8 * t + a] - sums[p, 8 * t + 6] * qx[a, p]) * ix)
                f += g / nc
            dv[i, a] = dt_m * f


#: Below this many agents one thread is as fast (see docs/performance.md) and robust to a busy machine.
PARALLEL_FROM = 2000


@njit(cache=True)
def _forces(x, v, types, wa, wc, c, planar, dv):
    """dv = dt/m (F_s + F_a + F_c) of every agent (eq. 1-9), on one thread."""
    n = x.shape[0]
    k = wa.shape[0]
    s_x, s_v, s_s = _scales(x, v, c[3])
    (ncx, ncy, nz, start, order, xs, qx, qv, ts, fx, fy, fz, fstart, fmain, fxs,
     cells) = _prepare(x, v, types, k, c, planar, 1, s_x, s_v)
    sums = np.empty((n, 8 * k), dtype=np.int64)  # every entry written
    sep = np.zeros((1, 3, n), dtype=np.int64)
    _sums_chunk(0, ncx * ncy * nz, ncx, ncy, nz, k, start, xs, qx, qv, c[2] * c[2], c[1] * c[1], sums)
    _separation_chunk(0, n, fx, fy, fz, fstart, fmain, fxs, c[0], c[3], s_s, sep[0])
    _combine(0, n, xs, qx, qv, ts, order, sums, sep, wa, wc, c, planar, s_x, s_v, s_s, dv)


# Called from Python only, never from another compiled function: a cached function that calls a
# parallel one can crash when loaded from the cache (numba issue 8578).
@njit(cache=True, parallel=True)
def _forces_parallel(x, v, types, wa, wc, c, planar, dv, nchunks):
    """:func:`_forces` split into ``nchunks`` parts on parallel threads (the result is the same: the
    sums are exact integers). Each chunk of R_c cells writes its own agents' sums; each chunk of
    the separation pairs writes its own ``sep[h]`` (a pair may cross chunks)."""
    n = x.shape[0]
    k = wa.shape[0]
    s_x, s_v, s_s = _scales(x, v, c[3])
    (ncx, ncy, nz, start, order, xs, qx, qv, ts, fx, fy, fz, fstart, fmain, fxs,
     cells) = _prepare(x, v, types, k, c, planar, nchunks, s_x, s_v)
    sums = np.empty((n, 8 * k), dtype=np.int64)
    sep = np.zeros((nchunks, 3, n), dtype=np.int64)
    r_c2, r_a2 = c[2] * c[2], c[1] * c[1]
    for h in prange(nchunks):
        _sums_chunk(cells[h], cells[h + 1], ncx, ncy, nz, k, start, xs, qx, qv, r_c2, r_a2, sums)
        _separation_chunk(h * n // nchunks, (h + 1) * n // nchunks, fx, fy, fz, fstart, fmain, fxs, c[0], c[3], s_s,
                          sep[h])
    for h in prange(nchunks):
        _combine(h * n // nchunks, (h + 1) * n // nchunks, xs, qx, qv, ts, order, sums, sep, wa, wc, c, planar, s_x,
                 s_v, s_s, dv)


@njit(cache=True)
def _advance(x, v, dv, c, vmax):
    """Semi-implicit update (eq. 1-2) and reflecting walls; an agent is never left outside the box
    (a reflection that would still land outside, possible only in a diverging run, is clamped).
    Returns True if a speed exceeded ``vmax`` or became NaN."""
    n = x.shape[0]
    box, dt = c[4], c[6]
    bad = False
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
        s = v[i, 0] * v[i, 0] + v[i, 1] * v[i, 1] + v[i, 2] * v[i, 2]
        if not (s <= vmax * vmax):
            bad = True
    return bad


@njit(cache=True)
def _run(x, v, types, wa, wc, c, planar, n_steps, vmax):
    """``n_steps`` steps on one thread; returns the first step (1-based) at which a speed exceeded
    ``vmax`` or became NaN, else 0."""
    dv = np.empty(x.shape)
    for k in range(n_steps):
        _forces(x, v, types, wa, wc, c, planar, dv)
        if _advance(x, v, dv, c, vmax):
            return k + 1
    return 0


#: Below this many agents one thread is as fast (see docs/performance.md) and robust to a busy machine.
PARALLEL_FROM = 2000


def _steps(x, v, types, wa, wc, c, planar: bool, n_steps: int, vmax: float) -> int:
    """:func:`_run`, or from :data:`PARALLEL_FROM` agents (and more than one numba thread) the same
    steps with the forces on all threads, stepped from Python (a step then takes milliseconds)."""
    nchunks = max(1, numba.get_num_threads())
    if len(x) < PARALLEL_FROM or nchunks == 1:
        return _run(x, v, types, wa, wc, c, planar, n_steps, vmax)
    dv = np.empty(x.shape)
    for k in range(n_steps):
        _forces_parallel(x, v, types, wa, wc, c, planar, dv, nchunks)
        if _advance(x, v, dv, c, vmax):
            return k + 1
    return 0


def _as3(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    return a if a.shape[1] == 3 else np.concatenate([a, np.zeros((a.shape[0], 3 - a.shape[1]))], axis=1)


def step_grid(x: np.ndarray, v: np.ndarray, types: np.ndarray, params: BoidParams, n_steps: int = 1) -> None:
    """Advance ``x``, ``v`` (arrays (n, D), updated in place) by ``n_steps`` steps with the cell-list
    engine. Raises :class:`UserError` when the run diverges."""
    x3, v3 = _as3(x), _as3(v)
    wa, wc, c = params.arrays()
    bad = _steps(x3, v3, np.asarray(types, dtype=np.int64), wa, wc, c, params.dims == 2, int(n_steps),
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
    head = (f"the run diverged at step {step}: an agent moved farther than the box side ({params.box:g}) in one step; "
            f"largest W_a entry {np.max(np.abs(wa)):g}, largest W_c entry {np.max(np.abs(wc)):g}")
    if np.max(np.abs(wa)) >= 10 or np.max(np.abs(wc)) >= 1:
        return head + " (the paper finds divergence from w_a >= 10 or w_c >= 1: the weights are too large)."
    if np.min(wa) < 0:
        return (head + " (a negative W_a entry: an agent among neighbours it anti-aligns with is pushed along its "
                "own velocity, which can run away; the paper's 5b does this now and then).")
    return head + " (the paper finds divergence from w_a >= 10 or w_c >= 1)."


# ---- the plain all-pairs reference -----------------------------------------------------------------


def step_reference(x: np.ndarray, v: np.ndarray, types: np.ndarray, params: BoidParams) -> None:
    """One step over all pairs in plain Python: the definition the engine is tested against (eq. 1-9,
    walls). Each sum is exact, in Python integers, of the fixed-point values ``trunc(y * s)`` (scales
    from :func:`_scales`): per neighbour type t, ``sum_j (Q(x_j) - Q(x_i))`` and ``sum_j (Q(v_j) -
    Q(v_i))`` over the zone and the neighbour counts; separation, ``sum_j trunc(w_s s xi_ij / d)``.
    The conversions back and the weighting by ``W[t_i, t]`` are the floating-point operations of the
    engine, in its order."""
    n, D = x.shape
    k = params.n_types
    wa, wc = np.array(params.wa), np.array(params.wc)
    s_x, s_v, s_s = _scales(_as3(x), _as3(v), params.w_s)
    qx = [[int(x[i, a] * s_x) for a in range(D)] for i in range(n)]
    qv = [[int(v[i, a] * s_v) for a in range(D)] for i in range(n)]
    r_s2, r_a2, r_c2 = params.r_s * params.r_s, params.r_a * params.r_a, params.r_c * params.r_c
    dv = np.zeros((n, D))
    for i in range(n):
        ti = int(types[i])
        nc, na = [0] * k, [0] * k
        sx = [[0] * D for _ in range(k)]  # per neighbour type: sum of Q(x_j) - Q(x_i) (cohesion)
        sv = [[0] * D for _ in range(k)]  # sum of Q(v_j) - Q(v_i) (alignment)
        ss = [0] * D  # separation
        for j in range(n):
            if j == i:
                continue
            xi = [float(x[i, a] - x[j, a]) for a in range(D)]
            d2 = 0.0
            for e in xi:
                d2 += e * e
            t = int(types[j])
            if d2 < r_c2:
                nc[t] += 1
                for a in range(D):
                    sx[t][a] += qx[j][a] - qx[i][a]
                if d2 < r_a2:
                    na[t] += 1
                    for a in range(D):
                        sv[t][a] += qv[j][a] - qv[i][a]
                    if 0.0 < d2 < r_s2:
                        w = params.w_s * s_s / math.sqrt(d2)
                        for a in range(D):
                            ss[a] += int(w * xi[a])
        n_c, n_a = sum(nc), sum(na)
        for a in range(D):
            f = float(ss[a]) * (1.0 / s_s)
            if x[i, a] < params.r_s:
                f += params.w_s
            if params.box - x[i, a] < params.r_s:
                f += -params.w_s
            if n_a:
                g = 0.0
                for t in range(k):
                    g += wa[ti, t] * (float(sv[t][a]) * (1.0 / s_v))
                f += g / n_a
            if n_c:
                g = 0.0
                for t in range(k):
                    g += wc[ti, t] * (float(sx[t][a]) * (1.0 / s_x))
                f += g / n_c
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
