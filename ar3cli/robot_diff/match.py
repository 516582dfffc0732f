"""Which link and joint of NEW is which of OLD.

Same name first. Then, where names differ, by position in the tree: walking down from the
matched roots, the still unmatched child joints of a matched link pair are paired with each other,
closest first by a score of joint type, origin (m + rad), whether their child links already
correspond, and the child links' geometry (shape kinds and mesh file names). A joint paired that
way whose child links have different names renames those links too. What stays unmatched was
added (NEW) or removed (OLD).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field

from ar3cli.robot_diff.tolerance import origin_delta
from ar3cli.urdf.model import Joint, Link, Model

TYPE_MISMATCH = 10.0
"""Score added when two joints differ in type: a renamed joint that also changed type still pairs
when it is the only candidate, but a same-type candidate wins."""
SAME_CHILD = -5.0
GEOMETRY_MISMATCH = 1.0


@dataclass
class Matching:
    """``links`` and ``joints`` map OLD names to NEW names (renames are pairs with different names)."""

    links: dict[str, str] = field(default_factory=dict)
    joints: dict[str, str] = field(default_factory=dict)

    def new_joint(self, old_name: str) -> str | None:
        return self.joints.get(old_name)

    def old_joint(self, new_name: str) -> str | None:
        return self._inverse_joints.get(new_name)

    def old_link(self, new_name: str) -> str | None:
        return self._inverse_links.get(new_name)

    @property
    def _inverse_joints(self) -> dict[str, str]:
        return {new: old for old, new in self.joints.items()}

    @property
    def _inverse_links(self) -> dict[str, str]:
        return {new: old for old, new in self.links.items()}


def geometry_signature(link: Link | None) -> tuple:
    """What a link looks like without its name: shape kinds and mesh file names, per role."""
    if link is None:
        return ()
    return tuple((shape.role, shape.geometry.kind, os.path.basename(shape.geometry.filename or ""))
                 for shape in (*link.visuals, *link.collisions))


def _children(model: Model) -> dict[str, list[Joint]]:
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        if joint.parent is not None:
            children.setdefault(joint.parent, []).append(joint)
    return children


def _score(old: Model, new: Model, old_joint: Joint, new_joint: Joint, links: dict[str, str]) -> float:
    metres, radians = origin_delta(old_joint.origin, new_joint.origin)
    score = (metres if metres == metres else 1.0) + (radians if radians == radians else 1.0)
    if old_joint.type != new_joint.type:
        score += TYPE_MISMATCH
    if old_joint.child is not None and links.get(old_joint.child) == new_joint.child:
        score += SAME_CHILD
    old_child = old.link(old_joint.child) if old_joint.child else None
    new_child = new.link(new_joint.child) if new_joint.child else None
    if geometry_signature(old_child) != geometry_signature(new_child):
        score += GEOMETRY_MISMATCH
    return score


def match(old: Model, new: Model) -> Matching:
    """Pair OLD's links and joints with NEW's (see the module docstring)."""
    new_links = {link.name for link in new.links}
    new_joints = {joint.name for joint in new.joints}
    result = Matching(links={link.name: link.name for link in old.links if link.name in new_links},
                      joints={joint.name: joint.name for joint in old.joints if joint.name in new_joints})
    old_roots, new_roots = old.root_links(), new.root_links()
    if len(old_roots) == 1 and len(new_roots) == 1:
        old_root, new_root = old_roots[0].name, new_roots[0].name
        if old_root not in result.links and new_root not in result.links.values():
            result.links[old_root] = new_root
    old_children, new_children = _children(old), _children(new)
    pending = list(result.links.items())
    done: set[tuple[str, str]] = set()
    while pending:
        old_link, new_link = pending.pop()
        if (old_link, new_link) in done:  # a loop in a malformed tree: each pair is walked once
            continue
        done.add((old_link, new_link))
        taken = set(result.joints.values())
        free_old = [j for j in old_children.get(old_link, []) if j.name not in result.joints]
        free_new = [j for j in new_children.get(new_link, []) if j.name not in taken]
        pairs = sorted((_score(old, new, a, b, result.links), index_a, index_b)
                       for index_a, a in enumerate(free_old) for index_b, b in enumerate(free_new))
        used_old: set[int] = set()
        used_new: set[int] = set()
        for _, index_a, index_b in pairs:
            if index_a in used_old or index_b in used_new:
                continue
            used_old.add(index_a)
            used_new.add(index_b)
            result.joints[free_old[index_a].name] = free_new[index_b].name
        mapped_new_links = set(result.links.values())
        for joint in old_children.get(old_link, []):
            counterpart = new.joint(result.joints.get(joint.name, "")) if joint.name in result.joints else None
            if counterpart is None or joint.child is None or counterpart.child is None:
                continue
            if joint.child not in result.links and counterpart.child not in mapped_new_links:
                result.links[joint.child] = counterpart.child
                mapped_new_links.add(counterpart.child)
            if result.links.get(joint.child) == counterpart.child:
                pending.append((joint.child, counterpart.child))
    return result
