"""Structure rules (S): names, the kinematic tree, and references between elements."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator

from ar3cli.lint.rules.base import Hit, arm, robot, rule
from ar3cli.urdf.model import URDF_JOINT_TYPES

JOINT_TYPES = URDF_JOINT_TYPES
PYBULLET_JOINT_TYPES = ("spherical",)
"""Joint types PyBullet accepts beyond the URDF spec (S010)."""


@rule("S001", "robot-name", "error", "<robot> has no name",
      why="urdfdom (check_urdf, ROS robot_state_publisher) refuses a <robot> without a name attribute.",
      fix='Add name="..." to <robot>.',
      bad='<?xml version="1.0"?>\n<robot>\n  <link name="base"/>\n</robot>\n',
      good=robot('<link name="base"/>'))
def robot_name(ctx) -> Iterator[Hit]:
    if not (ctx.model.root.get("name") or "").strip():
        yield Hit("<robot> has no name attribute", ctx.model.root)


def _duplicates(elements, kind: str) -> Iterator[Hit]:
    counts = Counter(element.get("name") for element in elements)
    first: set[str] = set()
    for element in elements:
        name = element.get("name")
        if name is None:
            yield Hit(f"<{kind}> has no name attribute", element, hint=f"Give every <{kind}> a unique name.")
        elif counts[name] > 1:
            if name in first:
                yield Hit(f"{kind} '{name}' is defined {counts[name]} times", element)
            first.add(name)


@rule("S002", "duplicate-link", "error", "Duplicate or missing link name",
      why="""Joints refer to links by name; with two links of the same name urdfdom refuses the file,
      and tools that accept it (PyBullet, yourdfpy) silently pick one of them.""",
      fix="Rename or remove one of the links.",
      bad=robot('<link name="base"/>\n<link name="base"/>'),
      good=robot('<link name="base"/>'))
def duplicate_link(ctx) -> Iterator[Hit]:
    yield from _duplicates([link.element for link in ctx.model.links], "link")


@rule("S003", "duplicate-joint", "error", "Duplicate or missing joint name",
      why="""Controllers, mimic tags and transmissions refer to joints by name; duplicates make those
      references ambiguous and urdfdom refuses the file.""",
      fix="Rename or remove one of the joints.",
      bad=robot("""
          <link name="a"/><link name="b"/><link name="c"/>
          <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
          <joint name="j" type="fixed"><parent link="b"/><child link="c"/></joint>"""),
      good=robot("""
          <link name="a"/><link name="b"/><link name="c"/>
          <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
          <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>"""))
def duplicate_joint(ctx) -> Iterator[Hit]:
    yield from _duplicates([joint.element for joint in ctx.model.joints], "joint")


@rule("S004", "missing-link", "error", "Joint names a link that does not exist",
      why="A joint whose <parent> or <child> is missing or names an unknown link cannot be built by any tool.",
      fix="Fix the link name (check the spelling) or add the link.",
      bad=robot("""
          <link name="base"/><link name="arm"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="amr"/></joint>"""),
      good=robot("""
          <link name="base"/><link name="arm"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="arm"/></joint>"""))
def missing_link(ctx) -> Iterator[Hit]:
    names = {link.name for link in ctx.model.links}
    for joint in ctx.model.joints:
        for role, value in (("parent", joint.parent), ("child", joint.child)):
            if value is None:
                yield Hit(f"joint '{joint.name}' has no <{role} link=...>", joint.element)
            elif value not in names:
                yield Hit(f"joint '{joint.name}' {role} link '{value}' does not exist", joint.element)


@rule("S005", "several-roots", "error", "Several root links or orphan links",
      why="""A URDF is one tree with exactly one root. A link that no joint connects is a second root:
      urdfdom refuses the file, PyBullet loads only one tree and drops the rest without a word.""",
      fix="Connect the orphan link with a joint, or delete it.",
      bad=robot('<link name="base"/>\n<link name="orphan"/>'),
      good=robot("""
          <link name="base"/><link name="tool"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="tool"/></joint>"""))
def several_roots(ctx) -> Iterator[Hit]:
    roots = ctx.model.root_links()
    if len(roots) <= 1:
        return
    connected = {j.parent for j in ctx.model.joints} | {j.child for j in ctx.model.joints}
    # The first root that has children is the real one; report the others.
    main = next((link for link in roots if link.name in connected), roots[0])
    names = ", ".join(link.name for link in roots)
    for link in roots:
        if link is main:
            continue
        kind = "is not connected by any joint" if link.name not in connected else "is a second root"
        yield Hit(f"link '{link.name}' {kind} ({len(roots)} roots: {names})", link.element)


@rule("S006", "not-a-tree", "error", "Link with two parents, or a kinematic cycle",
      why="""URDF describes a tree: every link but the root has exactly one parent joint. A link with
      two parents or a loop crashes check_urdf (segfault in urdfdom 3.0) and is silently broken in
      other tools.""",
      fix="Remove one of the joints; model closed chains with a mimic joint or in the simulator.",
      bad=robot("""
          <link name="a"/><link name="b"/>
          <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
          <joint name="j2" type="fixed"><parent link="b"/><child link="a"/></joint>"""),
      good=robot("""
          <link name="a"/><link name="b"/>
          <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>"""))
def not_a_tree(ctx) -> Iterator[Hit]:
    model = ctx.model
    parents: dict[str, list] = {}
    for joint in model.joints:
        if joint.child is not None:
            parents.setdefault(joint.child, []).append(joint)
    for child, joints in parents.items():
        for joint in joints[1:]:
            yield Hit(f"link '{child}' has {len(joints)} parent joints ({', '.join(j.name for j in joints)}); "
                      f"joint '{joint.name}' is one too many", joint.element)
    # Cycles: follow the first parent joint upwards from every link.
    parent_of = {child: joints[0] for child, joints in parents.items()}
    reported: set[str] = set()
    for start in parent_of:
        seen: list[str] = []
        link = start
        while link in parent_of and link not in seen:
            seen.append(link)
            link = parent_of[link].parent
        if link in seen:
            loop = seen[seen.index(link):]
            key = min(loop)
            if key not in reported:
                reported.add(key)
                joint = parent_of[key]
                yield Hit(f"joints form a cycle through links {' -> '.join(loop)} -> {link}", joint.element)


@rule("S007", "unknown-joint-reference", "error", "Mimic or transmission names an unknown joint",
      why="""A <mimic joint="..."> or a <transmission> <joint name="..."> that names no joint is
      ignored by some tools and an error in others (ros_control refuses to start).""",
      fix="Fix the joint name in the mimic/transmission, or remove it.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><mimic joint="j0"/>'),
      good=arm())
def unknown_joint_reference(ctx) -> Iterator[Hit]:
    names = {joint.name for joint in ctx.model.joints}
    for joint in ctx.model.joints:
        if joint.mimic is not None and joint.mimic.joint not in names:
            yield Hit(f"joint '{joint.name}' mimics unknown joint '{joint.mimic.joint}'", joint.mimic.element)
        if joint.mimic is not None and joint.mimic.joint == joint.name:
            yield Hit(f"joint '{joint.name}' mimics itself", joint.mimic.element)
    for transmission in ctx.model.root.iter("transmission"):
        for element in transmission.iter("joint"):
            name = element.get("name")
            if name not in names:
                yield Hit(f"transmission '{transmission.get('name', '?')}' names unknown joint '{name}'", element)


@rule("S008", "undefined-material", "info", "Material used but never defined",
      why="""A <material name="x"/> without <color> or <texture> refers to a top-level
      <material name="x"> definition. When there is none, check_urdf (urdfdom 3.0.1, measured) and
      PyBullet load the file without a word and draw the default colour: the intended colour is lost.""",
      fix="Define <material name=\"x\"><color rgba=\"...\"/></material> at the top level, or add a <color>.",
      bad=robot('<link name="base"><visual><geometry><box size="1 1 1"/></geometry><material name="blue"/></visual></link>'),
      good=robot("""
          <material name="blue"><color rgba="0 0 1 1"/></material>
          <link name="base"><visual><geometry><box size="1 1 1"/></geometry><material name="blue"/></visual></link>"""))
def undefined_material(ctx) -> Iterator[Hit]:
    defined = {m.get("name") for m in ctx.model.root.findall("material")}
    for link in ctx.model.links:
        for shape in link.visuals:
            for material in shape.element.findall("material"):
                name = material.get("name")
                has_own = material.find("color") is not None or material.find("texture") is not None
                if not has_own and name not in defined:
                    yield Hit(f"link '{link.name}' uses material '{name}', which is never defined", material)


@rule("S009", "joint-type", "error", "Joint type missing or unknown",
      why="""The type must be one of revolute, continuous, prismatic, fixed, floating, planar.
      urdfdom refuses anything else; PyBullet refuses the file with "Joint type not supported".""",
      fix="Use one of: " + ", ".join(JOINT_TYPES) + ".",
      bad=arm(joint_type="hinge"), good=arm())
def joint_type(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type not in (*JOINT_TYPES, *PYBULLET_JOINT_TYPES):
            shown = f"'{joint.type}'" if joint.type else "missing"
            yield Hit(f"joint '{joint.name}' type is {shown}", joint.element)


@rule("S010", "pybullet-joint-type", "warning", "Joint type only PyBullet understands",
      why="""PyBullet accepts type="spherical" (a ball joint), but it is not part of URDF: urdfdom,
      ROS, MoveIt and yourdfpy refuse the file.""",
      fix="Keep the file PyBullet-only, or replace the ball joint by three revolute joints with massless links.",
      bad=arm(joint_type="spherical"), good=arm())
def pybullet_joint_type(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in PYBULLET_JOINT_TYPES:
            yield Hit(f"joint '{joint.name}' type '{joint.type}' is a PyBullet extension, not URDF", joint.element)


@rule("S011", "no-links", "error", "<robot> has no links",
      why="""A robot is a tree of links. urdfdom refuses a file without one ("No link elements found in
      urdf file") and PyBullet cannot load it; an empty <robot> is usually a xacro argument or macro
      that expanded to nothing.""",
      fix="Add the links, or check the xacro arguments that should have produced them.",
      bad='<?xml version="1.0"?>\n<robot name="empty"/>\n',
      good=robot('<link name="base"/>'))
def no_links(ctx) -> Iterator[Hit]:
    if not ctx.model.links:
        yield Hit("<robot> has no <link> elements", ctx.model.root)


RULES = (robot_name, duplicate_link, duplicate_joint, missing_link, several_roots, not_a_tree,
         unknown_joint_reference, undefined_material, joint_type, pybullet_joint_type, no_links)
