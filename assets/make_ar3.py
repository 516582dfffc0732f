"""Generate the AR3 robot assets of ar3cli: ``python assets/make_ar3.py [OUTPUT_DIR]``.

Writes, below ``OUTPUT_DIR`` (default: the folder of this script):

* ``ar3/ar3.urdf``          the AR3 6-axis desktop arm (Annin Robotics) with a parallel-jaw gripper,
* ``ar3/ar3.urdf.xacro``    the same robot as xacro, with an ``xacro:arg`` ``with_gripper``,
* ``objects/cube.urdf``     a 45 mm cube to grasp,
* ``examples/*.urdf``       copies of ``ar3.urdf`` with one classic mistake each.

Why a generator: the geometry is primitives (boxes and cylinders) and every ``<inertial>``
is computed from that geometry with :mod:`ar3cli.maths.mass_properties`, so editing a shape by
hand would leave a stale inertia behind. Run the script after any change; the tests
check that the committed files equal its output byte for byte.

Where the numbers come from: the real AR3 description, ongdexter/ar3_core
``ar3_description`` (MIT/BSD, snapshot ``cd43fed``), files
``urdf/ar3.urdf.xacro`` (joint origins, axes), ``urdf/ar3.urdf`` (link masses) and
``ar3_moveit_config/config/joint_limits.yaml`` (position limits and velocity). They are
literals below, each with a comment; nothing outside this repository is read at run time.

Shapes are written down in *world* coordinates at the home pose (all joints zero), where
the arm stands straight up, and converted to each link's frame with the arm's own
forward kinematics. That keeps the geometry readable ("a cylinder from here to there")
while the link frames of the real robot are rotated in odd ways.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
if str(REPO) not in sys.path:  # allow `python assets/make_ar3.py` from a plain checkout
    sys.path.insert(0, str(REPO))

from ar3cli.maths import mass_properties as mp  # noqa: E402 - after the sys.path line that finds ar3cli

PI = math.pi

# --------------------------------------------------------------------------------------
# Number formatting: fixed, platform-independent text so that the output is deterministic.
# --------------------------------------------------------------------------------------


def fmt(value: float, digits: int = 6) -> str:
    """Format a length or angle with ``digits`` decimals, no trailing zeros, no ``-0``."""
    text = f"{value:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def fmt_sig(value: float) -> str:
    """Format a mass or inertia entry with 8 significant digits (they span many decades)."""
    if abs(value) < 1e-15:
        return "0"
    return f"{value:.8g}"


def fmt_vec(values: Iterable[float], digits: int = 6) -> str:
    """Space-separated :func:`fmt` of a vector, as URDF attributes want it."""
    return " ".join(fmt(v, digits) for v in values)


def parse_vec(text: str) -> np.ndarray:
    """Parse a URDF vector attribute such as ``"0 0.5236 -1.5708"``."""
    return np.array([float(v) for v in text.split()], dtype=float)


def matrix_to_rpy(rot: np.ndarray) -> np.ndarray:
    """Inverse of :func:`ar3cli.maths.mass_properties.rpy_to_matrix` (URDF fixed-axis x-y-z)."""
    pitch = math.atan2(-rot[2, 0], math.hypot(rot[0, 0], rot[1, 0]))
    if math.isclose(abs(pitch), PI / 2, abs_tol=1e-9):  # gimbal lock: put it all in yaw
        return np.array([0.0, pitch, math.atan2(-rot[0, 1], rot[1, 1])])
    return np.array([math.atan2(rot[2, 1], rot[2, 2]), pitch, math.atan2(rot[1, 0], rot[0, 0])])


def transform(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """4x4 homogeneous transform of a URDF ``<origin>``."""
    out = np.eye(4)
    out[:3, :3] = mp.rpy_to_matrix(rpy)
    out[:3, 3] = xyz
    return out


# --------------------------------------------------------------------------------------
# Model description
# --------------------------------------------------------------------------------------

# Colours, defined once at the top of the URDF and referenced by name.
MATERIALS: dict[str, str] = {
    "ar3_yellow": "1 0.76 0.05 1",  # the real description colours every link "1 1 0 1"
    "ar3_black": "0.12 0.12 0.12 1",  # motor housings and hubs
    "gripper_grey": "0.62 0.64 0.68 1",
    "pad_rubber": "0.05 0.05 0.05 1",
}

# Friction for the finger pads (pybullet reads <contact><lateral_friction/>; Bullet multiplies
# the two bodies' coefficients, so pads 1.0 x cube 1.0 = 1.0).
PAD_FRICTION = 1.0


@dataclass(frozen=True)
class Shape:
    """A box or cylinder, both its visual and its collision geometry, in its link frame."""

    kind: str  # "box" or "cylinder"
    dims: tuple[float, ...]  # box: (x, y, z); cylinder: (radius, length)
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    material: str

    def geometry_xml(self) -> str:
        """The ``<box>`` / ``<cylinder>`` element."""
        if self.kind == "box":
            return f'<box size="{fmt_vec(self.dims)}"/>'
        radius, length = self.dims
        return f'<cylinder radius="{fmt(radius)}" length="{fmt(length)}"/>'

    def unit_mass_properties(self) -> mp.MassProperties:
        """Mass properties at density 1 in the link frame (scaled to the link mass later)."""
        if self.kind == "box":
            local = mp.box(self.dims, density=1.0)
        else:
            local = mp.cylinder(*self.dims, density=1.0)
        return mp.transformed(local, self.xyz, self.rpy)


@dataclass(frozen=True)
class Link:
    """A link: shapes, a mass budget and optional pybullet contact parameters."""

    name: str
    mass: float
    shapes: tuple[Shape, ...] = ()
    lateral_friction: float | None = None
    comment: str = ""

    def mass_properties(self) -> mp.MassProperties:
        """Inertial of the link: its shapes at uniform density, scaled to ``mass``.

        A link without shapes (a pure frame such as ``tcp``) gets a tiny sphere-like
        inertial; see ``TCP_MASS`` for why it has one at all.
        """
        if not self.shapes:
            return mp.sphere(math.sqrt(2.5 * TCP_INERTIA / self.mass), mass=self.mass)
        return mp.scaled_to_mass(mp.combine(s.unit_mass_properties() for s in self.shapes), self.mass)


@dataclass(frozen=True)
class Limit:
    """A URDF ``<limit>``: position range (m or rad), effort (N or N*m), velocity."""

    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class Joint:
    """A URDF joint. ``xyz``/``rpy``/``axis`` are kept as the literal text written out."""

    name: str
    type: str
    parent: str
    child: str
    xyz: str
    rpy: str
    axis: str | None = None
    limit: Limit | None = None
    comment: str = ""


# --- Kinematics ------------------------------------------------------------------------
# Taken from ar3_description/urdf/ar3.urdf.xacro, not from ar3.urdf. Why: the xacro is the
# file the MoveIt config and joint_limits.yaml belong to. The two files disagree in three
# places: (1) joint_3's origin yaw is -1.04720367321 in the xacro but -1.4953816339 in
# ar3.urdf (a 25.68 deg different zero; the yaml's joint_3 range 0..143.7 deg only makes
# sense with the xacro's zero, where the home pose is the arm standing straight up);
# (2) joint_5's axis is "1 0 0" in the xacro and "-1 0 0" in ar3.urdf; (3) joint_1's origin
# is rpy="${pi} 0 0" in the xacro but "3.1416 -1.0248E-21 -1.6736E-05" (rounded SolidWorks
# output) in ar3.urdf. ${pi} is written out as Python's math.pi, as xacro expands it.
# The other rpy values (1.5708, 3.1416, ...) are the xacro's literals, kept unchanged so that
# link frames match the real robot's exactly.
#
# Position limits: joint_limits.yaml (has_position_limits: true for all six). joint_3's
# lower limit is 0.0 there (the xacro says 0.0174533); the yaml wins so that the all-zero
# home pose is inside the limits. Velocity: the yaml's max_velocity 1.0 rad/s.
# Effort: the real files say 0 (xacro) or 100 (gazebo xacro), neither is a rating. These
# are plausible for the AR3's geared steppers: 20-30 N*m for joints 1-3, a few N*m at the
# wrist (the arm's worst static gravity torque on joint_2 is about 5 N*m).
ARM_VELOCITY = 1.0  # rad/s, joint_limits.yaml max_velocity
ARM_JOINTS: tuple[Joint, ...] = (
    Joint("joint_1", "revolute", "base_link", "link_1", "0 0 0.003445", f"{PI!r} 0 0", "0 0 1",
          Limit(-2.96706, 2.96706, 20.0, ARM_VELOCITY), "+-170 deg"),
    Joint("joint_2", "revolute", "link_1", "link_2", "0 0.064146 -0.16608", "1.5708 0.5236 -1.5708", "0 0 -1",
          Limit(-0.6911504, 1.57079632679, 30.0, ARM_VELOCITY), "-39.6 .. 90 deg"),
    Joint("joint_3", "revolute", "link_2", "link_3", "0.1525 -0.26414 0", "0 0 -1.04720367321", "0 0 -1",
          Limit(0.0, 2.5080381, 20.0, ARM_VELOCITY), "0 .. 143.7 deg"),
    Joint("joint_4", "revolute", "link_3", "link_4", "0 0 0.00675", "1.5708 -1.2554 -1.5708", "0 0 -1",
          Limit(-2.8710666, 2.8710666, 5.0, ARM_VELOCITY), "+-164.5 deg"),
    Joint("joint_5", "revolute", "link_4", "link_5", "0 0 -0.22225", f"{PI!r} 0 -2.8262", "1 0 0",
          Limit(-1.81776042, 1.81776042, 5.0, ARM_VELOCITY), "+-104.15 deg"),
    Joint("joint_6", "revolute", "link_5", "link_6", "-0.000294 0 0.02117", "0 0 3.1416", "0 0 1",
          Limit(-2.5848326, 2.5848326, 2.0, ARM_VELOCITY), "+-148.1 deg"),
)

# --- Gripper (designed for this project, not part of the real description) -------------
# Jaw: two flat pads that move towards each other. Joint value = travel of one pad from
# fully open: 0 = open (80 mm between the pads), FINGER_TRAVEL = closed (0 mm). Open at
# zero so that the all-zero home pose has no finger-finger contact.
FINGER_TRAVEL = 0.04  # m per finger -> 80 mm total opening
PAD_SIZE = (0.022, 0.012, 0.055)  # m: width, thickness (along the jaw), length
PALM_SIZE = (0.04, 0.11, 0.02)
MOUNT_DISC = (0.024, 0.006)  # radius, thickness of the adapter plate on the flange
FLANGE_TO_GRIPPER = 0.016  # link_6 flange face (top of the real link_6 mesh, 16 mm)
PALM_TOP = MOUNT_DISC[1] + PALM_SIZE[2]  # finger joints sit on the palm's far face
TCP_Z = PALM_TOP + PAD_SIZE[2] - 0.0225  # a 45 mm cube centred here is fully between the pads
FINGER_EFFORT = 30.0  # N
FINGER_VELOCITY = 0.05  # m/s

# tcp is a frame only. pybullet gives a link without <inertial> mass 1 kg and inertia
# (1, 1, 1) and prints a b3Warning (measured, pybullet 3.2.7: a 1 kg point 0.3 m out
# raised a joint's holding torque from 0.086 to 2.67 N*m). mass="0" loads silently in
# pybullet but is a zero (not positive definite) tensor that linters and other engines
# reject. 1e-6 kg with 1e-12 kg*m^2 loads silently, changed that holding torque by
# 3e-6 N*m, and is a valid inertia.
TCP_MASS = 1e-6
TCP_INERTIA = 1e-12

GRIPPER_JOINTS: tuple[Joint, ...] = (
    Joint("gripper_mount", "fixed", "link_6", "gripper_base", f"0 0 {fmt(FLANGE_TO_GRIPPER)}", "0 0 0"),
    Joint("gripper_finger_left", "prismatic", "gripper_base", "finger_left",
          f"0 {fmt(FINGER_TRAVEL)} {fmt(PALM_TOP)}", "0 0 0", "0 -1 0",
          Limit(0.0, FINGER_TRAVEL, FINGER_EFFORT, FINGER_VELOCITY), "0 = open, 0.04 = closed"),
    Joint("gripper_finger_right", "prismatic", "gripper_base", "finger_right",
          f"0 {fmt(-FINGER_TRAVEL)} {fmt(PALM_TOP)}", f"0 0 {PI!r}", "0 -1 0",
          Limit(0.0, FINGER_TRAVEL, FINGER_EFFORT, FINGER_VELOCITY), "mirror image of the left finger"),
    Joint("tcp_joint", "fixed", "gripper_base", "tcp", f"0 0 {fmt(TCP_Z)}", "0 0 0",
          comment="between the pads, 22.5 mm up from the fingertips"),
)

# Real link masses, ar3_description/urdf/ar3.urdf <mass value>: each link's mass budget.
ARM_MASSES: dict[str, float] = {
    "base_link": 0.7102,
    "link_1": 0.88065,
    "link_2": 0.57738,
    "link_3": 0.1787,
    "link_4": 0.34936,
    "link_5": 0.11562,
    "link_6": 0.013863,
}
GRIPPER_MASSES: dict[str, float] = {"gripper_base": 0.08, "finger_left": 0.02, "finger_right": 0.02}


def home_frames(joints: Sequence[Joint]) -> dict[str, np.ndarray]:
    """World transform of every link at the all-zero pose (base_link = identity)."""
    frames = {"base_link": np.eye(4)}
    for joint in joints:
        frames[joint.child] = frames[joint.parent] @ transform(parse_vec(joint.xyz), parse_vec(joint.rpy))
    return frames


HOME = home_frames(ARM_JOINTS + GRIPPER_JOINTS)
COLUMN_Y = HOME["link_2"][1, 3]  # y of the vertical column (joint_2 .. joint_6 axes), -0.064146
Z_J2, Z_J3 = HOME["link_2"][2, 3], HOME["link_3"][2, 3]  # shoulder and elbow axis heights
X_J4 = HOME["link_4"][0, 3]  # the forearm axis is 6.75 mm off the column centre
Z_J5, Z_J6 = HOME["link_5"][2, 3], HOME["link_6"][2, 3]


def in_link(link: str, world: np.ndarray, kind: str, dims: Sequence[float], material: str) -> Shape:
    """A shape given by its world pose at home, expressed (and rounded) in ``link``'s frame."""
    local = np.linalg.inv(HOME[link]) @ world
    xyz = tuple(round(float(v), 6) for v in local[:3, 3])
    rpy = tuple(round(float(v), 6) for v in matrix_to_rpy(local[:3, :3]))
    return Shape(kind, tuple(round(float(d), 6) for d in dims), xyz, rpy, material)  # type: ignore[arg-type]


