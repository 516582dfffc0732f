"""Simulation rules (P, only with ``--sim``): load the model in PyBullet and see what it really does.

Each rule loads the model in the file's shared :class:`~ar3cli.sim.session.Session` (``ctx.session``,
gravity -9.81 m/s^2), checks one thing and removes the body again, so the rules are independent of
each other.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

from ar3cli.errors import UserError
from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, refusal_explained, robot, rule
from ar3cli.lint.rules.geometry import union_box

INERTIA_TOLERANCE = 0.10
"""Relative difference between the file and PyBullet's value above which P003 reports a link."""
SETTLE_STEPS = 240
MAX_SETTLE_SPEED = 100.0
"""rad/s or m/s: a joint faster than this after one second under gravity has exploded."""


@contextmanager
def _loaded(ctx, **load_options):
    """Load the model into the file's session and remove it afterwards; yields None when it fails."""
    session = ctx.session
    try:
        body = session.load(ctx.model, allow_nan_frames=True, visuals=False, **load_options)
    except UserError:
        yield None
        return
    try:
        yield body
    finally:
        body.remove()


def _home(body) -> dict[str, float] | None:
    """The body's home pose, or None when a joint's limits are not finite numbers: F007 reports those
    at their line, and the other rules of the file still run (a lint must not end at one bad limit)."""
    from ar3cli.sim.sampling import home_positions

    try:
        return home_positions(body)
    except UserError:
        return None


@rule("P001", "sim-load-failed", "error", "PyBullet cannot load the model",
      engines=("pybullet",), refused_by=("pybullet",), breaks="PyBullet refuses the file (measured: ar3cli loads it).",
      why="""What matters in the end is whether the simulator accepts the file. PyBullet's own error is
      "Cannot load URDF file."; ar3cli captures its C output and reports the real reason (a missing
      mesh, a joint without limits, ...). When a static error that PyBullet refuses (G001, J001, G004,
      ...) already names the cause at its line, P001 adds nothing.""",
      fix="Fix the reason quoted in the message (often a G001 or J001 finding).",
      bad=arm(link_extra=LINK_INERTIAL + '<collision><geometry><cylinder radius="0.05"/></geometry></collision>'),
      good=arm(), needs_sim=True)
def sim_load_failed(ctx) -> Iterator[Hit]:
    try:
        body = ctx.session.load(ctx.model, allow_nan_frames=True)
    except UserError as exc:
        if refusal_explained(ctx, "pybullet") is None:  # a static error already says why, at its line
            yield Hit(exc.message.removeprefix(f"{ctx.model.path}: "), ctx.model.root)
        return
    body.remove()


P002_FIX = ("Fix the collision geometry or the joint origin; if the overlap is by design, disable the pair "
                     "(SRDF / setCollisionFilterPair).")


def _stacked_boxes(tip_z: float) -> str:
    """P002's example: base and tip boxes joined through a small middle link; overlapping when tip_z < 0."""
    return robot(f"""
          <link name="base">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <link name="mid">{LINK_INERTIAL}<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
          <link name="tip">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/><origin xyz="0 0 0.3"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/><origin xyz="0 0 {tip_z}"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>""")


@rule("P002", "sim-self-collision-home", "warning", "Links collide at the home pose",
      engines=("pybullet",),
      why="""Two links that are not adjacent but interpenetrate (deeper than 1 µm) at the home pose
      (all joints at 0, or mid-range where 0 is outside the limits; mimic joints following) mean
      overlapping collision meshes or a wrong joint origin. With self-collision on, PyBullet pushes
      them apart the moment the simulation starts; planners see the start state as invalid.
      Adjacent is MoveIt's rule, as in sample-collisions: joined by a joint, looking through links
      without collision geometry (their overlap is by construction). Links joined only through
      fixed joints (one rigid group, as sample-collisions settles them) are not reported: they can
      never move apart, so their overlap is how the part is built, not a pose to fix. Nor are the pairs
      an SRDF disables: the one --srdf names, else the one the package ships for this robot (an .srdf
      beside the file, or in srdf/ or config/ next to it or next to its urdf/ folder, named like the file
      or naming the robot; the hint says which). Nor are the contacts a robot is built with, which no
      pose removes: links on either side of a joint cluster (a ball or universal joint written as two or
      three revolute joints at one point: the links meet at its centre), the two branches of one
      linkage driven through <mimic> (the halves of a four-bar URDF cannot close meet at the pin), two
      branches whose hulls touch by at most 3 mm (neighbouring fingers at rest), and a link that collides
      as a placeholder (a collision under 5% of its visual). A contact across a single joint, or across
      joints that do not meet at one point, is kept: a part sunk into its mount is real.""",
      fix=P002_FIX,
      bad=_stacked_boxes(tip_z=-0.25), good=_stacked_boxes(tip_z=0.25),
      thresholds="Deeper than 1 µm; not reported: a joint cluster (at least two moving joints on the chain between the "
                 "links, all within CLUSTER_RADIUS = 3 cm and half the smaller link's size of each other at the zero "
                 "pose), one linkage (two branches whose moving joints all follow one leader through <mimic>), two "
                 "branches touching by at most TOUCH_DEPTH = 3 mm, a collision under PLACEHOLDER = 5% of its link's "
                 "visual.",
      needs_sim=True)
