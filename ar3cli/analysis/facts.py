"""What the robot is made of: ``info``'s summary, the gravity torque check, the home pose, and the
facts about one link or joint an editor's hover or a viewer's panel shows.

The summary's centre of mass and bounding box need link frames at the zero configuration; the
info feature cannot compute them itself (features never import each other), so this layer hands
it the URDF forward kinematics of :mod:`ar3cli.kinematics.fk`, as ``ar3cli info`` does.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.errors import UserError

if TYPE_CHECKING:
    from ar3cli.info.summary import JointInfo, LinkInfo, Summary
    from ar3cli.info.torques import TorqueCheck

MOVED_SHOWN = 6
"""Joints a home-pose line names before it counts the rest."""


@question
def summary(analysis: RobotAnalysis) -> Summary:
    """``info``'s summary: tree, joints, DOF, masses, centre of mass and box at the zero configuration,
    meshes; computed in a child with the limits of every child (a file built to make it take hours or
    gigabytes is one line), as ``ar3cli info`` does."""
    from ar3cli.info.summary import summarize
    from ar3cli.infra.isolation import run_limited
    from ar3cli.kinematics.fk import urdf_link_frames

    def zero_frames(model):
        return {link: frames[0] for link, frames in urdf_link_frames(model, {}, 1).items()}

    model = analysis.require_model()
    return run_limited(lambda: summarize(model, zero_frames), analysis.shown_path, "summarising it")


@question
def torques(analysis: RobotAnalysis) -> TorqueCheck:
    """``info --torques``: each actuated joint's largest gravity torque against its effort (pybullet, in a child)."""
    from ar3cli.info.torques import gravity_torques

    return gravity_torques(analysis.require_model(), analysis.settings.samples, analysis.settings.seed)


@dataclass(frozen=True)
class HomePose:
    """Where every 1-DOF joint is at home (:mod:`ar3cli.urdf.home`: 0, or mid-range where 0 is outside
    the limits, mimic joints following), and the joints that are not at 0 with why."""

    values: dict[str, float]
    away_from_zero: dict[str, str] = field(default_factory=dict)
    """joint -> why it is not at 0 (``0 is outside [0.01, 0.04]``, ``follows finger_1``)."""

    @property
    def all_zero(self) -> bool:
        return not self.away_from_zero

    def line(self) -> str:
        """One line for people: ``every joint at 0``, or the joints that are not and why."""
        if self.all_zero:
            return "home pose: every joint at 0"
        moved = [f"{name} = {self.values[name]:.4g} ({why})" for name, why in self.away_from_zero.items()]
        shown = "; ".join(moved[:MOVED_SHOWN]) + (f"; and {len(moved) - MOVED_SHOWN} more" if len(moved) > MOVED_SHOWN
                                                  else "")
        return f"home pose is not all zeros: {shown}"

    def to_dict(self) -> dict[str, Any]:
        return {"values": self.values, "away_from_zero": self.away_from_zero, "all_zero": self.all_zero}


@question
def home_pose(analysis: RobotAnalysis) -> HomePose:
    """The pose the pictures, the collision matrix and the simulated lint start from."""
    from ar3cli.urdf.home import home_pose as computed
    from ar3cli.urdf.home import pybullet_limits

    model = analysis.require_model()
    values = computed(model)
    away: dict[str, str] = {}
    for name, value in values.items():
        if value == 0.0:
            continue
        joint = model.joint(name)
        if joint is not None and joint.mimic is not None and model.joint(joint.mimic.joint) is not None:
            away[name] = f"follows {joint.mimic.joint}"
        else:
            lower, upper = pybullet_limits(joint) if joint is not None else (None, None)
            away[name] = f"0 is outside [{lower:.4g}, {upper:.4g}]" if lower is not None and upper is not None \
                else "mid-range"
    return HomePose(values, away)


@dataclass(frozen=True)
class LinkFacts:
    """One link as a hover shows it: its info entry, the joint above it and those below it."""

    info: LinkInfo
    parent: JointInfo | None
    children: list[JointInfo]

    def lines(self) -> list[str]:
        from ar3cli.info.presentation import joint_label

        info = self.info
        mass = f"{info.mass:.4g} kg" if info.mass is not None else f"no mass ({info.mass_note})"
        lines = [f"link {info.name}: {mass}"]
        if self.parent is not None:
            lines.append(f"parent: {self.parent.parent} via {joint_label(self.parent)}")
        else:
            lines.append("root link (no parent joint)")
        if self.children:
            lines.append("children: " + "; ".join(f"{joint.child} via {joint.name} ({joint.type})"
                                                  for joint in self.children))
        if info.centre_of_mass is not None:
            lines.append("centre of mass at zero: (" + ", ".join(f"{v:.4f}" for v in info.centre_of_mass) + ") m")
        return lines

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.info.to_dict(), "parent_joint": self.parent.to_dict() if self.parent else None,
                "child_joints": [joint.to_dict() for joint in self.children]}


@dataclass(frozen=True)
class JointFacts:
    """One joint as a hover shows it: its info entry (type, parent, child, axis, limits, mimic) and home value."""

    info: JointInfo
    home: float | None

    def lines(self) -> list[str]:
        from ar3cli.info.presentation import joint_label

        info = self.info
        lines = [f"joint {joint_label(info)}", f"{info.parent} -> {info.child}"]
        if info.effort is not None or info.velocity is not None:
            lines.append(f"effort {info.effort if info.effort is not None else '-'}, "
                         f"velocity {info.velocity if info.velocity is not None else '-'}")
        if self.home is not None and self.home != 0.0:
            lines.append(f"home {self.home:.4g}")
        return lines

    def to_dict(self) -> dict[str, Any]:
        return {"joint": self.info.to_dict(), "home": self.home}


def link_facts(analysis: RobotAnalysis, name: str) -> LinkFacts | None:
    """The link named ``name`` (the first of that name), None when there is none or the file did not load."""
    if analysis.model is None:
        return None
    links, joints = _index(analysis)
    info = links.get(name)
    if info is None:
        return None
    return LinkFacts(info, joints.get(info.parent_joint) if info.parent_joint else None,
                     [joints[joint] for joint in info.child_joints if joint in joints])


def joint_facts(analysis: RobotAnalysis, name: str) -> JointFacts | None:
    """The joint named ``name`` (the first of that name), None when there is none or the file did not load."""
    if analysis.model is None:
        return None
    info = _index(analysis)[1].get(name)
    if info is None:
        return None
    try:
        home = home_pose(analysis).values.get(name)
    except UserError:  # a mimic cycle: the hover still shows the rest
        home = None
    return JointFacts(info, home)


@question
def _index(analysis: RobotAnalysis) -> tuple[dict[str, LinkInfo], dict[str, JointInfo]]:
    found = summary(analysis)
    return ({link.name: link for link in reversed(found.links)},
            {joint.name: joint for joint in reversed(found.joints)})
