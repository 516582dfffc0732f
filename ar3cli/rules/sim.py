"""Simulation rules (P, only with ``--sim``): load the model in PyBullet and see what it really does.

Each rule loads the model in the file's shared :class:`~ar3cli.sim.Session` (``ctx.session``),
checks one thing and removes the body again, so the rules are independent of each other.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager

from ar3cli.errors import UserError
from ar3cli.rules.base import LINK_INERTIAL, Hit, arm, robot, rule

PENETRATION_TOLERANCE = 5e-4
"""Contacts shallower than this (m) are touching surfaces, not a collision worth reporting."""
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
        body = session.load(ctx.model, **load_options)
    except UserError:
        yield None
        return
    try:
        yield body
    finally:
        session.p.removeBody(body.id, physicsClientId=session.client)


def _home(body) -> dict[str, float]:
    return {joint.name: joint.home() for joint in body.movable_joints}


@rule("P001", "sim-load-failed", "error", "PyBullet cannot load the model",
      why="""What matters in the end is whether the simulator accepts the file. PyBullet's own error is
      "Cannot load URDF file."; ar3cli captures its C output and reports the real reason (a missing
      mesh, a joint without limits, ...).""",
      fix="Fix the reason quoted in the message (often a G001 or J001 finding).",
      bad=arm(joint_extra=""), good=arm(), needs_sim=True)
def sim_load_failed(ctx) -> Iterator[Hit]:
    try:
        body = ctx.session.load(ctx.model)
    except UserError as exc:
        yield Hit(exc.message.removeprefix(f"{ctx.model.path}: "), ctx.model.root)
        return
    ctx.session.p.removeBody(body.id, physicsClientId=ctx.session.client)


@rule("P002", "sim-self-collision-home", "warning", "Links collide at the home pose",
      why="""Two links that are not parent and child but interpenetrate at the home pose (all joints at
      0, or mid-range where 0 is outside the limits) mean overlapping collision meshes or a wrong
      joint origin. With self-collision on, PyBullet pushes them apart the moment the simulation
      starts; planners see the start state as invalid.""",
      fix="Fix the collision geometry or the joint origin; if the overlap is by design, disable the pair "
          "(SRDF / setCollisionFilterPair).",
      bad=robot(f"""
          <link name="base">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <link name="mid">{LINK_INERTIAL}</link>
          <link name="tip">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/><origin xyz="0 0 0.05"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/><origin xyz="0 0 0.05"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"""),
      good=robot(f"""
          <link name="base">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <link name="mid">{LINK_INERTIAL}</link>
          <link name="tip">{LINK_INERTIAL}<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/><origin xyz="0 0 0.2"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/><origin xyz="0 0 0.2"/>
            <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"""),
      needs_sim=True)
def sim_self_collision_home(ctx) -> Iterator[Hit]:
    adjacent = {frozenset((j.parent, j.child)) for j in ctx.model.joints}
    with _loaded(ctx, self_collision="all-pairs") as body:
        if body is None:
            return
        body.set_positions(_home(body))
        for a, b, depth in body.contacts():
            if frozenset((a, b)) in adjacent or depth > -PENETRATION_TOLERANCE:
                continue
            link = ctx.model.link(b) or ctx.model.link(a)
            yield Hit(f"links '{a}' and '{b}' interpenetrate by {-depth * 1000:.1f} mm at the home pose",
                      link.element if link else None)


@rule("P003", "sim-inertia-differs", "info", "PyBullet uses a different mass or inertia than the file",
      why="""By default (no URDF_USE_INERTIA_FROM_FILE flag) PyBullet keeps the file's mass but
      recomputes every inertia tensor from the collision shape's bounding box, padded by the
      collision margin. Code that loads with default flags simulates these values, not the file's.""",
      fix="Load with flags=p.URDF_USE_INERTIA_FROM_FILE, or make the file's tensor match the geometry.",
      bad=arm(link_extra=LINK_INERTIAL + '<collision><geometry><box size="0.1 0.1 1"/></geometry></collision>'),
      good=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.08378" ixy="0" ixz="0" iyy="0.08378" iyz="0" '
                          'izz="0.001768"/></inertial><collision><geometry><box size="0.1 0.1 1"/></geometry></collision>'),
      needs_sim=True)
def sim_inertia_differs(ctx) -> Iterator[Hit]:
    from ar3cli.rules.inertia import _finite, _moments

    session = ctx.session
    p = session.p
    with _loaded(ctx, fixed_base=False, flags=p.URDF_MAINTAIN_LINK_ORDER) as body:
        if body is None:
            return
        for link in ctx.model.links:
            inertial = link.inertial
            index = body.link_index.get(link.name)
            if index is None or inertial is None or not _finite(inertial.tensor) or not (inertial.mass or 0) > 0:
                continue
            info = p.getDynamicsInfo(body.id, index, physicsClientId=session.client)
            used_mass, used = float(info[0]), sorted(float(v) for v in info[2])
            file_moments = sorted(float(m) for m in _moments(inertial.tensor))
            parts = []
            if _differs(used_mass, inertial.mass):
                parts.append(f"mass {inertial.mass:.4g} kg in the file, {used_mass:.4g} kg in PyBullet")
            if any(_differs(u, f) for u, f in zip(used, file_moments)):
                parts.append("principal moments " + "(" + ", ".join(f"{m:.3g}" for m in file_moments) + ") in the file, "
                             + "(" + ", ".join(f"{m:.3g}" for m in used) + ") used by PyBullet's default load")
            if parts:
                yield Hit(f"link '{link.name}': " + "; ".join(parts), inertial.element)


def _differs(used: float, declared: float) -> bool:
    scale = max(abs(used), abs(declared))
    return scale > 0 and abs(used - declared) > INERTIA_TOLERANCE * scale


@rule("P004", "sim-unstable", "error", "NaN or exploding states after settling under gravity",
      why="""ar3cli loads the model (fixed base, inertia from the file), puts it at the home pose,
      turns off PyBullet's default joint motors and simulates one second under gravity. A real
      robot falls limp; NaN positions or joint speeds above 100 rad/s mean an unphysical inertia,
      a zero axis or a degenerate mass.""",
      fix="Look at the I and J findings for this file (inertia, mass, axis); fix-inertia often cures it.",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/>'
                         '</inertial>').replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'),
      good=arm(), needs_sim=True)
def sim_unstable(ctx) -> Iterator[Hit]:
    session = ctx.session
    p = session.p
    with _loaded(ctx) as body:
        if body is None or not body.movable_joints:
            return
        p.setGravity(0, 0, -9.81, physicsClientId=session.client)
        body.set_positions(_home(body))
        body.release_motors()
        session.step(SETTLE_STEPS)
        indices = [joint.index for joint in body.movable_joints]
        states = p.getJointStates(body.id, indices, physicsClientId=session.client)
        for joint, state in zip(body.movable_joints, states):
            position, velocity = float(state[0]), float(state[1])
            if not (math.isfinite(position) and math.isfinite(velocity)):
                yield Hit(f"joint '{joint.name}' state is NaN/inf after {SETTLE_STEPS} steps under gravity",
                          joint.urdf.element if joint.urdf else None)
            elif abs(velocity) > MAX_SETTLE_SPEED:
                yield Hit(f"joint '{joint.name}' moves at {velocity:.3g} after {SETTLE_STEPS} steps under gravity",
                          joint.urdf.element if joint.urdf else None)


RULES = (sim_load_failed, sim_self_collision_home, sim_inertia_differs, sim_unstable)