def box_between(link: str, lo: Sequence[float], hi: Sequence[float], material: str = "ar3_yellow") -> Shape:
    """World-axis-aligned box with corners ``lo`` and ``hi`` at home."""
    lo_, hi_ = np.asarray(lo, float), np.asarray(hi, float)
    return in_link(link, transform((lo_ + hi_) / 2, (0, 0, 0)), "box", hi_ - lo_, material)


def cylinder_between(link: str, start: Sequence[float], end: Sequence[float], radius: float,
                     material: str = "ar3_black") -> Shape:
    """Cylinder from ``start`` to ``end`` (world, home); only x- or z-parallel axes are used."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    direction = (b - a) / np.linalg.norm(b - a)
    rpy = (0.0, PI / 2, 0.0) if abs(direction[0]) > 0.5 else (0.0, 0.0, 0.0)
    return in_link(link, transform((a + b) / 2, rpy), "cylinder", (radius, float(np.linalg.norm(b - a))), material)


def arm_links() -> tuple[Link, ...]:
    """The seven arm links with primitive geometry roughly following the real meshes.

    World extents of the real meshes at home were used as a guide (e.g. base_link spans
    x +-0.075, y -0.075..0.17, z 0..0.124; the upper arm sits at x 0..0.08 beside the
    column, the J2 motor at x down to -0.122). Neighbours may overlap (pybullet skips
    parent-child pairs); every non-adjacent pair keeps >= 3 mm clearance at home.
    """
    y = COLUMN_Y
    return (
        Link("base_link", ARM_MASSES["base_link"], (
            cylinder_between("base_link", (0, 0, 0), (0, 0, 0.045), 0.075, "ar3_yellow"),  # J1 drum
            box_between("base_link", (-0.065, 0.03, 0), (0.065, 0.17, 0.12)),  # rear housing (J1 drive)
        ), comment="fixed base, mass budget from ar3.urdf"),
        Link("link_1", ARM_MASSES["link_1"], (
            cylinder_between("link_1", (0, 0, 0.046), (0, 0, 0.1), 0.06, "ar3_yellow"),  # turntable
            box_between("link_1", (-0.06, y - 0.02, 0.1), (0.0, y + 0.05, 0.15)),  # shoulder column
            cylinder_between("link_1", (-0.125, y, Z_J2), (0.0, y, Z_J2), 0.045),  # J2 motor + housing
        )),
        Link("link_2", ARM_MASSES["link_2"], (
            cylinder_between("link_2", (0.005, y, Z_J2), (0.06, y, Z_J2), 0.045),  # shoulder hub
            box_between("link_2", (0.01, y - 0.025, Z_J2), (0.055, y + 0.025, Z_J3)),  # upper arm
            cylinder_between("link_2", (0.005, y, Z_J3), (0.06, y, Z_J3), 0.038),  # elbow hub
        )),
        Link("link_3", ARM_MASSES["link_3"], (
            cylinder_between("link_3", (-0.05, y, Z_J3), (0.0, y, Z_J3), 0.038),  # elbow housing
            cylinder_between("link_3", (X_J4, y, Z_J3), (X_J4, y, 0.525), 0.03, "ar3_yellow"),  # J4 bearing
        )),
        Link("link_4", ARM_MASSES["link_4"], (
            cylinder_between("link_4", (X_J4, y, 0.528), (X_J4, y, 0.655), 0.024, "ar3_yellow"),  # forearm
            box_between("link_4", (-0.052, y - 0.02, 0.655), (0.038, y + 0.02, 0.667)),  # wrist yoke base
            box_between("link_4", (-0.052, y - 0.02, 0.667), (-0.042, y + 0.02, 0.714)),  # yoke arm
            box_between("link_4", (0.028, y - 0.02, 0.667), (0.038, y + 0.02, 0.714)),  # yoke arm
        )),
        Link("link_5", ARM_MASSES["link_5"], (
            cylinder_between("link_5", (-0.039, y, Z_J5), (0.025, y, Z_J5), 0.021),  # J5 wrist body
        )),
        Link("link_6", ARM_MASSES["link_6"], (
            cylinder_between("link_6", (HOME["link_6"][0, 3], y, Z_J6),
                             (HOME["link_6"][0, 3], y, Z_J6 + FLANGE_TO_GRIPPER), 0.024, "gripper_grey"),  # flange
        )),
    )


def gripper_links() -> tuple[Link, ...]:
    """Gripper base, two identical fingers (the right one is rotated 180 deg) and tcp.

    Given directly in link frames: gripper z points away from the flange, the jaw moves
    along y. A finger's frame is on its inner (gripping) face.
    """
    pad = Shape("box", PAD_SIZE, (0.0, PAD_SIZE[1] / 2, PAD_SIZE[2] / 2), (0.0, 0.0, 0.0), "pad_rubber")
    return (
        Link("gripper_base", GRIPPER_MASSES["gripper_base"], (
            Shape("cylinder", MOUNT_DISC, (0.0, 0.0, MOUNT_DISC[1] / 2), (0.0, 0.0, 0.0), "gripper_grey"),
            Shape("box", PALM_SIZE, (0.0, 0.0, MOUNT_DISC[1] + PALM_SIZE[2] / 2), (0.0, 0.0, 0.0), "gripper_grey"),
        ), comment="parallel-jaw gripper (this project's design)"),
        Link("finger_left", GRIPPER_MASSES["finger_left"], (pad,), PAD_FRICTION),
        Link("finger_right", GRIPPER_MASSES["finger_right"], (pad,), PAD_FRICTION),
        Link("tcp", TCP_MASS, comment="tool centre point: a frame only, tiny inertial (see make_ar3.py)"),
    )


# --------------------------------------------------------------------------------------
# Rendering
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Variant:
    """Deliberate defects for the example files (defaults: the correct robot)."""

    no_inertial: frozenset[str] = frozenset()
    fake_continuous: bool = False
    zero_effort: bool = False
    note: str = ""


@dataclass
class Writer:
    """Collects indented lines of XML."""

    lines: list[str] = field(default_factory=list)

    def add(self, depth: int, text: str) -> None:
        self.lines.append("  " * depth + text)


def write_link(out: Writer, link: Link, variant: Variant, depth: int = 1) -> None:
    """Emit one ``<link>``: inertial, then a visual and a collision per shape, contact."""
    if link.comment:
        out.add(depth, f"<!-- {link.comment} -->")
    out.add(depth, f'<link name="{link.name}">')
    if link.name not in variant.no_inertial:
        props = link.mass_properties()
        i = props.inertia
        out.add(depth + 1, "<inertial>")
        out.add(depth + 2, f'<origin xyz="{fmt_vec(props.com, 7)}" rpy="0 0 0"/>')
        out.add(depth + 2, f'<mass value="{fmt_sig(props.mass)}"/>')
        out.add(depth + 2, f'<inertia ixx="{fmt_sig(i[0, 0])}" ixy="{fmt_sig(i[0, 1])}" ixz="{fmt_sig(i[0, 2])}" '
                           f'iyy="{fmt_sig(i[1, 1])}" iyz="{fmt_sig(i[1, 2])}" izz="{fmt_sig(i[2, 2])}"/>')
        out.add(depth + 1, "</inertial>")
    for tag in ("visual", "collision"):
        for shape in link.shapes:
            out.add(depth + 1, f"<{tag}>")
            out.add(depth + 2, f'<origin xyz="{fmt_vec(shape.xyz)}" rpy="{fmt_vec(shape.rpy)}"/>')
            out.add(depth + 2, f"<geometry>{shape.geometry_xml()}</geometry>")
            if tag == "visual":
                out.add(depth + 2, f'<material name="{shape.material}"/>')
            out.add(depth + 1, f"</{tag}>")
    if link.lateral_friction is not None:
        out.add(depth + 1, f'<contact><lateral_friction value="{fmt(link.lateral_friction)}"/></contact>')
    out.add(depth, "</link>")


def write_joint(out: Writer, joint: Joint, variant: Variant, depth: int = 1) -> None:
    """Emit one ``<joint>``, applying the variant's joint defects."""
    jtype, limit = joint.type, joint.limit
    if variant.fake_continuous and joint.name in {j.name for j in ARM_JOINTS}:
        jtype = "continuous"
        limit = Limit(-100.0, 100.0, limit.effort, limit.velocity)  # type: ignore[union-attr]
    if variant.zero_effort and limit is not None:
        limit = Limit(limit.lower, limit.upper, 0.0, 0.0)
    comment = f"  <!-- {joint.comment} -->" if joint.comment else ""
    out.add(depth, f'<joint name="{joint.name}" type="{jtype}">{comment}')
    out.add(depth + 1, f'<origin xyz="{joint.xyz}" rpy="{joint.rpy}"/>')
    out.add(depth + 1, f'<parent link="{joint.parent}"/>')
    out.add(depth + 1, f'<child link="{joint.child}"/>')
    if joint.axis is not None:
        out.add(depth + 1, f'<axis xyz="{joint.axis}"/>')
    if limit is not None:
        out.add(depth + 1, f'<limit lower="{fmt(limit.lower, 11)}" upper="{fmt(limit.upper, 11)}" '
                           f'effort="{fmt(limit.effort)}" velocity="{fmt(limit.velocity)}"/>')
    out.add(depth, "</joint>")


