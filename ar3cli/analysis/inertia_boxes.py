"""Each link's mass as Gazebo's "view inertia" and "view centre of mass" draw it: the uniform box with
the same mass and principal moments as the link's ``<inertial>``, in its principal axes, and a lead
sphere of the link's mass at its centre of mass.

A link with mass ``m`` and principal moments ``I1, I2, I3`` about axes ``e1, e2, e3`` has the same
inertia as a uniform box with edges ``a, b, c`` along those axes when
``I1 = m (b^2 + c^2) / 12`` (and cyclically), so::

    a = sqrt(6 (I2 + I3 - I1) / m),  b = sqrt(6 (I1 + I3 - I2) / m),  c = sqrt(6 (I1 + I2 - I3) / m)

The box is the size of a solid of that mass and inertia: a box ten times the link's geometry, or
far off it, is the picture of a wrong ``<inertial>``. A tensor whose moments break the triangle
inequality (``I1 + I2 < I3``: no body has it) would need an imaginary edge; that edge is drawn 0 and
:attr:`InertiaBox.problem` says why, as for a tensor that is not positive definite. Links without
an ``<inertial>``, or whose mass or tensor does not parse or is not finite, or whose mass is not
positive, get no box (lint's I rules report them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.urdf.model import Link

Vec3 = tuple[float, float, float]
Rotation = tuple[Vec3, Vec3, Vec3]

LEAD_DENSITY = 11340.0
"""kg/m^3: the centre-of-mass marker is a lead sphere of the link's mass (Gazebo's convention), so a
marker's size compares masses at a glance: 1 kg is a sphere of 2.8 cm radius, 10 kg of 5.9 cm."""
ROUNDING = 1e-9
"""Relative to the largest moment: a box edge whose square is above ``-ROUNDING`` is a thin shape
(a rod, a plate, where the triangle inequality holds with equality), not a broken tensor."""


@dataclass(frozen=True)
class InertiaBox:
    """One link's equivalent inertia box and centre of mass, in the link frame (SI units).

    ``rotation`` turns the box frame into the link frame (its columns are the principal axes, a
    right-handed frame); ``size`` is the box's edge along each of them, ``moments`` the principal
    moments about them (ascending).
    """

    link: str
    mass: float
    centre: Vec3
    rotation: Rotation
    size: Vec3
    moments: Vec3
    problem: str | None = None

    @property
    def marker_radius(self) -> float:
        """Radius of a lead sphere of the link's mass (m)."""
        return (3.0 * self.mass / (4.0 * math.pi * LEAD_DENSITY)) ** (1.0 / 3.0)


@question
def inertia_boxes(analysis: RobotAnalysis) -> list[InertiaBox]:
    """Every link with a usable ``<inertial>``, in file order."""
    boxes = (inertia_box(link) for link in analysis.require_model().links)
    return [box for box in boxes if box is not None]


def inertia_box(link: Link) -> InertiaBox | None:
    """The link's box, None when its ``<inertial>`` is missing or unusable (see the module docstring)."""
    import numpy as np

    inertial = link.inertial
    if inertial is None or inertial.mass is None or inertial.tensor is None:
        return None
    mass = inertial.mass
    tensor = np.array(inertial.matrix(), dtype=float)
    centre = np.asarray(inertial.origin.xyz, dtype=float)
    frame = np.asarray(inertial.origin.rotation, dtype=float)
    if not (math.isfinite(mass) and mass > 0.0 and np.isfinite(tensor).all() and np.isfinite(centre).all()
            and np.isfinite(frame).all()):
        return None
    moments, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:  # a right-handed frame: a box is drawn with a rotation, not a mirror
        axes[:, 2] = -axes[:, 2]
    rotation = frame @ axes
    squares = [6.0 * (moments[(i + 1) % 3] + moments[(i + 2) % 3] - moments[i]) / mass for i in range(3)]
    floor = -ROUNDING * 6.0 * max(abs(float(m)) for m in moments) / mass
    problem = None
    if moments[0] <= 0.0:
        problem = (f"the inertia tensor is not positive definite (principal moments "
                   f"{', '.join(f'{m:.3g}' for m in moments)} kg m^2)")
    elif min(squares) < floor:
        problem = (f"the principal moments {', '.join(f'{m:.3g}' for m in moments)} kg m^2 break the triangle "
                   "inequality (the largest exceeds the sum of the other two): no body has them")
    size = tuple(math.sqrt(max(square, 0.0)) for square in squares)
    return InertiaBox(link.name, mass, tuple(centre.tolist()), tuple(map(tuple, rotation.tolist())),  # type: ignore[arg-type]
                      size, tuple(float(m) for m in moments), problem)  # type: ignore[arg-type]
