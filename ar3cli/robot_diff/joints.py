"""What changed in one joint's kinematics: type, origin, axis, parent and child links. The
kinematics section reports these per joint, and names the first of them on an end effector's path
as the cause of its displacement."""

from __future__ import annotations

from dataclasses import dataclass

from ar3cli.robot_diff.tolerance import Tolerance, origin_changed, vector_angle
from ar3cli.urdf.model import Joint

AXIS_MATTERS = ("revolute", "continuous", "prismatic", "planar")
"""Joint types whose ``<axis>`` changes the robot (a fixed joint's axis is ignored by everyone)."""


@dataclass(frozen=True)
class JointDelta:
    what: str
    old: object
    new: object
    amount: float | None = None
    unit: str = ""


def joint_deltas(old: Joint, new: Joint, tolerance: Tolerance, link_map: dict[str, str]) -> list[JointDelta]:
    """The kinematic differences of two corresponding joints, beyond ``tolerance``; ``link_map``
    (OLD link name -> NEW) decides whether the parent and child are the same links."""
    deltas: list[JointDelta] = []
    if old.type != new.type:
        deltas.append(JointDelta("type", old.type, new.type))
    for role, old_link, new_link in (("parent", old.parent, new.parent), ("child", old.child, new.child)):
        if link_map.get(old_link or "", old_link) != new_link:
            deltas.append(JointDelta(role, old_link or "-", new_link or "-"))
    moved = origin_changed(old.origin, new.origin, tolerance)
    if moved is not None:
        metres, radians = moved
        translated = not metres <= tolerance.length  # NaN counts as translated
        deltas.append(JointDelta("origin", _origin_text(old), _origin_text(new), metres if translated else radians,
                                 "m" if translated else "rad"))
    if new.type in AXIS_MATTERS or old.type in AXIS_MATTERS:
        angle = vector_angle(old.axis, new.axis)
        if not angle <= tolerance.angle:  # NaN (a zero axis) counts
            deltas.append(JointDelta("axis", old.axis, new.axis, angle, "rad"))
    return deltas


def _origin_text(joint: Joint) -> str:
    from ar3cli.robot_diff.records import show

    return f"xyz {show(joint.origin.xyz)} rpy {show(joint.origin.rpy)}"