def sim_self_collision_home(ctx) -> Iterator[Hit]:
    from ar3cli.sim.adjacency import nonadjacent_collisions, rigid_groups

    with _loaded(ctx, self_collision="all-pairs") as body:
        home = _home(body) if body is not None else None
        if home is None:
            return
        body.set_positions(home)
        group = rigid_groups(ctx.model, (joint.name for joint in body.actuated_joints))
        disabled, note = ctx.disabled_pairs()
        for a, b, depth in nonadjacent_collisions(body):
            if disabled.covers(a, b):
                continue  # the SRDF (the user's, or the package's) tells MoveIt not to check this pair
            if a in group and group[a] == group.get(b):
                continue  # joined only by fixed joints: they can never move apart (issue 30 item 8)
            if built_touching(ctx, a, b, -depth) is not None:
                continue
            link = ctx.model.link(b) or ctx.model.link(a)
            yield Hit(f"links '{a}' and '{b}' interpenetrate by {depth_text(-depth)} at the home pose",
                      link.element if link else None, hint=srdf_hint(P002_FIX, note))


CLUSTER_RADIUS = 0.03
"""m: the moving joints on the chain between two links all within this distance of each other (at the zero pose),
and within half the smaller link's size, make a joint cluster: a ball or universal joint written as two or three
revolute joints at one point (iCub's shoulder: 1.6 and 2.6 cm apart; its elbow, 4.5 cm, is two joints). The
links on either side meet at its centre by construction."""
TOUCH_DEPTH = 0.003
"""m: links on two branches of the tree (two fingers of a hand) whose hulls overlap this little at home are at rest
side by side: a convex hull of a curved part reaches where the part does not."""
PLACEHOLDER = 0.05
"""A link whose collision shapes' box is smaller than this fraction of its visual's collides as a placeholder
(Baxter's screen: a 1 mm sphere for a 27 cm body): where that point sits says nothing about the part."""


def built_touching(ctx, a: str, b: str, depth: float) -> str | None:
    """Why links ``a`` and ``b``, overlapping ``depth`` m at home, meet there by construction (P002, M003), or None
    when their contact is worth a warning. On one chain: a joint cluster between them (at least two moving
    joints, all within CLUSTER_RADIUS and half the smaller link's size of each other). On two branches of the
    tree: one linkage (every moving joint on the path driven by one actuator through <mimic>: the halves of a
    four-bar URDF cannot close meet at its pin, parallel fingers at their closed home), or hulls touching by at
    most TOUCH_DEPTH (neighbouring fingers at rest). Either way: a link whose collision is a placeholder."""
    if _placeholder(ctx, a) or _placeholder(ctx, b):
        return "a placeholder collision"
    path = _tree_path(ctx, a, b)
    if path is None:
        return None
    joints, branches = path
    moving = [joint for joint in joints if joint.moves]
    if not branches:
        if len(moving) < 2:
            return None
        points = [frame[1] for joint in moving if joint.child and (frame := ctx.zero_pose_frame(joint.child)) is not None]
        sizes = [size for name in (a, b) if (size := ctx.link_size(ctx.model.link(name))) is not None]
        spread = max(math.dist(p, q) for p in points for q in points) if len(points) == len(moving) else math.inf
        return "a joint cluster" if spread <= min([CLUSTER_RADIUS, *(size / 2 for size in sizes)]) else None
    if len(moving) > 1 and len({_leader(ctx.model, joint) for joint in moving}) == 1:
        return "one linkage"
    if depth <= TOUCH_DEPTH:
        return "branches touching"
    return None


