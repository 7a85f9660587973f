"""The two butterfly backends side by side, behind one interface.

* :mod:`~lifelike_mj.butterfly.backends.paper`: the paper's point-mass equations (Oe 2010 eq. 7-11),
  compiled and batched; does not import MuJoCo;
* :mod:`~lifelike_mj.butterfly.backends.mj`: the MuJoCo model (``models/butterfly/``) with the wing
  force in a compiled passive callback.

This package names the backends and the MuJoCo configurations; flying a batch on either is
:func:`lifelike_mj.butterfly.batch.simulate`, above the stepper. Importing this package imports neither backend.
"""

from __future__ import annotations

from lifelike_mj.errors import UserError

BACKENDS = ("paper", "mujoco")
#: MuJoCo configurations: the paper-equivalent model and the rich one (free body, heavy wings).
CONFIGS = {"paper": "butterfly.xml", "rich": "butterfly_rich.xml"}
#: Default wing-force mode of each MuJoCo configuration.
DEFAULT_FORCE_MODE = {"paper": "tip", "rich": "strip"}


def check_backend(name: str) -> str:
    """``name`` if it is one of :data:`BACKENDS`, else a :class:`UserError`."""
    if name not in BACKENDS:
        raise UserError(f"unknown backend {name!r}; choose one of: {', '.join(BACKENDS)}.")
    return name


def mujoco_options(config: str = "paper", force_mode: str | None = None) -> dict:
    """``{"config", "force_mode"}`` of a MuJoCo flight, the force mode defaulting to the
    configuration's (:data:`DEFAULT_FORCE_MODE`); :class:`UserError` for an unknown configuration."""
    if config not in DEFAULT_FORCE_MODE:
        raise UserError(f"unknown configuration {config!r}; choose paper or rich.")
    return {"config": config, "force_mode": force_mode or DEFAULT_FORCE_MODE[config]}
