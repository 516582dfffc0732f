"""Joint rules (J): limits, efforts, velocities and axes as PyBullet and ROS read them."""

from __future__ import annotations

import math
from collections.abc import Iterator

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES as ACTUATED_TYPES

LIMITED_TYPES = ("revolute", "prismatic")
"""The types the URDF spec requires a <limit> with lower/upper on."""
RADIAN_PLAUSIBLE = 4 * math.pi
"""rad: multi-turn joints have real limits up to two turns each way (±3π on ANYmal, ±10 on Solo and
Bolt, (-3.05, 6.81) on TIAGo's hand, ±6.3 on many wrists): a limit within ±4π is taken as radians."""
DEGREE_PLAUSIBLE = 720.0
"""A degree limit beyond two turns each way is not a typed angle (±1e16 is "unlimited")."""
DEGREE_STEP = 5.0
"""Angles typed in degrees are round: 90, 135, 170, 180, 270, 360 are multiples of 5."""
DUMMY_MASS = 1e-3
"""kg: a link without geometry and at most this mass is a dummy of a virtual chain (massless frames
written by fix-inertia weigh 1e-6 kg)."""
PYBULLET_UNLIMITED = frozenset({(1.0, -1.0), (0.0, -1.0)})
"""(lower, upper) pairs written on purpose to mean "no limit" in PyBullet: pybullet_data's
lower="1" upper="-1" (cube_no_rotation.urdf, biped2d_pybullet.urdf) and (0, -1), what getJointInfo
itself reports for an unlimited joint. PyBullet reads any lower > upper as unlimited."""
WHEEL_LIKE = ("wheel", "caster", "castor", "roller", "rotor", "propeller", "prop_", "tire", "tyre", "track",
              "gear", "pulley", "spinner")
"""Name fragments of links that spin without stops by design (J011)."""


@rule("J001", "limit-missing", "error", "Revolute or prismatic joint without <limit>",
      refused_by=("pybullet", "ros"),
      breaks='PyBullet and urdfdom refuse the file ("Joint is of type REVOLUTE but it does not specify limits").',
      why="""The URDF spec requires <limit> on revolute and prismatic joints. PyBullet refuses the
      whole file ("Joint is of type REVOLUTE but it does not specify limits"), urdfdom too.""",
      fix='Add <limit lower="..." upper="..." effort="..." velocity="..."/> (radians, metres, N·m or N, rad/s or m/s).',
      bad=arm(joint_extra=""), good=arm())
def limit_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in LIMITED_TYPES and joint.limit is None:
            yield Hit(f"{joint.type} joint '{joint.name}' has no <limit>", joint.element)


@rule("J002", "limit-range-missing", "error", "<limit> without lower/upper on a revolute or prismatic joint",
      engines=("ros", "pybullet"),
      breaks="ROS tools lock the joint at 0 while PyBullet leaves it unlimited, or holds it in a range that "
             "excludes 0 (measured): one file, two different robots.",
      why="""The URDF spec defaults a missing lower or upper to 0, and urdfdom (ROS, MoveIt), MuJoCo and
      PyBullet's lower follow it; PyBullet's missing upper is -1 instead (measured with pybullet 3.2.7,
      getJointInfo and torque-driven motion). So what the joint becomes depends on which bound is missing.
      Neither: urdfdom reads 0..0 (the joint cannot move), PyBullet (0, -1), i.e. unlimited. Only lower:
      urdfdom reads lower..0; PyBullet reads lower..-1, which is unlimited when lower > -1 and otherwise a
      range that excludes 0 (the home pose is outside it, and a position target of 0 is driven to -1).
      Only upper: every tool reads 0..upper, the spec's meaning, which is not reported; an upper below 0
      puts the default lower above it (PyBullet: unlimited, urdfdom: an empty range).""",
      fix="Give lower and upper explicitly, or make the joint continuous if it really has no stops.",
      bad=arm(joint_extra='<limit effort="10" velocity="1"/>'),
      good=arm(joint_extra='<limit upper="0.04" effort="10" velocity="1"/>'),
      references="URDF spec (wiki.ros.org/urdf/XML/joint: lower and upper default to 0); PyBullet UrdfParser.cpp "
                 "parseJointLimits (upper defaults to -1); measured with pybullet 3.2.7 and MuJoCo 4.0.")
