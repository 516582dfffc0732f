"""Both sides of every numeric threshold a lint rule compares against: one table, keyed by rule code.

Each :class:`Edge` names a threshold as the rule's ``thresholds`` text writes it (``NAME`` for
``NAME = value``, else the bare number with its unit) and holds two documents built around it: ``fires``
just past it and ``quiet`` just inside it, as close to the edge as the arithmetic allows (3.1x against
2.9x for a factor 3, 0.9e-9 against 1.1e-9 for a ratio 1e-9, the nearest multiples of 5 on each side of
4π). ``tests/test_rule_edges.py`` lints each document in-process with only that rule selected, and checks
that every rule whose ``thresholds`` text names a number has its edges here: a new rule or constant
without edges fails there, saying what to add.

The simulation rules' thresholds that live in a pure function (the speed a settled joint may keep, the
relative difference P003 tolerates) are tested on that function: ``fires`` and ``quiet`` are then
callables answering "does the rule report this?", and the edge is *pure*. The others (P002, P005, M003)
use the smallest robots that reach them: spheres, whose overlap is exact in both engines (P005 swings one on a hinge
to a limit computed to sink it a given depth: it sweeps no prismatic joint).

A few named constants are not values anything is compared with (how long a robot settles, how many
values a sweep tries): :data:`NOT_COMPARED` says so, one reason each.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from ar3cli.lint.rules import mujoco as mujoco_rules
from ar3cli.lint.rules import pybullet_sim
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from tests.lint_helpers import fixed_child, tensor
from tests.test_lint_rules import binary_stl, box_stl


@dataclass(frozen=True)
class Doc:
    """A robot file (``text``, written as ``name``) and the files beside it: bytes, or an int for a
    sparse file of that many zero bytes (a 64 MB mesh costs no disk)."""

    text: str
    files: Mapping[str, bytes | int] = field(default_factory=dict)
    name: str = "robot.urdf"


@dataclass(frozen=True)
class Edge:
    """One threshold's two sides. ``contains`` counts only findings whose message holds it (the edge
    decides a verdict's wording, such as "looks like grams", not whether the rule reports at all)."""

    constant: str
    fires: str | Doc | Callable[[], bool]
    quiet: str | Doc | Callable[[], bool]
    contains: str = ""

    @property
    def pure(self) -> bool:
        """Tested on the function that holds the threshold, not on a linted document."""
        return callable(self.fires)


# ---- builders --------------------------------------------------------------------------------------------

def box(size: str, xyz: str = "0 0 0", role: str = "collision") -> str:
    return f'<{role}><origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry></{role}>'


def both(size: str, xyz: str = "0 0 0") -> str:
    """The same box as visual and collision."""
    return box(size, xyz, "visual") + box(size, xyz)


def limit(lower: float, upper: float, velocity: float = 1.0) -> str:
    return f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="{velocity}"/>'


def joint(name: str, parent: str, child: str, kind: str = "revolute", xyz: str = "0 0 0",
          extra: str = limit(-1, 1), axis: str = "0 0 1") -> str:
    body = f'<axis xyz="{axis}"/>{extra}' if kind != "fixed" else ""
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/>{body}</joint>')


def link(name: str, extra: str = LINK_INERTIAL) -> str:
    return f'<link name="{name}">{extra}</link>'


# ---- F, S: files and names ---------------------------------------------------------------------------------

LIBRARY = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="segment" params="name"><link name="${name}"/></xacro:macro>
</robot>
"""


def library_package(fillers: int) -> Doc:
    """A xacro library whose includer is the robot file found after ``fillers`` other robot files of
    its package (in the sorted order the search reads them)."""
    files: dict[str, bytes | int] = {f"f{index:03}.urdf": b'<robot name="f"/>' for index in range(fillers)}
    files["package.xml"] = b"<package><name>edge</name></package>"
    files["robot.xacro"] = b'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="lib.xacro"/></robot>'
    return Doc(LIBRARY, files, name="lib.xacro")


def joint_child(tag: str) -> str:
    """An arm whose joint holds an unknown child ``<tag>``."""
    return arm(joint_extra=limit(-1, 1) + f"<{tag}/>")


def limit_attribute(name: str) -> str:
    """An arm whose <limit> has an unknown attribute ``name`` (and no velocity it could be taken for)."""
    return arm(joint_extra=f'<limit lower="-1" upper="1" effort="10" {name}="1"/>')


# ---- J: joints ----------------------------------------------------------------------------------------------

def revolute_limits(lower: float, upper: float) -> str:
    return arm(joint_extra=limit(lower, upper))


def prismatic_limits(lower: float, upper: float) -> str:
    return arm(joint_type="prismatic", joint_extra=limit(lower, upper))


def virtual_base(carriage_mass: float) -> str:
    """A revolute joint in degrees below a prismatic one, through a geometry-less carriage of
    ``carriage_mass``: a floating base's virtual chain while the carriage is a massless dummy (J005)."""
    return robot(f"""
        {link("world", "")}{link("carriage", tensor(1e-9, 1e-9, 1e-9, mass=carriage_mass))}
        {link("arm", LINK_INERTIAL + box("0.1 0.1 0.1"))}
        {joint("px", "world", "carriage", "prismatic", axis="1 0 0")}
        {joint("yaw", "carriage", "arm", extra=limit(-90, 90))}""")