HEADER = (
    "<!-- Generated by assets/make_ar3.py; do not edit by hand, edit the script and rerun it. -->",
    "<!-- AR3 desktop arm (Annin Robotics) with a parallel-jaw gripper, written for ar3cli. Kinematics",
    "     and joint limits from ongdexter/ar3_core ar3_description (MIT/BSD), see assets/README.md;",
    "     geometry is primitives, inertials are computed from it at the real link masses. -->",
)


def render_body(out: Writer, variant: Variant, with_gripper_block: bool) -> None:
    """Materials, arm links/joints, then the gripper (optionally wrapped in ``xacro:if``)."""
    for name, rgba in MATERIALS.items():
        out.add(1, f'<material name="{name}"><color rgba="{rgba}"/></material>')
    arm = arm_links()
    write_link(out, arm[0], variant)
    for joint, link in zip(ARM_JOINTS, arm[1:]):
        write_link(out, link, variant)
        write_joint(out, joint, variant)
    depth = 1
    if with_gripper_block:
        out.add(1, '<xacro:if value="$(arg with_gripper)">')
        depth = 2
    for joint, link in zip(GRIPPER_JOINTS, gripper_links()):
        write_link(out, link, variant, depth)
        write_joint(out, joint, variant, depth)
    if with_gripper_block:
        out.add(1, "</xacro:if>")
        out.add(1, '<xacro:unless value="$(arg with_gripper)">')
        tcp = gripper_links()[-1]
        write_link(out, tcp, variant, 2)
        write_joint(out, Joint("tcp_joint", "fixed", "link_6", "tcp", f"0 0 {fmt(FLANGE_TO_GRIPPER)}", "0 0 0",
                               comment="without a gripper: the flange face"), variant, 2)
        out.add(1, "</xacro:unless>")


