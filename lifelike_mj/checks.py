"""Checks of numbers a user gives, each failing with one sentence (:class:`~lifelike_mj.errors.UserError`).

``bool`` is never a number here (``True`` is an ``int`` to Python, not a count or a length to a
user); NumPy scalars are.
"""

from __future__ import annotations

import math
import numbers

from lifelike_mj.errors import UserError


def is_number(v: object) -> bool:
    """Whether ``v`` is a real number (int, float or a NumPy scalar of either), not a bool."""
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def is_whole(v: object) -> bool:
    """Whether ``v`` is a whole number (int or NumPy integer), not a bool."""
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def number(name: str, v: object, lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
           unit: str = "") -> float:
    """``v`` as a float; a :class:`UserError` unless it is a finite number in ``[lo, hi]`` (``(lo, hi]``
    with ``lo_open``). ``name`` and ``unit`` phrase the sentence."""
    ok = is_number(v) and math.isfinite(float(v))
    if ok and lo is not None:
        ok = float(v) > lo if lo_open else float(v) >= lo
    if ok and hi is not None:
        ok = float(v) <= hi
    if not ok:
        u = f" {unit}" if unit else ""
        if lo is not None and hi is not None:
            rng = f"a number in {'(' if lo_open else '['}{lo:g}, {hi:g}]{u}"
        elif lo is not None and lo_open and lo == 0:
            rng = f"a positive number{u}"
        elif lo is not None:
            rng = f"a number {'>' if lo_open else '>='} {lo:g}{u}"
        elif hi is not None:
            rng = f"a number <= {hi:g}{u}"
        else:
            rng = f"a finite number{u}"
        raise UserError(f"{name} must be {rng}, got {v!r}.")
    return float(v)


def positive(name: str, v: object, unit: str = "") -> float:
    """``v`` as a float; a :class:`UserError` unless it is a finite number > 0."""
    return number(name, v, 0.0, lo_open=True, unit=unit)


def whole(name: str, v: object, lo: int | None = None, hi: int | None = None) -> int:
    """``v`` as an int; a :class:`UserError` unless it is a whole number in ``[lo, hi]``."""
    if not is_whole(v) or (lo is not None and v < lo) or (hi is not None and v > hi):
        if lo is not None and hi is not None:
            rng = f"a whole number from {lo} to {hi}"
        elif lo is not None:
            rng = f"a whole number of at least {lo}"
        else:
            rng = "a whole number"
        raise UserError(f"{name} must be {rng}, got {v!r}.")
    return int(v)


def flag(name: str, v: object) -> bool:
    """``v`` as a bool; a :class:`UserError` unless it is ``True`` or ``False`` (or a NumPy bool): a string such as
    ``"no"`` or a number would otherwise switch a flag on by being truthy."""
    import numpy as np

    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    raise UserError(f"{name} must be True or False, got {v!r}.")


def vector(name: str, v: object, n: int, unit: str = "") -> tuple[float, ...]:
    """``v`` as a tuple of ``n`` floats; a :class:`UserError` unless it is a sequence of ``n`` finite numbers."""
    try:
        items = list(v)  # type: ignore[call-overload]
    except TypeError:
        items = None
    if items is None or len(items) != n or not all(is_number(x) and math.isfinite(float(x)) for x in items):
        u = f" ({unit})" if unit else ""
        raise UserError(f"{name} must be {n} finite numbers{u}, got {v!r}.")
    return tuple(float(x) for x in items)


def points(name: str, v: object, unit: str = "", max_n: int = 1000, bound: float = 1e4) -> tuple[tuple[float, ...], ...]:
    """``v`` as ``n`` points of 3 floats, ``1 <= n <= max_n``, each coordinate finite and within ``+-bound``; a
    :class:`UserError` otherwise."""
    try:
        items = [vector(f"each of {name}", p, 3, unit) for p in v]  # type: ignore[union-attr]
    except TypeError:
        items = []
    if not 1 <= len(items) <= max_n:
        raise UserError(f"{name} must be 1 to {max_n:,} points (x, y, z), got {v!r}.")
    if max(abs(x) for p in items for x in p) > bound:
        u = f" {unit}" if unit else ""
        raise UserError(f"{name} must lie within {bound:g}{u} of the origin.")
    return tuple(items)


# ---- how much work a command may ask for ---------------------------------------------------------------

