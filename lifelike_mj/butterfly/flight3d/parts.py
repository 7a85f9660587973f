"""What a 3D flight is made of, grouped as dm_control separates physics, task and environment: the **butterfly** (its
animal, physical constants and force law: what flies), the **world** (wind, ground and flowers: where it flies), and
the flight itself (:class:`~lifelike_mj.butterfly.flight3d.flight.Flight3D`: the command, controller and task, the
start and the numerics)::

    from lifelike_mj.butterfly.flight3d import Butterfly, Flight3D, World, level

    flight = Flight3D(butterfly=Butterfly("monarch", force_law="calibrated"),
                      world=World(wind_to_m_s=(0.5, 0.0, 0.0), contact=True), controller="monarch", task=level(1.5))

Each part is a frozen dataclass, checked where it is used (:class:`Flight3D` names a bad value in one sentence), and
reusable: one :class:`Butterfly` for many flights. ``None`` leaves a choice to the flight: the controller's animal and
force law (a network's or a designed controller's), else the paper's swallowtail and the exact law; the controller's
kinematics filter, else one wing beat.

The flat keywords ``Flight3D`` took before (``animal=``, ``force_law=``, ``wind_to_m_s=``, ``flowers=``...) are still
taken for one release, with a note once per name (:data:`BUTTERFLY_KEYWORDS`, :data:`WORLD_KEYWORDS`).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any


@dataclass(frozen=True)
class Butterfly:
    """The butterfly flown: ``animal`` (``"swallowtail"``, the paper's, or ``"monarch"``, with measured wings;
    :mod:`~lifelike_mj.butterfly.flight3d.animals`), ``params`` (:class:`~lifelike_mj.butterfly.params.ButterflyParams`:
    mass, wing size, air; Oe 2010 Table 1), ``masses`` (``animal`` or ``paper``), ``force_law`` (``exact``: eq. 1
    integrated exactly over each wing; ``strip``: eq. 1 on wing panels; ``quasi_steady``: blade elements on the
    panels; ``calibrated``: the same scaled to a filmed monarch's flight; ``tip``: the paper's tip-speed formula;
    ``none``), ``drag_frame`` (``body`` or ``world``), ``body_areas_m2`` (the body's drag areas along x, y, z, m^2;
    default the paper's ``A_b`` on every axis), ``n_strips`` and ``n_chord`` (panels per wing, for the panel laws),
    ``drive_hz`` (Hz, the joints' tracking bandwidth) and ``omega_c`` (rad/s, how fast the kinematics follow a
    command)."""

    animal: str | None = None
    force_law: str | None = None
    params: Any = None
    masses: str = "animal"
    drag_frame: str = "body"
    body_areas_m2: Any = None
    n_strips: int = 8
    n_chord: int = 2
    drive_hz: float = 50.0
    omega_c: float | None = None


@dataclass(frozen=True)
class World:
    """Where the butterfly flies: the mean wind (world frame, m/s), given as where it blows to (``wind_to_m_s``) or
    where it comes from (``wind_from_m_s``), replacing the task's (gusts and flutter stay the task's); ``contact``:
    legs that touch the ground; ``flowers``: blossoms' centres (``(n, 3)``, m) the legs touch too (implies
    ``contact``); ``ground_m``: the ground's height (m; default 4 m below the start's altitude 0)."""

    wind_to_m_s: Any = None
    wind_from_m_s: Any = None
    contact: bool = False
    flowers: Any = None
    ground_m: float | None = None


#: The flat keywords of ``Flight3D`` that now belong to :class:`Butterfly` (``wind_m_s``, older still, to
#: :class:`World`'s ``wind_to_m_s``).
BUTTERFLY_KEYWORDS = tuple(f.name for f in fields(Butterfly))
WORLD_KEYWORDS = tuple(f.name for f in fields(World)) + ("wind_m_s",)


def with_force_law(flight: dict, force_law: str) -> dict:
    """``flight`` (``Flight3D``'s keywords) with its butterfly's force law set to ``force_law``: for the checks that
    take the law as their own argument and pass the rest through."""
    from dataclasses import replace

    return dict(flight, butterfly=replace(flight.get("butterfly") or Butterfly(), force_law=force_law))
