"""Which link and joint of NEW is which of OLD.

Same name first. Then, where names differ, by position in the tree: walking down from the
matched roots, the still unmatched child joints of a matched link pair are paired with each other,
closest first by a score of joint type, origin (m + rad), whether their child links already
correspond, and the child links' geometry (shape kinds and mesh file names). A joint paired that
way whose child links have different names renames those links too. What stays unmatched was
added (NEW) or removed (OLD).

Bounded work: up to :data:`EXACT_PAIRS` pairs of free child joints under one link pair (every real
robot: the most children of one link in example-robot-data and pybullet_data is a few dozen) are all
scored, as always. Beyond, scoring every pair was quadratic (a 1,000-child star whose children were
all renamed: 28-34 s; 2,000: 127 s and 585 MB), so only candidate pairs are scored
(:func:`_candidates`): the joints whose child link already corresponds, and the nearest few by
origin along each axis, among joints of the same type and child geometry and among all; the
candidates are taken closest first as before, and what is left is paired again the same way.
"""

from __future__ import annotations

import bisect
import math
import os
from dataclasses import dataclass, field

from ar3cli.robot_diff.tolerance import origin_delta
from ar3cli.urdf.model import Joint, Link, Model

EXACT_PAIRS = 10_000
"""Free joint pairs under one link pair up to which every pair is scored (100 x 100: ~0.2 s)."""
WINDOW = 4
"""Neighbours on each side, in each axis's order, a joint is scored against when pairs are many."""
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
    _inverse: dict[str, dict[str, str]] = field(default_factory=dict, repr=False, compare=False)

    def new_joint(self, old_name: str) -> str | None:
        return self.joints.get(old_name)

    def old_joint(self, new_name: str) -> str | None:
        return self._inverted("joints").get(new_name)

    def old_link(self, new_name: str) -> str | None:
        return self._inverted("links").get(new_name)

    def _inverted(self, kind: str) -> dict[str, str]:
        """NEW name -> OLD name, built once per size of the mapping (a mapping is one-to-one, so a
        changed one has another size; it was rebuilt on every question, once per end effector)."""
        mapping: dict[str, str] = getattr(self, kind)
        inverse = self._inverse.get(kind)
        if inverse is None or len(inverse) != len(mapping):
            inverse = self._inverse[kind] = {new: old for old, new in mapping.items()}
        return inverse


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
    taken = set(result.joints.values())  # kept up to date: rebuilding it per link pair was quadratic
    mapped_new_links = set(result.links.values())
    while pending:
        old_link, new_link = pending.pop()
        if (old_link, new_link) in done:  # a loop in a malformed tree: each pair is walked once
            continue
        done.add((old_link, new_link))
        free_old = [j for j in old_children.get(old_link, []) if j.name not in result.joints]
        free_new = [j for j in new_children.get(new_link, []) if j.name not in taken]
        for index_a, index_b in _pair_up(old, new, free_old, free_new, result.links):
            result.joints[free_old[index_a].name] = free_new[index_b].name
            taken.add(free_new[index_b].name)
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


def _pair_up(old: Model, new: Model, free_old: list[Joint], free_new: list[Joint],
             links: dict[str, str]) -> list[tuple[int, int]]:
    """(index in ``free_old``, index in ``free_new``) of the joints paired, closest first: every
    pair scored when they are few (:data:`EXACT_PAIRS`), else rounds over :func:`_candidates` until
    one side is used up (a round that pairs nothing ends it: a side left over is added or removed)."""
    if len(free_old) * len(free_new) <= EXACT_PAIRS:
        pairs = sorted((_score(old, new, a, b, links), index_a, index_b)
                       for index_a, a in enumerate(free_old) for index_b, b in enumerate(free_new))
        return _greedy(pairs)
    chosen: list[tuple[int, int]] = []
    left_old, left_new = list(range(len(free_old))), list(range(len(free_new)))
    while left_old and left_new:
        if len(left_old) * len(left_new) <= EXACT_PAIRS:
            candidates = [(a, b) for a in left_old for b in left_new]
        else:
            candidates = _candidates([free_old[a] for a in left_old], [free_new[b] for b in left_new], links, old, new)
            candidates = [(left_old[a], left_new[b]) for a, b in candidates]
        pairs = sorted((_score(old, new, free_old[a], free_new[b], links), a, b) for a, b in candidates)
        found = _greedy(pairs)
        if not found:
            break
        chosen += found
        used_old, used_new = {a for a, _ in found}, {b for _, b in found}
        left_old = [a for a in left_old if a not in used_old]
        left_new = [b for b in left_new if b not in used_new]
    return chosen