def two_speeds(written: float, other: float) -> str:
    """Two rotating joints: ``written`` (the one that may be in deg/s) and ``other`` (rad/s)."""
    return robot(f"""
        {link("base")}{link("upper")}{link("fore")}
        {joint("shoulder", "base", "upper", extra=limit(-3, 3, other))}
        {joint("elbow", "upper", "fore", extra=limit(-2, 2, written), axis="0 1 0")}""")


def degrees(value: float) -> float:
    return round(math.radians(value), 9)


def rpy(value: str) -> str:
    return arm(joint_extra=f'<origin xyz="0 0 0.1" rpy="{value}"/>' + limit(-1, 1))


# ---- I: inertia --------------------------------------------------------------------------------------------

def moving_tensor(ixx: float, iyy: float, izz: float, mass: float = 1.0) -> str:
    return arm(link_extra=tensor(ixx, iyy, izz, mass))


def welded_to(flange: tuple[float, float, float], base: tuple[float, float, float]) -> str:
    """A moving arm with tensor ``base`` and, welded to it at its COM, a flange of mass 1 with tensor ``flange``:
    the composite body's moments are the sum (no parallel-axis terms)."""
    return robot(f"""
        {link("base")}{link("arm", tensor(*base))}{link("flange", tensor(*flange))}
        {joint("j1", "base", "arm")}
        {joint("weld", "arm", "flange", "fixed")}""")


HALF_DIAGONAL = 0.05 * math.sqrt(3)
"""m: half the diagonal of a 0.1 m cube, the geometry of the links below."""
SOLID = (0.1 ** 2 + 0.1 ** 2) / 12
"""kg·m²: I_max of a solid 1 kg box of 0.1 m."""


def gyration_moment(ratio: float) -> float:
    """I_max of a 1 kg link whose radius of gyration is ``ratio`` half-diagonals of a 0.1 m cube."""
    return (ratio * HALF_DIAGONAL) ** 2


def gyration(ratio: float) -> str:
    """A 1 kg link in a 0.1 m collision cube, its tensor at ``ratio`` half-diagonals (I007)."""
    moment = gyration_moment(ratio)
    return arm(link_extra=tensor(moment, moment, moment) + box("0.1 0.1 0.1"))


def in_kg_mm2(reference_ratio: float, moment: float) -> str:
    """A base at ``reference_ratio`` (the robot's typical link) and an arm whose tensor is ``moment`` kg·m²
    written in kg·mm² (x 1e6): I007 names the unit when both plausibility tests pass."""
    reference = gyration_moment(reference_ratio)
    written = moment * 1e6
    return robot(f"""
        {link("base", tensor(reference, reference, reference) + box("0.1 0.1 0.1"))}
        {link("arm", tensor(written, written, written) + box("0.1 0.1 0.1"))}
        {joint("j1", "base", "arm")}""")


def density(mass: float, size: str = "0.5 0.5 0.5") -> str:
    """One link of ``mass`` whose collision (and visual) is a box of ``size``."""
    return robot(link("base", tensor(0.01, 0.01, 0.01, mass) + both(size)))


def grams(mass: float) -> str:
    """A 1000 kg/m³ base and a 0.1 m arm link of ``mass`` (typed in grams when ~1000x the base's density)."""
    return robot(f"""
        {link("base", tensor(0.01, 0.01, 0.01, 1.0) + both("0.1 0.1 0.1"))}
        {link("arm", tensor(0.01, 0.01, 0.01, mass) + both("0.1 0.1 0.1"))}
        {joint("j1", "base", "arm")}""")


def masses(base: float, arm_mass: float) -> str:
    return arm(base_extra=tensor(0.1, 0.1, 0.1, base), link_extra=tensor(1e-9, 1e-9, 1e-9, arm_mass))


def planar_base(carried: float) -> str:
    """A chassis of ``carried`` kg moved in the plane through a virtual x link without <inertial> (a prismatic
    joint from a geometry-less root, then the yaw joint): Clearpath's Ridgeback in one axis (I017)."""
    return robot(f"""
        {link("odom", "")}{link("x_link", "")}{link("chassis", tensor(4, 8, 10, carried))}
        {joint("x", "odom", "x_link", "prismatic", axis="1 0 0", extra=limit(-100, 100))}
        {joint("yaw", "x_link", "chassis")}""")


