"""Geometric consistency rules (G014-G016): where the parts sit relative to each other, from the boxes
ar3cli already reads (:mod:`ar3cli.urdf.bounds`): no mesh triangles, no simulator.

A joint origin typed 3 m (or 0.8 m) off, a collision pasted 0.3 m away from its visual, a hinge axis
that misses its part: every parser loads such a file and the robot flies apart, collides where
nothing is drawn, or swings about thin air (fusion2urdf #42/#50, kuka_experimental #191).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, robot, rule
from ar3cli.lint.rules.geometry import scale_mismatches
from ar3cli.maths.tensor_math import vector_length
from ar3cli.urdf.bounds import Box, box_around, box_union

DETACHED_FACTOR = 1.0
"""A child's box further from its parent's box than this many times the larger of the two box
diagonals (and than :data:`DETACHED_MIN_GAP`) is detached (G014)."""
DETACHED_MIN_GAP = 0.25
"""m: gaps below this are never reported (a sensor on a short bracket, a finger pad)."""
MAX_WALK = 8
"""Links without geometry G014 walks up through to find the nearest part with geometry."""
MAX_SIBLINGS = 16
"""Siblings (other children of the same part) a detached candidate is also compared with."""
COVER_MIN = 0.2
"""Fraction of the visual box the collision box must cover (G015)."""
OFFSET_FACTOR = 1.0
"""G015 also needs the boxes' centres apart by this many visual half-diagonals..."""
OFFSET_MIN = 0.05
"""... and by at least this many metres."""
AXIS_FACTOR = 1.0
"""G016: a hinge axis further from its part's box than this many box diagonals..."""
AXIS_MIN = 0.1
"""... and than this many metres misses the part."""


def _union(boxes) -> Box | None:
    boxes = [b for b in boxes if b is not None and all(map(math.isfinite, (*b[0], *b[1])))]
    return box_union(boxes) if boxes else None


def _diagonal(box: Box) -> float:
    return math.dist(box[0], box[1])


# The arithmetic below sums three-element lists where it summed generators: the same additions in the
# same order (so the same floats), without a generator per row; G014 composes and moves boxes for
# every link.


def _gap(a: Box, b: Box) -> float:
    """Distance between two axis-aligned boxes (0 when they touch or overlap)."""
    (al, ah), (bl, bh) = a, b
    return vector_length([max(0.0, bl[0] - ah[0], al[0] - bh[0]), max(0.0, bl[1] - ah[1], al[1] - bh[1]),
                    max(0.0, bl[2] - ah[2], al[2] - bh[2])])


def _moved(box: Box, rotation, translation) -> Box:
    """The axis-aligned box around ``box`` rotated by ``rotation`` (rows) and moved by ``translation``."""
    centre = [(lo + hi) / 2 for lo, hi in zip(*box)]
    half = [(hi - lo) / 2 for lo, hi in zip(*box)]
    return box_around(centre, half, rotation, translation)


def _compose(outer, inner):
    """(R, t) of ``outer`` applied after ``inner``: x -> R_o (R_i x + t_i) + t_o."""
    (ro, to), (ri, ti) = outer, inner
    (a0, a1, a2), (b0, b1, b2), (c0, c1, c2) = ri  # rows k = 0, 1, 2 of the inner rotation
    t0, t1, t2 = ti
    rotation = tuple([(sum([r0 * a0, r1 * b0, r2 * c0]), sum([r0 * a1, r1 * b1, r2 * c1]),
                       sum([r0 * a2, r1 * b2, r2 * c2])) for r0, r1, r2 in ro])
    translation = tuple([sum([r0 * t0, r1 * t1, r2 * t2]) + t for (r0, r1, r2), t in zip(ro, to)])
    return rotation, translation


def _joint_transform(joint):
    return joint.origin.rotation, joint.origin.xyz


def _finite_origin(joint) -> bool:
    return all(map(math.isfinite, (*joint.origin.xyz, *(v for row in joint.origin.rotation for v in row))))


