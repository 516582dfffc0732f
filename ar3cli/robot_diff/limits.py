"""Joint limits and mimic couplings of corresponding joints: lower/upper (m or rad, as the joint
moves), effort and velocity (relative), a ``<limit>`` or ``<mimic>`` appearing or going, and the
mimic's source joint (through the renames), multiplier and offset."""

from __future__ import annotations

from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import Change
from ar3cli.urdf.model import Joint


def mimic_deltas(pair: Pair, old: Joint, new: Joint) -> list[tuple[str, object, object, float | None]]:
    """(what, old, new, amount) of each mimic difference beyond the tolerance."""
    if old.mimic is None or new.mimic is None:
        return [] if old.mimic is new.mimic else [("mimic", old.mimic.joint if old.mimic else "-",
                                                    new.mimic.joint if new.mimic else "-", None)]
    deltas: list[tuple[str, object, object, float | None]] = []
    if pair.matching.joints.get(old.mimic.joint, old.mimic.joint) != new.mimic.joint:
        deltas.append(("mimic joint", old.mimic.joint, new.mimic.joint, None))
    multiplier = pair.tolerance.relative_change(old.mimic.multiplier, new.mimic.multiplier)
    if multiplier is not None:
        deltas.append(("mimic multiplier", old.mimic.multiplier, new.mimic.multiplier, multiplier))
    unit_tolerance = pair.tolerance.length if new.type == "prismatic" else pair.tolerance.angle
    offset = pair.tolerance.absolute_change(old.mimic.offset, new.mimic.offset, unit_tolerance)
    if offset is not None:
        deltas.append(("mimic offset", old.mimic.offset, new.mimic.offset, offset))
    return deltas


def joint_limit_changes(pair: Pair, old: Joint, new: Joint) -> list[Change]:
    name, at = f"joint '{new.name}'", new.element
    changes: list[Change] = []
    if (old.limit is None) != (new.limit is None):
        changes.append(pair.change("limits", name, "limit", "-" if old.limit is None else "given",
                                   "-" if new.limit is None else "given", at=at))
    elif old.limit is not None and new.limit is not None:
        unit = "m" if new.type == "prismatic" else "rad"
        bound_tolerance = pair.tolerance.length if unit == "m" else pair.tolerance.angle
        at = new.limit.element
        for what in ("lower", "upper"):
            before, after = getattr(old.limit, what), getattr(new.limit, what)
            if new.type == "continuous" and old.type == "continuous":
                continue  # ignored by the URDF spec and every engine
            amount = pair.tolerance.absolute_change(before, after, bound_tolerance)
            if amount is not None:
                changes.append(pair.change("limits", name, what, before, after, amount, unit, at=at))
        for what in ("effort", "velocity"):
            before, after = getattr(old.limit, what), getattr(new.limit, what)
            amount = pair.tolerance.relative_change(before, after)
            if amount is not None:
                changes.append(pair.change("limits", name, what, before, after, amount, "relative", at=at))
    for what, before, after, amount in mimic_deltas(pair, old, new):
        changes.append(pair.change("limits", name, what, before, after, amount,
                                   "relative" if what == "mimic multiplier" else "", at=new.element))
    return changes


def limit_changes(pair: Pair) -> list[Change]:
    changes: list[Change] = []
    for old_name, new_name in pair.matching.joints.items():
        old, new = pair.old.joint(old_name), pair.new.joint(new_name)
        if old is not None and new is not None:
            changes += joint_limit_changes(pair, old, new)
    return changes
