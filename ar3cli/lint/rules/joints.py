"""Joint rules (J): limits, efforts, velocities and axes as PyBullet and ROS read them."""

from __future__ import annotations

import math
from collections.abc import Iterator

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES as ACTUATED_TYPES

LIMITED_TYPES = ("revolute", "prismatic")
"""The types the URDF spec requires a <limit> with lower/upper on."""
DEGREE_THRESHOLD = 2 * math.pi + 0.01
"""A revolute limit beyond one full turn is almost always a value in degrees."""


@rule("J001", "limit-missing", "error", "Revolute or prismatic joint without <limit>",
      why="""The URDF spec requires <limit> on revolute and prismatic joints. PyBullet refuses the
      whole file ("Joint is of type REVOLUTE but it does not specify limits"), urdfdom too.""",
      fix='Add <limit lower="..." upper="..." effort="..." velocity="..."/> (radians, metres, N·m or N, rad/s or m/s).',
      bad=arm(joint_extra=""), good=arm())
def limit_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in LIMITED_TYPES and joint.limit is None:
            yield Hit(f"{joint.type} joint '{joint.name}' has no <limit>", joint.element)


@rule("J002", "limit-range-missing", "error", "<limit> without lower/upper on a revolute or prismatic joint",
      why="""Without lower/upper, urdfdom and ROS default both to 0 (the joint cannot move), while
      PyBullet reads (0, -1), i.e. unlimited: the same file means a locked joint in one tool and a
      free one in the other.""",
      fix="Give lower and upper explicitly, or make the joint continuous if it really has no stops.",
      bad=arm(joint_extra='<limit effort="10" velocity="1"/>'), good=arm())
def limit_range_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type in LIMITED_TYPES and limit is not None:
            missing = [key for key in ("lower", "upper") if limit.element.get(key) is None]
            if missing:
                yield Hit(f"{joint.type} joint '{joint.name}' <limit> has no {' or '.join(missing)} "
                          "(PyBullet: unlimited; ROS: 0)", limit.element)


@rule("J003", "limit-inverted", "error", "Joint lower limit greater than upper",
      why="""With lower > upper, PyBullet treats the joint as unlimited and MuJoCo disables the
      limit; samplers drawing uniform(lower, upper) fail or sample nonsense.""",
      fix="Swap lower and upper.",
      bad=arm(joint_extra='<limit lower="1" upper="-1" effort="10" velocity="1"/>'), good=arm())
