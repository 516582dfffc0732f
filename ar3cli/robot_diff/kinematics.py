"""End-effector displacement: where NEW puts each leaf link against where OLD puts it, at the home
pose (every joint 0) and at ``samples`` random configurations of the joints both files share.

The forward kinematics is ar3cli's own (:mod:`ar3cli.kinematics.fk`), handed in by the command as
a :class:`ForwardKinematics` (feature packages do not import each other). The shared joints are the
corresponding 1-DOF joints that are not mimic joints; each is drawn uniformly (``default_rng(seed)``)
in the range both files allow (the overlap of the two ranges; a joint without usable limits turns
in [-pi, pi], or stays at 0 when prismatic); mimic joints follow their source in each file, the
other joints stay at 0.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any, Protocol

from ar3cli.errors import UserError
from ar3cli.robot_diff.joints import joint_deltas
from ar3cli.robot_diff.limits import mimic_deltas
from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import Displacement, finite_or_none
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Model


class ForwardKinematics(Protocol):
    """What the diff needs of :mod:`ar3cli.kinematics.fk` (that module satisfies it)."""

    def urdf_link_frames(self, model: Model, positions: Mapping[str, Any], count: int) -> dict[str, Any]: ...

    def pose_errors(self, frames_a: Any, frames_b: Any) -> tuple[Any, Any]: ...


def shared_ranges(pair: Pair) -> dict[str, tuple[str, float, float]]:
    """NEW joint name -> (OLD joint name, lower, upper) of every shared driving joint."""
    ranges: dict[str, tuple[str, float, float]] = {}
    for old_name, new_name in pair.matching.joints.items():
        old_joint, new_joint = pair.old.joint(old_name), pair.new.joint(new_name)
        if old_joint is None or new_joint is None or new_joint.mimic is not None or old_joint.mimic is not None:
            continue
        if old_joint.type not in ACTUATED_JOINT_TYPES or new_joint.type not in ACTUATED_JOINT_TYPES:
            continue
        ranges[new_name] = (old_name, *_range(old_joint, new_joint))
    return ranges


def _limits(joint: Joint) -> tuple[float, float] | None:
    limit = joint.limit
    if joint.type == "continuous" or limit is None or limit.lower is None or limit.upper is None:
        return None
    if not (math.isfinite(limit.lower) and math.isfinite(limit.upper)) or limit.lower > limit.upper:
        return None
    return limit.lower, limit.upper


def _range(old: Joint, new: Joint) -> tuple[float, float]:
    known = [limits for limits in (_limits(old), _limits(new)) if limits is not None]
    if len(known) == 2 and max(known[0][0], known[1][0]) <= min(known[0][1], known[1][1]):
        return max(known[0][0], known[1][0]), min(known[0][1], known[1][1])
    if known:
        return known[-1]
    return (0.0, 0.0) if new.type == "prismatic" else (-math.pi, math.pi)


def end_effectors(model: Model) -> list[str]:
    """The links whose displacement is reported, in file order: the leaves (links no joint starts
    from: tool, sensor and finger frames), and a leaf's parent when the leaf hangs on a moving joint
    (the hand or palm a gripper's fingers slide or turn on)."""
    parents = {joint.parent for joint in model.joints}
    leaves = {link.name for link in model.links if link.name not in parents}
    hands = {joint.parent for joint in model.joints if joint.child in leaves and joint.moves}
    return [link.name for link in model.links if link.name in leaves or link.name in hands]


def displacements(pair: Pair, fk: ForwardKinematics, samples: int, seed: int
                  ) -> tuple[list[Displacement], tuple[dict[str, Any], dict[str, Any]], list[str]]:
    """The leaf links that moved beyond the tolerance, OLD's and NEW's home link frames (for the
    total centre of mass) and notes on what could not be computed."""
    import numpy as np

    ranges = shared_ranges(pair)
    rng = np.random.default_rng(seed)
    count = samples + 1  # row 0 is the home pose
    values = {name: np.concatenate([[0.0], rng.uniform(low, high, samples)]) for name, (_, low, high) in ranges.items()}
    try:
        old_frames = fk.urdf_link_frames(pair.old, {ranges[n][0]: v for n, v in values.items()}, count)
        new_frames = fk.urdf_link_frames(pair.new, values, count)
    except UserError as exc:
        return [], ({}, {}), [f"kinematics not compared: {exc.message}"]
    moved: list[Displacement] = []
    tolerance = pair.tolerance
    for link in end_effectors(pair.new):
        old_link = pair.matching.old_link(link)
        if old_link is None or link not in new_frames or old_link not in old_frames:
            continue
        metres, radians = fk.pose_errors(old_frames[old_link], new_frames[link])
        sampled_m, sampled_rad = (metres[1:], radians[1:]) if samples else (metres, radians)
        if not (float(np.max(metres)) <= tolerance.length and float(np.max(radians)) <= tolerance.angle):
            file, line = pair.new_locator.locate(pair.new.link(link).element)  # type: ignore[union-attr]
            measures = [float(value) for value in (metres[0], radians[0], np.max(sampled_m), np.mean(sampled_m),
                                                   np.max(sampled_rad), np.mean(sampled_rad))]
            moved.append(Displacement(link, *map(finite_or_none, measures), cause(pair, link), file, line))  # type: ignore[arg-type]
    homes = ({name: frames[0] for name, frames in old_frames.items()},
             {name: frames[0] for name, frames in new_frames.items()})
    return moved, homes, []


def path_joints(model: Model, link: str) -> list[Joint]:
    """The joints from the root down to ``link`` (each link entered once, so a loop ends the walk)."""
    return list(model.joints_above(link))[::-1]


def cause(pair: Pair, link: str) -> str:
    """The first joint on NEW's path to ``link`` that was added or whose type, parent, child, origin
    or axis changed, as ``joint 'j2' origin``; a joint removed from OLD's path; else ``-`` (a mimic
    coupling or a change the sampled ranges do not show)."""
    for joint in path_joints(pair.new, link):
        old_name = pair.matching.old_joint(joint.name)
        old_joint = pair.old.joint(old_name) if old_name is not None else None
        if old_joint is None:
            return f"joint '{joint.name}' added"
        deltas = [delta.what for delta in joint_deltas(old_joint, joint, pair.tolerance, pair.matching.links)]
        if mimic_deltas(pair, old_joint, joint):
            deltas.append("mimic")
        if deltas:
            return f"joint '{joint.name}' " + ", ".join(deltas)
    old_link = pair.matching.old_link(link)
    for joint in path_joints(pair.old, old_link) if old_link else []:
        if joint.name not in pair.matching.joints:
            return f"joint '{joint.name}' removed"
    return "-"