TALL = math.dist((-0.025, -0.025, 0.0), (0.025, 0.025, 0.3))
"""m: the diagonal of the arm's 0.05 x 0.05 x 0.3 box below."""


def com_above(height: float) -> str:
    """The arm's only geometry is a 0.05 x 0.05 x 0.3 box standing on its origin; its COM at ``height``."""
    return robot(f"""
        {link("base", "")}
        <link name="arm"><inertial><origin xyz="0 0 {height!r}"/><mass value="1"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>{box("0.05 0.05 0.3", "0 0 0.15")}</link>
        {joint("j1", "base", "arm")}""")


def small_com(x: float) -> str:
    """A 5 cm part among two 2 m parts (the robot's median link: 2√3 m), its COM at ``x``."""
    return robot(f"""
        {link("base", LINK_INERTIAL + box("2 2 2"))}{link("body", LINK_INERTIAL + box("2 2 2"))}
        <link name="part"><inertial><origin xyz="{x!r} 0 0"/><mass value="1"/>
          <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>{box("0.05 0.05 0.05")}</link>
        {joint("weld", "base", "body", "fixed")}{joint("j1", "body", "part")}""")


# ---- G: geometry ---------------------------------------------------------------------------------------------

CUBE = {"meshes/cube.stl": box_stl(1.0)}
"""A 1 m cube, scaled by each document."""


def scaled(visual: str, collision: str | None = None, more: str = "") -> Doc:
    """One link drawn (and collided) with the 1 m cube at these scales, and ``more`` of the robot."""
    shapes = f'<visual><geometry><mesh filename="meshes/cube.stl" scale="{visual}"/></geometry></visual>'
    if collision is not None:
        shapes += f'<collision><geometry><mesh filename="meshes/cube.stl" scale="{collision}"/></geometry></collision>'
    return Doc(robot(link("base", LINK_INERTIAL + shapes) + more), CUBE)


def uniform(factor: float) -> str:
    return " ".join([repr(factor)] * 3)


def spanned(span: float) -> Doc:
    """The 1 m cube scaled to 6 m on a robot whose kinematic span is ``span``: a frame welded that far away (G006)."""
    return scaled(uniform(6.0), more=link("frame", "") + joint("weld", "base", "frame", "fixed", xyz=f"{span!r} 0 0"))


def marker(side: float, mass: float = 1.0) -> str:
    """A link drawn as a cube of ``side`` with no collision, weighing ``mass``, welded 2 m above two 1 m parts
    (outside their collisions, which would enclose it)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + both("1 1 1"))}{link("body", LINK_INERTIAL + both("1 1 1"))}
        {link("marker", tensor(1e-6, 1e-6, 1e-6, mass) + box(uniform(side), role="visual"))}
        {joint("weld", "base", "body", "fixed")}{joint("tag", "body", "marker", "fixed", xyz="0 0 2")}""")


def light_marker(mass: float) -> str:
    """A 0.5 m visual-only link of ``mass`` welded 2 m above a 1 kg robot (outside its collision)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + both("1 1 1"))}
        {link("marker", tensor(1e-9, 1e-9, 1e-9, mass) + box("0.5 0.5 0.5", role="visual"))}
        {joint("tag", "base", "marker", "fixed", xyz="0 0 2")}""")


def frame_drawing(side: float) -> str:
    """A link without <inertial> drawn as a cube of ``side``, welded 2 m above a 1 m part: a frame drawn for people
    when its box is smaller than half its parent's (G008)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + both("1 1 1"))}{link("frame", box(uniform(side), role="visual"))}
        {joint("weld", "base", "frame", "fixed", xyz="0 0 2")}""")


def corners(low: tuple[float, float, float], high: tuple[float, float, float]) -> str:
    """A collision box from ``low`` to ``high``."""
    centre = " ".join(repr((a + b) / 2) for a, b in zip(low, high))
    return box(" ".join(repr(b - a) for a, b in zip(low, high)), centre)


def enclosed(inside: int) -> str:
    """A 1 m visual-only part (its box 0..1 on each axis) on a hinge, ``inside`` (56 to 60) of the 4 x 4 x 4 cell
    centres G008 samples in its box covered by its parent's three collision boxes: x < 0.75 (48), then y < 0.5
    (8), then y < 0.75 and z < (inside - 56) / 4 (a point per quarter: the centres sit at 0.125, 0.375, ...)."""
    covers = (corners((-1, -1, -1), (0.75, 2, 2)) + corners((0.75, -1, -1), (2, 0.5, 2))
              + corners((0.75, 0.5, -1), (2, 0.75, (inside - 56) / 4)))
    return robot(f"""
        {link("base", LINK_INERTIAL + covers)}{link("part", LINK_INERTIAL + box("1 1 1", "0.5 0.5 0.5", "visual"))}
        {joint("j1", "base", "part")}""")