def _placeholder(ctx, name: str) -> bool:
    """Whether link ``name`` collides as a placeholder: the box around its collision shapes under PLACEHOLDER of
    the box around its visual shapes (diagonals)."""
    link = ctx.model.link(name)
    if link is None or not link.visuals or not link.collisions:
        return False
    sizes = []
    for shapes in (link.collisions, link.visuals):
        boxes = [ctx.shape_bounds(shape) for shape in shapes]
        if any(box is None for box in boxes):
            return False
        sizes.append(math.dist(*union_box(boxes)))  # all of them: 9,261 small spheres can fill a body
    return sizes[0] < PLACEHOLDER * sizes[1]


def _tree_path(ctx, a: str, b: str):
    """(the joints on the tree path between links ``a`` and ``b``, whether the path turns at a third body: two
    branches), or None when they are not in one tree. Bodies are links welded by fixed joints: a cap welded to
    the torso turns nowhere on its way to the arm."""
    model = ctx.model
    up_a, up_b = list(model.joints_above(a)), list(model.joints_above(b))
    above_a = [a] + [joint.parent for joint in up_a]
    above_b = [b] + [joint.parent for joint in up_b]
    common = next((name for name in above_a if name in set(above_b)), None)
    if common is None or any(model.link(name) is None for name in (a, b, common)):
        return None
    joints = up_a[:above_a.index(common)] + up_b[:above_b.index(common)]
    tops = {ctx.rigid_body(model.link(name)).top for name in (a, b)}
    return joints, ctx.rigid_body(model.link(common)).top not in tops


def _leader(model, joint) -> str:
    """The joint that drives ``joint`` through <mimic> chains (itself when it has none; a cycle stops)."""
    seen = set()
    while joint.mimic is not None and joint.name not in seen:
        seen.add(joint.name)
        leader = model.joint(joint.mimic.joint)
        if leader is None:
            break
        joint = leader
    return joint.name


def srdf_hint(fix: str, note: str | None) -> str | None:
    """A P002/M003 hint that says which SRDF's pairs were left out (None: the rule's own)."""
    return None if note is None else f"{fix} ({note[0].upper()}{note[1:]}.)"


def depth_text(depth: float) -> str:
    """0.1 mm and deeper in mm, shallower in µm (a 4 µm overlap is not '0.0 mm')."""
    return f"{depth * 1000:.1f} mm" if depth >= 1e-4 else f"{depth * 1e6:.1f} µm"


@rule("P003", "sim-inertia-differs", "info", "PyBullet uses a different mass or inertia than the file",
      engines=("pybullet",),
      why="""By default (no URDF_USE_INERTIA_FROM_FILE flag) PyBullet keeps the file's mass but
      recomputes every inertia tensor from the collision shape's bounding box, padded by the
      collision margin. Code that loads with default flags simulates these values, not the file's.""",
      fix="Load with flags=p.URDF_USE_INERTIA_FROM_FILE, or make the file's tensor match the geometry.",
      bad=arm(link_extra=LINK_INERTIAL + '<collision><geometry><box size="0.1 0.1 1"/></geometry></collision>'),
      good=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.08378" ixy="0" ixz="0" iyy="0.08378" iyz="0" '
                          'izz="0.001768"/></inertial><collision><geometry><box size="0.1 0.1 1"/></geometry></collision>'),
      needs_sim=True,
      thresholds="Relative difference above INERTIA_TOLERANCE = 0.10 between the file's and PyBullet's mass or principal moments.")