def limit_range_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type in LIMITED_TYPES and limit is not None:
            message = _one_sided_limit(joint)
            if message is not None:
                yield Hit(f"{joint.type} joint '{joint.name}' <limit> {message}", limit.element)


def _one_sided_limit(joint) -> str | None:
    """What each tool makes of a <limit> missing a bound (J002), or None when they all agree."""
    limit = joint.limit
    has_lower, has_upper = limit.element.get("lower") is not None, limit.element.get("upper") is not None
    if has_lower and has_upper:
        return None
    if not has_lower and not has_upper:
        return "has no lower or upper: PyBullet reads (0, -1), i.e. unlimited; urdfdom and MuJoCo read 0..0, a locked joint"
    if has_upper:
        upper = limit.upper
        if upper is None or not math.isfinite(upper) or upper >= 0:
            return None  # every tool reads 0..upper (a malformed number is F007's)
        return (f"has upper {upper:g} and no lower: the default lower 0 is above it, so PyBullet leaves the joint "
                "unlimited and urdfdom reads an empty range")
    lower = limit.lower
    if lower is None or not math.isfinite(lower):
        return None
    ros = f"urdfdom and MuJoCo read {lower:g}..0" if lower <= 0 else f"urdfdom reads an empty range {lower:g}..0"
    if lower > -1:
        return f"has lower {lower:g} and no upper: PyBullet reads upper -1, below lower, i.e. unlimited; {ros}"
    return (f"has lower {lower:g} and no upper: PyBullet reads upper -1, so its range {lower:g}..-1 excludes 0 "
            f"(a position target of 0 is driven to -1); {ros}")


@rule("J003", "limit-inverted", "error", "Joint lower limit greater than upper",
      breaks="PyBullet treats the joint as unlimited and MuJoCo disables the limit: the stops are gone.",
      why="""With lower > upper, PyBullet treats the joint as unlimited and MuJoCo disables the
      limit; samplers drawing uniform(lower, upper) fail or sample nonsense. PyBullet's deliberate
      "no limit" idiom (lower="1" upper="-1" as in pybullet_data, or lower="0" upper="-1") is not
      reported here: J014 explains it instead, and fix-joints leaves it alone.""",
      fix="Swap lower and upper.",
      bad=arm(joint_extra='<limit lower="1.5" upper="-1.5" effort="10" velocity="1"/>'), good=arm(),
      thresholds="Not reported for the (lower, upper) pairs of PYBULLET_UNLIMITED: (1, -1) and (0, -1).",
      fixed_by="fix-joints")