def enclosed_from(frames: int) -> str:
    """A 0.5 m visual-only part inside the 2 m collision cube of the base, ``frames + 1`` joints up the chain through
    geometry-less links (G008 looks for covers NEIGHBOUR_DEPTH joints away)."""
    chain = ["base", *(f"frame{index}" for index in range(frames)), "part"]
    links = [link("base", LINK_INERTIAL + box("2 2 2")), *(link(name) for name in chain[1:-1]),
             link("part", LINK_INERTIAL + box("0.5 0.5 0.5", role="visual"))]
    joints = [joint(f"j{index}", parent, child) for index, (parent, child) in enumerate(zip(chain, chain[1:]))]
    return robot("".join(links + joints))


def stl(triangles: int, extra: bytes = b"") -> Doc:
    """A binary STL holding ``triangles`` copies of one triangle, with ``extra`` bytes after them."""
    triangle = ((0, 0, 0), (0.1, 0, 0), (0, 0.1, 0))
    return Doc(robot(link("part", LINK_INERTIAL + '<collision><geometry><mesh filename="meshes/part.stl"/>'
                                                   '</geometry></collision>')),
               {"meshes/part.stl": binary_stl([triangle] * triangles) + extra})


def obj(text: str, size: int | None = None) -> Doc:
    """A collision mesh ``meshes/part.obj`` holding ``text``, padded with comments to ``size`` bytes."""
    data = text.encode()
    if size is not None:
        data += b"#" * (size - len(data) - 1) + b"\n"
    return Doc(robot(link("part", LINK_INERTIAL + '<collision><geometry><mesh filename="meshes/part.obj"/>'
                                                   '</geometry></collision>')), {"meshes/part.obj": data})


def slab(thickness: float) -> str:
    """A closed 1 x 1 x ``thickness`` box as OBJ, its faces split over two objects (PyBullet then makes a hull
    of each, and G012's hull test does not apply: only the box's extents decide)."""
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, thickness)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    lines = [f"v {x} {y} {z!r}" for x, y, z in corners]
    for index, (a, b, c) in enumerate(faces):
        if index % 6 == 0:
            lines.append(f"o part{index}")
        lines.append(f"f {a + 1} {b + 1} {c + 1}")
    return "\n".join(lines) + "\n"


def needle(share: float) -> str:
    """A closed tetrahedron along the diagonal of a unit cube whose volume is ``share`` x 1e-9 of the
    diagonal cubed (two corners eps off the diagonal's midpoint: volume eps² / 6). G012 snaps the corners to
    a grid of 1/2**20 of the diagonal before measuring the hull, so its volume is known to about 2 %."""
    eps = math.sqrt(share * 1e-9 * 3 ** 1.5 * 6)
    corners = [(0, 0, 0), (1, 1, 1), (0.5 + eps, 0.5, 0.5), (0.5, 0.5 + eps, 0.5)]
    return ("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in corners)
            + "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")


