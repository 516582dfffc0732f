"""Schema rules (S016-S020): the URDF 1.0/1.1/1.2 element and attribute sets, checked on every element.

Every URDF parser (urdfdom's TinyXML ``FirstChildElement``/``Attribute``, PyBullet's UrdfParser,
MuJoCo's xml_urdf.cc, Drake's detail_urdf_parser.cc) looks up the names it knows and ignores the rest
without a word, so ``<orign xyz="0 0 0.2"/>`` or ``<axis xzy="0 0 1"/>`` is dead text that looks
like it matters. These rules compare what the file says with what the spec has.

Extensions stay quiet: ``<gazebo>``, ``<transmission>``, ``<ros2_control>``, ``<sensor>``,
``<mujoco>`` and anything else at the top level that is not close to a URDF name, namespaced
elements and attributes (``drake:``, ``xacro:``; declared or not: other rules report xacro leftovers),
and the few extensions engines read inside URDF elements (:data:`ENGINE_EXTENSIONS`).
"""

from __future__ import annotations

import difflib
import functools
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.urdf.model import URDF_VERSION_FEATURES

SCHEMA: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    "robot": (frozenset({"name", "version"}), frozenset({"link", "joint", "material"})),
    "link": (frozenset({"name", "type"}), frozenset({"inertial", "visual", "collision"})),
    "inertial": (frozenset(), frozenset({"origin", "mass", "inertia"})),
    "origin": (frozenset({"xyz", "rpy", "quat_xyzw"}), frozenset()),
    "mass": (frozenset({"value"}), frozenset()),
    "inertia": (frozenset({"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}), frozenset()),
    "visual": (frozenset({"name"}), frozenset({"origin", "geometry", "material"})),
    "collision": (frozenset({"name"}), frozenset({"origin", "geometry"})),
    "geometry": (frozenset(), frozenset({"box", "cylinder", "sphere", "mesh", "capsule"})),
    "box": (frozenset({"size"}), frozenset()),
    "cylinder": (frozenset({"radius", "length"}), frozenset()),
    "sphere": (frozenset({"radius"}), frozenset()),
    "capsule": (frozenset({"radius", "length"}), frozenset()),
    "mesh": (frozenset({"filename", "scale"}), frozenset()),
    "material": (frozenset({"name"}), frozenset({"color", "texture"})),
    "color": (frozenset({"rgba"}), frozenset()),
    "texture": (frozenset({"filename"}), frozenset()),
    "joint": (frozenset({"name", "type"}), frozenset({"origin", "parent", "child", "axis", "calibration", "dynamics",
                                                      "limit", "mimic", "safety_controller"})),
    "parent": (frozenset({"link"}), frozenset()),
    "child": (frozenset({"link"}), frozenset()),
    "axis": (frozenset({"xyz"}), frozenset()),
    "calibration": (frozenset({"rising", "falling", "reference_position"}), frozenset()),
    "dynamics": (frozenset({"damping", "friction"}), frozenset()),
    "limit": (frozenset({"lower", "upper", "effort", "velocity", "acceleration", "deceleration", "jerk"}), frozenset()),
    "mimic": (frozenset({"joint", "multiplier", "offset"}), frozenset()),
    "safety_controller": (frozenset({"soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"}),
                          frozenset()),
}
"""Element -> (its attributes, its child elements) in URDF 1.2 (wiki.ros.org/urdf/XML, urdfdom's
urdf.xsd and urdf_parser/src/{link,joint,model,pose}.cpp). 1.1 added ``quat_xyzw`` and ``<capsule>``,
1.2 ``acceleration``/``deceleration``/``jerk`` (S020 says when a file uses them without declaring the
version). ``<link type>`` is in urdfdom's XSD (Drake warns it ignores it)."""

ENGINE_EXTENSIONS: dict[str, tuple[frozenset[str], frozenset[str]]] = {
    "robot": (frozenset(), frozenset()),
    "link": (frozenset({"drake_ignore", "concave"}), frozenset({"contact", "self_collision_checking", "sensor"})),
    "visual": (frozenset({"group"}), frozenset()),
    "collision": (frozenset({"group", "concave", "mask"}), frozenset({"verbose", "material"})),
    "joint": (frozenset({"drake_ignore"}), frozenset({"sensor"})),
    "dynamics": (frozenset({"coulomb_window", "spring_stiffness", "spring_reference"}), frozenset()),
    "material": (frozenset(), frozenset({"specular"})),
}
"""What engines read beyond the spec inside URDF elements, never reported: PyBullet's ``<contact>``
and ``concave`` (UrdfParser.cpp), Drake's ``drake_ignore`` and ``coulomb_window``
(detail_urdf_parser.cc), PyBullet's ``<specular>`` in ``<material>`` and collision filter ``group``/``mask``,
the old spec's ``<self_collision_checking>`` and ``<verbose>`` (wiki.ros.org/urdf/XML/link, 2009), and a
``<material>`` in ``<collision>`` (exporters write it; nothing reads it, and nothing is lost).
Other unknown names are reported only when they are a misspelling of an allowed one (or a URDF element
in the wrong place): anything else is taken for an extension."""

GEOMETRY_SHAPES_OWNED_ELSEWHERE = frozenset({"geometry"})
"""Unknown children of ``<geometry>`` are G010's (non-spec geometry: plane, cdf, drake:capsule)."""

INERTIA_SYMMETRY = {"iyx": "ixy", "izx": "ixz", "izy": "iyz"}
"""The tensor is symmetric, so ``iyx`` means ``ixy``: the closest spelling is not the right one."""

WHAT_PARSERS_DO = "urdfdom, PyBullet, MuJoCo and Drake ignore it without a word"


def _local(tag) -> str | None:
    """The plain tag of a URDF element; None for comments, processing instructions and namespaced tags."""
    if not isinstance(tag, str) or tag.startswith("{") or ":" in tag:
        return None
    return tag


TYPO_LENGTH = 2
"""A name is a misspelling of an allowed one when their lengths differ by at most this much and
difflib finds them similar (ratio >= 0.6): ``orign``/``origin``, ``xzy``/``xyz``; ``command_effort``
is an extension's own attribute, not a misspelt ``effort``."""


@functools.lru_cache(maxsize=4096)
def _closest(name: str, allowed: frozenset[str]) -> str | None:
    """The allowed name ``name`` is a misspelling of, or None (cached: extensions repeat their names
    on every link, and difflib is the costliest step of the schema rules)."""
    if name in INERTIA_SYMMETRY and INERTIA_SYMMETRY[name] in allowed:
        return INERTIA_SYMMETRY[name]
    candidates = sorted(a for a in allowed if abs(len(a) - len(name)) <= TYPO_LENGTH)
    matches = difflib.get_close_matches(name, candidates, n=1, cutoff=0.6)
    return matches[0] if matches else None


@functools.lru_cache(maxsize=1024)
def _home_of(tag: str) -> tuple[str, ...]:
    """The URDF elements that may hold ``tag`` as a child (for "belongs in <inertial>")."""
    return tuple(parent for parent, (_attrs, children) in SCHEMA.items() if tag in children and parent != "robot")


Node = tuple[Any, str, list[tuple[Any, Any]]]
"""(element, its tag, [(child, child's tag), ...] for every child, comments included)."""


@dataclass(frozen=True)
class SchemaWalk:
    """The URDF part of a file, walked once for the five schema rules (lxml makes a new object and a
    new tag string each time an element is reached: the walk is most of their cost).

    ``nodes`` holds every element the schema rules judge (:func:`_urdf_nodes`), in the walk's order;
    ``odd`` those of them with a child the schema does not name there (an unknown element, an
    attribute written as an element, an extension, a comment), in the same order: the only nodes S016
    and S018 can report, and few in a real robot."""

    nodes: tuple[Node, ...]
    odd: tuple[Node, ...]


def _urdf_nodes(model) -> SchemaWalk:
    """Every element inside the robot's URDF part: <link>, <joint> and <material> children of <robot>
    and, below them, only children the schema knows (so an extension's subtree is never walked);
    each with its children (:meth:`~ar3cli.urdf.model.Model.children`: those the load read are not read
    again), read once for every schema rule. Depth first, the last child first."""
    # ``tag in names`` is ``_local(tag) in names``: the schema's names are plain, and a comment's tag
    # (a function) or a namespaced tag ("{uri}origin") is none of them.
    nodes: list[Node] = []
    odd: list[Node] = []
    stack = [(child, tag) for child, tag in model.children(model.root) if tag in SCHEMA["robot"][1]]
    read = model.read_children
    while stack:
        element, tag = stack.pop()
        children = read.get(element)
        if children is None:  # not a link, joint or one of their containers: read here
            if not len(element):  # a leaf (<origin/>, <mass/>): most elements
                nodes.append((element, tag, []))
                continue
            children = [(child, child.tag) for child in element]
        node = (element, tag, children)
        nodes.append(node)
        if not children:
            continue
        names = SCHEMA[tag][1]
        known = [pair for pair in node[2] if pair[1] in names]
        if len(known) != len(node[2]):
            odd.append(node)
        if tag != "geometry":
            stack += known
    return SchemaWalk(tuple(nodes), tuple(odd))


def _schema_walk(ctx) -> SchemaWalk:
    """:func:`_urdf_nodes` of the file, walked once for all the schema rules."""
    return ctx.structure("schema-walk", _urdf_nodes)


def owner(element) -> str:
    """"link 'arm' <visual> <origin>" for messages."""
    path, node = [], element
    while node is not None and node.tag not in ("link", "joint", "material", "robot"):
        path.append(node.tag)
        node = node.getparent()
    if node is None or node.tag == "robot":
        return "".join(f"<{tag}>" for tag in reversed(path)) or "<robot>"
    inner = "".join(f" <{tag}>" for tag in reversed(path))
    return f"{node.tag} '{node.get('name', '?')}'{inner}"


def _unknown_children(ctx) -> Iterator[tuple]:
    """(element, unknown child, closest allowed name or None) for every child the schema lacks."""
    root = ctx.model.root
    for element, element_tag, element_children in ((root, root.tag, ctx.model.children(root)), *_schema_walk(ctx).odd):
        attrs, children = SCHEMA[element_tag]
        if element_tag in GEOMETRY_SHAPES_OWNED_ELSEWHERE:
            continue
        extra = ENGINE_EXTENSIONS.get(element_tag, (frozenset(), frozenset()))[1]
        for child, tag in element_children:
            if tag in children or tag in extra:
                continue
            tag = _local(tag)
            if tag is None:
                continue
            if tag in attrs:
                continue  # S018: an attribute written as an element
            # a URDF element's own name is no misspelling: it is in the wrong place (<inertial> under <robot>)
            guess = None if tag in SCHEMA else _closest(tag, children)
            if guess is None and (element_tag == "robot" and tag not in SCHEMA or not _home_of(tag)):
                continue  # an extension (<gazebo>, <sensor>, <joint_properties>, ...), not a misspelling
            yield element, child, guess


@rule("S016", "unknown-element", "warning", "Element the URDF spec does not have here",
      why=f"""Parsers look up the children they know by name and skip the rest: {WHAT_PARSERS_DO}.
      A misspelt <orign> in a <collision> leaves the collision at the link origin, <axes> leaves the
      axis at 1 0 0, a <mass> written directly in <link> gives the link no mass at all, and the file
      still loads everywhere. Extensions are not reported: <gazebo>, <transmission>, <ros2_control>,
      <sensor>, <mujoco> and other top-level elements that are not close to a URDF name, namespaced
      elements (drake:, xacro:), PyBullet's <contact> in <link>; nor is an identity <origin> (all zeros)
      where none is read (directly in <link>): ignored, it loses nothing.""",
      fix="Rename the element to the one the message suggests, or move it where it belongs.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/>').replace(
          '<axis xyz="0 0 1"/>', '<axes xyz="0 0 1"/>'),
      good=arm(),
      thresholds="Reported: a misspelling of an allowed child (difflib similarity >= 0.6, lengths within 2) or a URDF "
                 "element in the wrong place (<mass> in <link>); other unknown names are taken for extensions.",
      references="wiki.ros.org/urdf/XML (link, joint, model); urdfdom xsd/urdf.xsd and urdf_parser/src/link.cpp, "
                 "joint.cpp; PyBullet examples/Importers/ImportURDFDemo/UrdfParser.cpp; Drake "
                 "multibody/parsing/detail_urdf_parser.cc.")
def unknown_element(ctx) -> Iterator[Hit]:
    for parent, child, guess in _unknown_children(ctx):
        if not guess and child.tag == "origin" and _identity_origin(child):
            continue  # an identity <origin> where none is read: ignored, and nothing the author meant is lost
        homes = [home for home in _home_of(child.tag) if home != parent.tag]
        if guess:
            advice = f"did you mean <{guess}>?"
            hint = f"Rename <{child.tag}> to <{guess}>."
        else:
            advice = f"<{child.tag}> belongs in <{'> or <'.join(homes)}>"
            hint = f"Move <{child.tag}> into <{homes[0]}>."
        yield Hit(f"{owner(parent)} has an unknown child <{child.tag}> ({advice}): {WHAT_PARSERS_DO}", child,
                  hint=hint)


def _identity_origin(element) -> bool:
    """An ``<origin>`` whose every number is 0 (or that has none): the frame it would give is the default."""
    from ar3cli.urdf.model import parse_floats

    values = [parse_floats(element.get(key)) for key in ("xyz", "rpy") if element.get(key) is not None]
    return element.get("quat_xyzw") is None and all(v is not None and not any(v) for v in values)


@rule("S017", "unknown-attribute", "warning", "Attribute the URDF spec does not have on this element",
      why=f"""Parsers read the attributes they know by name and skip the rest: {WHAT_PARSERS_DO}.
      <axis xzy="0 0 1"/> leaves the axis at the default 1 0 0, <origin ryp="..."/> leaves the frame
      unrotated, <inertia iyx="..."/> leaves ixy at 0: the robot loads, and moves wrongly. Namespaced
      attributes (drake:, xmlns:) and the few that engines read beyond the spec (PyBullet's concave,
      Drake's coulomb_window) are not reported.""",
      fix="Rename the attribute to the one the message suggests.",
      bad=arm().replace('<axis xyz="0 0 1"/>', '<axis xzy="0 0 1"/>'),
      good=arm(),
      thresholds="Reported: a misspelling of an allowed attribute the element does not also have (difflib similarity "
                 ">= 0.6, lengths within 2); iyx, izx, izy are ixy, ixz, iyz (the tensor is symmetric): alone they are "
                 "reported, next to their twin only when the two values differ. Other unknown "
                 "attributes are taken for extensions (ANYmal's command_effort, Isaac's dont_collapse).",
      references="wiki.ros.org/urdf/XML (link, joint); urdfdom xsd/urdf.xsd; urdfdom urdf_parser/src/pose.cpp, "
                 "joint.cpp, link.cpp.")
def unknown_attribute(ctx) -> Iterator[Hit]:
    root = ctx.model.root
    for element, tag, _children in ((root, root.tag, None), *_schema_walk(ctx).nodes):
        attrs = SCHEMA[tag][0]
        names = element.keys()
        if attrs.issuperset(names):
            continue  # every attribute is the spec's (nearly always)
        extra = ENGINE_EXTENSIONS.get(tag, (frozenset(), frozenset()))[0]
        for name in names:
            if name in attrs or name in extra or _local(name) is None:
                continue
            guess = _closest(name, attrs)
            if guess is None or (guess in element.attrib and name not in INERTIA_SYMMETRY):
                continue  # an extension's attribute (command_effort, dont_collapse, twist), not a misspelling
            if guess in element.attrib:  # iyx next to ixy: the tensor's redundant twin
                if _same_number(element.get(name), element.get(guess)):
                    continue  # written twice, read once: nothing is lost
                yield Hit(f"{owner(element)} has {name}=\"{element.get(name)}\" and {guess}=\"{element.get(guess)}\": the "
                          f"tensor is symmetric, parsers read {guess} and ignore {name}", element,
                          hint=f"Keep the value you mean in {guess}= and delete {name}=.")
                continue
            yield Hit(f"{owner(element)} has an unknown attribute {name}=\"{element.get(name)}\" (did you mean "
                      f"{guess}?): {WHAT_PARSERS_DO}", element, hint=f"Rename {name}= to {guess}=.")


def _same_number(a: str | None, b: str | None) -> bool:
    """Whether two attribute texts hold the same number ("0" and "0.0"), or the same text."""
    try:
        return float(a or "") == float(b or "")
    except ValueError:
        return (a or "").strip() == (b or "").strip()


@rule("S018", "attribute-as-element", "error", "Attribute written as a child element",
      refused_by=("ros", "pybullet"),
      breaks="urdfdom and PyBullet refuse a <limit> whose required value is written only as an element; every "
             "engine silently drops a damping or friction written so (Drake #18796).",
      why="""<dynamics><damping>5</damping></dynamics> and <limit><effort>10</effort></limit> look
      right but URDF values are attributes: urdfdom, PyBullet and MuJoCo read damping="..." and
      never look at a child element, so the joint gets no damping (Drake #18796); a <limit> whose
      effort is only an element is refused by urdfdom and PyBullet with a message that names no
      line.""",
      fix="Write the value as an attribute: <dynamics damping=\"5\"/>.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><dynamics><damping>5</damping></dynamics>'),
      good=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><dynamics damping="5"/>'),
      references="Drake issue #18796 (damping as an element silently ignored); urdfdom urdf_parser/src/joint.cpp.")
def attribute_as_element(ctx) -> Iterator[Hit]:
    for element, element_tag, element_children in _schema_walk(ctx).odd:  # a child the schema names is no attribute
        attrs = SCHEMA[element_tag][0]
        if not attrs:
            continue
        for child, tag in element_children:
            # the attribute names are plain: a namespaced tag or a comment is none of them
            if tag not in attrs or tag in SCHEMA[element_tag][1]:
                continue
            value = " ".join((child.text or "").split()) or "..."
            yield Hit(f"{owner(element)} has <{tag}> as a child element: parsers read only the attribute "
                      f"{tag}=\"...\" and ignore the element", child,
                      hint=f"Write <{element.tag} {tag}=\"{value}\" .../> and delete the <{tag}> element.")


REQUIRED_CHILDREN = {"visual": ("geometry",), "collision": ("geometry",), "inertial": ("mass", "inertia")}
"""Element -> children urdfdom refuses the element without (link.cpp parseVisual/parseCollision,
parseInertial: "Inertial element must have a mass element", "... inertia element")."""


@rule("S019", "missing-required-child", "error", "<visual>/<collision> without <geometry>, <inertial> without <mass>",
      engines=("ros", "pybullet", "isaac"),
      refused_by=("ros", "pybullet", "isaac"),
      breaks="urdfdom refuses the link and the file, PyBullet fails to parse the link, Isaac Sim's importer "
             "fails (IsaacSim #599).",
      why="""urdfdom refuses a <visual> or <collision> without <geometry> and an <inertial> without
      <mass> or <inertia>, and with it the whole file ("failed to parse link"); Isaac Sim's importer
      fails the same way with no location (IsaacSim #599); PyBullet's --sim load says only "failed to
      parse link". Found here at the element's line. A missing <mass> or <inertia> on a moving link
      is I003's and I006's (not reported twice).""",
      fix="Add the missing child (a <geometry> with a shape; <mass value=...> and <inertia .../>), or delete the element.",
      bad=robot(f'<link name="base">{LINK_INERTIAL}<visual><origin xyz="0 0 0"/></visual></link>'),
      good=robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="1 1 1"/></geometry></visual></link>'),
      references="urdfdom urdf_parser/src/link.cpp (parseVisual, parseCollision, parseInertial); IsaacSim #599.")
def missing_required_child(ctx) -> Iterator[Hit]:
    moving = {joint.child for joint in ctx.model.joints if joint.moves}
    for element, element_tag, element_children in _schema_walk(ctx).nodes:
        required = REQUIRED_CHILDREN.get(element_tag)
        if not required:
            continue
        link = element.getparent()
        if element_tag == "inertial" and link is not None and link.get("name") in moving:
            continue  # I003 (mass) and I006 (inertia) report moving links
        present = {child_tag for _child, child_tag in element_children}
        missing = [tag for tag in required if tag not in present]  # element.find(tag) is None
        if missing:  # one finding per element, whatever it lacks
            yield Hit(f"{owner(element)} has no {' and no '.join(f'<{tag}>' for tag in missing)}: urdfdom refuses "
                      "the link, and the file", element)


VERSION_FEATURE_ELEMENTS = {"quat_xyzw": "origin", "acceleration": "limit", "deceleration": "limit", "jerk": "limit"}
"""Attribute -> element for the URDF 1.1/1.2 attributes (``<capsule>`` is G010's)."""
VERSION_FEATURE_HOLDERS = frozenset(VERSION_FEATURE_ELEMENTS.values())
"""The elements that may hold one (S020 reads only their attributes)."""
VERSION_FEATURE_NAMES = tuple(name.encode() for name in VERSION_FEATURE_ELEMENTS)
"""Their names as a file's bytes spell them: without one of them, S020 has nothing to read."""


@rule("S020", "undeclared-urdf-version", "info", "URDF 1.1/1.2 attribute in a file that does not declare it",
      engines=("ros",),
      why="""<origin quat_xyzw> is URDF 1.1, acceleration/deceleration/jerk on <limit> URDF 1.2. In a
      file without <robot version="1.1"> (or "1.2") urdfdom 5.1+ ignores them (a quat_xyzw frame stays
      unrotated for ROS tools while ar3cli, which reads it, rotates it), and older urdfdom does not know
      them at all.""",
      fix='Declare the version: <robot name="..." version="1.2"> (1.1 is enough for quat_xyzw).',
      bad=arm(joint_extra='<origin xyz="0 0 0.1" quat_xyzw="0 0 0 1"/>'
                          '<limit lower="-1" upper="1" effort="10" velocity="1"/>'),
      good=arm(joint_extra='<origin xyz="0 0 0.1" quat_xyzw="0 0 0 1"/>'
                           '<limit lower="-1" upper="1" effort="10" velocity="1"/>').replace(
          '<robot name="r">', '<robot name="r" version="1.1">'),
      references="urdfdom README (URDF versioning) and urdf_parser/src/pose.cpp, joint.cpp; ros/urdfdom#238.")
def undeclared_urdf_version(ctx) -> Iterator[Hit]:
    model = ctx.model
    if not any(name in model.xml_bytes for name in VERSION_FEATURE_NAMES):
        return  # no attribute can have a name the parsed bytes never spell (entities are refused): skip the walk
    for element, tag, _children in _schema_walk(ctx).nodes:
        if tag not in VERSION_FEATURE_HOLDERS:
            continue
        for name in element.keys():  # noqa: SIM118 - an lxml element: iterating it gives its children
            if VERSION_FEATURE_ELEMENTS.get(name) == tag and not model.declares(name):
                major, minor = URDF_VERSION_FEATURES[name]
                yield Hit(f"{owner(element)} uses {name}, which is URDF {major}.{minor}: the file does not declare it "
                          "(urdfdom ignores it)", element,
                          hint=f'Declare <robot name="..." version="{major}.{minor}"> (or later).')
