"""Short public names for the butterfly package (see its ``__init__``)."""

from __future__ import annotations

from lifelike_mj.butterfly.controllers import builtin_names as controller_names
from lifelike_mj.butterfly.controllers import load as load_controller

__all__ = ["controller_names", "load_controller"]
