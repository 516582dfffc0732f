"""Structure and joint changes: links and joints added, removed or renamed, and for each pair of
corresponding joints its type, parent/child (structure) and origin/axis (kinematics) changes."""

from __future__ import annotations

from ar3cli.robot_diff.joints import joint_deltas
from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import Change

KINEMATIC = ("origin", "axis")


def structure_changes(pair: Pair) -> list[Change]:
    old, new, matching = pair.old, pair.new, pair.matching
    changes: list[Change] = []
    for kind, old_items, new_items, mapping in (("link", old.links, new.links, matching.links),
                                               ("joint", old.joints, new.joints, matching.joints)):
        mapped = set(mapping.values())
        for item in old_items:
            if item.name not in mapping:
                changes.append(pair.change("structure", f"{kind} '{item.name}'", "removed", old=item.name,
                                           old_at=item.element))
            elif mapping[item.name] != item.name:
                target = new.link(mapping[item.name]) if kind == "link" else new.joint(mapping[item.name])
                changes.append(pair.change("structure", f"{kind} '{mapping[item.name]}'", "renamed", old=item.name,
                                           new=mapping[item.name], at=target.element if target else None))
        changes += [pair.change("structure", f"{kind} '{item.name}'", "added", new=item.name, at=item.element)
                    for item in new_items if item.name not in mapped]
    for old_name, new_name in matching.joints.items():
        old_joint, new_joint = old.joint(old_name), new.joint(new_name)
        if old_joint is None or new_joint is None:
            continue
        for delta in joint_deltas(old_joint, new_joint, pair.tolerance, matching.links):
            section = "kinematics" if delta.what in KINEMATIC else "structure"
            changes.append(pair.change(section, f"joint '{new_name}'", delta.what, delta.old, delta.new, delta.amount,
                                       delta.unit, at=new_joint.element))
    return changes
