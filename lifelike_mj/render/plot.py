"""Figures on matplotlib's Agg canvas, without pyplot: drawing never changes the process's backend.

Figure functions of the creatures build their figure with :func:`new_figure` and return it; they
write a PNG (atomically, through :func:`save`) only when given a path.
"""

from __future__ import annotations

import os
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from lifelike_mj.errors import UserError
from lifelike_mj.io import atomic_path

#: Resolution of the saved PNGs, dots per inch.
DPI = 120


def new_figure(width_in: float, height_in: float, layout: str | None = "constrained") -> Figure:
    """A figure of ``width_in`` x ``height_in`` inches on the Agg canvas."""
    fig = Figure(figsize=(width_in, height_in), layout=layout)
    FigureCanvasAgg(fig)
    return fig


def png_path(path: str | os.PathLike, what: str) -> Path:
    """``path`` as a Path; a :class:`UserError` unless it names a ``.png`` file."""
    p = Path(path)
    if p.suffix.lower() != ".png":
        raise UserError(f"cannot write {p.name}: the {what} is a .png file.")
    return p


def save(fig: Figure, path: str | os.PathLike, dpi: int = DPI) -> Path:
    """Write ``fig`` as a PNG to ``path`` atomically, with the package version and the command in its
    text chunks (:func:`lifelike_mj.provenance.png_metadata`); return the path."""
    from lifelike_mj.provenance import png_metadata

    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata=png_metadata())
    return path


def finish(fig: Figure, path: str | os.PathLike | None, what: str = "figure") -> Figure:
    """The end of every figure function: save ``fig`` to ``path`` when one is given; return ``fig``."""
    if path is not None:
        save(fig, png_path(path, what))
    return fig


def markdown_figure(file: str, caption: str) -> str:
    """A figure in a Markdown report: the image (its caption as alt text) and the caption below it."""
    return f"![{caption}]({file})\n\n*{caption}*"
