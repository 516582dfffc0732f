"""Unit and reference rules: values that parse, load and simulate without a word, in the wrong unit or
frame. An angle typed in degrees (J015), a joint velocity in deg/s (J016), soft limits outside the hard
ones (J017), a centre of mass in millimetres or in the parent's frame (I016), a colour in 0-255 (G017).

Each one is judged against the robot itself (a full turn, the robot's other joints, the link's own
geometry, the joint's own hard limits), never against one constant alone, and each message says which
unit the value looks like and what it would be once converted: "rpy 90 looks like degrees (1.571
rad?)". Masses in grams and tensors in kg·mm² are I013's and I007's; a collision mesh scaled unlike its
visual is G006's; URDF 1.1's quat_xyzw, which PyBullet ignores, is T009's.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.lint.rules.schema import owner
from ar3cli.urdf.model import ROTATING_JOINT_TYPES, parse_float, parse_floats

FULL_TURN = 2 * math.pi
"""rad. An rpy angle beyond a full turn is the same frame as the angle less 2π: nobody writes radians so;
above it, up to 360, the angle was typed in degrees (J015)."""
TURN_SLACK = 0.01
"""rad: 6.2832 (2π rounded up) is a radian value."""
DEGREE_SPEED_STEP = 5.0
"""deg/s: speeds typed in degrees are round (85, 90, 135, 180 ... on arm datasheets)."""
SAME_SPEED = 0.02
"""A velocity converted from deg/s within 2 % of another joint's is the speed the author meant (J016)."""
DEGREE_SPEED_RATIO = 10.0
"""... and the value as written must be at least this many times that joint's speed."""
COM_FACTOR = 3.0
"""A centre of mass further from its link's geometry (visual and collision boxes) than this many box
diagonals lies outside the body (I016); a body's COM is inside its convex hull."""
COM_SCALE = 0.5
"""... and further than this fraction of the robot's median link size (a hand's parts are small)."""
COLOUR_MAX = 255.0
"""The largest component of a colour written in 0-255 (G017)."""


def origins(model):
    """(origin element, owner words) for every <origin> of a joint, inertial, visual or collision."""
    for joint in model.joints:
        if joint.origin.element is not None:
            yield joint.origin.element, f"joint '{joint.name}'"
    for link in model.links:
        if link.inertial is not None and link.inertial.origin.element is not None:
            yield link.inertial.origin.element, f"link '{link.name}' <inertial>"
        for shape in (*link.visuals, *link.collisions):
            if shape.origin.element is not None:
                yield shape.origin.element, f"link '{link.name}' <{shape.role}>"


def degree_angles(values) -> bool:
    """True when some angle of ``values`` lies beyond a full turn (and within 360): typed in degrees."""
    return any(FULL_TURN + TURN_SLACK < abs(v) <= 360.0 for v in values) and all(abs(v) <= 360.0 for v in values)


def in_radians(values) -> str:
    """``values`` (degrees) in radians, as URDF text."""
    return " ".join("0" if v == 0 else f"{math.radians(v):.6g}" for v in values)


@rule("J015", "rpy-degrees", "warning", "Origin rpy that looks like degrees",
      why="""URDF angles are radians. rpy="0 0 90" is a rotation of 90 rad, that is 90 - 14 x 2π =
      5.58 rad (320°), not a quarter turn: the file loads everywhere and the part sits rotated by an
      angle nobody chose. No rotation needs more than a full turn, so an rpy angle beyond 2π (up to
      360) was typed in degrees.""",
      fix="Convert to radians (degrees x π/180): rpy=\"0 0 1.5708\".",
      bad=arm(joint_extra='<origin xyz="0 0 0.1" rpy="0 0 90"/><limit lower="-1" upper="1" effort="10" velocity="1"/>'),
      good=arm(joint_extra='<origin xyz="0 0 0.1" rpy="0 0 1.5708"/><limit lower="-1" upper="1" effort="10" velocity="1"/>'),
      thresholds=f"An angle |v| with FULL_TURN = 2π + {TURN_SLACK} < |v| <= 360, every angle of the triple within 360.",
      fixed_by="fix-joints (joint origins)")
def rpy_degrees(ctx) -> Iterator[Hit]:
    for element, where in origins(ctx.model):
        text = element.get("rpy")
        values = parse_floats(text, 3) if text else None
        if values and all(map(math.isfinite, values)) and degree_angles(values):
            converted = in_radians(values)
            yield Hit(f"{where} <origin rpy=\"{text}\"> looks like degrees ({converted} rad?): "
                      f"{max(map(abs, values)):g} is more than a full turn", element,
                      hint=f'Write rpy="{converted}".')


