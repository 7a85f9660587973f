"""Figures of the boids in the style of Nakamura 2013 (Fig. 2, 4 and 5), and a phase diagram.

The paper's snapshots show each agent's path over its last 5 steps as a short line segment, type A
in red and type B in yellow-green, in a 2D projection of the 20^3 box. Here (in colour-blind-safe blue
and orange unless :func:`~lifelike_mj.boids.palette.use_palette` chooses the paper's colours):

* the projection is onto the **x-y plane** by default (the view from above, looking down -z, x to
  the right, y up; the ``top`` camera of :mod:`lifelike_mj.boids.scene`): the same plane for 3D and
  2D runs, and, as the model has no gravity, no axis is special. ``plane="xz"`` or ``"yz"`` gives a
  side view of a 3D run (seen from -y, resp. +x). The agents are drawn farthest from the viewer
  first, so that the picture is what one sees from that side: in a shell (4c) the upper half of the
  shell covers the core;
* a trail is the agent's positions at the last :data:`TRAIL_STEPS` ``+ 1`` recorded steps (5 steps
  of motion), which must be consecutive engine steps: record the end of the run every step, e.g.
  ``simulate(params, n_steps=3000, record_every=1, record_from=2995)``. Round line caps keep an
  agent that hardly moves visible as a dot;
* the box is outlined (the square of side ``params.box``).

:func:`pattern_figure` draws one run, :func:`patterns_grid_figure` the eight patterns of Fig. 4-5
in a 2 x 4 grid, :func:`homogeneous_grid_figure` the 4 x 4 grid of Fig. 2 (``w_a`` by ``w_c``, one
type) and :func:`phase_diagram_figure` a categorical map of classified pattern labels over a sweep.

The figures are built on :class:`matplotlib.figure.Figure` with the Agg canvas, without pyplot (the
process's matplotlib backend is never changed); every PNG is written atomically.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch, Rectangle

from lifelike_mj.boids.palette import PALETTES, type_colour, use_palette
from lifelike_mj.errors import UserError
from lifelike_mj.render.plot import finish, png_path
from lifelike_mj.render.plot import new_figure as _figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

    from lifelike_mj.boids.engine import BoidRun

#: Steps of motion in a trail (the paper's figures: 5 steps).
TRAIL_STEPS = 5
TYPE_COLOURS = PALETTES["colour-blind"]
#: Short names of the eight patterns (Nakamura 2013 section 3.2).
PATTERN_NAMES = {
    "4a": "two ellipsoidal groups, small interface",
    "4b": "wide interface, loose swarms",
    "4c": "shell around a core",
    "4d": "one flock split in hemispheres",
    "5a": "mixed single flock",
    "5b": "groups pass each other, hit walls",
    "5c": "two groups repelling on contact",
    "5d": "loose unmixed groups",
}
#: plane: (horizontal axis, vertical axis, projected-out axis, its sign towards the viewer); a right-handed
#: view: x-y from +z (above), x-z from -y, y-z from +x.
_PLANES = {"xy": (0, 1, 2, 1.0), "xz": (0, 2, 1, -1.0), "yz": (1, 2, 0, 1.0)}
_LINE_WIDTH = 1.3
#: Colours of the labels of :func:`phase_diagram_figure`: the eight patterns, then other labels.
_LABEL_COLOURS = {"4a": "#1f77b4", "4b": "#ff7f0e", "4c": "#2ca02c", "4d": "#d62728", "5a": "#9467bd", "5b": "#8c564b",
                  "5c": "#e377c2", "5d": "#17becf"}
_LABEL_COLOURS.update({"aligned lattice": "#0072b2", "lattice": "#009e73", "compact flock": "#d55e00",
                       "swarm": "#e69f00", "spread": "#56b4e9"})
_EXTRA_COLOURS = ("#bcbd22", "#aec7e8", "#ffbb78", "#98df8a", "#ff9896", "#c5b0d5", "#c49c94", "#f7b6d2", "#dbdb8d",
                  "#9edae5", "#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173")
_NO_LABEL = {"", "none", "nan", "n/a", "diverged", "unclassified", "unknown", "?"}


def _new_figure(width_in: float, height_in: float) -> Figure:
    fig = _figure(width_in, height_in)
    fig.get_layout_engine().set(w_pad=0.06, h_pad=0.08)  # inches: keep titles clear of the edge
    return fig


def _plane(run: BoidRun, plane: str) -> tuple[int, int, int | None, float]:
    if plane not in _PLANES:
        raise UserError(f"unknown projection plane {plane!r}; choose xy, xz or yz.")
    D = run.positions.shape[2]
    if D == 2:
        if plane != "xy":
            raise UserError(f"a 2D run can only be drawn in the x-y plane, not {plane}.")
        return 0, 1, None, 1.0
    return _PLANES[plane]


def trails(run: BoidRun, trail_steps: int = TRAIL_STEPS, plane: str = "xy") -> tuple[np.ndarray, np.ndarray]:
    """The projected trails of a run: ``(segments, depth)``, ``segments`` (n, trail_steps + 1, 2) the
    agents' positions at the last ``trail_steps + 1`` recorded steps in the ``plane`` (box units),
    ``depth`` (n,) the projected-out coordinate at the last step, signed to grow towards the viewer
    (z for x-y, -y for x-z, x for y-z; zeros in 2D). :class:`UserError` unless those records are
    consecutive engine steps."""
    a, b, c, sign = _plane(run, plane)
    steps = np.asarray(run.steps)
    k = int(trail_steps) + 1
    tail = steps[-k:]
    if len(steps) < k or np.any(np.diff(tail) != 1):
        raise UserError(f"a pattern figure needs the last {trail_steps} steps of the run recorded every step (got "
                        f"records at steps {', '.join(str(int(s)) for s in tail[-4:])}{' ...' if len(tail) > 4 else ''}); "
                        f"run simulate(..., record_every=1, record_from=n_steps - {trail_steps}).")
    p = np.asarray(run.positions[-k:], dtype=float)  # (k, n, D)
    seg = np.stack([p[:, :, a], p[:, :, b]], axis=-1).transpose(1, 0, 2)
    depth = sign * p[-1, :, c] if c is not None else np.zeros(p.shape[1])
    return seg, depth


def _draw_run(ax: Axes, run: BoidRun, plane: str, trail_steps: int, colour: str | None = None,
              line_width: float = _LINE_WIDTH) -> None:
    """Trails of ``run`` on ``ax`` (farthest agents first), the box outline, equal axes, no ticks."""
    seg, depth = trails(run, trail_steps, plane)
    order = np.argsort(depth, kind="stable")
    types = np.asarray(run.types)
    colours = [colour or type_colour(types[i]) for i in order]
    ax.add_collection(LineCollection(seg[order], colors=colours, linewidths=line_width, capstyle="round",
                                     joinstyle="round"))
    L = float(run.params.box)
    ax.add_patch(Rectangle((0.0, 0.0), L, L, fill=False, ec="0.25", lw=0.8))
    pad = 0.02 * L
    ax.set_xlim(-pad, L + pad)
    ax.set_ylim(-pad, L + pad)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    for s in ax.spines.values():
        s.set_visible(False)


def _axis_names(plane: str) -> tuple[str, str]:
    return plane[0], plane[1]


def _type_legend(fig: Figure, n_types: int) -> None:
    names = "AB" if n_types <= 2 else [chr(ord("A") + k) for k in range(n_types)]
    handles = [Patch(color=type_colour(k), label=f"type {names[k]}") for k in range(max(n_types, 1))]
    fig.legend(handles=handles, loc="outside lower center", ncol=len(handles), frameon=False, fontsize=9)


def _label_title(label: str) -> str:
    name = PATTERN_NAMES.get(str(label))
    return f"{label}: {name}" if name else str(label)


def pattern_figure(run: BoidRun, out_path: str | os.PathLike | None = None, title: str | None = None, plane: str = "xy",
                   trail_steps: int = TRAIL_STEPS) -> Figure:
    """One run as in Nakamura 2013 Fig. 4-5: each agent's last ``trail_steps`` (5) steps as a short
    trail, A blue, B orange (or the paper's red and yellow-green), in the x-y projection (``plane``: module docstring) of the box.

    The run must hold the last ``trail_steps`` steps recorded every step:
    ``simulate(params, n_steps=N, record_every=1, record_from=N - 5)`` (:class:`UserError` otherwise).
    ``title``: default the preset's name and pattern. Writes a PNG atomically; returns its path."""
    out = None if out_path is None else png_path(out_path, "pattern figure")
    fig = _new_figure(4.8, 5.2)
    ax = fig.add_subplot()
    _draw_run(ax, run, plane, trail_steps)
    name = run.params.name
    ax.set_title(title if title is not None else (_label_title(name) if name else "boids"), fontsize=10)
    x, y = _axis_names(plane)
    ax.set_xlabel(f"{x}  (step {int(run.steps[-1])}, n = {run.n}, trails of {trail_steps} steps)", fontsize=8)
    ax.set_ylabel(y, fontsize=8)
    _type_legend(fig, int(np.max(run.types)) + 1 if run.n else 1)
    return finish(fig, out)


def patterns_grid_figure(runs: Mapping[str, BoidRun], out_path: str | os.PathLike | None = None, plane: str = "xy",
                         trail_steps: int = TRAIL_STEPS, title: str | None = None) -> Figure:
    """Nakamura 2013 Fig. 4-5: the runs (``{label: run}``, e.g. the eight patterns ``4a`` ... ``5d``
    in that order) in a grid of 4 columns (2 x 4 for eight), each panel as :func:`pattern_figure`
    and titled with its label and pattern name. Writes a PNG atomically; returns its path."""
    out = None if out_path is None else png_path(out_path, "patterns figure")
    if not runs:
        raise UserError("the patterns figure needs at least one run.")
    items = list(runs.items())
    cols = min(4, len(items))
    rows = -(-len(items) // cols)
    fig = _new_figure(3.0 * cols, 3.25 * rows + 0.6)
    n_types = 1
    for i, (label, run) in enumerate(items):
        ax = fig.add_subplot(rows, cols, i + 1)
        _draw_run(ax, run, plane, trail_steps)
        ax.set_title(_label_title(label), fontsize=9)
        n_types = max(n_types, int(np.max(run.types)) + 1 if run.n else 1)
    steps = sorted({int(r.steps[-1]) for _, r in items})
    ns = sorted({r.n for _, r in items})
    x, y = _axis_names(plane)
    fig.suptitle(title if title is not None else
                 f"Heterogeneous boids (cf. Nakamura 2013 Fig. 4-5): {x}-{y} projection, trails of the last "
                 f"{trail_steps} steps at step {', '.join(map(str, steps))}, n = {', '.join(map(str, ns))}", fontsize=10)
    _type_legend(fig, n_types)
    return finish(fig, out)


def homogeneous_grid_figure(runs: Mapping[tuple[float, float], BoidRun | None], out_path: str | os.PathLike | None = None,
                            plane: str = "xy", trail_steps: int = TRAIL_STEPS, title: str | None = None) -> Figure:
    """Nakamura 2013 Fig. 2: homogeneous runs keyed by ``(w_a, w_c)`` in a grid, ``w_a`` decreasing
    down the rows (1, 0.1, 0.01, 0.001 in the paper) and ``w_c`` decreasing along the columns (0.1,
    0.01, 0.001, 0), each cell as :func:`pattern_figure` (one type: one colour). A cell whose run
    diverged is passed as ``None`` and drawn as "diverged"; a combination missing from ``runs`` is
    left blank ("not run"). Writes a PNG atomically; returns its path."""
    out = None if out_path is None else png_path(out_path, "homogeneous grid figure")
    if not runs:
        raise UserError("the homogeneous grid figure needs at least one run.")
    try:
        keys = [(float(a), float(c)) for a, c in runs]
    except (TypeError, ValueError):
        raise UserError("the homogeneous runs must be keyed by (w_a, w_c) pairs of numbers.") from None
    by_key = dict(zip(keys, runs.values()))
    w_a = sorted({a for a, _ in keys}, reverse=True)
    w_c = sorted({c for _, c in keys}, reverse=True)
    fig = _new_figure(2.5 * len(w_c) + 0.6, 2.5 * len(w_a) + 0.7)
    grid = fig.add_gridspec(len(w_a), len(w_c))
    for i, a in enumerate(w_a):
        for j, c in enumerate(w_c):
            ax = fig.add_subplot(grid[i, j])
            run = by_key.get((a, c), "missing")
            if isinstance(run, str) or run is None:
                ax.set_xlim(0, 1)
                ax.set_ylim(0, 1)
                ax.set_aspect("equal")
                ax.set_xticks([])
                ax.set_yticks([])
                ax.add_patch(Rectangle((0.02, 0.02), 0.96, 0.96, fill=True, fc="0.95", ec="0.6", lw=0.8, ls="--"))
                ax.text(0.5, 0.5, "not run" if isinstance(run, str) else "diverged", ha="center", va="center",
                        fontsize=10, color="0.35")
                for s in ax.spines.values():
                    s.set_visible(False)
            else:
                _draw_run(ax, run, plane, trail_steps, line_width=1.0)
            if i == 0:
                ax.set_title(f"$w_c$ = {c:g}", fontsize=10)
            if j == 0:
                ax.set_ylabel(f"$w_a$ = {a:g}", fontsize=10)
    x, y = _axis_names(plane)
    fig.suptitle(title if title is not None else
                 f"Homogeneous boids (cf. Nakamura 2013 Fig. 2): {x}-{y} projection, trails of the last {trail_steps} "
                 f"steps; alignment weight $w_a$ down, cohesion weight $w_c$ across", fontsize=10)
    return finish(fig, out)


def _label_colours(labels: Sequence[str]) -> dict[str, str]:
    out: dict[str, str] = {}
    extra = iter(_EXTRA_COLOURS * 4)
    for lab in labels:
        if lab in _LABEL_COLOURS:
            out[lab] = _LABEL_COLOURS[lab]
        elif lab.lower() in _NO_LABEL:
            out[lab] = {"diverged": "#7f7f7f", "unclassified": "#c7c7c7", "unknown": "#c7c7c7", "?": "#c7c7c7"}.get(
                lab.lower(), "#f2f2f2")
        else:
            out[lab] = next(extra, "#d9d9d9")
    return out


def phase_diagram_figure(labels, x_values: Sequence[float], y_values: Sequence[float], x_label: str, y_label: str,
                         out_path: str | os.PathLike | None = None, title: str | None = None,
                         annotate: bool | None = None) -> Figure:
    """A categorical map of classified pattern labels over a sweep grid: ``labels`` (2-D, one row per
    ``y_values`` entry and one column per ``x_values`` entry; ``None`` is shown as "n/a") as
    coloured cells, row 0 at the bottom, the values as tick labels (cells equally spaced, whatever
    the spacing of the values), one colour per label (the eight patterns always in the same colours;
    "diverged" dark grey, "unclassified" grey, "n/a" and empty labels very light grey) and a legend. ``annotate``: write the
    label in each cell (default: when the grid has at most 12 columns). Writes a PNG atomically."""
    out = None if out_path is None else png_path(out_path, "phase diagram")
    lab = np.array([["n/a" if v is None else str(v) for v in row] for row in np.asarray(labels, dtype=object)],
                   dtype=object)
    xs, ys = list(x_values), list(y_values)
    if lab.ndim != 2 or lab.shape != (len(ys), len(xs)) or lab.size == 0:
        raise UserError(f"the labels must be a 2-D grid of {len(ys)} rows (y values) x {len(xs)} columns (x values), "
                        f"got shape {np.asarray(labels, dtype=object).shape}.")
    pattern_order = {k: i for i, k in enumerate(_LABEL_COLOURS)}
    seen = sorted(set(lab.ravel().tolist()), key=lambda s: (s.lower() in _NO_LABEL, pattern_order.get(s, 99), s))
    colours = _label_colours(seen)
    rgb = np.array([[_hex(colours[v]) for v in row] for row in lab])
    ny, nx = lab.shape
    fig = _new_figure(min(14.0, 2.2 + 0.75 * nx + 1.8), min(12.0, 1.5 + 0.55 * ny))
    ax = fig.add_subplot()
    ax.imshow(rgb, origin="lower", aspect="auto", interpolation="nearest", extent=(-0.5, nx - 0.5, -0.5, ny - 0.5))
    ax.set_xticks(range(nx), [_fmt(v) for v in xs], fontsize=8, rotation=0 if nx <= 12 else 90)
    ax.set_yticks(range(ny), [_fmt(v) for v in ys], fontsize=8)
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.set_xticks(np.arange(-0.5, nx), minor=True)
    ax.set_yticks(np.arange(-0.5, ny), minor=True)
    ax.grid(which="minor", color="white", lw=1.0)
    ax.tick_params(which="minor", length=0)
    if annotate if annotate is not None else nx <= 12:
        for i in range(ny):
            for j in range(nx):
                r, g, b = rgb[i, j]
                ax.text(j, i, lab[i, j], ha="center", va="center", fontsize=7,
                        color="white" if 0.299 * r + 0.587 * g + 0.114 * b < 0.5 else "black")
    handles = [Patch(color=colours[s], label=_label_title(s)) for s in seen]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    ax.set_title(title if title is not None else "Classified patterns", fontsize=10)
    return finish(fig, out)


def _hex(c: str) -> tuple[float, float, float]:
    c = c.lstrip("#")
    return tuple(int(c[i:i + 2], 16) / 255.0 for i in (0, 2, 4))  # type: ignore[return-value]


def _fmt(v) -> str:
    try:
        x = round(float(v), 12)
        return f"{x:.3g}" if x else "0"
    except (TypeError, ValueError):
        return str(v)


__all__ = ["PALETTES", "PATTERN_NAMES", "TRAIL_STEPS", "TYPE_COLOURS", "homogeneous_grid_figure", "pattern_figure",
           "patterns_grid_figure", "phase_diagram_figure", "trails", "type_colour", "use_palette"]