def limit_inverted(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type in LIMITED_TYPES and limit and limit.lower is not None and limit.upper is not None \
                and limit.lower > limit.upper:
            yield Hit(f"joint '{joint.name}' lower {limit.lower:g} > upper {limit.upper:g}", limit.element)


@rule("J004", "limit-empty", "warning", "Moving joint with lower == upper",
      why="""A revolute or prismatic joint whose range is a single point cannot move: it is a fixed
      joint that costs a degree of freedom in every solver and planner.""",
      fix='Give the real range, or make it type="fixed".',
      bad=arm(joint_extra='<limit lower="0" upper="0" effort="10" velocity="1"/>'), good=arm())
def limit_empty(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type in LIMITED_TYPES and limit and limit.lower is not None and limit.lower == limit.upper \
                and limit.element.get("lower") is not None and limit.element.get("upper") is not None:
            yield Hit(f"joint '{joint.name}' has lower == upper == {limit.lower:g}: it cannot move", limit.element)


@rule("J005", "limit-degrees", "warning", "Revolute limits that look like degrees",
      why="""URDF angles are radians. A revolute limit beyond ±2π (one full turn) is almost always a
      value typed in degrees: 90 means 14 turns.""",
      fix="Convert to radians (degrees × π/180).",
      bad=arm(joint_extra='<limit lower="-90" upper="90" effort="10" velocity="1"/>'), good=arm())
def limit_degrees(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type != "revolute" or limit is None:
            continue
        values = [v for v in (limit.lower, limit.upper) if v is not None and math.isfinite(v)]
        if any(abs(v) > DEGREE_THRESHOLD for v in values):
            shown = ", ".join(f"{v:g}" for v in values)
            yield Hit(f"revolute joint '{joint.name}' limits ({shown}) exceed ±2π rad; degrees?", limit.element,
                      hint=f"In radians: {', '.join(f'{math.radians(v):.4f}' for v in values)}.")


@rule("J006", "continuous-with-range", "warning", "Continuous joint with lower/upper",
      why="""The URDF spec ignores lower/upper on continuous joints, and PyBullet never makes them
      a physical stop, but it does clamp POSITION_CONTROL targets to [lower, upper]. The popular
      lower="-100" upper="100" "fix" adds a clamp and fixes nothing; a real arm with hard stops
      should be revolute.""",
      fix="Remove lower/upper, or make the joint revolute with its real limits.",
      bad=arm(joint_type="continuous", joint_extra='<limit lower="-100" upper="100" effort="10" velocity="1"/>'),
      good=arm(joint_type="continuous", joint_extra='<limit effort="10" velocity="1"/>'))
def continuous_with_range(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type == "continuous" and limit is not None and (
                limit.element.get("lower") is not None or limit.element.get("upper") is not None):
            yield Hit(f"continuous joint '{joint.name}' has lower/upper "
                      f"({limit.element.get('lower')}, {limit.element.get('upper')}): ignored by the spec, "
                      "but PyBullet clamps position targets to them", limit.element)


@rule("J007", "effort-velocity-missing", "error", "<limit> without effort or velocity",
      why="""effort and velocity are required attributes of <limit>: urdfdom refuses the file, and
      PyBullet reads 0 (no force, no speed for controllers that use them).""",
      fix="Add effort (N·m or N) and velocity (rad/s or m/s) from the actuator's datasheet.",
      bad=arm(joint_extra='<limit lower="-1" upper="1"/>'), good=arm())
def effort_velocity_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.limit is None or joint.type not in ACTUATED_TYPES:
            continue
        missing = [key for key in ("effort", "velocity") if joint.limit.element.get(key) is None]
        if missing:
            yield Hit(f"joint '{joint.name}' <limit> has no {' or '.join(missing)}", joint.limit.element)


@rule("J008", "effort-velocity-zero", "warning", "Effort or velocity <= 0 on a moving joint",
      why="""effort and velocity are the actuator's limits. Zero means the joint can exert no force or
      cannot move: ros_control and MoveIt respect that, and controllers that take PyBullet's
      maxForce from the URDF cannot hold the arm against gravity.""",
      fix="Use the real actuator limits from the datasheet.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="0" velocity="0"/>'), good=arm())
def effort_velocity_zero(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.limit is None or joint.type not in ACTUATED_TYPES:
            continue
        bad = [f"{key}={value:g}" for key, value in (("effort", joint.limit.effort), ("velocity", joint.limit.velocity))
               if value is not None and value <= 0]
        if bad:
            yield Hit(f"joint '{joint.name}' has {' and '.join(bad)}", joint.limit.element)


@rule("J009", "axis-zero", "error", "Zero joint axis",
      why="""A moving joint needs a direction. With axis 0 0 0 PyBullet loads the file and every
      joint state becomes NaN on the first step; urdfdom and MuJoCo refuse it.""",
      fix='Set the axis to a unit vector, e.g. <axis xyz="0 0 1"/>.',
      bad=arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'), good=arm())
def axis_zero(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in ACTUATED_TYPES and joint.axis_given and all(c == 0 for c in joint.axis):
            yield Hit(f"joint '{joint.name}' axis is 0 0 0", joint.element.find("axis"))


@rule("J010", "axis-not-unit", "warning", "Joint axis is not a unit vector",
      why="""The spec says the axis is normalised; tools disagree on whether they normalise it
      (KDL does, some IK and Jacobian code does not), so a non-unit axis scales velocities in some
      tools only.""",
      fix="Normalise the axis (divide by its length).",
      bad=arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 2"/>'), good=arm())
def axis_not_unit(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type not in ACTUATED_TYPES or not joint.axis_given:
            continue
        norm = math.sqrt(sum(c * c for c in joint.axis))
        if norm > 0 and math.isfinite(norm) and abs(norm - 1.0) > 1e-3:
            unit = " ".join(f"{c / norm:.6g}" for c in joint.axis)
            yield Hit(f"joint '{joint.name}' axis has length {norm:.4g}", joint.element.find("axis"),
                      hint=f'Use <axis xyz="{unit}"/>.')


@rule("J011", "continuous-arm-joint", "warning", "Continuous joint without <limit> inside a chain",
      why="""A continuous joint with no <limit> at all that carries further moving joints is the
      signature of a CAD export: SolidWorks' sw_urdf_exporter writes every joint as continuous with
      no limits unless told otherwise. Arm joints almost always have hard stops; planners then
      wrap through them, and PyBullet reports effort 0 and velocity 0. Wheels and turntables at
      the end of a chain, and continuous joints that state effort/velocity, are not flagged.""",
      fix="Make it revolute with the real lower/upper/effort/velocity from the datasheet.",
      bad=robot(f"""
          <link name="base"/><link name="upper">{LINK_INERTIAL}</link><link name="fore">{LINK_INERTIAL}</link>
          <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/></joint>
          <joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/></joint>"""),
      good=robot(f"""
          <link name="base"/><link name="upper">{LINK_INERTIAL}</link><link name="fore">{LINK_INERTIAL}</link>
          <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
            <limit lower="-2.9" upper="2.9" effort="20" velocity="1"/></joint>
          <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/>
            <limit lower="-2" upper="2" effort="10" velocity="1"/></joint>"""))
def continuous_arm_joint(ctx) -> Iterator[Hit]:
    model = ctx.model
    for joint in model.joints:
        if joint.type != "continuous" or joint.limit is not None or not joint.child:
            continue
        downstream = _moving_descendants(model, joint.child)
        if downstream:
            yield Hit(f"continuous joint '{joint.name}' has no <limit> and carries {downstream} more moving joint"
                      f"{'s' if downstream != 1 else ''}: an arm joint with no stops, effort 0 and velocity 0 "
                      "in PyBullet", joint.element)


def _moving_descendants(model, link_name: str) -> int:
    """How many moving joints hang below ``link_name`` (cycles are S006's business: visited once)."""
    count, stack, seen = 0, [link_name], {link_name}
    while stack:
        for child in model.child_joints(stack.pop()):
            count += child.moves
            if child.child and child.child not in seen:
                seen.add(child.child)
                stack.append(child.child)
    return count


RULES = (limit_missing, limit_range_missing, limit_inverted, limit_empty, limit_degrees, continuous_with_range,
         effort_velocity_missing, effort_velocity_zero, axis_zero, axis_not_unit, continuous_arm_joint)