def _rotating_speeds(model) -> list[tuple[float, object]]:
    """(velocity, joint) of the revolute and continuous joints with a positive velocity, mimics left out,
    sorted by velocity."""
    return sorted(((joint.limit.velocity, joint) for joint in model.joints
                   if joint.type in ROTATING_JOINT_TYPES and joint.limit is not None and joint.mimic is None
                   and joint.limit.velocity is not None and math.isfinite(joint.limit.velocity)
                   and joint.limit.velocity > 0), key=lambda item: item[0])


def degree_speed(speeds, joint) -> tuple[float, object] | None:
    """(the velocity in rad/s, the joint whose speed it matches) when ``joint``'s velocity looks like deg/s:
    a round number of degrees per second which, converted, is within SAME_SPEED of another rotating joint
    of the robot that moves at least DEGREE_SPEED_RATIO times slower as written; None otherwise.
    ``speeds`` is :func:`_rotating_speeds` of the robot (found by bisection: linear in the joints)."""
    import bisect

    mine = joint.limit.velocity if joint.limit is not None else None
    if mine is None or not FULL_TURN < mine <= 720 or mine % DEGREE_SPEED_STEP or joint.mimic is not None:
        return None
    converted = math.radians(mine)
    start = bisect.bisect_left(speeds, converted / (1 + SAME_SPEED), key=lambda item: item[0])
    for speed, other in speeds[start:]:
        if speed > converted / (1 - SAME_SPEED):
            break
        if other is not joint and mine >= DEGREE_SPEED_RATIO * speed and abs(converted - speed) <= SAME_SPEED * speed:
            return converted, other
    return None


@rule("J016", "velocity-degrees", "warning", "Joint velocity that looks like deg/s",
      why="""<limit velocity> is rad/s on a revolute joint. A speed typed in degrees per second (180
      for half a turn a second) is 57 times too fast: planners and controllers that respect the limit
      (MoveIt's time parameterisation, ros_control's joint limits) let the joint move at 180 rad/s.
      Judged against the robot: the value is a round number of degrees per second and, converted, is
      the speed another joint of the same robot is written with in rad/s.""",
      fix="Convert to rad/s (deg/s x π/180).",
      bad=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="upper">{LINK_INERTIAL}</link><link name="fore">{LINK_INERTIAL}</link>
          <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
            <limit lower="-3" upper="3" effort="50" velocity="3.1416"/></joint>
          <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/>
            <limit lower="-2" upper="2" effort="30" velocity="180"/></joint>"""),
      good=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="upper">{LINK_INERTIAL}</link><link name="fore">{LINK_INERTIAL}</link>
          <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
            <limit lower="-3" upper="3" effort="50" velocity="3.1416"/></joint>
          <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/>
            <limit lower="-2" upper="2" effort="30" velocity="3.1416"/></joint>"""),
      thresholds=f"Velocity v of a revolute or continuous joint (not a mimic) with 2π < v <= 720, v a multiple of "
                 f"DEGREE_SPEED_STEP = {DEGREE_SPEED_STEP:g}, and v x π/180 within SAME_SPEED = {SAME_SPEED:.0%} of another "
                 f"rotating joint's velocity w, with v >= DEGREE_SPEED_RATIO = {DEGREE_SPEED_RATIO:g} x w.",
      fixed_by="fix-joints")
def velocity_degrees(ctx) -> Iterator[Hit]:
    speeds = _rotating_speeds(ctx.model)
    for joint in ctx.model.joints:
        found = degree_speed(speeds, joint) if joint.type in ROTATING_JOINT_TYPES else None
        if found is not None:
            converted, other = found
            velocity = joint.limit.element.get("velocity")
            yield Hit(f"joint '{joint.name}' velocity {velocity} looks like deg/s ({converted:.4g} rad/s?): joint "
                      f"'{other.name}' of this robot moves at {other.limit.velocity:g} rad/s",
                      joint.limit.element, hint=f'Write velocity="{converted:.6g}".')


def _soft_robot(soft: str) -> str:
    return arm(joint_extra='<limit lower="-1.5" upper="1.5" effort="10" velocity="1"/>'
                           f'<safety_controller {soft} k_position="100" k_velocity="10"/>')


@rule("J017", "soft-limits-outside", "warning", "<safety_controller> soft limits outside the hard limits",
      engines=("ros",),
      why="""The safety controller (pr2_controller_manager, ros_control's joint_limits_interface) starts
      pushing back at the soft limits so that the joint never reaches its hard stop. Soft limits
      outside [lower, upper] never act before the stop: the protection the file describes does not
      exist. Often the soft limits were typed in degrees, or kept from another joint.""",
      fix="Put the soft limits inside the hard limits (a little short of them), in the joint's unit (rad or m).",
      bad=_soft_robot('soft_lower_limit="-1.6" soft_upper_limit="90"'),
      good=_soft_robot('soft_lower_limit="-1.4" soft_upper_limit="1.4"'),
      references="wiki.ros.org/pr2_controller_manager/safety_limits; ros_control joint_limits_interface "
                 "(SoftJointLimits).")
