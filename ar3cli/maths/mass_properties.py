"""Rigid-body mass properties: the project's one place for inertia math.

Conventions (the same as URDF ``<inertial>``):

* SI units throughout: metres, kilograms, kg*m^2.
* ``MassProperties.com`` is the centre of mass in the *reference frame* (usually the
  link frame); ``MassProperties.inertia`` is the 3x3 inertia tensor **about the COM**,
  with its axes parallel to that reference frame. This is exactly what a URDF
  ``<inertial>`` with ``<origin rpy="0 0 0" xyz="com"/>`` expresses, so a result can be
  written out without any further rotation.
* Primitive shapes follow URDF geometry conventions: a box is centred on its origin, a
  cylinder is centred on its origin with its axis along z, a sphere is centred, and a capsule
  (URDF 1.1) is a cylinder of ``length`` along z with a hemisphere of its radius on each end.
* ``rpy`` angles follow URDF: fixed-axis roll about x, then pitch about y, then yaw about
  z, i.e. ``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)``.

The functions use numpy but not pybullet or trimesh. The 3x3 eigenvalue and rotation
formulas live in :mod:`ar3cli.maths.tensor_math` (plain Python, so that the linter need not import
numpy); the functions here delegate to them and return numpy arrays. Mesh-based mass
properties belong in a separate function that returns the same ``MassProperties`` type.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from ar3cli.maths import tensor_math

__all__ = [
    "MassProperties",
    "box",
    "box_volume",
    "capsule",
    "capsule_volume",
    "combine",
    "cylinder",
    "cylinder_volume",
    "is_positive_definite",
    "principal_moments",
    "rpy_to_matrix",
    "scaled_to_mass",
    "satisfies_triangle_inequality",
    "sphere",
    "sphere_volume",
    "transformed",
]


@dataclass(frozen=True)
class MassProperties:
    """Mass, centre of mass and inertia tensor of a rigid body.

    ``inertia`` is taken about ``com`` and expressed in the reference frame (see the
    module docstring). Arrays are copied and made read-only so that the frozen
    dataclass is really immutable.
    """

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def __post_init__(self) -> None:
        com = np.array(self.com, dtype=float).reshape(3)
        inertia = np.array(self.inertia, dtype=float).reshape(3, 3)
        com.setflags(write=False)
        inertia.setflags(write=False)
        object.__setattr__(self, "mass", float(self.mass))
        object.__setattr__(self, "com", com)
        object.__setattr__(self, "inertia", inertia)


def _resolve_mass(volume: float, mass: float | None, density: float | None) -> float:
    """Return the mass given either ``mass`` or ``density`` (exactly one of them).

    Requiring exactly one avoids silently preferring one when a caller passes both.
    """
    if (mass is None) == (density is None):
        raise ValueError("give exactly one of mass= or density=")
    value = mass if mass is not None else density * volume  # type: ignore[operator]
    if not value > 0.0:
        raise ValueError(f"mass must be positive, got {value!r}")
    return float(value)


def _at_origin(mass: float, diagonal: Sequence[float]) -> MassProperties:
    """Mass properties of a shape centred on the origin with a diagonal tensor."""
    return MassProperties(mass, np.zeros(3), np.diag(np.asarray(diagonal, dtype=float)))


def box_volume(size: ArrayLike) -> float:
    """Volume of a box with edge lengths ``size`` = (x, y, z)."""
    x, y, z = np.asarray(size, dtype=float).reshape(3)
    return float(x * y * z)


def cylinder_volume(radius: float, length: float) -> float:
    """Volume of a solid cylinder."""
    return math.pi * radius**2 * length


def sphere_volume(radius: float) -> float:
    """Volume of a solid sphere."""
    return 4.0 / 3.0 * math.pi * radius**3


def capsule_volume(radius: float, length: float) -> float:
    """Volume of a solid capsule: a cylinder of ``length`` plus a sphere of the same radius."""
    return cylinder_volume(radius, length) + sphere_volume(radius)


def box(size: ArrayLike, mass: float | None = None, density: float | None = None) -> MassProperties:
    """Solid box centred on the origin, edges along the axes (URDF ``<box size>``).

    ``I_xx = m (y^2 + z^2) / 12`` and cyclic permutations.
    """
    x, y, z = np.asarray(size, dtype=float).reshape(3)
    m = _resolve_mass(box_volume((x, y, z)), mass, density)
    return _at_origin(m, (m * (y * y + z * z) / 12.0, m * (x * x + z * z) / 12.0, m * (x * x + y * y) / 12.0))


def cylinder(
    radius: float, length: float, mass: float | None = None, density: float | None = None
) -> MassProperties:
    """Solid cylinder centred on the origin, axis along z (URDF ``<cylinder>``).

    ``I_xx = I_yy = m (3 r^2 + l^2) / 12``, ``I_zz = m r^2 / 2``.
    """
    m = _resolve_mass(cylinder_volume(radius, length), mass, density)
    side = m * (3.0 * radius**2 + length**2) / 12.0
    return _at_origin(m, (side, side, m * radius**2 / 2.0))


def sphere(radius: float, mass: float | None = None, density: float | None = None) -> MassProperties:
    """Solid sphere centred on the origin: ``I = 2 m r^2 / 5`` about every axis."""
    m = _resolve_mass(sphere_volume(radius), mass, density)
    moment = 2.0 * m * radius**2 / 5.0
    return _at_origin(m, (moment, moment, moment))


def capsule(radius: float, length: float, mass: float | None = None, density: float | None = None) -> MassProperties:
    """Solid capsule centred on the origin, axis along z (URDF 1.1 ``<capsule>``, as urdfdom, PyBullet,
    Drake and MuJoCo read it: ``length`` is the cylinder between the two hemispherical caps).

    With ``m_c`` the cylinder's mass and ``m_h`` one cap's: ``I_zz = m_c r^2 / 2 + 4 m_h r^2 / 5``
    and ``I_xx = I_yy = m_c (3 r^2 + l^2) / 12 + 2 m_h (2 r^2 / 5 + l^2 / 4 + 3 l r / 8)`` (a cap
    has ``2 m_h r^2 / 5`` about a diameter of its flat face; its COM sits ``3 r / 8`` from that face,
    and the parallel-axis theorem moves it to the capsule's centre). ``length`` 0 is a sphere.
    """
    m = _resolve_mass(capsule_volume(radius, length), mass, density)
    share = m / capsule_volume(radius, length)  # the density, however the mass was given
    m_c, m_h = share * cylinder_volume(radius, length), share * sphere_volume(radius) / 2.0
    r2 = radius**2
    side = m_c * (3.0 * r2 + length**2) / 12.0 + 2.0 * m_h * (0.4 * r2 + length**2 / 4.0 + 3.0 * length * radius / 8.0)
    return _at_origin(m, (side, side, m_c * r2 / 2.0 + 0.8 * m_h * r2))


def rpy_to_matrix(rpy: ArrayLike) -> np.ndarray:
    """Rotation matrix of URDF roll-pitch-yaw angles: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``."""
    return np.array(tensor_math.rpy_to_matrix(np.asarray(rpy, dtype=float).reshape(3)))


def transformed(mp: MassProperties, xyz: ArrayLike = (0.0, 0.0, 0.0), rpy: ArrayLike = (0.0, 0.0, 0.0)) -> MassProperties:
    """Express ``mp`` in a parent frame in which its own frame sits at ``xyz``/``rpy``.

    This is what a URDF ``<visual>``/``<collision>`` ``<origin>`` does to a shape: the
    COM moves to ``xyz + R com`` and the tensor, still about the COM, is rotated to
    ``R I R^T`` so that its axes are the parent's axes.
    """
    rot = rpy_to_matrix(rpy)
    com = np.asarray(xyz, dtype=float).reshape(3) + rot @ mp.com
    return MassProperties(mp.mass, com, rot @ mp.inertia @ rot.T)


def combine(parts: Iterable[MassProperties]) -> MassProperties:
    """Mass properties of several bodies rigidly joined, all in the same frame.

    Total mass, mass-weighted COM, and each part's tensor moved to the common COM with
    the parallel-axis theorem ``I + m (|d|^2 E - d d^T)``.
    """
    items = list(parts)
    if not items:
        raise ValueError("combine() needs at least one part")
    total = sum(p.mass for p in items)
    com = sum((p.mass * p.com for p in items), np.zeros(3)) / total
    inertia = np.zeros((3, 3))
    for p in items:
        d = p.com - com
        inertia += p.inertia + p.mass * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return MassProperties(total, com, inertia)


def scaled_to_mass(mp: MassProperties, mass: float) -> MassProperties:
    """Same shape and density distribution, different total mass.

    COM is unchanged and the tensor scales linearly with mass. Used to give geometry a
    known mass budget (for example a measured or CAD link mass).
    """
    if not mass > 0.0:
        raise ValueError(f"mass must be positive, got {mass!r}")
    return MassProperties(mass, mp.com, mp.inertia * (mass / mp.mass))


def _matrix(inertia: ArrayLike) -> np.ndarray:
    return np.asarray(inertia, dtype=float).reshape(3, 3)


def principal_moments(inertia: ArrayLike) -> np.ndarray:
    """Eigenvalues of the (symmetrised) tensor, ascending.

    They do not depend on the frame's orientation, which makes them the right thing to
    compare and to check physical validity on.
    """
    return np.array(tensor_math.symmetric_eigenvalues(_matrix(inertia)))


def is_positive_definite(inertia: ArrayLike) -> bool:
    """True when every principal moment is strictly positive (a physical body)."""
    return tensor_math.is_positive_definite(_matrix(inertia))


def satisfies_triangle_inequality(inertia: ArrayLike, tol: float = 1e-12) -> bool:
    """True when each principal moment is at most the sum of the other two (+ ``tol``); see
    :func:`ar3cli.maths.tensor_math.satisfies_triangle_inequality`."""
    return tensor_math.satisfies_triangle_inequality(_matrix(inertia), tol)