def sim_inertia_differs(ctx) -> Iterator[Hit]:
    """One finding per file: how many links PyBullet's default load changes, pointing at the worst one.

    A per-link finding would bury a clean model in rows: the default load replaces *every* tensor.
    """
    from ar3cli.lint.rules.inertia import finite_tensor, tensor_moments

    changed: list[tuple[float, str, object]] = []  # (relative difference, description, element)
    with _loaded(ctx, fixed_base=False, flags=ctx.session.p.URDF_MAINTAIN_LINK_ORDER) as body:
        if body is None:
            return
        for link in ctx.model.links:
            inertial = link.inertial
            if link.name not in body.link_index or inertial is None or not finite_tensor(inertial.tensor) \
                    or not (inertial.mass or 0) > 0:
                continue
            dynamics = body.dynamics(link.name)
            used_mass, used = dynamics.mass, sorted(dynamics.inertia_diagonal)
            file_moments = sorted(float(m) for m in tensor_moments(inertial.tensor))
            parts = []
            if _differs(used_mass, inertial.mass):
                parts.append(f"mass {inertial.mass:.4g} kg -> {used_mass:.4g} kg")
            if any(_differs(u, f) for u, f in zip(used, file_moments)):
                parts.append("principal moments (" + ", ".join(f"{m:.3g}" for m in file_moments) + ") -> ("
                             + ", ".join(f"{m:.3g}" for m in used) + ")")
            if parts:
                worst = max(_relative(u, f) for u, f in zip([used_mass, *used], [inertial.mass, *file_moments]))
                changed.append((worst, f"link '{link.name}': " + "; ".join(parts), inertial.element))
    if changed:
        worst, description, element = max(changed, key=lambda item: item[0])
        count = f"{len(changed)} link{'s' if len(changed) != 1 else ''}"
        yield Hit(f"PyBullet's default load (without URDF_USE_INERTIA_FROM_FILE) changes the mass properties of "
                  f"{count}; most: {description} ({worst:.0%})", element)


def _relative(used: float, declared: float) -> float:
    scale = max(abs(used), abs(declared))
    return abs(used - declared) / scale if scale > 0 else 0.0


def _differs(used: float, declared: float) -> bool:
    return _relative(used, declared) > INERTIA_TOLERANCE


@rule("P004", "sim-unstable", "error", "NaN or exploding states after settling under gravity",
      engines=("pybullet",),
      breaks="PyBullet's joint states become NaN or explode within one simulated second (measured).",
      why="""ar3cli loads the model (fixed base, inertia from the file), puts it at the home pose,
      turns off PyBullet's default joint motors and simulates one second under gravity. A real
      robot falls limp; NaN positions or joint speeds above 100 rad/s mean an unphysical inertia,
      a zero axis or a degenerate mass.""",
      fix="Look at the I and J findings for this file (inertia, mass, axis); fix-inertia often cures it.",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/>'
                         '</inertial>').replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'),
      good=arm(), needs_sim=True,
      thresholds="A joint NaN/inf, or faster than MAX_SETTLE_SPEED = 100 rad/s or m/s, after SETTLE_STEPS = 240 steps (1 s) "
                 "under gravity; one finding per file, at the first such joint, naming the others.")
def sim_unstable(ctx) -> Iterator[Hit]:
    with _loaded(ctx) as body:
        home = _home(body) if body is not None and body.actuated_joints else None
        if home is None:
            return
        body.set_positions(home)
        body.release_motors()
        ctx.session.step(SETTLE_STEPS)  # the lint session has gravity (lint.Context.session)
        states = [(joint.name, joint.urdf.element if joint.urdf else None, position, velocity)
                  for joint, (position, velocity) in zip(body.actuated_joints, body.joint_states())]
        found = unstable_hit(states, f"after {SETTLE_STEPS} steps under gravity", MAX_SETTLE_SPEED)
        if found is not None:
            yield found


