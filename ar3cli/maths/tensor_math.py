"""3x3 tensor and rotation math in plain Python (no numpy), for the linter's hot path.

Importing numpy costs ~0.1-0.2 s, more than linting a typical robot; the static rules only
need eigenvalues of 3x3 inertia tensors and URDF rotations, which closed forms give in
microseconds. :mod:`ar3cli.maths.mass_properties` delegates to these functions (so there is one
definition of "positive definite" and of the triangle inequality) and wraps the results in
numpy arrays for its own array math.

Matrices are anything indexable as ``m[i][j]`` (nested lists/tuples or a numpy array);
results are plain floats and tuples.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = ["is_positive_definite", "matrix_to_rpy", "quaternion_to_matrix", "rpy_to_matrix", "satisfies_triangle_inequality",
           "symmetric_eigenvalues", "unit_quaternion"]

Matrix3 = Sequence[Sequence[float]]
NEAR_SINGULAR = 1e-4
"""An eigenvalue this much smaller than the largest is recomputed from the exact determinant."""


def symmetric_eigenvalues(matrix: Matrix3) -> tuple[float, float, float]:
    """Eigenvalues of the symmetrised 3x3 ``matrix`` (``(M + M^T) / 2``), ascending.

    Closed-form trigonometric solution of the characteristic cubic (O. K. Smith, "Eigenvalues
    of a symmetric 3x3 matrix", CACM 4(4), 1961). The matrix is first scaled by a power of two
    (exact) so that its largest entry is ~1: no overflow or underflow whatever its units. A
    diagonal matrix (all off-diagonal entries zero) returns its diagonal exactly. Absolute error
    is a few ulps of the largest eigenvalue, like LAPACK's ``eigvalsh``; in addition, when one
    eigenvalue is tiny next to the other two (a tensor on the edge of positive definiteness, e.g.
    "0.2404 -0.01 -0.048 0.2404 -0.048 0.02", singular in decimal), it is recomputed as
    ``det(M) / (l2 l3)`` with the determinant in exact rational arithmetic, so its sign is right
    and it is accurate relative to itself. Non-finite entries give three NaNs.
    """
    a11, a22, a33 = float(matrix[0][0]), float(matrix[1][1]), float(matrix[2][2])
    a12 = 0.5 * (float(matrix[0][1]) + float(matrix[1][0]))
    a13 = 0.5 * (float(matrix[0][2]) + float(matrix[2][0]))
    a23 = 0.5 * (float(matrix[1][2]) + float(matrix[2][1]))
    entries = (a11, a22, a33, a12, a13, a23)
    if not all(map(math.isfinite, entries)):
        return (math.nan, math.nan, math.nan)
    if a12 == 0.0 and a13 == 0.0 and a23 == 0.0:
        return tuple(sorted((a11, a22, a33)))  # type: ignore[return-value]
    exponent = math.frexp(max(map(abs, entries)))[1]
    if exponent > MAX_EXPONENT:  # entries near the largest float: 2**1024 itself does not exist
        entries = tuple(value / 2.0 for value in entries)
        return tuple(value * 2.0 for value in symmetric_eigenvalues(_matrix(entries)))  # type: ignore[return-value]
    scale = math.ldexp(1.0, exponent)  # power of two: scaling is exact
    a11, a22, a33, a12, a13, a23 = (value / scale for value in entries)
    q = (a11 + a22 + a33) / 3.0
    b11, b22, b33 = a11 - q, a22 - q, a33 - q
    p = math.sqrt((b11 * b11 + b22 * b22 + b33 * b33 + 2.0 * (a12 * a12 + a13 * a13 + a23 * a23)) / 6.0)
    if p == 0.0:  # off-diagonals so small next to the diagonal that their squares underflow
        return (q * scale, q * scale, q * scale)
    # B = (A - qI) / p has entries of size ~1 and det(B) / 2 = cos(3 phi); rounding can push it
    # just outside [-1, 1].
    b11, b22, b33, c12, c13, c23 = b11 / p, b22 / p, b33 / p, a12 / p, a13 / p, a23 / p
    det = b11 * (b22 * b33 - c23 * c23) - c12 * (c12 * b33 - c23 * c13) + c13 * (c12 * c23 - b22 * c13)
    r = max(-1.0, min(1.0, det / 2.0))
    # The roots of the cubic are 2 cos(phi + 2 pi k / 3). The one farthest from the others
    # (largest when r >= 0, smallest when r < 0) is well conditioned; the other two can be
    # close, and the cubic determines close roots only to sqrt(epsilon). So they come from the
    # 2x2 block of B on the plane orthogonal to the isolated eigenvector instead.
    phi = math.acos(r) / 3.0
    isolated = 2.0 * math.cos(phi) if r >= 0.0 else 2.0 * math.cos(phi + 2.0 * math.pi / 3.0)
    rows = ((b11 - isolated, c12, c13), (c12, b22 - isolated, c23), (c13, c23, b33 - isolated))
    vector = max((_cross(rows[0], rows[1]), _cross(rows[0], rows[2]), _cross(rows[1], rows[2])), key=_dot_self)
    u, w = _orthonormal_complement(_scaled(vector, 1.0 / math.sqrt(_dot_self(vector))))
    matrix_b = ((b11, c12, c13), (c12, b22, c23), (c13, c23, b33))
    bu, bw = _apply(matrix_b, u), _apply(matrix_b, w)
    m00, m01, m11 = _dot(u, bu), 0.5 * (_dot(u, bw) + _dot(w, bu)), _dot(w, bw)
    centre, radius = 0.5 * (m00 + m11), math.hypot(0.5 * (m00 - m11), m01)
    values = [(q + p * beta) * scale for beta in (isolated, centre - radius, centre + radius)]
    return _refine_near_singular(entries, values)


MAX_EXPONENT = 1023
"""The largest ``frexp`` exponent whose power of two is a float."""


def _matrix(entries: tuple[float, ...]) -> Matrix3:
    """The symmetric matrix of (a11, a22, a33, a12, a13, a23)."""
    a11, a22, a33, a12, a13, a23 = entries
    return ((a11, a12, a13), (a12, a22, a23), (a13, a23, a33))


def _refine_near_singular(entries: tuple[float, ...], values: list[float]) -> tuple[float, float, float]:
    """Sorted eigenvalues, the smallest in magnitude recomputed when it is tiny (see above)."""
    small, middle, large = sorted(values, key=abs)
    if abs(small) < NEAR_SINGULAR * abs(large) and abs(middle) >= NEAR_SINGULAR * abs(large):
        from fractions import Fraction  # rare: importing it costs ~2 ms of every lint's start-up

        a11, a22, a33, a12, a13, a23 = map(Fraction, entries)
        det = a11 * (a22 * a33 - a23 * a23) - a12 * (a12 * a33 - a23 * a13) + a13 * (a12 * a23 - a22 * a13)
        small = float(det / (Fraction(middle) * Fraction(large)))
    return tuple(sorted((small, middle, large)))  # type: ignore[return-value]


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _dot_self(a: Sequence[float]) -> float:
    return a[0] * a[0] + a[1] * a[1] + a[2] * a[2]


def _cross(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _scaled(a: Sequence[float], factor: float) -> tuple[float, float, float]:
    return (a[0] * factor, a[1] * factor, a[2] * factor)


def _apply(matrix: Matrix3, vector: Sequence[float]) -> tuple[float, float, float]:
    return (_dot(matrix[0], vector), _dot(matrix[1], vector), _dot(matrix[2], vector))


def _orthonormal_complement(unit: Sequence[float]) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """Two unit vectors orthogonal to ``unit`` and to each other."""
    x, y, z = unit
    other = (-y, x, 0.0) if abs(x) > abs(z) else (0.0, -z, y)  # never (near) zero for a unit vector
    first = _scaled(other, 1.0 / math.sqrt(_dot_self(other)))
    return first, _cross(unit, first)


def is_positive_definite(matrix: Matrix3) -> bool:
    """True when every principal moment is strictly positive (a physical body)."""
    return all(value > 0.0 for value in symmetric_eigenvalues(matrix))


def satisfies_triangle_inequality(matrix: Matrix3, tol: float = 1e-12) -> bool:
    """True when each principal moment is at most the sum of the other two (+ ``tol``).

    Every real mass distribution satisfies ``I_a + I_b >= I_c``; a tensor that violates it
    cannot come from any body, and physics engines may become unstable with it. ``tol``
    absorbs rounding for thin shapes, where equality holds exactly.
    """
    a, b, c = symmetric_eigenvalues(matrix)
    return a + b + tol >= c and a + c + tol >= b and b + c + tol >= a


def vector_length(parts: Sequence[float]) -> float:
    """The Euclidean length of ``parts``: ``sqrt`` of the squares summed in order (the same floats as
    that expression everywhere it fits), and ``math.hypot`` where a square overflows (components past
    1e154, which a file may hold: a float ``**`` raises OverflowError there instead of giving inf)."""
    try:
        return math.sqrt(sum([part ** 2 for part in parts]))
    except OverflowError:
        return math.hypot(*parts)


def exact_sum(values: Sequence[float]) -> float:
    """``math.fsum(values)`` (exactly rounded), but ``inf`` where the sum passes the largest float
    (masses of 1e308 kg, which a file may hold): fsum raises OverflowError where ``sum`` gives inf."""
    try:
        return math.fsum(values)
    except OverflowError:
        return math.inf


def rpy_to_matrix(rpy: Sequence[float]) -> tuple[tuple[float, float, float], ...]:
    """Rotation matrix (rows) of URDF roll-pitch-yaw: ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``; NaN rows
    for an infinite or NaN angle (which has no rotation: lint's F007 reports the value)."""
    roll, pitch, yaw = (float(angle) for angle in rpy)
    if not (math.isfinite(roll) and math.isfinite(pitch) and math.isfinite(yaw)):
        return ((math.nan,) * 3,) * 3
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return ((cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr),
            (sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr),
            (-sp, cp * sr, cp * cr))


def unit_quaternion(quat_xyzw: Sequence[float]) -> tuple[float, float, float, float] | None:
    """``quat_xyzw`` (x, y, z, w: the order of URDF 1.1's ``<origin quat_xyzw>``) scaled to norm 1.

    urdfdom normalises the quaternion it reads (urdfdom_headers ``Rotation::setFromQuaternion``);
    None when it has no direction (all zeros) or holds a non-finite number, which urdfdom would turn
    into the identity or into NaN frames and the linter reports.
    """
    values = tuple(float(v) for v in quat_xyzw)
    if len(values) != 4 or not all(map(math.isfinite, values)):
        return None
    norm = math.sqrt(sum(v * v for v in values))
    if not norm > 0.0 or not math.isfinite(norm):
        return None
    x, y, z, w = (v / norm for v in values)
    return x, y, z, w


def quaternion_to_matrix(quat_xyzw: Sequence[float]) -> tuple[tuple[float, float, float], ...]:
    """Rotation matrix (rows) of a quaternion given as (x, y, z, w); normalised first.

    The identity when the quaternion has no direction (see :func:`unit_quaternion`).
    """
    unit = unit_quaternion(quat_xyzw)
    if unit is None:
        return ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    x, y, z, w = unit
    return ((1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - z * w), 2.0 * (x * z + y * w)),
            (2.0 * (x * y + z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - x * w)),
            (2.0 * (x * z - y * w), 2.0 * (y * z + x * w), 1.0 - 2.0 * (x * x + y * y)))


def matrix_to_rpy(rotation: Matrix3) -> tuple[float, float, float]:
    """URDF roll, pitch, yaw of a rotation matrix: the inverse of :func:`rpy_to_matrix`, pitch in [-pi/2, pi/2].

    Pitch comes from ``atan2(-r20, hypot(r00, r10))`` (well conditioned everywhere, unlike
    ``asin``), yaw from the first column, and roll from ``Rz(yaw)^T R`` once yaw is known, so that
    near gimbal lock (pitch at +-pi/2, where roll and yaw are not separately defined) the roll
    makes up for whatever yaw the rounding gave: the angles rebuild the matrix to ~1e-16 everywhere,
    lock included (reading roll from ``atan2(r21, r22)`` there loses all its digits).
    """
    r = rotation
    pitch = math.atan2(-r[2][0], math.hypot(r[0][0], r[1][0]))
    yaw = math.atan2(r[1][0], r[0][0])
    cy, sy = math.cos(yaw), math.sin(yaw)
    roll = math.atan2(sy * r[0][2] - cy * r[1][2], cy * r[1][1] - sy * r[0][1])
    return float(roll), float(pitch), float(yaw)