def _greedy(pairs: list[tuple[float, int, int]]) -> list[tuple[int, int]]:
    """Sorted (score, a, b) pairs taken in order, each a and each b once."""
    used_old: set[int] = set()
    used_new: set[int] = set()
    chosen = []
    for _, index_a, index_b in pairs:
        if index_a in used_old or index_b in used_new:
            continue
        used_old.add(index_a)
        used_new.add(index_b)
        chosen.append((index_a, index_b))
    return chosen


def _candidates(free_old: list[Joint], free_new: list[Joint], links: dict[str, str], old: Model,
                new: Model) -> set[tuple[int, int]]:
    """The pairs worth scoring among many free joints, O(n log n) of them: a joint whose child link
    already corresponds to another's (the :data:`SAME_CHILD` bonus), and, in each axis's order of
    the origins, the :data:`WINDOW` nearest on either side, among the joints of the same type and
    child geometry (the score's other terms) and among all of them (a joint that changed type)."""
    found: set[tuple[int, int]] = set()
    by_child: dict[str, list[int]] = {}
    for index_b, joint in enumerate(free_new):
        if joint.child is not None:
            by_child.setdefault(joint.child, []).append(index_b)
    for index_a, joint in enumerate(free_old):
        counterpart = links.get(joint.child) if joint.child is not None else None
        found.update((index_a, index_b) for index_b in by_child.get(counterpart, []) if counterpart is not None)

    def kind(model: Model, joint: Joint) -> tuple:
        return joint.type, geometry_signature(model.link(joint.child) if joint.child else None)

    groups: dict[tuple, tuple[list[int], list[int]]] = {}
    for index_a, joint in enumerate(free_old):
        groups.setdefault(kind(old, joint), ([], []))[0].append(index_a)
    for index_b, joint in enumerate(free_new):
        groups.setdefault(kind(new, joint), ([], []))[1].append(index_b)
    everyone = (list(range(len(free_old))), list(range(len(free_new))))
    for members_old, members_new in [*groups.values(), everyone]:
        if members_old and members_new:
            found |= _neighbours(members_old, members_new, free_old, free_new)
    return found


def _neighbours(members_old: list[int], members_new: list[int], free_old: list[Joint],
                free_new: list[Joint]) -> set[tuple[int, int]]:
    """(a, b) pairs of OLD and NEW joints at most :data:`WINDOW` places apart in one merged order of
    their origins along x, along y or along z (NaN sorts last)."""
    found: set[tuple[int, int]] = set()
    for axis in range(3):
        merged = sorted([(_coordinate(free_old[a], axis), 0, a) for a in members_old]
                        + [(_coordinate(free_new[b], axis), 1, b) for b in members_new])
        new_places = [at for at, entry in enumerate(merged) if entry[1] == 1]
        for at, (_, side, index) in enumerate(merged):
            if side != 0:
                continue
            after = bisect.bisect_left(new_places, at)  # the WINDOW nearest NEW joints on each side
            for place in new_places[max(0, after - WINDOW):after + WINDOW]:
                found.add((index, merged[place][2]))
    return found


def _coordinate(joint: Joint, axis: int) -> float:
    value = joint.origin.xyz[axis]
    return value if value == value else math.inf