def soft_limits_outside(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        limit = joint.limit
        safety = joint.first_child("safety_controller")
        if safety is None or limit is None or joint.type not in ("revolute", "prismatic") \
                or limit.lower is None or limit.upper is None or not limit.lower <= limit.upper:
            continue
        slack = 1e-6 * max(limit.upper - limit.lower, 1.0)
        for key, hard, sign in (("soft_lower_limit", limit.lower, -1.0), ("soft_upper_limit", limit.upper, 1.0)):
            value = parse_float(safety.get(key))
            if value is None or not math.isfinite(value) or not sign * (value - hard) > slack:
                continue
            unit = ""
            if joint.type == "revolute" and degree_angles([value]) \
                    and limit.lower - slack <= math.radians(value) <= limit.upper + slack:
                unit = f": it looks like degrees ({math.radians(value):.4g} rad?)"
            side = "below the lower" if key == "soft_lower_limit" else "above the upper"
            yield Hit(f"joint '{joint.name}' {key}={safety.get(key)} is {side} limit {hard:g}{unit}; the safety "
                      "controller never acts before the hard stop", safety)


def _com_robot(com: str) -> str:
    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link>
        <link name="arm"><inertial><origin xyz="{com}"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
          <collision><origin xyz="0 0 0.15"/><geometry><box size="0.05 0.05 0.3"/></geometry></collision></link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>""")


def _outside(point, box) -> float:
    """Distance from ``point`` to ``box`` (0 inside)."""
    return math.sqrt(sum(max(0.0, lo - p, p - hi) ** 2 for p, lo, hi in zip(point, *box)))


def com_outside(ctx, link) -> tuple[float, float, str] | None:
    """(distance from the COM to the link's geometry, the geometry's size, what the COM looks like) when
    the centre of mass lies far outside the body (I016); None when it does not, or nothing says."""
    inertial = link.inertial
    if inertial is None or inertial.origin.element is None or not (inertial.mass or 0) > 0:
        return None
    box = ctx.body_bounds(link)
    com = inertial.origin.xyz
    if box is None or not all(map(math.isfinite, (*com, *box[0], *box[1]))):
        return None
    size = math.dist(*box)
    distance = _outside(com, box)
    scale = ctx.robot_scale() or size
    if not size > 0 or distance <= max(COM_FACTOR * size, COM_SCALE * scale):
        return None
    near = max(size, 1e-9)  # "inside" is within one box size: a COM need not sit in the box of a thin part
    millimetres = tuple(v / 1000 for v in com)
    typical = _typical_com_offset(ctx)
    if _outside(millimetres, box) <= near and (typical is None or math.hypot(*millimetres) / size >= typical / 10):
        return distance, size, f"it looks like millimetres (xyz=\"{' '.join(f'{v:.6g}' for v in millimetres)}\" m?)"
    angle = next(((axis, value, fraction) for axis, value in zip("xyz", com)
                  if (fraction := _angle_fraction(value)) is not None and abs(value) > size), None)
    if angle is not None:
        axis, value, fraction = angle
        return distance, size, (f"its {axis} {value:g} is {fraction}: an angle in radians, an rpy value typed into "
                                "xyz?")
    joint = ctx.model.parent_joint(link.name)
    if joint is not None and all(map(math.isfinite, joint.origin.xyz)):
        rotation, shift = joint.origin.rotation, joint.origin.xyz
        moved = tuple(sum(rotation[k][i] * (com[k] - shift[k]) for k in range(3)) for i in range(3))
        if _outside(moved, box) <= near:
            return distance, size, (f"it looks like it is written in the frame of the parent link '{joint.parent}' "
                                    f"(xyz=\"{' '.join(f'{v:.6g}' for v in moved)}\" in this link's frame?)")
    return distance, size, "it belongs to another body, or another frame"


def _typical_com_offset(ctx) -> float | None:
    """The median, over the robot's links whose COM lies inside their geometry's box and off its origin, of
    the COM's distance from the link origin over the link's size: how far from their frames this robot's
    parts carry their mass. A COM in millimetres, read in metres, lands about as far (I016); one that
    lands on the origin (1.047 "mm" on a 16 cm part) is no millimetre slip."""
    def build(_model) -> float | None:
        ratios = []
        for link in ctx.model.links:
            inertial = link.inertial
            box = ctx.body_bounds(link)
            if inertial is None or box is None or not all(map(math.isfinite, inertial.origin.xyz)):
                continue
            size, offset = math.dist(*box), math.hypot(*inertial.origin.xyz)
            if size > 0 and offset > 0 and _outside(inertial.origin.xyz, box) == 0:
                ratios.append(offset / size)
        ratios.sort()
        return ratios[len(ratios) // 2] if ratios else None
    return ctx.shared("typical-com-offset", build)


ANGLE_STEPS = 12
"""An xyz value equal to k·π/12 (15° steps: π/6, π/4, π/3, π/2, π ...) to 1e-5 is an angle in radians."""


def _angle_fraction(value: float) -> str | None:
    """"-π/3" when ``value`` is a multiple of π/12 (to 1e-5 relative), else None."""
    steps = value / (math.pi / ANGLE_STEPS)
    k = round(steps)
    if k == 0 or abs(steps - k) > 1e-5 * abs(steps) or abs(k) > 2 * ANGLE_STEPS:
        return None
    from fractions import Fraction

    ratio = Fraction(abs(k), ANGLE_STEPS)
    sign = "-" if k < 0 else ""
    numerator = "" if ratio.numerator == 1 else str(ratio.numerator)
    return f"{sign}{numerator}π" + (f"/{ratio.denominator}" if ratio.denominator != 1 else "")


@rule("I016", "com-outside-body", "warning", "Centre of mass far outside the link's geometry",
      why="""A body's centre of mass lies inside its convex hull. An <inertial> origin many times the
      link's size away from its visual and collision geometry is a value in millimetres, a COM written
      in the parent's (or the CAD assembly's) frame, or one pasted from another link: gravity then pulls
      on a lever arm the part does not have, and every torque computed for the joint above it is wrong.""",
      fix="Write the COM in metres in the link's own frame (a CAD export's COM is often in the assembly frame), or "
          "recompute it from the geometry (ar3cli fix-inertia --links LINK).",
      bad=_com_robot("0 0 150"), good=_com_robot("0 0 0.15"),
      thresholds=f"COM further from the box around the link's visual and collision shapes than COM_FACTOR = "
                 f"{COM_FACTOR:g} box diagonals and than COM_SCALE = {COM_SCALE:g} of the robot's median link size. "
                 "It looks like millimetres when xyz / 1000 lies within one box diagonal of the box, as far from the "
                 "link origin (relative to the link's size) as a tenth of the robot's typical link at least; like an "
                 "angle when a component beyond the box is a multiple of π/12; like the parent's frame when xyz moved "
                 "into the link's frame by its joint origin lies within one box diagonal of the box.")
def com_outside_body(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        found = com_outside(ctx, link)
        if found is not None:
            distance, size, looks = found
            xyz = link.inertial.origin.element.get("xyz")
            yield Hit(f"link '{link.name}' centre of mass xyz=\"{xyz}\" is {distance:.3g} m outside its geometry "
                      f"(about {size:.3g} m across): {looks}", link.inertial.origin.element)


def colour_0_255(values) -> bool:
    """True when an rgba's colour is written on the 0-255 scale: a component above 1, none above 255."""
    return any(v > 1 for v in values[:3]) and all(0 <= v <= COLOUR_MAX for v in values)


