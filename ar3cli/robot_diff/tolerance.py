"""What counts as a change: lengths (m), angles (rad) and relative amounts (masses, inertias,
efforts), and the plain-Python measures of two origins, axes and numbers they are compared with.

Rotations are compared as rotations (the angle of ``R_old^T R_new``), never as rpy numbers, so
``rpy="0 0 0"`` and ``"0.0 0 -0"``, or ``"3.14159265 0 3.14159265"`` and ``"0 3.14159265 0"``, are the same.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from ar3cli.maths.tensor_math import rpy_to_matrix, vector_length

DEFAULT = 1e-9
"""Default for all three tolerances: far below any manufacturing tolerance, far above the rounding
of numbers written with 9+ significant digits (the float64 of "0.1" and "0.10000000001" differ by 1e-11)."""


@dataclass(frozen=True)
class Tolerance:
    """``length`` in metres, ``angle`` in radians, ``relative`` as a fraction of the larger value."""

    length: float = DEFAULT
    angle: float = DEFAULT
    relative: float = DEFAULT

    def to_dict(self) -> dict[str, float]:
        return {"length_m": self.length, "angle_rad": self.angle, "relative": self.relative}

    def relative_change(self, old: float | None, new: float | None) -> float | None:
        """``|new - old| / max(|old|, |new|)`` when that is beyond the tolerance, else None; a value
        that appears, disappears or stops being a number (NaN) is a change of 1."""
        if old is None or new is None or not (math.isfinite(old) and math.isfinite(new)):
            same = (old is None and new is None) or (old is not None and new is not None and str(old) == str(new))
            return None if same else 1.0
        scale = max(abs(old), abs(new))
        change = abs(new - old) / scale if scale else 0.0
        return change if change > self.relative else None

    def absolute_change(self, old: float | None, new: float | None, limit: float) -> float | None:
        """``|new - old|`` when beyond ``limit`` (one of the tolerances), else None; presence and NaN as above."""
        if old is None or new is None or not (math.isfinite(old) and math.isfinite(new)):
            same = (old is None and new is None) or (old is not None and new is not None and str(old) == str(new))
            return None if same else math.inf
        change = abs(new - old)
        return change if change > limit else None


def distance(a: Sequence[float], b: Sequence[float]) -> float:
    return vector_length([x - y for x, y in zip(a, b)])


def rotation_angle(rpy_a: Sequence[float], rpy_b: Sequence[float]) -> float:
    """Angle (rad, in [0, pi]) of the rotation between two URDF rpy orientations: ``atan2(|skew|, (tr - 1) / 2)``
    of ``R_a^T R_b``, which keeps tiny angles precise (``acos`` of the trace cannot resolve 1e-8 rad)."""
    a, b = rpy_to_matrix(rpy_a), rpy_to_matrix(rpy_b)
    r = [[sum(a[k][i] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    skew = (r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1])
    return math.atan2(0.5 * math.sqrt(sum(v * v for v in skew)), 0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0))


def vector_angle(a: Sequence[float], b: Sequence[float]) -> float:
    """Angle (rad) between two directions (axes are normalised, as the URDF spec says); NaN for a zero vector."""
    cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    dot = sum(x * y for x, y in zip(a, b))
    norm = math.sqrt(sum(v * v for v in cross))
    if math.sqrt(sum(x * x for x in a)) == 0.0 or math.sqrt(sum(x * x for x in b)) == 0.0:
        return math.nan
    return math.atan2(norm, dot)


def origin_delta(old, new) -> tuple[float, float]:
    """(metres, radians) between two :class:`~ar3cli.urdf.model.Origin` values."""
    return distance(old.xyz, new.xyz), rotation_angle(old.rpy, new.rpy)


def origin_changed(old, new, tolerance: Tolerance) -> tuple[float, float] | None:
    """The (m, rad) delta of two origins when either part is beyond the tolerance (or not a number), else None."""
    metres, radians = origin_delta(old, new)
    moved = not (metres <= tolerance.length) or not (radians <= tolerance.angle)  # NaN counts as moved
    return (metres, radians) if moved else None
