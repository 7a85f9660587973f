"""The butterflies the 3D model can be: each a species with its own wing outline, masses and body.

* ``"swallowtail"``: the paper's swallowtail (Oe et al. 2010): 0.319 g, each wing one planform-2 triangle
  (eq. 3: chord ``W r / L`` at span ``r``; ``L`` 5.5 cm, ``W`` 5.0 cm), fore and hind wing merged, the stroke
  plane the body's transverse plane; the parts' masses in the proportions of a tree nymph (*Idea leuconoe*).
  The model file ``models/butterfly/butterfly3d.xml`` as it is. The controllers ``steer`` and ``wind`` (withdrawn) were
  evolved on it, and the reduction to the planar paper model uses it.
* ``"monarch"``: the monarch (*Danaus plexippus*), one species for outline, masses and kinematics, all from
  the morphology and free-flight fit of the FWUAV group's monarch (Tejaswi, Sridhar, Lee et al.;
  repository fdcl-gwu/FWUAV, ``morp_MONARCH.m``, after a chord table measured by Dr. Kang):

  - **outline**: the measured leading and trailing edge of the whole wing at 15 spans, ``R`` = 61.0 mm from
    the hinge (:data:`MONARCH_EDGES_CM`): 12.69 cm^2 per side, radii of the area moments ``r1, r2, r3`` =
    0.497, 0.543, 0.580 (the triangle: 0.667, 0.707, 0.737);
  - **fore and hind wing**: separate surfaces split along the fore wing's inner margin, taken as the straight
    line from the hinge's trailing edge to the tornus, where the trailing edge's steep run ends (0.73 ``R``,
    the kink of the measured trailing edge, where the hind wing stops showing behind the fore wing). The fore
    wing is then 57 % of the area; in the FWUAV group's monarch mesh (``Monarch_reduced_5.stl``, flattened
    into each wing's plane) the fore wing shows 55 % of the pair. A monarch has no tails. The hind wing
    follows the fore wing rigidly: in butterflies the hind wing's humeral lobe lies under the fore wing
    (amplexiform coupling), so both flap and feather as one; the overlap under the fore wing is not a surface
    of its own (the force is over what the air meets, the union of the two outlines);
  - **masses**: thorax and head 0.1485 g (14.63 x 5.68 mm), abdomen 0.1092 g (17.38 x 3.71 mm), each wing
    0.0251 g, together 0.3079 g; thorax and abdomen as ellipsoids, each wing a plate of even areal density
    over its outline (as FWUAV computes its wing inertia);
  - **joints**: the wing hinges beside the thorax's mass centre, half its width out; the abdomen's hinge at
    the thorax's rear end; the stroke plane tilted 25.4 deg from the body's transverse plane, the top of the
    stroke rearward (the fit of the filmed monarch).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from lifelike_mj.errors import unknown_name

#: The monarch's wing, as measured (cm; FWUAV ``morp_MONARCH.m``, Dr. Kang's table): span from the hinge,
#: chord, leading edge and trailing edge (+ ahead of the hinge line).
MONARCH_EDGES_CM = np.array([
    [0.0, 0.172, 0.0329, -0.1391], [0.4475, 0.6961, 0.2329, -0.4632], [0.895, 1.326, 0.3974, -0.9286],
    [1.3425, 1.9723, 0.5329, -1.4394], [1.79, 2.6186, 0.6595, -1.9591], [2.2375, 3.2319, 0.765, -2.4669],
    [2.685, 3.6628, 0.8822, -2.7806], [3.1325, 3.5136, 0.9702, -2.5434], [3.58, 3.149, 1.0346, -2.1144],
    [4.0275, 2.6849, 1.0727, -1.6122], [4.475, 1.8895, 1.0815, -0.808], [4.9225, 1.5414, 1.0845, -0.4569],
    [5.37, 1.2762, 1.0933, -0.1829], [5.8175, 0.746, 0.9614, 0.2154], [6.0997, 0.3319, 0.7621, 0.4302]])
#: Row of :data:`MONARCH_EDGES_CM` at the tornus, the fore wing's rear corner (module docstring).
MONARCH_TORNUS_ROW = 10


@dataclass(frozen=True, eq=False)
class Animal:
    """One species of the 3D model (module docstring). Lengths in m, masses in kg, angles in degrees.

    ``surfaces``: the wing's surfaces (fore wing, hind wing), each a polygon ``(n, 2)`` in the left wing's
    frame (``x`` along the chord, + forward; ``y`` along the span from the hinge); the right wing is its
    mirror. ``None``: the paper's planform-2 triangle of the flight's ``ButterflyParams``."""

    name: str
    species: str
    surfaces: tuple = ()
    surface_names: tuple = ()
    mass_body_kg: float = 0.0
    mass_abdomen_kg: float = 0.0
    mass_wing_kg: float = 0.0
    thorax_m: tuple = (0.0, 0.0)  # length, width
    abdomen_m: tuple = (0.0, 0.0)
    stroke_plane_deg: float = 0.0
    colours: tuple = ()  # each surface's drawn colour (RGBA)
    source: str = ""

    @property
    def mass_kg(self) -> float:
        """The whole animal's mass (kg)."""
        return self.mass_body_kg + self.mass_abdomen_kg + 2.0 * self.mass_wing_kg

    @property
    def measured(self) -> bool:
        """Whether the wing is a measured outline (else the paper's triangle)."""
        return bool(self.surfaces)

    @functools.cached_property
    def triangles(self) -> np.ndarray:
        """``(n, 3, 2)``: every surface cut into triangles (m, the left wing's frame)."""
        from lifelike_mj.physics.planform import triangulate

        return np.concatenate([triangulate(s) for s in self.surfaces])

    @functools.cached_property
    def span_m(self) -> float:
        """The wing's length from the hinge (m)."""
        return float(max(s[:, 1].max() for s in self.surfaces))

    @functools.cached_property
    def moments(self) -> dict:
        """Area and the radii of its moments (:func:`lifelike_mj.physics.planform.area_moments`)."""
        from lifelike_mj.physics.planform import area_moments

        return area_moments(self.triangles, self.span_m)

    def body_areas_m2(self) -> tuple[float, float, float]:
        """The body's projected areas (m^2) along its own x, y, z: ellipses of the thorax's and abdomen's
        length and width (front: the thorax's disc)."""
        (lt, wt), (la, wa) = self.thorax_m, self.abdomen_m
        side = math.pi / 4.0 * (lt * wt + la * wa)
        return (math.pi / 4.0 * wt * wt, side, side)