def _geometric_ancestor(ctx, link):
    """(ancestor link, its box, transform from ``link``'s frame to the ancestor's, the first joint) for
    the nearest ancestor with a known box, or None (at home: every joint at 0)."""
    model = ctx.model
    joint = model.parent_joint(link.name)
    first = joint
    transform = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 0.0)
    for _ in range(MAX_WALK):
        if joint is None or joint.parent is None or not _finite_origin(joint):
            return None
        transform = _compose(_joint_transform(joint), transform)
        parent = model.link(joint.parent)
        if parent is None:
            return None
        box = ctx.link_bounds(parent)
        if box is not None:
            return parent, box, transform, first
        joint = model.parent_joint(parent.name)
    return None


def detachment(ctx, link) -> tuple[float, float, object, object] | None:
    """(gap in metres, the size it is compared with, the ancestor, the joint) for a link with a box,
    or None when there is nothing to compare with. The gap is the smallest distance from the link's
    box to its nearest geometric ancestor's box or to a sibling's box (other children of that ancestor)."""
    box = ctx.link_bounds(link)
    if box is None or not all(map(math.isfinite, (*box[0], *box[1]))):
        return None
    found = _geometric_ancestor(ctx, link)
    if found is None:
        return None
    ancestor, ancestor_box, transform, joint = found
    moved = _moved(box, *transform)
    gap = _gap(moved, ancestor_box)
    size = max(_diagonal(box), _diagonal(ancestor_box))
    if gap <= max(DETACHED_MIN_GAP, DETACHED_FACTOR * size):
        return gap, size, ancestor, joint
    for sibling_joint in ctx.model.child_joints(ancestor.name)[:MAX_SIBLINGS]:
        sibling = ctx.model.link(sibling_joint.child) if sibling_joint.child else None
        if sibling is None or sibling is link or not _finite_origin(sibling_joint):
            continue
        sibling_box = ctx.link_bounds(sibling)
        if sibling_box is not None:
            gap = min(gap, _gap(moved, _moved(sibling_box, *_joint_transform(sibling_joint))))
    return gap, size, ancestor, joint


def _part(name: str, xyz: str, shape: str = '<box size="0.1 0.1 0.1"/>') -> str:
    return f'<link name="{name}">{LINK_INERTIAL}<collision><origin xyz="{xyz}"/><geometry>{shape}</geometry></collision></link>'


def _two_parts(joint_xyz: str, child_xyz: str = "0 0 0.05", axis: str = "0 0 1") -> str:
    return robot(f"""
        {_part("base", "0 0 0.05")}
        {_part("arm", child_xyz)}
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="{joint_xyz}"/>
          <axis xyz="{axis}"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>""")


@rule("G014", "detached-child", "warning", "Link far away from the part it hangs from",
      why="""A child whose geometry, at the home pose, is further from its parent's geometry (and from
      its siblings') than the parts are large is almost always a joint origin typed wrong (metres for
      millimetres, a sign, an exporter's world frame): every parser loads it and the robot flies
      apart when drawn or simulated (fusion2urdf #42/#50, kuka_experimental #191). Links without
      geometry in between are looked through (the nearest ancestor with geometry is compared).""",
      fix="Check the joint's <origin xyz> (units, sign, which frame it is written in) against the drawings.",
      bad=_two_parts("0 0 3.0"), good=_two_parts("0 0 0.1"),
      thresholds=f"Reported when the gap between the boxes exceeds both {DETACHED_MIN_GAP} m and {DETACHED_FACTOR:g} "
                 f"x the larger box diagonal; up to {MAX_WALK} geometry-less links are looked through and "
                 f"{MAX_SIBLINGS} siblings compared.",
      references="fusion2urdf issues #42 and #50; ros-industrial/kuka_experimental #191; simcheck 0.2.0 "
                 "kinematics.attached.")
