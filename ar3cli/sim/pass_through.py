"""P005's measurement: sweep each movable joint and measure how deep its child sinks into its parent.

PyBullet never tests a link against its direct parent for self-collision, and MoveIt calls the pair
adjacent, so a child that passes through its parent when its joint turns is invisible to every
other check. Parent and child meshes of real robots overlap at the joint at every angle (they are
designed touching), so what counts is the penetration *added* by moving the joint: the depth at a
sweep step minus the depth at the home pose.

The sweep: every driving joint in pybullet order (at most :data:`MAX_SWEPT_JOINTS`), at
:data:`SWEEP_STEPS` evenly spaced values over its range, limits included (continuous and unlimited
revolute joints over a full turn, prismatic joints not at all: :data:`TELESCOPES`), the other joints at
home, mimic joints following. At each step the child of the swept joint (and of each mimic joint
that follows it) is tested against its parent with ``getClosestPoints``. Links without collision
geometry are looked through (the parent is the nearest ancestor with geometry) and, as the child,
skipped.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from ar3cli.sim.adjacency import collision_links
from ar3cli.sim.sampling import joint_space

TELESCOPES = ("prismatic",)
"""Joint types not swept: a prismatic joint slides its child along its axis, and into its parent is how a
telescopic lift, a sleeve or a retracting pole is built (ARMAR-6's torso sinks 0.365 m into its platform's
column, R2-D2's gripper pole retracts into the body); convex hulls cannot tell a sleeve from a solid, so the
depth it adds says nothing about the robot."""
SWEEP_STEPS = 13
"""Values per joint, both limits included (a step of 30 degrees over a full turn)."""
MAX_SWEPT_JOINTS = 64
"""Driving joints swept, in pybullet order; the rest of a very large robot is not (bounded time)."""
MIN_NEW_DEPTH = 0.01
"""m: added penetration below this is never reported."""
SIZE_FRACTION = 0.6
"""Added penetration must also exceed this fraction of the smaller part's size (the middle extent of its
bounding box at home: a rod's thickness). Measured on 69 example-robot-data and 46 pybullet_data files: benign
cases (quadruped knees folded to their limit, convex hulls of vendor meshes, cartpole's pole lying in its
cart) add at most 0.49; parts that really pass through (r2d2's gripper pole, the humanoid's knees and elbows,
Solo's unlimited knees) 0.88 and more."""


@dataclass(frozen=True)
class PassThrough:
    """A joint whose child sinks ``depth`` m into its parent at ``value`` (rad or m), ``home_depth`` at home.

    ``threshold`` is the added depth the finding exceeds (:data:`MIN_NEW_DEPTH`, :data:`SIZE_FRACTION`).
    """

    joint: Any  # a sim.session.JointRecord
    parent: str
    child: str
    value: float
    depth: float
    home_depth: float
    threshold: float


def _geometric_parent(model: Any, link: str, solid: set[str]) -> str | None:
    """The nearest ancestor of ``link`` with collision geometry, looking through links without."""
    for joint in model.joints_above(link):
        if joint.parent and joint.parent != link and joint.parent in solid:
            return joint.parent  # (a loop back to ``link`` is no ancestor; other links seen again had none)
    return None


def _depth(body: Any, a: int, b: int) -> float:
    """How deep (m, >= 0) links ``a`` and ``b`` of ``body`` interpenetrate at the current pose."""
    p, client = body.session.p, body.session.client
    points = p.getClosestPoints(body.id, body.id, 0.0, linkIndexA=a, linkIndexB=b, physicsClientId=client)
    return max((-float(point[8]) for point in points), default=0.0)


def _size(body: Any, index: int) -> float:
    """A link's size: the middle extent of its axis-aligned box at the current pose."""
    low, high = body.session.p.getAABB(body.id, index, physicsClientId=body.session.client)
    return sorted(h - lo for h, lo in zip(high, low))[1]


def _sweep_values(lower: float, upper: float, continuous: bool) -> np.ndarray:
    """SWEEP_STEPS values over [lower, upper]; a full turn for continuous joints, 0 included, -pi and pi (one pose) not."""
    if continuous:
        return np.linspace(-math.pi, math.pi, SWEEP_STEPS, endpoint=False) + math.pi / SWEEP_STEPS
    return np.linspace(lower, upper, SWEEP_STEPS)


def pass_throughs(body: Any) -> Iterator[PassThrough]:
    """The worst sweep step of every checked joint whose child sinks into its parent beyond the threshold."""
    model = body.model
    solid = set(collision_links(model))
    space = joint_space(body)
    joints = body.actuated_joints
    pairs: dict[int, tuple[int, int, str, str]] = {}  # column -> (child index, parent index, child, parent)
    for column, joint in enumerate(joints):
        parent = _geometric_parent(model, joint.link_name, solid)
        if joint.link_name in solid and parent is not None and parent in body.link_index:
            pairs[column] = (body.link_index[joint.link_name], body.link_index[parent], joint.link_name, parent)
    if not pairs:
        return
    body.set_positions(list(space.home))
    home = {column: _depth(body, child, parent) for column, (child, parent, _, _) in pairs.items()}
    size = {column: min(_size(body, child), _size(body, parent)) for column, (child, parent, _, _) in pairs.items()}
    home_driving = space.home[list(space.driving)]
    for position, column in enumerate(space.driving[:MAX_SWEPT_JOINTS]):
        joint = joints[column]
        if joint.urdf_type in TELESCOPES:
            continue  # a slider into its parent is a telescope, a sleeve or a retracting pole
        driving = np.tile(home_driving, (SWEEP_STEPS, 1))
        driving[:, position] = _sweep_values(space.lower[position], space.upper[position], space.continuous[position])
        configurations = space.fill(driving)
        changed = np.flatnonzero(np.any(configurations != space.home, axis=0))  # the swept joint, its mimic joints
        worst: dict[int, tuple[float, float]] = {}
        for configuration in configurations:
            body.set_positions({joints[c].name: configuration[c] for c in changed})  # only these: the rest stay home
            for c in changed:
                if c in pairs:
                    depth = _depth(body, *pairs[c][:2])
                    if depth > worst.get(c, (-1.0, 0.0))[0]:
                        worst[c] = (depth, float(configuration[c]))
        body.set_positions({joints[c].name: space.home[c] for c in changed})
        for c, (depth, value) in worst.items():
            threshold = max(MIN_NEW_DEPTH, SIZE_FRACTION * size[c])
            if depth - home[c] > threshold:
                yield PassThrough(joints[c], pairs[c][3], pairs[c][2], value, depth, home[c], threshold)