def render_urdf(variant: Variant = Variant()) -> str:
    """The AR3 URDF text (``variant`` adds the defects of an example file)."""
    out = Writer(['<?xml version="1.0"?>', *HEADER])
    if variant.note:
        out.add(0, f"<!-- EXAMPLE WITH A DELIBERATE MISTAKE: {variant.note} -->")
    out.add(0, '<robot name="ar3">')
    render_body(out, variant, with_gripper_block=False)
    out.add(0, "</robot>")
    return "\n".join(out.lines) + "\n"


def render_xacro() -> str:
    """xacro version: same robot; ``with_gripper:=false`` drops the gripper, keeps a tcp."""
    out = Writer(['<?xml version="1.0"?>', *HEADER])
    out.add(0, '<robot name="ar3" xmlns:xacro="http://www.ros.org/wiki/xacro">')
    out.add(1, "<!-- with_gripper:=false gives the bare arm with tcp on the link_6 flange. -->")
    out.add(1, '<xacro:arg name="with_gripper" default="true"/>')
    render_body(out, Variant(), with_gripper_block=True)
    out.add(0, "</robot>")
    return "\n".join(out.lines) + "\n"


# Cube to grasp: 45 mm, 70 g (about the density of a hardwood block), friction 1.0.
CUBE_EDGE = 0.045
CUBE_MASS = 0.07


