"""Where every link is at one joint configuration: the sliders a viewer gives a robot, the values of
its mimic joints, and the forward kinematics of one pose, drawing whatever the file says.

:func:`posing` answers once per analysis with a :class:`Posing`: one :class:`JointControl` per
1-DOF joint a user moves (revolute, continuous, prismatic; not a ``<mimic>`` follower), with its
range as every simulating command samples it (:mod:`ar3cli.urdf.home`: the URDF limits as PyBullet
reads them; continuous and unlimited revolute joints -pi..pi, unlimited prismatic -1..1) and its home
value (0, or mid-range where 0 is outside the limits); mimic joints follow their leader
(``multiplier * leader + offset``, chains followed).

The forward kinematics is :mod:`ar3cli.kinematics.fk`'s URDF convention (joint origin, then the
motion about the normalised axis) for one configuration, but tolerant, because a viewer must draw
the files lint refuses: a joint it cannot move (floating, planar, a zero or non-finite axis) is drawn
at its zero position, a non-finite origin as the identity, joints in a mimic cycle get sliders of
their own, every root link of a forest sits at the world origin, and a link reached twice (a loop)
is placed once. :attr:`Posing.notes` says what was drawn that way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Model

if TYPE_CHECKING:
    import numpy as np

Frames = dict[str, "np.ndarray"]
"""Link name -> its world frame, a 4x4 homogeneous transform."""


@dataclass(frozen=True)
class JointControl:
    """One joint a user moves: its range (``lower`` .. ``upper``) and home value."""

    name: str
    type: str
    lower: float
    upper: float
    home: float
    limited: bool
    """False for a continuous or unlimited joint: the range is the sampling range, not a limit."""

    def clamp(self, value: float) -> float:
        """``value`` within the range (a non-finite value is the home value)."""
        if not math.isfinite(value):
            return self.home
        return min(max(value, self.lower), self.upper)


@dataclass(frozen=True)
class _Step:
    """One joint of the walk: its child is placed at ``parent frame @ origin @ motion(value)``."""

    joint: str
    parent: str
    child: str
    origin: Any
    axis: Any
    """The unit axis (numpy), or None: the joint is drawn at its zero position."""
    prismatic: bool


@dataclass(frozen=True)
class Posing:
    """The posable robot: its controls, its mimic joints and the joint walk of its kinematic tree."""

    controls: list[JointControl]
    followers: dict[str, tuple[str, float, float]]
    """Mimic joint -> (the joint it follows, multiplier, offset)."""
    roots: list[str]
    steps: list[_Step] = field(repr=False)
    notes: list[str] = field(default_factory=list)
    """What is drawn differently from what the file asks, and why (one line each)."""

    @property
    def control_names(self) -> list[str]:
        return [control.name for control in self.controls]

    def control(self, name: str) -> JointControl | None:
        return next((control for control in self.controls if control.name == name), None)

    def home(self) -> dict[str, float]:
        """Every control at its home value."""
        return {control.name: control.home for control in self.controls}

    def random(self, rng: np.random.Generator) -> dict[str, float]:
        """Every control drawn uniformly in its range, in control order (one draw per control)."""
        draws = rng.uniform([c.lower for c in self.controls], [c.upper for c in self.controls])
        return {control.name: float(value) for control, value in zip(self.controls, draws)}

    def kept(self, earlier: Mapping[str, float]) -> dict[str, float]:
        """The home pose with the values of ``earlier`` (a pose of another load of the robot) for
        the controls it names, clamped to their range now: a reload keeps the sliders by name."""
        values = self.home()
        for control in self.controls:
            if control.name in earlier:
                values[control.name] = control.clamp(float(earlier[control.name]))
        return values

    def joint_values(self, values: Mapping[str, float]) -> dict[str, float]:
        """Every joint's value: the controls from ``values`` (clamped; missing ones at home), the
        mimic joints computed from their leaders."""
        result = {control.name: control.clamp(float(values.get(control.name, control.home)))
                  for control in self.controls}
        for name in self.followers:
            self._follow(name, result)
        return result

    def _follow(self, name: str, result: dict[str, float]) -> float:
        if name in result:
            return result[name]
        chain: list[str] = []
        while name in self.followers and name not in result:  # a chain (no cycles: posing() broke them)
            chain.append(name)
            name = self.followers[name][0]
        value = result.get(name, 0.0)
        for follower in reversed(chain):
            _, multiplier, offset = self.followers[follower]
            value = multiplier * value + offset
            result[follower] = value
        return value

    def frames(self, values: Mapping[str, float]) -> Frames:
        """The world frame of every link reached from a root at the configuration ``values`` (the
        controls' values by name; see :meth:`joint_values`)."""
        import numpy as np

        from ar3cli.kinematics.fk import axis_rotations

        joints = self.joint_values(values)
        frames: Frames = {root: np.eye(4) for root in self.roots}
        for step in self.steps:
            frame = frames[step.parent] @ step.origin
            value = joints.get(step.joint, 0.0)
            if step.axis is not None and value != 0.0:
                if step.prismatic:
                    motion = np.eye(4)
                    motion[:3, 3] = step.axis * value
                else:
                    motion = axis_rotations(step.axis, np.array([value]))[0]
                frame = frame @ motion
            frames[step.child] = frame
        return frames


@question
def posing(analysis: RobotAnalysis) -> Posing:
    """The controls, the mimic joints and the joint walk of the analysed robot."""
    return build_posing(analysis.require_model())


def build_posing(model: Model) -> Posing:
    """:func:`posing` for a model."""
    from ar3cli.urdf.home import home_value, pybullet_limits, sample_range

    notes: list[str] = []
    movable = [joint for joint in model.joints if joint.type in ACTUATED_JOINT_TYPES]
    axes = {joint.name: _unit_axis(joint) for joint in movable}
    for joint in movable:
        if axes[joint.name] is None:
            notes.append(f"joint {joint.name} is drawn still: its axis {_numbers(joint.axis)} has no direction")
    followers = _followers(model, movable, notes)
    controls = []
    for joint in movable:
        if joint.name in followers or axes[joint.name] is None:
            continue
        lower, upper = pybullet_limits(joint)
        low, high = sample_range(joint.type, lower, upper)
        controls.append(JointControl(joint.name, joint.type, low, high, home_value(low, high),
                                     limited=lower is not None and upper is not None))
    steps, roots = _walk(model, axes, notes)
    return Posing(controls, followers, roots, steps, notes)


def _unit_axis(joint: Joint):
    """The joint's normalised axis (numpy), None when it has no direction."""
    import numpy as np

    axis = np.asarray(joint.axis, dtype=float)
    norm = float(np.linalg.norm(axis))
    return axis / norm if math.isfinite(norm) and norm > 0.0 else None


def _followers(model: Model, movable: list[Joint], notes: list[str]) -> dict[str, tuple[str, float, float]]:
    """Mimic joint -> (leader, multiplier, offset) for the mimic joints that can follow: their leader
    is a 1-DOF joint and no chain comes back to them (the joints of a cycle get sliders of their own)."""
    names = {joint.name for joint in movable}
    wanted = {joint.name: (joint.mimic.joint, joint.mimic.multiplier, joint.mimic.offset) for joint in movable
              if joint.mimic is not None and joint.mimic.joint in names and joint.mimic.joint != joint.name
              and math.isfinite(joint.mimic.multiplier) and math.isfinite(joint.mimic.offset)}
    in_cycle: set[str] = set()
    for start in wanted:
        seen = [start]
        name = wanted[start][0]
        while name in wanted and name not in seen:
            seen.append(name)
            name = wanted[name][0]
        if name == start:
            in_cycle.add(start)
    if in_cycle:
        notes.append(f"mimic joints {', '.join(sorted(in_cycle))} form a cycle: each gets a slider of its own")
    return {name: leader for name, leader in wanted.items() if name not in in_cycle}


def _walk(model: Model, axes: Mapping[str, Any], notes: list[str]) -> tuple[list[_Step], list[str]]:
    """The joints in parent-before-child order from every root link, each link placed once."""
    import numpy as np

    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        if joint.parent is not None and joint.child is not None:
            children.setdefault(joint.parent, []).append(joint)
    roots = [link.name for link in model.root_links()]
    if len(roots) > 1:
        notes.append(f"{len(roots)} root links ({', '.join(roots[:4])}{', ...' if len(roots) > 4 else ''}): "
                     "each is drawn at the world origin")
    placed = set(roots)
    steps: list[_Step] = []
    stack = list(reversed(roots))
    while stack:
        link = stack.pop()
        for joint in reversed(children.get(link, [])):
            if joint.child in placed:
                continue
            placed.add(joint.child)  # type: ignore[arg-type]
            origin = np.eye(4)
            origin[:3, :3] = joint.origin.rotation
            origin[:3, 3] = joint.origin.xyz
            if not np.isfinite(origin).all():
                notes.append(f"joint {joint.name}'s origin is not finite: drawn at its parent's frame")
                origin = np.eye(4)
            moving = joint.type in ACTUATED_JOINT_TYPES
            if joint.type not in (*ACTUATED_JOINT_TYPES, "fixed"):
                notes.append(f"joint {joint.name} is {joint.type}: drawn at its zero position")
            steps.append(_Step(joint.name, link, joint.child, origin,  # type: ignore[arg-type]
                               axes.get(joint.name) if moving else None, joint.type == "prismatic"))
            stack.append(joint.child)  # type: ignore[arg-type]
    unplaced = [link.name for link in model.links if link.name not in placed]
    if unplaced:
        notes.append(f"{len(unplaced)} link(s) not reached from a root link (a loop?): "
                     f"{', '.join(unplaced[:4])}{', ...' if len(unplaced) > 4 else ''} not drawn")
    return steps, roots


def _numbers(values) -> str:
    return " ".join(f"{value:g}" for value in values)