def two_cubes(gap: float) -> str:
    """Two unit cubes ``gap`` apart in one OBJ object: hull / volume = (2 + gap) / 2."""
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
             (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    lines = []
    for first, offset in ((1, 0.0), (9, 1.0 + gap)):
        lines += [f"v {x + offset!r} {y} {z}" for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        lines += [f"f {a + first} {b + first} {c + first}" for a, b, c in faces]
    return "\n".join(lines) + "\n"


HULL_MAX_BYTES = 2 * 1024 * 1024
"""meshinfo's limit for examining a mesh's hull, written here rather than imported (as every number of these
edges is): a constant that moves must fail its edge, not move the edge with it."""


def apart(gap: float, side: float) -> str:
    """Two cubes of ``side`` one above the other, their boxes ``gap`` apart at home (G014)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + box(uniform(side)))}{link("arm", LINK_INERTIAL + box(uniform(side)))}
        {joint("j1", "base", "arm", xyz=f"0 0 {side + gap!r}")}""")


def walked(frames: int) -> str:
    """A 1 cm part 3 m above the base through ``frames`` geometry-less links (G014 walks up to 8)."""
    chain = ["base", *(f"frame{index}" for index in range(frames)), "tip"]
    links = [link("base", LINK_INERTIAL + box("0.01 0.01 0.01"))]
    links += [link(name, "") for name in chain[1:-1]] + [link("tip", LINK_INERTIAL + box("0.01 0.01 0.01"))]
    joints = [joint(f"j{index}", parent, child, "fixed", xyz="0 0 3" if child == "tip" else "0 0 0")
              for index, (parent, child) in enumerate(zip(chain, chain[1:]))]
    return robot("".join(links + joints))


def siblings(before: int) -> str:
    """``before`` small children beside the base, then a part 3 m away and its twin next to it: the part is
    near a sibling only when the twin is among the first 16 children compared (G014)."""
    parts = [link("base", LINK_INERTIAL + box("0.01 0.01 0.01"))]
    joints = []
    for index in range(before):
        parts.append(link(f"small{index}", LINK_INERTIAL + box("0.01 0.01 0.01")))
        joints.append(joint(f"s{index}", "base", f"small{index}", "fixed", xyz="0 0 0.01"))
    for name, xyz in (("far", "0 0 3"), ("twin", "0 0 3.02")):
        parts.append(link(name, LINK_INERTIAL + box("0.01 0.01 0.01")))
        joints.append(joint(name, "base", name, "fixed", xyz=xyz))
    return robot("".join(parts + joints))


def collision_shift(x: float, visual: float = 0.1, collision: str | None = None) -> str:
    """A visual cube of ``visual`` at the origin and a collision box (a cube of ``visual`` unless
    ``collision`` gives its size) ``x`` away along x (G015)."""
    size = collision or uniform(visual)
    return robot(link("base", LINK_INERTIAL + box(uniform(visual), role="visual") + box(size, f"{x!r} 0 0")))


PAD = 5e-4
"""m: G015 pads each box by this much on every side (flat boxes still have a volume)."""


def covering(covered: float, x: float = 0.15) -> str:
    """A collision box centred ``x`` from a 0.1 m visual cube, wide enough to cover ``covered`` of it (G015)."""
    width = 2 * (covered * (0.1 + 2 * PAD) - (0.05 + 2 * PAD) + x)
    return collision_shift(x, collision=f"{width!r} 0.2 0.2")


def axis_offset(x: float, side: float) -> str:
    """A hinge about z whose child is a cube of ``side`` centred ``x`` from the axis (G016)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + box(uniform(side)))}{link("arm", LINK_INERTIAL + box(uniform(side), f"{x!r} 0 0"))}
        {joint("j1", "base", "arm", xyz="0 0 1")}""")


def colour(rgba: str) -> str:
    return robot(link("base", LINK_INERTIAL + '<visual><geometry><box size="0.1 0.1 0.1"/></geometry>'
                                              f'<material name="paint"><color rgba="{rgba}"/></material></visual>'))


# ---- P, M: simulation --------------------------------------------------------------------------------------

def sphere(radius: float, xyz: str = "0 0 0") -> str:
    return f'<collision><origin xyz="{xyz}"/><geometry><sphere radius="{radius!r}"/></geometry></collision>'


SWING = 0.5
"""m: how far the ball below swings from its hinge, and the hinge from the base's centre."""


def swinging_ball(radius: float, depth: float, before: int = 0) -> str:
    """Two spheres of ``radius``; the child's centre is SWING from a hinge that stands SWING from the parent's, so
    at angle θ the centres are 2 SWING sin((π/2 - θ) / 2) apart (0.71 m at home): the upper limit is the angle that
    sinks it ``depth`` into its parent, exactly. ``before`` geometry-less revolute joints come first."""
    upper = math.pi / 2 - 2 * math.asin((2 * radius - depth) / (2 * SWING))
    fillers = [link(f"l{index}") for index in range(before)]
    chain = ["base", *(f"l{index}" for index in range(before))]
    joints = [joint(f"j{index}", parent, child, extra=limit(-0.1, 0.1))
              for index, (parent, child) in enumerate(zip(chain, chain[1:]))]
    return robot(f"""
        {link("base", LINK_INERTIAL + sphere(radius))}{"".join(fillers)}
        {link("ball", LINK_INERTIAL + sphere(radius, f"{SWING} 0 0"))}{"".join(joints)}
        {joint("swing", chain[-1], "ball", xyz=f"0 {-SWING} 0", extra=limit(0, upper))}""")


def touching(overlap: float, base_visual: str = "") -> str:
    """Base and tip spheres (5 cm) overlapping by ``overlap`` at home, joined through a small middle link; the base
    drawn as ``base_visual``."""
    return robot(f"""
        {link("base", LINK_INERTIAL + sphere(0.05) + base_visual)}{link("mid", LINK_INERTIAL + sphere(0.01))}
        {link("tip", LINK_INERTIAL + sphere(0.05))}
        {joint("j1", "base", "mid", xyz="1 0 0")}{joint("j2", "mid", "tip", xyz=f"{-0.9 - overlap!r} 0 0")}""")


def cluster(spread: float, tip: float = 0.05) -> str:
    """A 5 cm base sphere and a tip sphere of radius ``tip`` deep in it, two hinges ``spread`` apart between them
    (the first at the base's centre, through a 1 cm middle link): a joint cluster when the hinges are within
    CLUSTER_RADIUS and half the smaller link's size (its box diagonal: 2√3 ``tip``) of each other (P002)."""
    return robot(f"""
        {link("base", LINK_INERTIAL + sphere(0.05))}{link("mid", LINK_INERTIAL + sphere(0.01))}
        {link("tip", LINK_INERTIAL + sphere(tip))}
        {joint("j1", "base", "mid")}{joint("j2", "mid", "tip", xyz=f"{spread!r} 0 0")}""")