#: The most simulation steps one command may ask for, summed over every body it simulates (a flight, each fish
#: of a tank, each butterfly of a garden) and every run it makes: 10^9, about an hour of a 3D garden or a
#: 1,000-fish tank on two cores. The boids count agent-steps, which cost far less: see ``MAX_AGENT_STEPS``.
MAX_BODY_STEPS = 1_000_000_000
#: The most agent-steps of boids one command may ask for (2 x 10^9, about 20 minutes at the engine's speed).
MAX_AGENT_STEPS = 2_000_000_000
#: The most agent-steps of a boids sweep (every cell and seed): ten runs' worth, since a sweep runs on a process
#: pool or a Ray cluster.
MAX_SWEEP_AGENT_STEPS = 10 * MAX_AGENT_STEPS
#: The most seeds (or courses) one command may run.
MAX_SEEDS = 10_000
#: The most simulation steps an evolution may ask for (generations x population x flights x steps per flight):
#: 10^12, a thousand times the paper's whole evolution (1000 generations of 40 flights of 24,000 steps).
MAX_EVOLUTION_STEPS = 1_000_000_000_000
#: The most rows a recorded run may keep in memory (10^7 rows of a few dozen numbers: a few GB).
MAX_RECORD_ROWS = 10_000_000
#: The most frames a video or an exported animation may have (36,000: ten minutes at 60 frames per second).
MAX_FRAMES = 36_000


def work(what: str, amount: float, limit: float, unit: str, hint: str = "") -> int:
    """Before any work: ``amount`` (of ``unit``: "steps", "frames") as an int, or a :class:`UserError` saying how
    much ``what`` asks for and the limit (``hint``: what to change)."""
    if not (math.isfinite(float(amount)) and amount <= limit):
        tail = f" ({hint})" if hint else ""
        raise UserError(f"{what} asks for {float(amount):,.0f} {unit}; at most {limit:,.0f} are allowed{tail}.")
    return int(amount)


def steps_of(duration_s: float, dt_s: float) -> int:
    """The number of time steps of ``dt_s`` in ``duration_s`` (rounded; at least 1), computed without
    building anything (a huge count is for :func:`work` to refuse)."""
    n = float(duration_s) / float(dt_s)
    return max(1, int(round(n))) if math.isfinite(n) and n < 1e18 else int(1e18)


# ---- names a user types -----------------------------------------------------------------------------------


def known_keywords(func):
    """Decorator: a keyword argument ``func`` does not take is an :class:`~lifelike_mj.errors.UnknownName` (a
    ``TypeError``, as Python's own) naming the closest one it takes, instead of Python's bare "unexpected keyword
    argument". Names starting with ``_`` are accepted but never suggested."""
    import functools
    import inspect

    from lifelike_mj.errors import unknown_name

    params = inspect.signature(func).parameters.values()
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return func
    names = [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]
    shown = [n for n in names if not n.startswith("_") and n != "self"]
    owner = func.__qualname__.removesuffix(".__init__")

    @functools.wraps(func)
    def checked(*args, **kwargs):
        for key in kwargs:
            if key not in names:
                raise unknown_name(f"{owner} has no option", key, shown)
        return func(*args, **kwargs)

    return checked


_RENAMED: set[str] = set()


def renamed(old: str, new: str, why: str = "", stacklevel: int = 3) -> None:
    """A one-line note (a ``DeprecationWarning``, once per name and process) that ``old`` is now spelled ``new``
    (``why``: what the new name says); the old spelling goes in the next release. ``stacklevel``: as
    ``warnings.warn``'s, counted from the caller of this function's caller (3: the line that used the old name, where
    that caller is the function called with it)."""
    if old in _RENAMED:
        return
    import warnings

    _RENAMED.add(old)
    warnings.warn(f"{old} is now {new}{f' ({why})' if why else ''}; the old name goes in the next release.",
                  DeprecationWarning, stacklevel=stacklevel)


def one_wind(where: str, to_m_s, from_m_s, old_m_s=None, old_means: str = "to", n: int = 3):
    """The wind (m/s), given once: as where it blows to (``to_m_s``, the air's velocity), where it comes from
    (``from_m_s``), or in the old spelling ``old_m_s`` (meaning ``old_means``, taken with a note). Returns the
    air's velocity, a tuple of ``n`` floats, or ``None`` if none was given; two spellings at once, or anything
    but ``n`` finite numbers, are a :class:`UserError` naming the argument."""
    given = [(k, v) for k, v in (("wind_to_m_s", to_m_s), ("wind_from_m_s", from_m_s), ("wind_m_s", old_m_s))
             if v is not None]
    if len(given) > 1:
        raise UserError(f"{where}: give the wind once, as wind_to_m_s or wind_from_m_s, not {given[0][0]} and "
                        f"{given[1][0]}.")
    if not given:
        return None
    name, v = given[0]
    w = vector(name, v, n, "m/s")
    if name == "wind_m_s":
        renamed(f"{where}(wind_m_s=...)", f"wind_{old_means}_m_s",
                "where the wind " + ("blows to" if old_means == "to" else "comes from"))
        name = f"wind_{old_means}_m_s"
    return w if name == "wind_to_m_s" else tuple(0.0 - x for x in w)