def _colours(model):
    """Every <color> of the robot's materials: the top-level ones and those inside visuals."""
    for material in model.root.findall("material"):
        yield from material.findall("color")
    for link in model.links:
        for shape in link.visuals:
            for material in shape.element.findall("material"):
                yield from material.findall("color")


def _material(colour: str) -> str:
    return robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="0.1 0.1 0.1"/></geometry>'
                 f'<material name="orange"><color rgba="{colour}"/></material></visual>'
                 '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>')


@rule("G017", "colour-0-255", "info", "Colour written on the 0-255 scale",
      why="""<color rgba> components are 0 to 1. A colour picked in an image editor and typed as
      "255 128 0 1" saturates: every component above 1 draws as 1, so the orange meant is drawn
      yellow (1 1 0), and most 0-255 colours come out white.""",
      fix="Divide each colour component by 255.",
      bad=_material("255 128 0 1"), good=_material("1 0.502 0 1"),
      thresholds="A red, green or blue component above 1 and every component within 0-255; the alpha is "
                 "converted too when it is above 1.")
def colour_scale(ctx) -> Iterator[Hit]:
    for colour in _colours(ctx.model):
        text = colour.get("rgba")
        values = parse_floats(text, 4) if text else None
        if values and all(map(math.isfinite, values)) and colour_0_255(values):
            converted = " ".join(f"{v / COLOUR_MAX:.3g}" for v in values[:3]) + " " + (
                f"{values[3] / COLOUR_MAX:.3g}" if values[3] > 1 else f"{values[3]:g}")
            yield Hit(f"{owner(colour)} rgba=\"{text}\" looks like 0-255 ({converted}?): components are 0 to 1",
                      colour, hint=f'Write rgba="{converted}".')