def fingers(overlap: float) -> str:
    """Two 5 cm finger spheres on two hinges of a small base (two branches), overlapping by ``overlap`` at home."""
    return robot(f"""
        {link("base", LINK_INERTIAL + sphere(0.01))}
        {link("left", LINK_INERTIAL + sphere(0.05))}{link("right", LINK_INERTIAL + sphere(0.05))}
        {joint("j1", "base", "left", xyz="0 0 0.2")}{joint("j2", "base", "right", xyz=f"0 {0.1 - overlap!r} 0.2")}""")


def settles_at(speed: float, fastest: float) -> Callable[[], bool]:
    """Whether P004/M004 report a joint still moving at ``speed`` after settling (``fastest`` is the rule's limit)."""
    return lambda: pybullet_sim.unstable_hit([("j1", None, 0.0, speed)], "after settling", fastest) is not None


# ---- the table ---------------------------------------------------------------------------------------------

EDGES: dict[str, tuple[Edge, ...]] = {
    "F008": (Edge("400 files", library_package(399), library_package(400), contains="included by"),),
    "S016": (Edge("lengths within 2", joint_child("orig"), joint_child("ori")),
             Edge("similarity 0.6", joint_child("calibrqqq"), joint_child("calibrqqqq"))),  # 12/20 = 0.6, 12/21
    "S017": (Edge("lengths within 2", limit_attribute("veloci"), limit_attribute("veloc")),  # velocity: 8 letters
             Edge("similarity 0.6", limit_attribute("velocqqq"), limit_attribute("velocqqqq"))),  # 10/16, 10/17
    "J003": (Edge("(1, -1)", revolute_limits(1, -1.001), revolute_limits(1, -1)),
             Edge("(0, -1)", revolute_limits(0, -1.001), revolute_limits(0, -1))),
    "J014": (Edge("(1, -1)", prismatic_limits(1, -1), prismatic_limits(1, -1.001)),
             Edge("(0, -1)", prismatic_limits(0, -1), prismatic_limits(0.001, -1))),
    "J005": (Edge("RADIAN_PLAUSIBLE", revolute_limits(-1, 15), revolute_limits(-1, 10)),  # the multiples of 5 around 4π
             Edge("DEGREE_PLAUSIBLE", revolute_limits(-1, 720), revolute_limits(-1, 725)),
             Edge("DEGREE_STEP", revolute_limits(-1, 95), revolute_limits(-1, 96)),
             Edge("DUMMY_MASS", virtual_base(1.01e-3), virtual_base(0.99e-3))),
    "J010": (Edge("1e-3", arm().replace('xyz="0 0 1"', 'xyz="0 0 1.0011"'),
                  arm().replace('xyz="0 0 1"', 'xyz="0 0 1.0009"')),),
    "J015": (Edge("FULL_TURN", rpy("0 0 6.2932"), rpy("0 0 6.2931")),  # 2π + 0.01 = 6.29318
             Edge("360", rpy("0 0 360"), rpy("0 0 360.01"))),
    "J016": (Edge("SAME_SPEED", two_speeds(180, 3.0803), two_speeds(180, 3.0797)),  # π / 1.02 = 3.07999
             Edge("DEGREE_SPEED_STEP", two_speeds(185, degrees(185)), two_speeds(184, degrees(184))),
             Edge("2 pi", two_speeds(10, degrees(10)), two_speeds(5, degrees(5))),  # the multiples of 5 around 2π
             Edge("720", two_speeds(720, degrees(720)), two_speeds(725, degrees(725)))),
    "I004": (Edge("EFFECTIVELY_ZERO", moving_tensor(1.02e-15, 1.02e-15, -1.02e-15),
                  moving_tensor(0.98e-15, 0.98e-15, -0.98e-15)),),
    "I005": (Edge("TRIANGLE_TOLERANCE", moving_tensor(1, 1, 2.00203), moving_tensor(1, 1, 2.00198)),  # 2 / (1 - 1e-3 x 1.014, 0.989)
             Edge("EFFECTIVELY_ZERO", moving_tensor(0.2e-15, 0.2e-15, 1.02e-15),
                  moving_tensor(0.2e-15, 0.2e-15, 0.98e-15))),
    "I006": (Edge("EFFECTIVELY_ZERO", moving_tensor(0.98e-15, 0.98e-15, 0.98e-15),
                  moving_tensor(1.02e-15, 1.02e-15, 1.02e-15)),
             Edge("NEAR_SINGULAR_RATIO", welded_to((0, 0, 0), (0.98e-9, 1, 1)), welded_to((0, 0, 0), (1.02e-9, 1, 1)))),
    "I008": (Edge("EFFECTIVELY_ZERO", fixed_child(tensor(0.98e-15, 0.98e-15, 0.98e-15)),
                  fixed_child(tensor(1.02e-15, 1.02e-15, 1.02e-15))),
             Edge("NEAR_SINGULAR_RATIO", welded_to((0, 0, 0), (1.02e-9, 1, 1)), welded_to((0, 0, 0), (0.98e-9, 1, 1)))),
    "I009": (Edge("NEAR_SINGULAR_RATIO", moving_tensor(0.98e-9, 1, 1), moving_tensor(1.02e-9, 1, 1)),
             Edge("MJ_MINVAL", moving_tensor(0.98e-15, 1e-7, 1e-7), moving_tensor(1.02e-15, 1e-7, 1e-7))),
    "I007": (Edge("IMPLAUSIBLE_FACTOR", gyration(3.03), gyration(2.97)),
             Edge("SAME_SHAPE", in_kg_mm2(1.0, gyration_moment(0.202)), in_kg_mm2(1.0, gyration_moment(0.198)),
                  contains="looks like kg·mm²"),  # a fifth of the typical link's ratio
             Edge("SOLID_RANGE", in_kg_mm2(0.3, 0.051 * SOLID), in_kg_mm2(0.3, 0.049 * SOLID), contains="looks like"),
             Edge("SOLID_RANGE", in_kg_mm2(0.3, 3.96 * SOLID), in_kg_mm2(0.3, 4.04 * SOLID), contains="looks like")),
    "I013": (Edge("MIN_DENSITY", density(6.2), density(6.3)),  # 49.6 and 50.4 kg/m³ in a 0.125 m³ box
             Edge("MAX_DENSITY", density(25.1, "0.1 0.1 0.1"), density(24.9, "0.1 0.1 0.1")),
             Edge("DENSITY_MIN_MASS", density(0.051), density(0.049)),
             Edge("SAME_MATERIAL", grams(101), grams(99), contains="looks like grams")),  # / 1000: 101 vs 1000 / 10
    "I014": (Edge("MIN_MASS", masses(1, 0.99e-3), masses(1, 1.01e-3)),),
    "I015": (Edge("MAX_MASS_RATIO", masses(10.01, 0.01), masses(9.99, 0.01)),
             Edge("MIN_MASS", masses(100, 1.01e-3), masses(100, 0.99e-3))),
    "I017": (Edge("PHANTOM_SHARE", planar_base(50.5), planar_base(49.5)),),  # 1 kg / 0.02 = 50 kg
    "I016": (Edge("COM_FACTOR", com_above(0.3 + 3.03 * TALL), com_above(0.3 + 2.97 * TALL)),
             Edge("COM_SCALE", small_com(0.025 + 0.505 * 2 * math.sqrt(3)), small_com(0.025 + 0.495 * 2 * math.sqrt(3)))),
    "G006": (Edge("MAX_PLAUSIBLE_EXTENT", scaled(uniform(5.05)), scaled(uniform(4.95))),
             Edge("FLAT_RATIO", scaled("6 6 0.0606"), scaled("6 6 0.0594")),
             Edge("MIN_PLAUSIBLE_EXTENT", scaled(uniform(0.00099)), scaled(uniform(0.00101))),
             Edge("SCALE_MISMATCH", scaled(uniform(0.01), uniform(2.51)), scaled(uniform(0.01), uniform(2.49))),
             Edge("SCALE_MISMATCH", scaled(uniform(0.0011), uniform(0.0011 * 3999)),
                  scaled(uniform(0.0011), uniform(0.0011 * 4001))),
             Edge("SPAN_FACTOR", spanned(1.98), spanned(2.02))),  # 6 m against 3.03 and 2.97 spans
    "G008": (Edge("MARKER_SIZE", marker(0.101), marker(0.099)),  # a tenth of the median link (√3 m), over √3
             Edge("MARKER_MASS", light_marker(1.02e-4), light_marker(0.98e-4)),
             Edge("FRAME_DRAWING", frame_drawing(0.505), frame_drawing(0.495)),
             Edge("ENCLOSED", enclosed(57), enclosed(58)),  # 57/64 = 0.89, 58/64 = 0.91: the grid allows no closer
             Edge("NEIGHBOUR_DEPTH", enclosed_from(2), enclosed_from(1))),
    "G011": (Edge("84 + 50 x count", stl(1, extra=b"\0"), stl(1)),
             Edge("count >= 1", stl(0), stl(1)),
             Edge("MAX_MESH_BYTES", Doc(stl(0).text, {"meshes/part.stl": 64 * 1024 * 1024 + 1}),
                  Doc(stl(0).text, {"meshes/part.stl": 64 * 1024 * 1024}), contains="MB limit")),
    "G012": (Edge("ZERO_THICKNESS", obj(slab(0.98e-9)), obj(slab(1.02e-9))),
             Edge("1e-9 of the diagonal cubed", obj(needle(0.98)), obj(needle(1.02))),
             Edge("2 MB", obj(needle(0.5), HULL_MAX_BYTES), obj(needle(0.5), HULL_MAX_BYTES + 1))),
    "G013": (Edge("HULL_RATIO", obj(two_cubes(2.04)), obj(two_cubes(1.96))),
             Edge("HULL_MAX_BYTES", obj(two_cubes(4), HULL_MAX_BYTES), obj(two_cubes(4), HULL_MAX_BYTES + 1))),
    "G014": (Edge("DETACHED_MIN_GAP", apart(0.2525, 0.01), apart(0.2475, 0.01)),
             Edge("DETACHED_FACTOR", apart(0.875, 0.5), apart(0.857, 0.5)),  # the diagonal: 0.866
             Edge("MAX_WALK", walked(7), walked(8)),
             Edge("MAX_SIBLINGS", siblings(15), siblings(14))),
    "G015": (Edge("OFFSET_FACTOR", collision_shift(0.0875), collision_shift(0.0857)),  # a half-diagonal: 0.0866
             Edge("OFFSET_MIN", collision_shift(0.0505, 0.02), collision_shift(0.0495, 0.02)),
             Edge("COVER_MIN", covering(0.198), covering(0.202))),
    "G016": (Edge("AXIS_FACTOR", axis_offset(0.05 + 0.175, 0.1), axis_offset(0.05 + 0.171, 0.1)),  # the diagonal: 0.1732
             Edge("AXIS_MIN", axis_offset(0.01 + 0.101, 0.02), axis_offset(0.01 + 0.099, 0.02))),
    "G017": (Edge("above 1", colour("1.01 0 0 1"), colour("1 0 0 1")),
             Edge("within 0-255", colour("255 0 0 1"), colour("255.1 0 0 1"))),
    "P002": (Edge("1 um", touching(1.02e-6), touching(0.98e-6)),
             Edge("CLUSTER_RADIUS", cluster(0.0303), cluster(0.0297)),
             Edge("half the smaller link's size", cluster(0.02, 0.98 * 0.02 / math.sqrt(3)),
                  cluster(0.02, 1.02 * 0.02 / math.sqrt(3))),
             Edge("TOUCH_DEPTH", fingers(3.03e-3), fingers(2.97e-3)),
             Edge("PLACEHOLDER", touching(1e-3, box(uniform(1.98), role="visual")),  # 5% of a 2 m cube's diagonal
                  touching(1e-3, box(uniform(2.02), role="visual")))),
    "M003": (Edge("PENETRATION", touching(1.02e-6), touching(0.98e-6)),),
    "P003": (Edge("INERTIA_TOLERANCE", lambda: pybullet_sim._differs(0.899, 1.0),
                  lambda: pybullet_sim._differs(0.901, 1.0)),),
    "P004": (Edge("MAX_SETTLE_SPEED", settles_at(101, pybullet_sim.MAX_SETTLE_SPEED),
                  settles_at(99, pybullet_sim.MAX_SETTLE_SPEED)),),
    "M004": (Edge("MAX_SETTLE_SPEED", settles_at(101, mujoco_rules.MAX_SETTLE_SPEED),
                  settles_at(99, mujoco_rules.MAX_SETTLE_SPEED)),),
    "P005": (Edge("SIZE_FRACTION", swinging_ball(0.05, 0.0612), swinging_ball(0.05, 0.0588)),  # 0.6 x 0.1 m
             Edge("MIN_NEW_DEPTH", swinging_ball(0.008, 0.0102), swinging_ball(0.008, 0.0098)),
             Edge("MAX_SWEPT_JOINTS", swinging_ball(0.05, 0.1, before=63), swinging_ball(0.05, 0.1, before=64))),
}
"""Rule code -> its thresholds' edges."""

NOT_COMPARED: dict[tuple[str, str], str] = {
    ("P004", "SETTLE_STEPS"): "how long the robot settles (1 s at PyBullet's 240 Hz) before the speed is compared",
    ("M004", "SETTLE_SECONDS"): "how long the robot settles before the speed is compared",
    ("P005", "SWEEP_STEPS"): "how many values of each joint's range the sweep tries, not a value compared with",
    ("J016", "DEGREE_SPEED_RATIO"): "never decides: a speed within SAME_SPEED of v·π/180 is v / 57.3 (± 2 %), "
                                    "always below v / 10, so no robot is on either side of it",
}
"""(rule code, constant) -> why the constant has no edges: it is no value anything is compared with."""
