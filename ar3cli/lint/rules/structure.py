"""Structure rules (S): names, the kinematic tree, and references between elements."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator

from ar3cli.findings import listed
from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.urdf.model import URDF_JOINT_TYPES

JOINT_TYPES = URDF_JOINT_TYPES
PYBULLET_JOINT_TYPES = ("spherical",)
"""Joint types PyBullet accepts beyond the URDF spec (S010)."""


@rule("S001", "robot-name", "error", "<robot> has no name",
      engines=("ros",), refused_by=("ros",), breaks="urdfdom (check_urdf, robot_state_publisher) refuses the file.",
      why="""urdfdom (check_urdf, ROS robot_state_publisher) refuses a <robot> without a name attribute. An
      empty <robot> (no links either) is S011's, which says the name is missing too.""",
      fix='Add name="..." to <robot>.',
      bad='<?xml version="1.0"?>\n<robot>\n  <link name="base"/>\n</robot>\n',
      good=robot('<link name="base"/>'))
def robot_name(ctx) -> Iterator[Hit]:
    if not (ctx.model.root.get("name") or "").strip() and ctx.model.links:  # an empty <robot> is S011's
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
      refused_by=("ros",), breaks="urdfdom refuses the file; PyBullet and yourdfpy silently pick one of the links.",
      why="""Joints refer to links by name; with two links of the same name urdfdom refuses the file,
      and tools that accept it (PyBullet, yourdfpy) silently pick one of them.""",
      fix="Rename or remove one of the links.",
      bad=robot('<link name="base"/>\n<link name="base"/>'),
      good=robot('<link name="base"/>'))
def duplicate_link(ctx) -> Iterator[Hit]:
    yield from _duplicates([link.element for link in ctx.model.links], "link")