def detached_child(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        found = detachment(ctx, link)
        if found is None:
            continue
        gap, size, ancestor, joint = found
        if gap > max(DETACHED_MIN_GAP, DETACHED_FACTOR * size) and collision_off(ctx, link) is None:
            yield Hit(f"joint '{joint.name}' origin xyz=\"{' '.join(f'{v:g}' for v in joint.origin.xyz)}\" looks "
                      f"wrong: it puts link '{link.name}' {gap:.3g} m away from link '{ancestor.name}' (parts about "
                      f"{size:.3g} m across) at the home pose",
                      joint.origin.element if joint.origin.element is not None else joint.element)


def _overlap_fraction(inner: Box, outer: Box) -> float:
    """Fraction of ``inner``'s volume inside ``outer`` (flat boxes padded by 1 mm)."""
    pad = 5e-4
    a = [(lo - pad, hi + pad) for lo, hi in zip(*inner)]
    b = [(lo - pad, hi + pad) for lo, hi in zip(*outer)]
    shared = 1.0
    volume = 1.0
    for (alo, ahi), (blo, bhi) in zip(a, b):
        shared *= max(0.0, min(ahi, bhi) - max(alo, blo))
        volume *= ahi - alo
    return shared / volume if volume > 0 else 1.0


def collision_offset(ctx, link) -> tuple[float, float, Box, Box] | None:
    """(covered fraction of the visual box, centre offset in m, visual box, collision box), or None."""
    if not link.visuals or not link.collisions:
        return None
    visual = _union(ctx.shape_bounds(s) for s in link.visuals)
    collision = _union(ctx.shape_bounds(s) for s in link.collisions)
    if visual is None or collision is None:
        return None
    centre = [(lo + hi) / 2 for lo, hi in zip(*visual)]
    other = [(lo + hi) / 2 for lo, hi in zip(*collision)]
    return _overlap_fraction(visual, collision), math.dist(centre, other), visual, collision


def collision_off(ctx, link) -> tuple[float, float, Box, Box] | None:
    """G015's verdict for ``link``: its :func:`collision_offset` when its collision box barely covers
    its visual box and sits apart, else None. G014 then stays quiet about the same link: the joint is
    not to blame when only the collision is off (alex_nub_hands.urdf's nubs: ``<origin xyz="0 1.57 0">``,
    the rpy typed into xyz)."""
    found = collision_offset(ctx, link)
    if found is None or scale_mismatches(ctx, link):  # a mesh in the wrong unit is G006's
        return None
    covered, offset, visual, _collision = found
    if covered >= COVER_MIN or offset <= max(OFFSET_MIN, OFFSET_FACTOR * _diagonal(visual) / 2):
        return None
    return None if _covered_by_companion(ctx, link, visual) else found


def _companions(ctx, link):
    """Links with collision shapes and no visual welded (fixed joint) to ``link`` or to its parent: where
    a description keeps a part's collision on a link of its own (Rethink's Baxter: ``right_upper_elbow``'s
    cylinder is on ``right_upper_elbow_visual``, welded to the parent at the elbow joint)."""
    model = ctx.model
    joint = model.parent_joint(link.name)
    anchors = [link.name] + ([joint.parent] if joint is not None and joint.parent else [])
    for anchor in anchors:
        for other_joint in model.child_joints(anchor):
            other = model.link(other_joint.child) if other_joint.type == "fixed" and other_joint.child else None
            if other is not None and other is not link and other.collisions and not other.visuals:
                yield other


def _covered_by_companion(ctx, link, visual: Box) -> bool:
    """True when a companion link's collision (:func:`_companions`) covers COVER_MIN of ``link``'s visual
    box at the zero pose."""
    placed = ctx.zero_pose_box(link.name, visual)
    if placed is None:
        return False
    for other in _companions(ctx, link):
        box = ctx.zero_pose_box(other.name, _union(ctx.shape_bounds(s) for s in other.collisions))
        if box is not None and _overlap_fraction(placed, box) >= COVER_MIN:
            return True
    return False


def _visual_and_collision(collision_xyz: str) -> str:
    shape = '<geometry><box size="0.1 0.1 0.1"/></geometry>'
    return robot(f"""
        <link name="base">{LINK_INERTIAL}<visual>{shape}</visual>
          <collision><origin xyz="{collision_xyz}"/>{shape}</collision></link>""")


@rule("G015", "collision-off-visual", "warning", "Collision geometry does not cover the visual geometry",
      why="""The collision shapes are what the simulator and the planner see; the visual shapes are
      what people see. When their boxes barely overlap and their centres are apart (a collision
      <origin> forgotten, pasted from another link, or a misspelt <orign> ignored), the robot collides
      where nothing is drawn and passes through what is drawn. A part whose collision lives on a
      companion link (a link with collision and no visual, welded to the part or to its parent, as
      Rethink's Baxter does for its elbows) is judged with that collision too.""",
      fix="Give the <collision> the same <origin> as the <visual>, and check its spelling (<orign> is ignored).",
      bad=_visual_and_collision("0.3 0 0"), good=_visual_and_collision("0 0 0"),
      thresholds=f"Reported when the collision box covers less than {COVER_MIN:.0%} of the visual box and their "
                 f"centres are more than {OFFSET_FACTOR:g} visual half-diagonals and {OFFSET_MIN} m apart.",
      references="simcheck 0.2.0 (collision-vs-visual match).")
def collision_off_visual(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        found = collision_off(ctx, link)
        if found is not None:
            covered, offset, _visual, _collision = found
            yield Hit(f"link '{link.name}' collision box covers {covered:.0%} of its visual box; their centres are "
                      f"{offset:.3g} m apart", link.collisions[0].element)


def _line_box_distance(direction, box: Box) -> float:
    """Distance from the line through the origin along ``direction`` to ``box``, exactly.

    The squared distance from the point ``t * u`` to the box is a convex, piecewise quadratic function
    of ``t`` whose pieces meet where the point crosses a face plane (``t = lo / u`` or ``hi / u`` per
    axis): its minimum is at one of those breakpoints or at a piece's own minimum, clipped into the
    piece. That is a dozen evaluations (an 80-step ternary search cost G016 a quarter of a cold lint).
    """
    lows, highs = box
    if all(lo <= 0.0 <= hi for lo, hi in zip(lows, highs)):
        return 0.0  # the line's own point at the joint origin is in the box (most hinges sit in their part)
    norm = math.sqrt(sum(v * v for v in direction))
    if math.isinf(norm):  # a huge axis (1e200): its squares overflowed
        norm = math.hypot(*direction)
    if not norm > 0:
        return 0.0
    u = [v / norm for v in direction]

    def distance(t: float) -> float:
        return vector_length([max(0.0, lo - t * a, t * a - hi) for a, lo, hi in zip(u, lows, highs)])

    breaks = sorted({bound / a for a, lo, hi in zip(u, lows, highs) if a != 0 for bound in (lo, hi)})
    candidates = list(breaks)
    pieces = list(zip([-math.inf, *breaks], [*breaks, math.inf]))
    for left, right in pieces:
        probe = (left + right) / 2 if math.isfinite(left) and math.isfinite(right) else \
            (right - 1.0 if math.isfinite(right) else left + 1.0)
        weighted = weight = 0.0
        for a, lo, hi in zip(u, lows, highs):
            if lo - probe * a > 0 or probe * a - hi > 0:  # this axis is outside the box over the piece
                weighted += a * (lo if lo - probe * a > 0 else hi)
                weight += a * a
        if weight > 0:
            candidates.append(min(max(weighted / weight, left), right))
    return min(map(distance, candidates))


def axis_offset(ctx, joint) -> tuple[float, float] | None:
    """(distance from the joint axis to the child's box, the box diagonal) for a hinge, or None."""
    if joint.type not in ("revolute", "continuous") or joint.child is None:
        return None
    child = ctx.model.link(joint.child)
    box = ctx.link_bounds(child) if child is not None else None
    if box is None or not all(map(math.isfinite, joint.axis)) or not all(map(math.isfinite, (*box[0], *box[1]))):
        return None
    return _line_box_distance(joint.axis, box), _diagonal(box)


@rule("G016", "axis-off-part", "warning", "Hinge axis far from the part it turns",
      why="""A revolute joint turns its child about a line through the joint origin along <axis>.
      When that line passes far from the child's geometry, the part swings about thin air: usually
      a joint origin and a mesh exported in different frames, or an axis typed in the wrong frame.""",
      fix="Place the joint origin on the hinge (and the child's geometry relative to it), or fix the axis.",
      bad=_two_parts("0 0 0.1", child_xyz="1.0 0 0.05"), good=_two_parts("0 0 0.1"),
      thresholds=f"Reported when the distance from the axis line to the child's box exceeds both {AXIS_MIN} m and "
                 f"{AXIS_FACTOR:g} x the box diagonal.",
      references="simcheck 0.2.0 (hinge axis off the part).")
def axis_off_part(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        found = axis_offset(ctx, joint)
        if found is None:
            continue
        distance, size = found
        if distance > max(AXIS_MIN, AXIS_FACTOR * size):
            yield Hit(f"joint '{joint.name}' axis passes {distance:.3g} m from link '{joint.child}' "
                      f"(about {size:.3g} m across)", joint.element)