def render_cube() -> str:
    """Single-link URDF of the cube; inertia ``m a^2 / 6`` from mass_properties.box."""
    props = mp.box((CUBE_EDGE,) * 3, mass=CUBE_MASS)
    i = props.inertia
    size = fmt_vec((CUBE_EDGE,) * 3)
    return "\n".join([
        '<?xml version="1.0"?>',
        "<!-- Generated by assets/make_ar3.py. A 45 mm cube for the pick-and-lift demo. -->",
        '<robot name="cube">',
        '  <material name="cube_red"><color rgba="0.85 0.1 0.1 1"/></material>',
        '  <link name="cube">',
        "    <inertial>",
        '      <origin xyz="0 0 0" rpy="0 0 0"/>',
        f'      <mass value="{fmt_sig(props.mass)}"/>',
        f'      <inertia ixx="{fmt_sig(i[0, 0])}" ixy="0" ixz="0" iyy="{fmt_sig(i[1, 1])}" iyz="0" izz="{fmt_sig(i[2, 2])}"/>',
        "    </inertial>",
        f'    <visual><geometry><box size="{size}"/></geometry><material name="cube_red"/></visual>',
        f'    <collision><geometry><box size="{size}"/></geometry></collision>',
        f'    <contact><lateral_friction value="{fmt(PAD_FRICTION)}"/></contact>',
        "  </link>",
        "</robot>",
    ]) + "\n"