def limit_inverted(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if _inverted(joint) and not _pybullet_unlimited_idiom(joint):
            yield Hit(f"joint '{joint.name}' lower {limit.lower:g} > upper {limit.upper:g}", limit.element)


def _inverted(joint) -> bool:
    """A revolute or prismatic joint whose lower limit is above its upper one."""
    limit = joint.limit
    return joint.type in LIMITED_TYPES and limit is not None and limit.lower is not None \
        and limit.upper is not None and limit.lower > limit.upper


def _pybullet_unlimited_idiom(joint) -> bool:
    """lower > upper with exactly one of the PYBULLET_UNLIMITED pairs: "no limit" written on purpose."""
    return _inverted(joint) and (joint.limit.lower, joint.limit.upper) in PYBULLET_UNLIMITED


@rule("J004", "limit-empty", "warning", "Moving joint with lower == upper",
      why="""A revolute or prismatic joint whose range is a single point cannot move: it is a fixed
      joint that costs a degree of freedom in every solver and planner.""",
      fix='Give the real range, or make it type="fixed".',
      bad=arm(joint_extra='<limit lower="0" upper="0" effort="10" velocity="1"/>'), good=arm())
def limit_empty(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if _cannot_move(joint):
            limit = joint.limit
            zeros = [f"{key}={value:g}" for key, value in (("effort", limit.effort), ("velocity", limit.velocity))
                     if value is not None and value <= 0]
            also = f" (and {' and '.join(zeros)})" if zeros and joint.mimic is None else ""
            yield Hit(f"joint '{joint.name}' has lower == upper == {limit.lower:g}{also}: it cannot move",
                      limit.element)


def _cannot_move(joint) -> bool:
    """A revolute or prismatic joint whose lower and upper limits are written and equal (J004)."""
    limit = joint.limit
    return joint.type in LIMITED_TYPES and limit is not None and limit.lower is not None \
        and limit.lower == limit.upper and limit.element.get("lower") is not None \
        and limit.element.get("upper") is not None


def _looks_like_degrees(value: float) -> bool:
    """Implausible as radians (beyond ±4π) and plausible as typed degrees (a multiple of 5 up to 720)."""
    magnitude = abs(value)
    if not RADIAN_PLAUSIBLE < magnitude <= DEGREE_PLAUSIBLE:
        return False
    return abs(magnitude / DEGREE_STEP - round(magnitude / DEGREE_STEP)) < 1e-9


@rule("J005", "limit-degrees", "warning", "Revolute limits that look like degrees",
      why="""URDF angles are radians. A revolute limit of 90 or 180 is almost always a value typed in
      degrees: 90 rad is 14 turns. Multi-turn joints legitimately go beyond ±2π (±3π, ±10, -3.05 to
      6.81 are real radian limits), so only values that cannot be radians for a robot joint
      (beyond ±4π) and look like typed degrees (a round number up to 720) are reported.
      The virtual joints of a floating base (a hand or gripper moved by 3 prismatic + 3 revolute
      joints through dummy links) are not: they often share one "large enough" range such as ±20
      between the prismatic joints (metres) and the revolute ones, which is no typed angle. A
      revolute joint is taken as virtual when a prismatic joint of the same chain of geometry-less
      links has the very same lower/upper, or when every link from the root down to its parent is
      a massless dummy (no geometry, mass at most DUMMY_MASS) with a moving joint among them.""",
      fix="Convert to radians (degrees × π/180).",
      bad=arm(joint_extra='<limit lower="-90" upper="90" effort="10" velocity="1"/>'),
      good=arm(joint_extra='<limit lower="-9.42478" upper="9.42478" effort="10" velocity="1"/>'),
      thresholds="A value v is reported when RADIAN_PLAUSIBLE = 4π < |v| <= DEGREE_PLAUSIBLE = 720 and v is a "
                 "multiple of DEGREE_STEP = 5; dummy links weigh at most DUMMY_MASS = 1e-3 kg.",
      fixed_by="fix-joints")
def limit_degrees(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type != "revolute" or limit is None:
            continue
        values = [v for v in (limit.lower, limit.upper) if v is not None and math.isfinite(v)]
        if any(map(_looks_like_degrees, values)) and virtual_base_evidence(ctx.model, joint) is None:
            shown = ", ".join(f"{v:g}" for v in values)
            yield Hit(f"revolute joint '{joint.name}' limits ({shown}) look like degrees: {max(map(abs, values)):g} rad "
                      f"is {max(map(abs, values)) / (2 * math.pi):.0f} turns", limit.element,
                      hint=f"In radians: {', '.join(f'{math.radians(v):.4f}' for v in values)}.")


def _dummy(link, massless: bool) -> bool:
    """A link with no geometry (and, when ``massless``, no mass above DUMMY_MASS): a frame of a virtual chain."""
    if link is None or link.has_geometry:
        return False
    mass = link.inertial.mass if link.inertial is not None else None
    return not massless or mass is None or not mass > DUMMY_MASS


def _virtual_chain(model, joint) -> list:
    """The joints linked to ``joint`` through links without geometry, up and down (``joint`` included)."""
    chain, seen, stack = [], {joint.name}, [joint]
    while stack:
        current = stack.pop()
        chain.append(current)
        neighbours = []
        if current.parent and _dummy(model.link(current.parent), massless=False):
            neighbours.append(model.parent_joint(current.parent))
            neighbours.extend(model.child_joints(current.parent))
        if current.child and _dummy(model.link(current.child), massless=False):
            neighbours.extend(model.child_joints(current.child))
        for other in neighbours:
            if other is not None and other.name not in seen:
                seen.add(other.name)
                stack.append(other)
    return chain


def virtual_base_evidence(model, joint) -> str | None:
    """Why ``joint`` is a virtual joint of a floating base (see J005), or None when nothing says so.

    Evidence: a prismatic joint of the same geometry-less chain with the very same lower/upper (a
    range shared with joints in metres is no angle), or a floating chain: every link from the root
    down to the joint's parent is a massless dummy, and a moving joint lies among them.
    """
    limit = joint.limit
    if limit is not None and limit.lower is not None and limit.upper is not None:
        for other in _virtual_chain(model, joint):
            if other.type == "prismatic" and other.limit is not None \
                    and (other.limit.lower, other.limit.upper) == (limit.lower, limit.upper):
                return f"same limits as prismatic joint '{other.name}' of its virtual chain"
    moving, name, seen = 0, joint.parent, set()
    while name is not None and name not in seen:
        seen.add(name)
        if not _dummy(model.link(name), massless=True):
            return None
        above = model.parent_joint(name)
        if above is None:
            return "floating chain of massless dummy links from the root" if moving else None
        moving += above.moves
        name = above.parent
    return None


@rule("J006", "continuous-with-range", "warning", "Continuous joint with lower/upper",
      engines=("pybullet",),
      why="""The URDF spec ignores lower/upper on continuous joints, and PyBullet never makes them
      a physical stop, but it does clamp POSITION_CONTROL targets to [lower, upper]. The popular
      lower="-100" upper="100" "fix" adds a clamp and fixes nothing; a real arm with hard stops
      should be revolute.""",
      fix="Remove lower/upper, or make the joint revolute with its real limits.",
      bad=arm(joint_type="continuous", joint_extra='<limit lower="-100" upper="100" effort="10" velocity="1"/>'),
      good=arm(joint_type="continuous", joint_extra='<limit effort="10" velocity="1"/>'),
      fixed_by="fix-continuous")
def continuous_with_range(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        if joint.type == "continuous" and limit is not None and (
                limit.element.get("lower") is not None or limit.element.get("upper") is not None):
            yield Hit(f"continuous joint '{joint.name}' has lower/upper "
                      f"({limit.element.get('lower')}, {limit.element.get('upper')}): ignored by the spec, "
                      "but PyBullet clamps position targets to them", limit.element)


@rule("J007", "effort-velocity-missing", "error", "<limit> without effort or velocity",
      engines=("ros", "pybullet"),
      refused_by=("ros",),
      breaks="urdfdom refuses the file; PyBullet reads 0 for the missing value.",
      why="""effort and velocity are required attributes of <limit>: urdfdom refuses the file, and
      PyBullet reads 0 (no force, no speed for controllers that use them).""",
      fix="Add effort (N·m or N) and velocity (rad/s or m/s) from the actuator's datasheet.",
      bad=arm(joint_extra='<limit lower="-1" upper="1"/>'), good=arm(),
      fixed_by="fix-joints --limits-from joint_limits.yaml")
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
      maxForce from the URDF cannot hold the arm against gravity. A <mimic> follower has no actuator
      of its own (its leader drives it), so its zeros are not reported; nor are those of a joint whose
      range is a single point (J004 says it cannot move, and lists them).""",
      fix="Use the real actuator limits from the datasheet.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="0" velocity="0"/>'), good=arm())
def effort_velocity_zero(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.limit is None or joint.type not in ACTUATED_TYPES or joint.mimic is not None or _cannot_move(joint):
            continue  # a mimic follower has no actuator; a joint that cannot move is J004's
        bad = [f"{key}={value:g}" for key, value in (("effort", joint.limit.effort), ("velocity", joint.limit.velocity))
               if value is not None and value <= 0]
        if bad:
            yield Hit(f"joint '{joint.name}' has {' and '.join(bad)}", joint.limit.element)


@rule("J009", "axis-zero", "error", "Zero joint axis",
      refused_by=("ros", "mujoco"),
      breaks="PyBullet loads the file and every joint state is NaN after one step; urdfdom and MuJoCo refuse the file.",
      why="""A moving joint needs a direction. With axis 0 0 0 PyBullet loads the file and every
      joint state becomes NaN on the first step; urdfdom and MuJoCo refuse it.""",
      fix='Set the axis to a unit vector, e.g. <axis xyz="0 0 1"/>.',
      bad=arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>'), good=arm())
def axis_zero(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in ACTUATED_TYPES and joint.axis_given and all(c == 0 for c in joint.axis):
            yield Hit(f"joint '{joint.name}' axis is 0 0 0", joint.first_child("axis"))


@rule("J010", "axis-not-unit", "warning", "Joint axis is not a unit vector",
      why="""The spec says the axis is normalised; tools disagree on whether they normalise it
      (KDL does, some IK and Jacobian code does not), so a non-unit axis scales velocities in some
      tools only.""",
      fix="Normalise the axis (divide by its length).",
      bad=arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 2"/>'), good=arm(),
      thresholds="Length differing from 1 by more than 1e-3.",
      fixed_by="fix-joints")
def axis_not_unit(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type not in ACTUATED_TYPES or not joint.axis_given:
            continue
        norm = math.sqrt(sum(c * c for c in joint.axis))
        if norm > 0 and math.isfinite(norm) and abs(norm - 1.0) > 1e-3:
            unit = " ".join(f"{c / norm:.6g}" for c in joint.axis)
            yield Hit(f"joint '{joint.name}' axis has length {norm:.4g}", joint.first_child("axis"),
                      hint=f'Use <axis xyz="{unit}"/>.')


@rule("J011", "continuous-arm-joint", "warning", "Continuous joint without <limit> inside an arm-like chain",
      why="""A continuous joint with no <limit> at all that carries further moving joints is the
      signature of a CAD export: SolidWorks' sw_urdf_exporter writes every joint as continuous with
      no limits unless told otherwise. Arm joints almost always have hard stops; planners then
      wrap through them, and PyBullet reports effort 0 and velocity 0. Joints that spin by design are
      not flagged: wheels and turntables at the end of a chain, caster swivels, differentials and
      pendulums (a wheel-like link below: named wheel, caster, roller, rotor, gear ..., or a cylinder
      or sphere spinning on a continuous joint at the end of the chain), and the virtual joints of a
      planar or floating base (the parent is a link without geometry that itself moves).""",
      fix="Make it revolute with the real lower/upper/effort/velocity from the datasheet.",
      bad=robot(f"""
          <link name="base"/><link name="upper">{LINK_INERTIAL}<visual><geometry><box size="0.1 0.1 0.3"/></geometry></visual></link>
          <link name="fore">{LINK_INERTIAL}<visual><geometry><box size="0.1 0.1 0.3"/></geometry></visual></link>
          <joint name="shoulder" type="continuous"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/></joint>
          <joint name="elbow" type="continuous"><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/></joint>"""),
      good=robot(f"""
          <link name="base"><visual><geometry><box size="0.4 0.4 0.1"/></geometry></visual></link>
          <link name="caster_swivel">{LINK_INERTIAL}</link>
          <link name="caster_wheel">{LINK_INERTIAL}<collision><geometry><cylinder radius="0.04" length="0.02"/></geometry></collision></link>
          <joint name="swivel" type="continuous"><parent link="base"/><child link="caster_swivel"/><axis xyz="0 0 1"/></joint>
          <joint name="spin" type="continuous"><parent link="caster_swivel"/><child link="caster_wheel"/><axis xyz="0 1 0"/></joint>"""),
      fixed_by="fix-continuous --limits-from joint_limits.yaml",
      thresholds="Wheel-like names: " + ", ".join(WHEEL_LIKE) + ".")
def continuous_arm_joint(ctx) -> Iterator[Hit]:
    model = ctx.model
    below: _Below | None = None
    for joint in model.joints:
        if joint.type != "continuous" or joint.limit is not None or not joint.child:
            continue
        below = below or _Below(model)
        downstream = below.moving(joint.child)
        if downstream and not _virtual_base_joint(model, joint) and not below.wheel(joint.child):
            yield Hit(f"continuous joint '{joint.name}' has no <limit> and carries {downstream} more moving joint"
                      f"{'s' if downstream != 1 else ''} and no wheel: an arm joint with no stops, effort 0 and "
                      "velocity 0 in PyBullet", joint.element)


def _virtual_base_joint(model, joint) -> bool:
    """True for a joint of a virtual base chain: its parent link has no geometry and itself moves."""
    parent = model.link(joint.parent) if joint.parent else None
    if parent is None or parent.has_geometry:
        return False
    above = model.parent_joint(parent.name)
    return above is not None and above.moves


class _Below:
    """For every link, computed once bottom-up (linear in the joints, also for a chain of thousands of
    continuous joints): how many moving joints hang below it, and whether a link that spins by design
    (see J011) is at or below it. A link reached again (a cycle or a second parent: S006's business)
    adds nothing the second time."""

    def __init__(self, model) -> None:
        self.model = model
        self._moving: dict[str, int] = {}
        self._wheel: dict[str, bool] = {}

    def moving(self, link_name: str) -> int:
        self._fill(link_name)
        return self._moving[link_name]

    def wheel(self, link_name: str) -> bool:
        self._fill(link_name)
        return self._wheel[link_name]

    def _fill(self, top: str) -> None:
        """Post-order walk from ``top`` (iterative: no recursion limit on deep chains)."""
        if top in self._moving:
            return
        model, moving, wheel = self.model, self._moving, self._wheel
        started: set[str] = {top}
        stack: list[tuple[str, bool]] = [(top, False)]
        while stack:
            name, children_done = stack.pop()
            children = model.child_joints(name)
            if not children_done:
                stack.append((name, True))
                for child in children:
                    if child.child and child.child not in started and child.child not in moving:
                        started.add(child.child)
                        stack.append((child.child, False))
                continue
            moving[name] = sum(child.moves + moving.get(child.child or "", 0) for child in children)
            wheel[name] = self._spins(name, moving[name]) or any(wheel.get(child.child or "", False) for child in children)

    def _spins(self, name: str, moving_below: int) -> bool:
        """True when the link itself spins by design: a wheel-like name, or a round, continuous leaf."""
        if any(fragment in name.lower() for fragment in WHEEL_LIKE):
            return True
        link = self.model.link(name)
        above = self.model.parent_joint(name)
        if link is None or above is None or above.type != "continuous" or moving_below:
            return False
        shapes = link.collisions or link.visuals
        return bool(shapes) and all(shape.geometry.kind in ("cylinder", "sphere") for shape in shapes)


SINGLE_DOF_TYPES = ACTUATED_TYPES
"""The joint types a <mimic> can couple: one position each (Drake refuses anything else)."""


def _mimic_robot(follower_type: str, leader_type: str) -> str:
    def limit(kind: str) -> str:
        return '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind in ("revolute", "prismatic") else ""

    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="left">{LINK_INERTIAL}</link><link name="right">{LINK_INERTIAL}</link>
        <joint name="left_finger" type="{leader_type}"><parent link="base"/><child link="left"/><axis xyz="0 1 0"/>{limit(leader_type)}</joint>
        <joint name="right_finger" type="{follower_type}"><parent link="base"/><child link="right"/><axis xyz="0 1 0"/>{limit(follower_type)}
          <mimic joint="left_finger" multiplier="-1"/></joint>""")


@rule("J012", "mimic-not-single-dof", "error", "<mimic> on, or of, a joint that is not revolute, continuous or prismatic",
      engines=("drake", "ros"),
      refused_by=("drake",),
      breaks="Drake refuses the file (a 0-DOF joint cannot mimic a 1-DOF one); MoveIt and joint_state_publisher "
             "compute the follower from a leader that never moves.",
      why="""A mimic couples one joint position to another: both joints must have exactly one degree
      of freedom. Drake refuses a file where a fixed joint mimics a moving one or a moving joint
      mimics a fixed one ("Joint 'a' which has 0 DOF cannot mimic joint 'b' which has 1 DOF"), and
      ignores mimics between multi-DOF or fixed joints with a warning; MoveIt and
      joint_state_publisher compute the follower from a leader that never moves. PyBullet ignores
      <mimic> altogether. A mimic of a joint that does not exist is S007's.""",
      fix="Put the <mimic> on the moving follower joint and name a moving leader joint, or remove it.",
      bad=_mimic_robot("fixed", "revolute"), good=_mimic_robot("revolute", "revolute"),
      references="Drake multibody/parsing/detail_urdf_parser.cc ParseMimicTag; URDF spec joint/mimic "
                 "(wiki.ros.org/urdf/XML/joint).")
def mimic_not_single_dof(ctx) -> Iterator[Hit]:
    model = ctx.model
    for joint in model.joints:
        if joint.mimic is None:
            continue
        leader = model.joint(joint.mimic.joint)
        if joint.type not in SINGLE_DOF_TYPES:
            target = f"'{leader.name}' ({leader.type})" if leader is not None else f"'{joint.mimic.joint}'"
            yield Hit(f"{joint.type or 'untyped'} joint '{joint.name}' has a <mimic> of {target}: only revolute, "
                      "continuous and prismatic joints can follow another", joint.mimic.element)
        elif leader is not None and leader is not joint and leader.type not in SINGLE_DOF_TYPES:
            yield Hit(f"joint '{joint.name}' mimics {leader.type or 'untyped'} joint '{leader.name}': Drake refuses it "
                      f"({joint.type} has 1 DOF, {leader.type} does not)", joint.mimic.element)


PORTABILITY = {
    "floating": "PyBullet turns it into a fixed joint (\"joint unsupported, creating a fixed joint instead\", "
                "measured with pybullet 3.2.7); Drake ignores it and leaves the child a free body; MuJoCo makes "
                "it a free joint, allowed only on a top-level body; KDL (robot_state_publisher) treats it as "
                "fixed; Pinocchio makes it a free flyer",
    "planar": "PyBullet and Drake make it a planar joint; MuJoCo builds two slides and a hinge; KDL "
              "(robot_state_publisher, MoveIt's KDL plugin) treats it as fixed",
}
"""What each engine does with the URDF joint types outside the 1-DOF family (J013)."""


@rule("J013", "joint-type-portability", "info", "Planar or floating joint: engines disagree on it",
      why="""planar and floating are URDF joint types, but few engines treat them alike: PyBullet
      turns a floating joint into a fixed one (measured: "Warning: joint unsupported, creating a
      fixed joint instead"), Drake ignores floating joints, MuJoCo accepts a free joint only on a
      top-level body, and KDL-based ROS tools treat both types as fixed. None of them needs a <limit>
      on these joints (PyBullet 3.2.7 loads planar, floating and spherical joints without one). The
      PyBullet-only spherical type is S010's.""",
      fix="Keep it if your target engine supports it; for a mobile base prefer a floating root (no joint) and let "
          "the simulator or a planar controller move it.",
      bad=arm(joint_type="floating", joint_extra=""), good=arm())
def joint_type_portability(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in PORTABILITY:
            yield Hit(f"{joint.type} joint '{joint.name}': {PORTABILITY[joint.type]}", joint.element)


@rule("J014", "pybullet-unlimited-idiom", "info", "lower > upper written as PyBullet's \"no limit\"",
      engines=("ros",),
      why="""pybullet_data writes lower="1" upper="-1" on purpose (cube_no_rotation.urdf,
      biped2d_pybullet.urdf): PyBullet reads any lower > upper as unlimited, and (0, -1) is what
      getJointInfo reports for an unlimited joint. It is not an inverted range to swap (J003): a
      swap would limit a free joint in PyBullet. Other tools do not share the idiom: urdfdom and
      MoveIt read an empty, inverted range, and samplers drawing uniform(lower, upper) fail.""",
      fix="Keep it for PyBullet only; for a portable file make a revolute joint continuous, or give a prismatic "
          "joint its real travel.",
      bad=arm(joint_type="prismatic", joint_extra='<limit lower="1" upper="-1" effort="0" velocity="1000"/>'),
      good=arm(joint_type="prismatic"),
      thresholds="The (lower, upper) pairs of PYBULLET_UNLIMITED: (1, -1) and (0, -1).")
def pybullet_unlimited_idiom(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if _pybullet_unlimited_idiom(joint):
            limit = joint.limit
            yield Hit(f"{joint.type} joint '{joint.name}' lower {limit.lower:g} > upper {limit.upper:g}: PyBullet's "
                      "\"no limit\" idiom (unlimited in PyBullet; urdfdom and MoveIt read an inverted range)",
                      limit.element)