def _monarch() -> Animal:
    e = MONARCH_EDGES_CM * 1e-2
    le = np.c_[e[:, 2], e[:, 0]]
    te = np.c_[e[:, 3], e[:, 0]]
    k = MONARCH_TORNUS_ROW
    fore = np.concatenate([te[:1], le, te[:k - 1:-1]])  # root's trailing corner, the leading edge, tip to tornus
    hind = te[: k + 1]  # root's trailing corner along the trailing edge to the tornus, back along the margin
    return Animal(name="monarch", species="Danaus plexippus", surfaces=(fore, hind),
                  surface_names=("fore wing", "hind wing"), mass_body_kg=1.485e-4, mass_abdomen_kg=1.092e-4,
                  mass_wing_kg=2.510e-5, thorax_m=(1.463e-2, 5.680e-3), abdomen_m=(1.738e-2, 3.710e-3),
                  stroke_plane_deg=25.4, colours=((0.93, 0.47, 0.08, 1.0), (0.87, 0.40, 0.06, 1.0)),
                  source="FWUAV (github.com/fdcl-gwu/FWUAV) morp_MONARCH.m: chord table, masses, body sizes; "
                         "stroke-plane tilt from its fit of a filmed free flight")


def _swallowtail() -> Animal:
    return Animal(name="swallowtail", species="Papilio (Oe et al. 2010)",
                  source="Oe et al. 2010 (planform-2 triangle, 0.319 g); tree-nymph mass proportions")


#: The species of the 3D model, by name.
ANIMALS = ("swallowtail", "monarch")


def animal(name) -> Animal:
    """The :class:`Animal` of ``name`` (one of :data:`ANIMALS`; an :class:`Animal` is returned as it is)."""
    if isinstance(name, Animal):
        return name
    if name not in ANIMALS:
        raise unknown_name("unknown butterfly", name, ANIMALS)
    return _cached(name)


@functools.cache
def _cached(name: str) -> Animal:
    return _monarch() if name == "monarch" else _swallowtail()