def render_joint_limits() -> str:
    """MoveIt's ``joint_limits.yaml`` for the arm, from the same table as ar3.urdf.

    ``ar3cli fix-continuous --limits-from`` turns a continuous-jointed export of the AR3 (like
    examples/ar3_fake_continuous.urdf, or the real ar3.urdf) back into revolute joints with these
    hard stops, efforts and velocities.
    """
    lines = ["# Generated by assets/make_ar3.py: the AR3's joint limits in MoveIt's joint_limits.yaml format.",
             "# Position and velocity limits from the real AR3's ar3_moveit_config; efforts as in ar3.urdf.",
             "joint_limits:"]
    for joint in ARM_JOINTS:
        limit = joint.limit
        assert limit is not None
        lines += [f"  {joint.name}:  # {joint.comment}",
                  "    has_position_limits: true",
                  f"    min_position: {fmt(limit.lower, 11)}",
                  f"    max_position: {fmt(limit.upper, 11)}",
                  "    has_velocity_limits: true",
                  f"    max_velocity: {fmt(limit.velocity)}",
                  "    has_effort_limits: true",
                  f"    max_effort: {fmt(limit.effort)}"]
    return "\n".join(lines) + "\n"


# Example files: ar3.urdf with one classic mistake each (same script, so diffs are minimal).
NO_INERTIA_LINKS = frozenset({"link_4", "link_5", "link_6"})
EXAMPLES: dict[str, Variant] = {
    "ar3_no_inertia.urdf": Variant(
        no_inertial=NO_INERTIA_LINKS,
        note="link_4, link_5 and link_6 have no <inertial>; pybullet gives each 1 kg and inertia 1,1,1"),
    "ar3_fake_continuous.urdf": Variant(
        fake_continuous=True,
        note="joint_1..joint_6 are continuous with fake limits lower=-100 upper=100"),
    "ar3_zero_effort.urdf": Variant(
        zero_effort=True,
        note='every limit has effort="0" velocity="0", as in the real ar3.urdf.xacro'),
}


def outputs() -> dict[str, str]:
    """Every generated file: relative path -> text."""
    files = {
        "ar3/ar3.urdf": render_urdf(),
        "ar3/ar3.urdf.xacro": render_xacro(),
        "ar3/joint_limits.yaml": render_joint_limits(),
        "objects/cube.urdf": render_cube(),
    }
    files.update({f"examples/{name}": render_urdf(variant) for name, variant in EXAMPLES.items()})
    return files


def main(argv: Sequence[str] | None = None) -> int:
    """Write every file below ``argv[0]`` (default: this script's folder)."""
    args = list(sys.argv[1:] if argv is None else argv)
    target = Path(args[0]) if args else Path(__file__).resolve().parent
    for rel, text in outputs().items():
        path = target / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text.encode("utf-8"))
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
