"""The colours of the boids' types, shared by the figures and the 3D scene.

The default is safe for colour-blind readers (Okabe & Ito 2008: A blue, B orange, then bluish green,
reddish purple, sky blue, vermillion, yellow, black). The paper draws A red and B yellow-green, which
many colour-blind readers cannot tell apart; ``use_palette("paper")`` brings those back.
"""

from __future__ import annotations

from lifelike_mj.errors import UserError

PALETTES: dict[str, tuple[str, ...]] = {
    "colour-blind": ("#0072b2", "#e69f00", "#009e73", "#cc79a7", "#56b4e9", "#d55e00", "#f0e442", "#000000"),
    "paper": ("#dc140f", "#9acd32", "#1f77b4", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf"),
}
_current = ["colour-blind"]


def use_palette(name: str) -> None:
    """Draw the types in ``"colour-blind"`` colours (the default) or the ``"paper"``'s."""
    if name not in PALETTES:
        raise UserError(f"unknown palette {name!r}; choose {' or '.join(PALETTES)}.")
    _current[0] = name


def palette() -> str:
    """The name of the palette in use."""
    return _current[0]


def type_colour(k: int) -> str:
    """Hex colour of type ``k`` in the palette in use (cycles after 8 types)."""
    colours = PALETTES[_current[0]]
    return colours[int(k) % len(colours)]


def type_rgba(k: int) -> tuple[float, float, float, float]:
    """RGBA (0-1) colour of type ``k`` in the palette in use."""
    c = type_colour(k).lstrip("#")
    r, g, b = (int(c[i:i + 2], 16) / 255.0 for i in (0, 2, 4))
    return (r, g, b, 1.0)
