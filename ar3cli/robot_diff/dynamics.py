"""Mass properties: per link the mass (relative tolerance), the centre of mass (m) and the inertia,
and for the robot the total mass and the centre of mass at the home pose.

The inertia is compared in the link frame (``R I R^T`` with the ``<inertial>`` origin's rotation),
so a tensor written about rotated axes but equal in the link frame is no change. A change is
explained by its principal moments (:func:`~ar3cli.maths.tensor_math.symmetric_eigenvalues`) and
by how far the principal axes turned (only between distinct moments: equal moments have no axes).
"""

from __future__ import annotations

import math
from typing import Any

from ar3cli.maths.tensor_math import rpy_to_matrix, symmetric_eigenvalues
from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import Change, finite_or_none, show
from ar3cli.robot_diff.tolerance import distance
from ar3cli.urdf.model import Inertial, Link


def link_frame_tensor(inertial: Inertial) -> list[list[float]] | None:
    """The inertia tensor about the centre of mass, in the link frame's axes."""
    matrix = inertial.matrix()
    if matrix is None:
        return None
    r = rpy_to_matrix(inertial.origin.rpy)
    rotated = [[sum(r[i][k] * matrix[k][m] for k in range(3)) for m in range(3)] for i in range(3)]
    return [[sum(rotated[i][m] * r[j][m] for m in range(3)) for j in range(3)] for i in range(3)]


def _norm(matrix: list[list[float]]) -> float:
    return math.sqrt(sum(value * value for row in matrix for value in row))


def _axes_angle(old: list[list[float]], new: list[list[float]], relative: float) -> float | None:
    """Largest angle (rad) between corresponding principal axes whose moment is distinct from the others."""
    import numpy as np

    old_values, old_vectors = np.linalg.eigh(np.array(old))
    new_values, new_vectors = np.linalg.eigh(np.array(new))
    scale = max(float(np.max(np.abs(new_values))), 1e-300)
    angles = []
    for index in range(3):
        others = [other for other in range(3) if other != index]
        if min(abs(new_values[index] - new_values[other]) for other in others) <= 1e3 * relative * scale:
            continue
        dot = min(1.0, abs(float(old_vectors[:, index] @ new_vectors[:, index])))
        angles.append(math.acos(dot))
    return max(angles) if angles else None


def inertia_change(pair: Pair, name: str, old: Inertial, new: Inertial, at: Any) -> Change | None:
    old_tensor, new_tensor = link_frame_tensor(old), link_frame_tensor(new)
    if old_tensor is None or new_tensor is None:
        return None if old_tensor is new_tensor else pair.change(
            "dynamics", name, "inertia", "-" if old_tensor is None else "given", "-" if new_tensor is None else "given",
            at=at)
    difference = [[a - b for a, b in zip(row_a, row_b)] for row_a, row_b in zip(old_tensor, new_tensor)]
    scale = max(_norm(old_tensor), _norm(new_tensor))
    relative = _norm(difference) / scale if scale else 0.0
    if relative <= pair.tolerance.relative:
        return None
    old_moments, new_moments = symmetric_eigenvalues(old_tensor), symmetric_eigenvalues(new_tensor)
    axes = _axes_angle(old_tensor, new_tensor, pair.tolerance.relative) if all(map(math.isfinite, new_moments)) \
        and all(map(math.isfinite, old_moments)) else None
    turned = f"; principal axes turned {axes:.4g} rad" if axes is not None and axes > pair.tolerance.angle else ""
    return pair.change("dynamics", name, "inertia", f"moments {show(old_moments)}",
                       f"moments {show(new_moments)}{turned}", relative, "relative", at=at)


def link_changes(pair: Pair, old: Link, new: Link) -> list[Change]:
    name = f"link '{new.name}'"
    at = new.inertial.element if new.inertial is not None else new.element
    if old.inertial is None or new.inertial is None:
        if old.inertial is new.inertial:
            return []
        return [pair.change("dynamics", name, "inertial", "-" if old.inertial is None else f"{show(old.inertial.mass)} kg",
                            "-" if new.inertial is None else f"{show(new.inertial.mass)} kg", at=at)]
    changes = []
    mass = pair.tolerance.relative_change(old.inertial.mass, new.inertial.mass)
    if mass is not None:
        changes.append(pair.change("dynamics", name, "mass", old.inertial.mass, new.inertial.mass, mass, "relative", at=at))
    moved = distance(old.inertial.origin.xyz, new.inertial.origin.xyz)
    if not moved <= pair.tolerance.length:
        changes.append(pair.change("dynamics", name, "centre of mass", old.inertial.origin.xyz, new.inertial.origin.xyz,
                                   moved, "m", at=at))
    inertia = inertia_change(pair, name, old.inertial, new.inertial, at)
    return changes + ([inertia] if inertia is not None else [])


def total_mass(links: list[Link]) -> float:
    return sum(link.inertial.mass for link in links if link.inertial is not None and link.inertial.mass is not None
               and math.isfinite(link.inertial.mass))


def centre_of_mass(links: list[Link], home: dict[str, Any]) -> tuple[float, float, float] | None:
    """The robot's centre of mass at home in the root frame, from NEW's home link frames (4x4)."""
    weighted, mass = [0.0, 0.0, 0.0], 0.0
    for link in links:
        inertial = link.inertial
        if inertial is None or inertial.mass is None or not math.isfinite(inertial.mass) or link.name not in home:
            continue
        frame = home[link.name]
        point = [sum(float(frame[i][k]) * inertial.origin.xyz[k] for k in range(3)) + float(frame[i][3]) for i in range(3)]
        weighted = [w + inertial.mass * p for w, p in zip(weighted, point)]
        mass += inertial.mass
    return tuple(w / mass for w in weighted) if mass > 0 else None  # type: ignore[return-value]


def dynamics_changes(pair: Pair, old_home: dict[str, Any], new_home: dict[str, Any]) -> tuple[list[Change], dict]:
    """Per-link changes of corresponding links, and the robot totals (as changes when they differ, and as data)."""
    changes: list[Change] = []
    for old_name, new_name in pair.matching.links.items():
        old_link, new_link = pair.old.link(old_name), pair.new.link(new_name)
        if old_link is not None and new_link is not None:
            changes += link_changes(pair, old_link, new_link)
    old_mass, new_mass = total_mass(pair.old.links), total_mass(pair.new.links)
    totals: dict[str, Any] = {"mass_kg": [finite_or_none(old_mass), finite_or_none(new_mass)]}
    relative = pair.tolerance.relative_change(old_mass, new_mass)
    if relative is not None:
        changes.append(pair.change("dynamics", "robot", "total mass", old_mass, new_mass, relative, "relative"))
    old_com, new_com = centre_of_mass(pair.old.links, old_home), centre_of_mass(pair.new.links, new_home)
    totals["centre_of_mass_at_home_m"] = [[finite_or_none(v) for v in com] if com else None for com in (old_com, new_com)]
    if old_com is not None and new_com is not None:
        moved = distance(old_com, new_com)
        if not moved <= pair.tolerance.length and math.isfinite(moved):
            changes.append(pair.change("dynamics", "robot", "centre of mass at home", old_com, new_com, moved, "m"))
    return changes, totals