@rule("S003", "duplicate-joint", "error", "Duplicate or missing joint name",
      refused_by=("ros",), breaks="urdfdom refuses the file.",
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
      refused_by=("ros", "pybullet", "mujoco"),
      breaks="urdfdom, PyBullet and MuJoCo refuse the file (MuJoCo 4.0: \"URDF joint parent or child missing\").",
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
      refused_by=("ros",), breaks="urdfdom refuses the file; PyBullet silently drops every tree but one.",
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
    names = listed(link.name for link in roots)  # once for all: a message per root naming all of them is quadratic
    for link in roots:
        if link is main:
            continue
        kind = "is not connected by any joint" if link.name not in connected else "is a second root"
        yield Hit(f"link '{link.name}' {kind} ({len(roots)} roots: {names})", link.element)


@rule("S006", "not-a-tree", "error", "Link with two parents, or a kinematic cycle",
      refused_by=("ros",), breaks="check_urdf crashes (urdfdom 3.0 segfaults); other tools build a broken tree.",
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
            yield Hit(f"link '{child}' has {len(joints)} parent joints ({listed(j.name for j in joints)}); "
                      f"joint '{joint.name}' is one too many", joint.element)
    # Cycles: follow the first parent joint upwards from every link, stopping at a link an earlier
    # walk already went through (its way up is known), so every link is walked once: linear in the
    # number of links, also for a chain of thousands.
    parent_of = {child: joints[0] for child, joints in parents.items()}
    reported: set[str] = set()
    walked: set[str] = set()
    for start in parent_of:
        seen: dict[str, int] = {}  # link -> position on this walk
        link = start
        while link in parent_of and link not in seen and link not in walked:
            seen[link] = len(seen)
            link = parent_of[link].parent
        walked.update(seen)
        if link in seen:
            loop = list(seen)[seen[link]:]
            key = min(loop)
            if key not in reported:
                reported.add(key)
                joint = parent_of[key]
                yield Hit(f"joints form a cycle through links {listed([*loop, link], separator=' -> ')}", joint.element)


@rule("S007", "unknown-joint-reference", "error", "Reference to a joint or link that does not exist",
      engines=("drake", "ros", "gazebo"),
      refused_by=("drake", "gazebo"),
      breaks="Drake refuses a mimic of a joint that does not exist; gazebo_ros_control refuses to start on a "
             "transmission that names one.",
      why="""A <mimic joint="...">, a <transmission> <joint name="...">, a <ros2_control> <joint
      name="..."> or a <gazebo reference="..."> that names no joint (or link) is ignored by some
      tools and an error in others: ros_control and ros2_control refuse to start, Drake refuses a
      transmission or mimic of a missing joint, and Gazebo applies the <gazebo> block (friction,
      material, sensor, plugin) to nothing, without a word.""",
      fix="Fix the name (check the spelling and any xacro prefix), or remove the element.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><mimic joint="j0"/>'),
      good=arm(),
      references="Drake multibody/parsing/detail_urdf_parser.cc (ParseMimicTag, ParseTransmission: \"which does not "
                 "exist\"); gazebo_ros_control default_robot_hw_sim.cpp (\"which is not in the gazebo model\").")
def unknown_joint_reference(ctx) -> Iterator[Hit]:
    names = {joint.name for joint in ctx.model.joints}
    links = {link.name for link in ctx.model.links}
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
    for block in ctx.model.root.iter("ros2_control"):
        for element in block.findall("joint"):
            name = element.get("name")
            if name not in names:
                yield Hit(f"ros2_control '{block.get('name', '?')}' names unknown joint '{name}'", element)
    for block in ctx.model.root.iter("gazebo"):
        reference = block.get("reference")
        if reference is not None and reference not in links and reference not in names:
            yield Hit(f"<gazebo reference=\"{reference}\"> names no link or joint: Gazebo applies it to nothing", block)


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
      refused_by=("ros", "pybullet"), breaks='urdfdom and PyBullet refuse the file ("Joint type not supported").',
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
      engines=("ros", "mujoco", "isaac", "drake", "gazebo"),
      why="""PyBullet accepts type="spherical" (a ball joint), but it is not part of URDF: urdfdom,
      ROS, MoveIt and yourdfpy refuse the file.""",
      fix="Keep the file PyBullet-only, or replace the ball joint by three revolute joints with massless links.",
      bad=arm(joint_type="spherical"), good=arm())
def pybullet_joint_type(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        if joint.type in PYBULLET_JOINT_TYPES:
            yield Hit(f"joint '{joint.name}' type '{joint.type}' is a PyBullet extension, not URDF", joint.element)


@rule("S011", "no-links", "error", "<robot> has no links",
      refused_by=("ros", "pybullet"),
      breaks='urdfdom refuses the file ("No link elements found") and PyBullet cannot load it.',
      why="""A robot is a tree of links. urdfdom refuses a file without one ("No link elements found in
      urdf file") and PyBullet cannot load it; an empty <robot> is usually a xacro argument or macro
      that expanded to nothing.""",
      fix="Add the links, or check the xacro arguments that should have produced them.",
      bad='<?xml version="1.0"?>\n<robot name="empty"/>\n',
      good=robot('<link name="base"/>'))
def no_links(ctx) -> Iterator[Hit]:
    if not ctx.model.links:
        unnamed = "" if (ctx.model.root.get("name") or "").strip() else " (and no name)"
        yield Hit(f"<robot> has no <link> elements{unnamed}: nothing to load", ctx.model.root)


def _transmissions(model):
    """(transmission element, its type, its joint names, its actuator elements) for every <transmission>."""
    for transmission in model.root.iter("transmission"):
        type_element = transmission.find("type")
        kind = (type_element.text or "") if type_element is not None else transmission.get("type", "")
        joints = [element.get("name") for element in transmission.iter("joint")]
        actuators = [element for tag in ("actuator", "leftActuator", "rightActuator")
                     for element in transmission.iter(tag)]
        yield transmission, kind.strip(), joints, actuators


def _transmission_robot(second: str) -> str:
    return robot(f"""
        <link name="base"/><link name="arm">{LINK_INERTIAL}</link><link name="tool">{LINK_INERTIAL}</link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
        <joint name="tool_joint" type="fixed"><parent link="arm"/><child link="tool"/></joint>
        <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
          <joint name="j1"><hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
          <actuator name="m1"><mechanicalReduction>1</mechanicalReduction></actuator></transmission>
        {second}""")


@rule("S012", "transmission-fixed-joint", "warning", "Transmission on a fixed joint",
      engines=("drake", "gazebo", "ros"),
      why="""A fixed joint has nothing to drive. Drake skips the transmission ("Skipping transmission
      since it's attached to a fixed joint"); Gazebo merges fixed joints away when it converts the
      URDF, so gazebo_ros_control refuses to start ("This robot has a joint named ... which is not in
      the gazebo model") and gz_ros2_control skips the joint; a ros_control controller for it never
      moves anything.""",
      fix="Remove the transmission, or make the joint the moving type it really is.",
      bad=_transmission_robot("""<transmission name="t2"><type>transmission_interface/SimpleTransmission</type>
          <joint name="tool_joint"/><actuator name="m2"/></transmission>"""),
      good=_transmission_robot(""),
      references="Drake multibody/parsing/detail_urdf_parser.cc ParseTransmission; gazebo_ros_control "
                 "default_robot_hw_sim.cpp.")
def transmission_fixed_joint(ctx) -> Iterator[Hit]:
    for transmission, _kind, joints, _actuators in _transmissions(ctx.model):
        for name in joints:
            joint = ctx.model.joint(name) if name else None
            if joint is not None and joint.type == "fixed":
                yield Hit(f"transmission '{transmission.get('name', '?')}' drives fixed joint '{name}'", transmission)


@rule("S013", "duplicate-actuator", "error", "Two transmissions name the same actuator",
      engines=("drake", "ros"),
      refused_by=("drake",),
      breaks="Drake refuses the file (actuator names must be unique); ros_control sends one joint's commands to "
             "the other.",
      why="""A SimpleTransmission couples one actuator to one joint. Two of them that name the same
      actuator make two motors of one: Drake refuses the file ("already contains a joint actuator
      named ... Joint actuator names must be unique"), and ros_control registers the actuator twice,
      so one joint's commands go to the other. Transmissions of other types may share a motor by
      design (PAL's Hey5Reducer drives five finger joints from one motor) and are not checked.""",
      fix="Give every actuator its own name (usually JOINT_motor), or merge the transmissions.",
      bad=_transmission_robot(f"""<link name="arm2">{LINK_INERTIAL}</link>
          <joint name="j2" type="revolute"><parent link="arm"/><child link="arm2"/><axis xyz="0 1 0"/>
            <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <transmission name="t2"><type>transmission_interface/SimpleTransmission</type>
            <joint name="j2"/><actuator name="m1"/></transmission>"""),
      good=_transmission_robot(""),
      thresholds="Only transmissions whose type contains SimpleTransmission are compared.",
      references="Drake multibody/tree/multibody_tree.cc AddJointActuator (unique names); Drake "
                 "detail_urdf_parser.cc ParseTransmission (SimpleTransmission only).")
def duplicate_actuator(ctx) -> Iterator[Hit]:
    owner: dict[str, str] = {}
    for transmission, kind, _joints, actuators in _transmissions(ctx.model):
        if "SimpleTransmission" not in kind:
            continue  # other types may share a motor by design (PAL's Hey5Reducer: one motor, five finger joints)
        name = transmission.get("name", "?")
        for element in actuators:
            actuator = element.get("name")
            if not actuator:
                continue
            if actuator in owner and owner[actuator] != name:
                yield Hit(f"transmission '{name}' names actuator '{actuator}', already driven by transmission "
                          f"'{owner[actuator]}'", element)
            owner.setdefault(actuator, name)


SINGLE_CHILDREN = {
    "joint": ("origin", "parent", "child", "axis", "calibration", "dynamics", "limit", "safety_controller", "mimic"),
    "link": ("inertial",),
    "inertial": ("origin", "mass", "inertia"),
    "visual": ("origin", "geometry", "material"),
    "collision": ("origin", "geometry"),
}
"""Element -> the children the URDF spec allows at most once (wiki.ros.org/urdf/XML/joint, /link)."""


@rule("S014", "duplicate-element", "warning", "Element given twice where the spec allows one",
      why="""urdfdom, PyBullet, Drake and MuJoCo read the first <axis>, <origin>, <limit>,
      <inertial> or <mass> of an element (TinyXML's FirstChildElement) and ignore the others without
      a word, so a second one (a xacro macro and its caller both adding <limit>, a pasted
      <inertial>) is dead text that looks like it matters. Which one wins depends on document order,
      not on intent.""",
      fix="Keep the one you mean and delete the others.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/>'
                          '<limit lower="-2" upper="2" effort="10" velocity="1"/>'),
      good=arm(),
      thresholds="Single children: " + "; ".join(f"<{parent}>: {', '.join(children)}"
                                                 for parent, children in SINGLE_CHILDREN.items()) + ".")
def duplicate_element(ctx) -> Iterator[Hit]:
    root = ctx.model.root
    for parent_tag, children in SINGLE_CHILDREN.items():
        # <joint> inside <transmission> or <ros2_control> is another element: only <robot>'s own count
        for parent in (root.findall(parent_tag) if parent_tag in ("joint", "link") else root.iter(parent_tag)):
            tags = [tag for _child, tag in ctx.model.children(parent)]  # read at load for links and joints
            if len(set(tags)) == len(tags):
                continue  # no tag twice (the common case): nothing to count
            counts = Counter(tag for tag in tags if isinstance(tag, str))
            for tag in children:
                if counts[tag] > 1:
                    extra = [child for child in parent if child.tag == tag][1]
                    owner = _owner_name(parent)
                    yield Hit(f"{owner} has {counts[tag]} <{tag}> elements: every parser reads the first and ignores "
                              "the rest", extra)
    for geometry in ctx.model.root.iter("geometry"):
        shapes = [child for child, tag in ctx.model.children(geometry) if isinstance(tag, str)]
        if len(shapes) > 1:
            yield Hit(f"{_owner_name(geometry)} has {len(shapes)} children ({listed(child.tag for child in shapes)}): "
                      "parsers read the first as the shape and ignore the rest", shapes[1])


def _owner_name(element) -> str:
    """'joint 'j1'' / 'link 'arm' <visual>' for messages."""
    node, path = element, []
    while node is not None and node.tag not in ("link", "joint"):
        path.append(node.tag)
        node = node.getparent()
    if node is None:
        return f"<{element.tag}>"
    inner = "".join(f" <{tag}>" for tag in reversed(path))
    return f"{node.tag} '{node.get('name', '?')}'{inner}"


@rule("S015", "link-order", "info", "Root link not first, or a link declared before its parent",
      engines=("pybullet",),
      why="""URDF does not order links, and ar3cli does not care (it hands pybullet a reordered copy).
      But pybullet loaded with URDF_MAINTAIN_LINK_ORDER, which keeps link indices in file order,
      crashes in C (SIGSEGV, no message) when the root is not the first <link> (every UR file of
      example-robot-data, TIAGo, Talos), and gives NaN frames to a link declared before its parent
      and to everything below it (pybullet 3.2.7, docs/pybullet-facts.md). Listing links parent
      first, root first, makes the file safe for every loader.""",
      fix="Move the root <link> to the top and list every link after its parent (ar3cli works around it; other "
          "pybullet users need this).",
      bad=robot("""
          <link name="tool"/><link name="base"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="tool"/></joint>"""),
      good=robot("""
          <link name="base"/><link name="tool"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="tool"/></joint>"""),
      references="docs/pybullet-facts.md (link order and URDF_MAINTAIN_LINK_ORDER); tests/data/link_order/.")
def link_order(ctx) -> Iterator[Hit]:
    model = ctx.model
    roots = model.root_links()
    if len(roots) != 1 or len(model.links) < 2:
        return  # S005/S011's business
    position = {}
    for index, link in enumerate(model.links):
        position.setdefault(link.name, index)
    parent_of: dict[str, str] = {}
    for joint in model.joints:  # the first parent joint of each link (a second one is S006's)
        if joint.child and joint.parent:
            parent_of.setdefault(joint.child, joint.parent)
    early = sorted(((model.link(child), parent) for child, parent in parent_of.items()
                    if child in position and parent in position and position[child] < position[parent]),
                   key=lambda pair: position[pair[0].name])
    if model.links[0] is not roots[0]:
        also = f" ({len(early)} link{'s' if len(early) != 1 else ''} declared before their parent too)" if early else ""
        yield Hit(f"root link '{roots[0].name}' is not the first <link> ('{model.links[0].name}' is){also}: pybullet "
                  "with URDF_MAINTAIN_LINK_ORDER crashes on this file", roots[0].element)
    elif early:
        link, parent = early[0]
        more = f" ({len(early) - 1} more link{'s' if len(early) > 2 else ''} too)" if len(early) > 1 else ""
        yield Hit(f"link '{link.name}' is declared before its parent '{parent}'{more}: pybullet with "
                  "URDF_MAINTAIN_LINK_ORDER gives it and the links below it NaN frames", link.element)