def unstable_hit(states, when: str, fastest: float, blamed: str | None = None) -> Hit | None:
    """One finding for one instability (P004, M004): the joints whose state is NaN/inf or faster than
    ``fastest`` after settling, from ``states`` ((name, element, position, velocity) in file order), at
    the joint the engine ``blamed`` (MuJoCo names the degree of freedom whose acceleration blew up) or
    the first of them, naming the others (an exploding body drags every joint below it along: iCub's
    one bad link made 27 findings)."""
    bad = []
    for name, element, position, velocity in states:
        if not (math.isfinite(position) and math.isfinite(velocity)):
            bad.append((name, element, "state is NaN/inf"))
        elif abs(velocity) > fastest:
            bad.append((name, element, f"moves at {velocity:.3g}"))
    if not bad:
        return None
    first = next((state for state in states if state[0] == blamed), None)
    if first is not None and first[0] not in [name for name, _element, _what in bad]:
        bad.insert(0, (first[0], first[1], "made MuJoCo's accelerations blow up (the simulation was reset)"))
    bad.sort(key=lambda item: item[0] != blamed)  # the blamed joint first, the rest in file order
    name, element, what = bad[0]
    others = [other for other, _element, _what in bad[1:]]
    listed = ", ".join(f"'{other}'" for other in others[:UNSTABLE_LISTED]) + (", ..." if len(others) > UNSTABLE_LISTED else "")
    also = f" (and {len(others)} more joint{'s' if len(others) != 1 else ''}: {listed})" if others else ""
    return Hit(f"joint '{name}' {what} {when}{also}", element)


UNSTABLE_LISTED = 3
"""Other unstable joints a P004/M004 message names (the rest are counted)."""


def _swinging_arm(limit: float) -> str:
    """P005's example: an arm standing on a plate, turning about x within +-``limit`` rad (past ~1.3 it dips into the plate)."""
    return robot(f"""
          <link name="base">{LINK_INERTIAL}<collision><origin xyz="0 0 -0.05"/><geometry><box size="0.3 0.3 0.1"/></geometry></collision></link>
          <link name="arm">{LINK_INERTIAL}<collision><origin xyz="0 0 0.12"/><geometry><box size="0.05 0.05 0.2"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.02"/>
            <axis xyz="1 0 0"/><limit lower="-{limit}" upper="{limit}" effort="10" velocity="1"/></joint>""")


@rule("P005", "sim-passes-through-parent", "warning", "A part passes through its parent when its joint moves",
      engines=("pybullet",),
      why="""PyBullet never tests a link against its direct parent for self-collision and MoveIt calls
      the pair adjacent, so a child that swings through its parent's body is seen by no other check,
      and the robot's planners happily command poses the real robot cannot reach. ar3cli sweeps each
      movable joint over its range (SWEEP_STEPS = 13 values, limits included; continuous joints over a
      full turn; the other joints at home, mimic joints following) and measures how deep the child's
      collision geometry sinks into its parent's (the nearest ancestor with collision geometry). Real
      parent and child meshes overlap at the joint at every angle, by design: only the depth *added*
      relative to the home pose counts. Children without collision geometry are skipped, and so are
      prismatic joints: a child sliding into its parent is how telescopic lifts, sleeves and retracting
      poles are built (ARMAR-6's torso, R2-D2's gripper pole), which convex hulls cannot tell from a
      solid. At most
      MAX_SWEPT_JOINTS = 64 joints are swept, so a huge robot stays fast.""",
      fix="Fix the joint limits (the child should stop where it meets its parent) or the collision geometry "
          "(a convex hull of a concave part fills its hollow: split it or use a simpler shape).",
      bad=_swinging_arm(limit=3.1), good=_swinging_arm(limit=1.2), needs_sim=True,
      thresholds="Reported when the penetration depth at some step exceeds the depth at home by more than "
                 "max(MIN_NEW_DEPTH = 0.01 m, SIZE_FRACTION = 0.6 x the smaller part's size (the middle extent of "
                 "its bounding box)); SWEEP_STEPS = 13 per joint, MAX_SWEPT_JOINTS = 64.")
def sim_passes_through_parent(ctx) -> Iterator[Hit]:
    from ar3cli.sim.pass_through import pass_throughs

    with _loaded(ctx, self_collision="all-pairs") as body:  # else getClosestPoints skips a link and its parent
        if body is None or body.nonfinite_links():
            return
        try:
            found_all = list(pass_throughs(body))
        except UserError:
            return  # limits that cannot be sampled: F007 reports them
        for found in found_all:
            unit = "m" if found.joint.urdf_type == "prismatic" else "rad"
            yield Hit(f"moving joint '{found.joint.name}' to {found.value:.3g} {unit} sinks link '{found.child}' "
                      f"{depth_text(found.depth)} into its parent '{found.parent}' (at home: "
                      f"{depth_text(found.home_depth)}; threshold: {depth_text(found.threshold)} more)",
                      found.joint.urdf.element if found.joint.urdf else None)
