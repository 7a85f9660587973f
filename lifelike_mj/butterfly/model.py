"""The MuJoCo model of the butterfly (``models/butterfly/``): configurations, building, addresses.

* ``paper`` (``butterfly.xml``): the paper-equivalent model: a 0.319 g body on planar joints
  (forward, height), a pitch hinge, two planform-2 wings on flap hinges (Oe 2010 section 4);
* ``rich`` (``butterfly_rich.xml``): a free body and realistic wing mass (0.016 g each).

:func:`build_model` applies the physical constants of :class:`~lifelike_mj.butterfly.params.ButterflyParams`
(mass, L, W) through ``MjSpec``; :func:`layout` reads the joint addresses by name.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from lifelike_mj import paths
from lifelike_mj.butterfly.backends import CONFIGS
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError

#: Wing-force modes of the passive callback: none, the paper's tip-speed formula, strip integration.
FORCE_MODES = {"none": 0, "tip": 1, "strip": 2}
#: Centre of pressure of planform 2 as a fraction of L: tau_2 / F_2 = (alpha L/10)/(alpha/8) (eq. 4, 6).
CP_FRACTION = 0.8


@dataclass(frozen=True)
class Layout:
    """Addresses the stepping loop needs (qpos/qvel indices), read by name from the model."""

    rich: bool
    q_forward: int
    q_height: int
    d_forward: int
    d_height: int
    q_pitch: int  # paper model: pitch hinge; rich: quaternion start
    d_pitch: int
    q_flap_left: int

    def as_array(self) -> np.ndarray:
        return np.array([int(self.rich), self.q_forward, self.q_height, self.d_forward, self.d_height,
                         self.q_pitch, self.d_pitch, self.q_flap_left], dtype=np.int64)


def check_config(config: str, force_mode: str) -> None:
    if config not in CONFIGS:
        raise UserError(f"unknown MuJoCo configuration {config!r}; choose one of: {', '.join(CONFIGS)}.")
    if force_mode not in FORCE_MODES:
        raise UserError(f"unknown wing-force mode {force_mode!r}; choose one of: {', '.join(FORCE_MODES)}.")


def model_path(config: str = "paper") -> Path:
    """Path of the MJCF file of a configuration ("paper" or "rich")."""
    check_config(config, "tip")
    return paths.model_path("butterfly", CONFIGS[config])


def build_model(params: ButterflyParams | None = None, config: str = "paper") -> mujoco.MjModel:
    """Compile the model with the physical constants of ``params`` (mass, L, W) applied via MjSpec.

    The thorax takes the total mass ``m`` less the two wings; the wing meshes and their sites are
    scaled to ``L`` and ``W``.
    """
    p = params or ButterflyParams()
    spec = mujoco.MjSpec.from_file(str(model_path(config)))
    wing_mass = spec.geom("wing_left").mass
    if p.mass_kg <= 2.0 * wing_mass:
        raise UserError(f"butterfly mass {p.mass_kg * 1e3:g} g is not more than its two wings ({2e3 * wing_mass:g} g).")
    spec.geom("thorax").mass = p.mass_kg - 2.0 * wing_mass
    for side, sign in (("left", 1.0), ("right", -1.0)):
        spec.mesh(f"wing_{side}").scale = [p.width_m, p.span_m, 1.0]
        spec.site(f"wing_{side}_cp").pos = [0.0, sign * CP_FRACTION * p.span_m, 0.0]
        spec.site(f"wing_{side}_tip").pos = [0.0, sign * p.span_m, 0.0]
    return spec.compile()


def layout(m: mujoco.MjModel) -> Layout:
    """Read joint addresses by name."""
    def jq(name):
        return int(m.jnt_qposadr[m.joint(name).id])

    def jd(name):
        return int(m.jnt_dofadr[m.joint(name).id])

    if m.njnt and m.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE:
        q0, d0 = jq("root"), jd("root")
        return Layout(True, q0, q0 + 2, d0, d0 + 2, q0 + 3, d0 + 3, jq("flap_left"))
    return Layout(False, jq("forward"), jq("height"), jd("forward"), jd("height"), jq("pitch"), jd("pitch"),
                  jq("flap_left"))
