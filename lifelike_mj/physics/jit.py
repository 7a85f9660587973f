"""Compiling one loop for several callees: the built-in one cached, a user's one on demand.

numba caches a compiled function only when nothing in it refers to a Python object that lives
only in this process. A stepping loop that takes the pitch law as a *first-class* function argument
therefore cannot be cached once that law calls other compiled code. Instead a loop is written once as
a plain Python function that calls its callee by a global name (``law``); :func:`njit_with` compiles a
copy of it whose globals map that name to another compiled function. The shipped variant is compiled
with ``cache=True`` from the module's own globals; a user's variant is compiled when first asked for
(in the user's process, not cached) and runs at the same speed, the callee inlined the same way.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any

from numba import njit


def njit_with(fn: Callable, name: str, replacements: dict[str, Any], **options: Any):
    """``numba.njit(**options)`` of a copy of the plain function ``fn`` whose global names in
    ``replacements`` are replaced (e.g. ``{"law": my_law}``), named ``name``."""
    g = dict(fn.__globals__)
    g.update(replacements)
    copy = types.FunctionType(fn.__code__, g, name, fn.__defaults__, fn.__closure__)
    copy.__qualname__ = name
    copy.__doc__ = fn.__doc__
    return njit(**options)(copy)
