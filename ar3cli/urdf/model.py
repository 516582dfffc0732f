"""Load a ``.urdf`` or ``.xacro`` file once into a :class:`Model` that every command reads.

The Model keeps the parsed lxml tree (each element knows its source line), typed views of links,
joints, inertials and geometry, mesh URIs resolved to paths (with the places tried), and the
:class:`~ar3cli.urdf.xmlsource.Quirk` list of everything odd about the file. Values that do not parse
are kept as ``None`` next to their raw text, so the linter can report them while the other
commands still load the file. Nothing here imports pybullet or trimesh.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.infra.safe_read import read_bytes
from ar3cli.maths.tensor_math import matrix_to_rpy, quaternion_to_matrix, rpy_to_matrix, unit_quaternion
from ar3cli.urdf import xmlsource
from ar3cli.urdf.file_kind import is_xacro
from ar3cli.urdf.packages import PackageResolver, Resolution
from ar3cli.urdf.xmlsource import Quirk

Vec3 = tuple[float, float, float]
ROTATING_JOINT_TYPES = ("revolute", "continuous")
"""1-DOF joints that turn about their axis."""
ACTUATED_JOINT_TYPES = (*ROTATING_JOINT_TYPES, "prismatic")
"""1-DOF joints: the ones PyBullet reports with one position and drives with one motor."""
MOVING_JOINT_TYPES = (*ACTUATED_JOINT_TYPES, "planar", "floating", "spherical")
"""Joint types whose child link moves relative to its parent (``spherical`` is PyBullet's ball joint)."""
URDF_JOINT_TYPES = (*ACTUATED_JOINT_TYPES, "fixed", "floating", "planar")
"""The joint types of the URDF spec."""
URDF_VERSION_FEATURES: Mapping[str, tuple[int, int]] = {
    "quat_xyzw": (1, 1), "capsule": (1, 1), "acceleration": (1, 2), "deceleration": (1, 2), "jerk": (1, 2)}
"""What URDF 1.1 and 1.2 added and the ``<robot version>`` that declares it: urdfdom 5.1 reads 1.1
(``<origin quat_xyzw>``, ``<capsule>``), urdfdom 6.0 reads 1.2 (``acceleration``, ``deceleration`` and
``jerk`` on ``<limit>``). A feature used in a file that declares an older version is ignored by
urdfdom with a warning (a capsule's whole visual or collision is dropped); urdfdom before 5.1 refuses
any version but 1.0, and refuses a capsule ("Unknown geometry type")."""


@lru_cache(maxsize=4096)
def parse_floats(text: str | None, count: int | None = None) -> tuple[float, ...] | None:
    """Parse whitespace-separated numbers; ``None`` when missing, non-numeric or the wrong count.

    NaN and inf parse (they are numbers to Python) and are left for the linter to flag. Cached:
    robot files repeat the same few texts ("0 0 0", "1 0 0") thousands of times.
    """
    if text is None:
        return None
    try:
        values = tuple(map(float, text.split()))
    except ValueError:
        return None
    if count is not None and len(values) != count:
        return None
    return values


def rpy_rotation(rpy: Sequence[float]) -> tuple[tuple[float, float, float], ...]:
    """:func:`~ar3cli.maths.tensor_math.rpy_to_matrix`, cached: robot files repeat a few orientations
    ("0 0 0", "0 0 1.5708") thousands of times, and the bounds of every shape and the frames of every
    joint ask for them (2,600 rotations for pybullet_data's 95 robots)."""
    return _rpy_rotation(tuple(rpy))


@lru_cache(maxsize=4096)
def _rpy_rotation(rpy: tuple[float, ...]) -> tuple[tuple[float, float, float], ...]:
    return rpy_to_matrix(rpy)


def parse_float(text: str | None) -> float | None:
    """One number, or ``None`` when missing or malformed."""
    values = parse_floats(text, 1)
    return values[0] if values else None


@dataclass(frozen=True)
class Origin:
    """An ``<origin>``; identity when the element is absent or malformed.

    The orientation is ``rpy`` (URDF 1.0) or ``quat_xyzw`` (URDF 1.1: x, y, z, w, normalised as
    urdfdom does). With a quaternion, ``quat_xyzw`` holds it and ``rpy`` holds the same rotation as
    roll-pitch-yaw, so code written for rpy places the frame right; :attr:`rotation` is the exact
    matrix either way. The quaternion is read whatever version the file declares (urdfdom ignores
    it below 1.1: the linter says so); when ``rpy`` is also given, ``rpy`` wins (urdfdom ignores the
    quaternion in a 1.0 file and refuses a 1.1 file that has both). A quaternion that is not four
    finite numbers, or all zeros, leaves the identity, like a malformed ``rpy``.
    """

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)
    element: Any = None
    quat_xyzw: tuple[float, float, float, float] | None = None

    @classmethod
    def from_parent(cls, parent) -> Origin:
        return cls.from_element(parent.find("origin") if parent is not None else None)

    @classmethod
    def from_element(cls, element) -> Origin:
        """The origin an ``<origin>`` element (or None: absent) gives."""
        if element is None:
            return cls()
        xyz = parse_floats(element.get("xyz", "0 0 0"), 3) or (0.0, 0.0, 0.0)
        rpy_text, quat_text = element.get("rpy"), element.get("quat_xyzw")
        if quat_text is not None and rpy_text is None:
            quat = read_quaternion(quat_text)
            if quat is not None:
                return cls(xyz, quat[1], element, quat[0])  # type: ignore[arg-type]
        rpy = parse_floats(rpy_text or "0 0 0", 3) or (0.0, 0.0, 0.0)
        return cls(xyz, rpy, element)  # type: ignore[arg-type]

    @property
    def rotation(self) -> tuple[tuple[float, float, float], ...]:
        """The rotation matrix (rows): from the quaternion when one was given, else from ``rpy``."""
        return quaternion_to_matrix(self.quat_xyzw) if self.quat_xyzw is not None else rpy_rotation(self.rpy)


@lru_cache(maxsize=1024)
def read_quaternion(text: str) -> tuple[tuple[float, float, float, float], Vec3] | None:
    """The unit quaternion in a ``quat_xyzw`` text and its roll-pitch-yaw, or None when unusable."""
    values = parse_floats(text, 4)
    unit = unit_quaternion(values) if values is not None else None
    if unit is None:
        return None
    return unit, matrix_to_rpy(quaternion_to_matrix(unit))


@dataclass(frozen=True)
class Geometry:
    """The shape inside a ``<visual>`` or ``<collision>``.

    ``kind`` is box / cylinder / sphere / capsule / mesh, or ``None`` when the element is missing
    or of an unknown type. ``params`` holds the parsed dimensions (``size``, ``radius``,
    ``length``, ``scale``) and ``resolution`` where a mesh file was found.
    """

    kind: str | None
    params: Mapping[str, Any]
    element: Any
    filename: str | None = None
    resolution: Resolution | None = None


@dataclass(frozen=True)
class Shape:
    """A ``<visual>`` or ``<collision>`` element with its origin and geometry."""

    role: str
    origin: Origin
    geometry: Geometry
    element: Any


@dataclass(frozen=True)
class Inertial:
    """An ``<inertial>``: ``mass`` and ``tensor`` (ixx, ixy, ixz, iyy, iyz, izz) are None when malformed."""

    origin: Origin
    mass: float | None
    tensor: tuple[float, float, float, float, float, float] | None
    element: Any
    parts: Mapping[Any, Any] = field(default_factory=dict, compare=False, repr=False)
    """Each child tag -> the first child with it, read at load (:func:`_first_children`)."""

    def first_child(self, tag: str) -> Any:
        """``element.find(tag)`` without a search: the first ``<mass>``/``<inertia>``/``<origin>`` child, or None.
        The inertia rules ask for it on every link (lxml's ``find`` costs ~2.5 µs a call)."""
        return self.parts.get(tag) if self.parts else self.element.find(tag)

    def matrix(self) -> list[list[float]] | None:
        """The symmetric 3x3 tensor as nested lists, or None."""
        if self.tensor is None:
            return None
        ixx, ixy, ixz, iyy, iyz, izz = self.tensor
        return [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]


@dataclass(frozen=True)
class Limit:
    """A joint ``<limit>``; each value None when absent or malformed.

    ``acceleration``, ``deceleration`` and ``jerk`` are URDF 1.2's (urdfdom 6): kept for the rules
    and reports that will want them; nothing in ar3cli enforces them (PyBullet ignores them).
    """

    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    element: Any
    acceleration: float | None = None
    deceleration: float | None = None
    jerk: float | None = None


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float
    offset: float
    element: Any


@dataclass(frozen=True)
class Link:
    name: str
    inertial: Inertial | None
    visuals: tuple[Shape, ...]
    collisions: tuple[Shape, ...]
    element: Any

    @property
    def line(self) -> int:
        return self.element.sourceline or 0

    @property
    def has_geometry(self) -> bool:
        return bool(self.visuals or self.collisions)


@dataclass(frozen=True)
class Joint:
    name: str
    type: str
    parent: str | None
    child: str | None
    origin: Origin
    axis: Vec3
    axis_given: bool
    limit: Limit | None
    mimic: Mimic | None
    element: Any
    parts: Mapping[Any, Any] = field(default_factory=dict, compare=False, repr=False)
    """Each child tag -> the first child with it, read at load (:func:`_first_children`)."""

    def first_child(self, tag: str) -> Any:
        """``element.find(tag)`` without a search: the joint's first child ``tag`` (``<safety_controller>``,
        ``<dynamics>``, ``<axis>``) or None. Rules ask for one on every joint (``find`` costs ~2.5 µs a call)."""
        return self.parts.get(tag) if self.parts else self.element.find(tag)

    @property
    def line(self) -> int:
        return self.element.sourceline or 0

    @property
    def moves(self) -> bool:
        return self.type in MOVING_JOINT_TYPES


@dataclass
class Model:
    """A robot description loaded from one file. Build it with :func:`load_model`."""

    path: Path
    root: Any
    source_bytes: bytes
    xml_bytes: bytes
    is_xacro: bool
    resolver: PackageResolver
    quirks: list[Quirk] = field(default_factory=list)
    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    expansion: Any = field(default=None, repr=False, compare=False)
    """A xacro file's :class:`~ar3cli.urdf.xacro_expand.Expansion` (its elements' origins, the files
    it included), held so they stay known while the model is in use; None for a URDF."""
    read_children: dict[Any, list[tuple[Any, Any]]] = field(default_factory=dict, repr=False, compare=False)
    """Element -> ``[(child, child.tag), ...]`` (comments included) for each element whose children the
    load read: the links and joints, and each link's inertial, visuals, collisions and their geometry."""
    edited_away: bool = field(default=False, repr=False, compare=False)
    """An edit of its text changed this model's tree in place and made the model of the new text from it
    (:func:`~ar3cli.urdf.model_edit.edited`): its links and joints no longer all match the tree, and it is
    never the base of another edit."""

    def children(self, element) -> list[tuple[Any, Any]]:
        """``[(child, child.tag) for child in element]``, from :attr:`read_children` when the load read them:
        the rules that read the children of every URDF element (the schema rules, S014) do not ask lxml
        again (each child reached makes a new object and a new tag string)."""
        known = self.read_children.get(element)
        if known is not None:
            return known
        return [(child, child.tag) for child in element] if len(element) else []  # most are leaves: <origin/>

    # ---- lookups -------------------------------------------------------------------------
    @property
    def name(self) -> str | None:
        return self.root.get("name")

    @cached_property
    def urdf_version(self) -> tuple[int, int] | None:
        """The ``<robot version="MAJOR.MINOR">`` the file declares; (1, 0) when it declares none (urdfdom's
        default), None when the text is not ``MAJOR.MINOR`` (urdfdom refuses such a file)."""
        text = self.root.get("version")
        if text is None:
            return (1, 0)
        match = re.fullmatch(r"([0-9]+)\.([0-9]+)", text.strip())
        return (int(match.group(1)), int(match.group(2))) if match else None

    def declares(self, feature: str) -> bool:
        """True when the file declares a URDF version that has ``feature`` (a key of :data:`URDF_VERSION_FEATURES`)."""
        version = self.urdf_version
        return version is not None and version >= URDF_VERSION_FEATURES[feature]

    def link(self, name: str) -> Link | None:
        return self._links_by_name.get(name)

    def joint(self, name: str) -> Joint | None:
        return self._joints_by_name.get(name)

    @cached_property
    def _links_by_name(self) -> dict[str, Link]:
        return {link.name: link for link in reversed(self.links)}

    @cached_property
    def _joints_by_name(self) -> dict[str, Joint]:
        return {joint.name: joint for joint in reversed(self.joints)}

    def parent_joint(self, link_name: str) -> Joint | None:
        """The joint whose child is ``link_name`` (the first one, if the file has several)."""
        return self._joints_by_child.get(link_name)

    def joints_above(self, link_name: str) -> Iterator[Joint]:
        """The joints from ``link_name`` up to the root, nearest first: its parent joint, that joint's
        parent link's parent joint, ... The walk ends after a joint whose parent is missing or was
        already passed (a loop in a broken file), so it always ends."""
        seen = {link_name}
        joint = self.parent_joint(link_name)
        while joint is not None:
            yield joint
            if joint.parent is None or joint.parent in seen:
                return
            seen.add(joint.parent)
            joint = self.parent_joint(joint.parent)

    def child_joints(self, link_name: str) -> list[Joint]:
        return list(self._joints_by_parent.get(link_name, ()))

    @cached_property
    def _joints_by_child(self) -> dict[str, Joint]:
        """Indexed once, so rules asking for every link's parent stay linear in the number of joints."""
        return {joint.child: joint for joint in reversed(self.joints) if joint.child is not None}

    @cached_property
    def _joints_by_parent(self) -> dict[str, list[Joint]]:
        found: dict[str, list[Joint]] = {}
        for joint in self.joints:
            if joint.parent is not None:
                found.setdefault(joint.parent, []).append(joint)
        return found

    def root_links(self) -> list[Link]:
        """Links that are no joint's child. A well-formed robot has exactly one."""
        children = {j.child for j in self.joints}
        return [link for link in self.links if link.name not in children]

    @property
    def root_link(self) -> Link:
        """The single root link; raises UserError when the tree has none or several."""
        roots = self.root_links()
        if len(roots) != 1:
            names = listed(link.name for link in roots) or "none"
            raise UserError(f"{self.path}: expected one root link, found {len(roots)} ({names}); "
                            "run ar3cli lint-urdf for details")
        return roots[0]

    @cached_property
    def looks_like_xacro(self) -> bool:
        """A ``.urdf`` that is really an unexpanded xacro source: it holds ``<xacro:...>`` elements.
        (Declaring the xacro namespace alone says nothing: xacro keeps the declaration in the URDF
        it writes, as in example-robot-data's panda.urdf.) ``.xacro`` files are expanded on load."""
        if self.is_xacro or b"xacro" not in self.xml_bytes:
            return False
        return any(isinstance(element.tag, str) and element.tag.startswith("{") and "xacro" in element.tag.split("}")[0]
                   for element in self.root.iter())

    def movable_joints(self) -> list[Joint]:
        return [j for j in self.joints if j.moves]

    def meshes(self) -> Iterator[tuple[Link, Shape]]:
        """Every (link, shape) whose geometry is a mesh (listed once per model: nine rules ask)."""
        return iter(self._mesh_shapes)

    @cached_property
    def _mesh_shapes(self) -> list[tuple[Link, Shape]]:
        return [(link, shape) for link in self.links for shape in (*link.visuals, *link.collisions)
                if shape.geometry.kind == "mesh"]

    # ---- text positions ----------------------------------------------------------------------
    @cached_property
    def text_lines(self) -> list[str]:
        """Lines of the parsed document (the expanded URDF for xacro files)."""
        return xmlsource.decode_text(self.xml_bytes).splitlines()

    def column_of(self, element) -> int:
        """1-based column of the element's start tag on its line (1 when it cannot be found). Of several
        elements with one tag on a line (``<link .../><link .../>``), each its own: the n-th ``<tag``."""
        line = element.sourceline or 0
        if not 1 <= line <= len(self.text_lines):
            return 1
        text = self.text_lines[line - 1]
        index = text.find(f"<{element.tag}")
        if index < 0:
            return 1
        if text.find(f"<{element.tag}", index + 1) >= 0:  # several on the line (rare): this one's own
            starts = [match.start() + 1 for match in re.finditer(f"<{re.escape(element.tag)}(?=[\\s/>]|$)", text)]
            nth = self._alike_on_line.get(element, 0)
            return starts[nth] if nth < len(starts) else index + 1
        return index + 1

    @cached_property
    def _alike_on_line(self) -> dict[Any, int]:
        """Each element -> how many elements with its tag end their start tag on its line before it."""
        seen: dict[tuple[int, Any], int] = {}
        nth: dict[Any, int] = {}
        for element in self.root.iter():
            if isinstance(element.tag, str):
                key = (element.sourceline or 0, element.tag)
                nth[element] = seen.get(key, 0)
                seen[key] = nth[element] + 1
        return nth


SRDF_ELEMENTS = frozenset({"group", "group_state", "disable_collisions", "enable_collisions", "disable_default_collisions",
                           "virtual_joint", "end_effector", "passive_joint", "link_sphere_approximation"})
"""Elements of MoveIt's SRDF (srdfdom) that a URDF never has: a ``<robot>`` of them and no ``<link>`` is an SRDF."""


def load_model(
    path: str | Path,
    package_paths: Mapping[str, Path] | None = None,
    xacro_args: Mapping[str, str] | None = None,
    source: bytes | None = None,
) -> Model:
    """Read, expand (xacro), parse and index one robot file; bad input raises :class:`UserError`.

    ``source`` stands in for the file's bytes (a fixer's result, checked before anything is
    written; an editor's unsaved buffer, xacro expanded from it); ``path`` still says where relative
    mesh paths and included files start.
    """
    path = Path(path)
    given = source
    source = read_bytes(path) if source is None else source
    if not source.strip(b"\x00 \t\r\n"):
        raise UserError(f"{path}: file is empty")
    resolver = PackageResolver(path.parent, package_paths)
    xmlsource.refuse_entities(source, path)
    quirks: list[Quirk] = []
    expansion = None
    if is_xacro(path):
        from ar3cli.urdf.xacro_expand import expand, expansion_of

        _, quirks = xmlsource.normalize(source)
        xml_bytes = expand(path, dict(xacro_args or {}), resolver, source=given)
        expansion = expansion_of(xml_bytes)
        xmlsource.refuse_entities(xml_bytes, path)  # an included file may declare some
    else:
        xml_bytes, quirks = xmlsource.normalize(source)
    root, parse_quirks = xmlsource.parse(xml_bytes, path)
    quirks.extend(xmlsource.source_lines(parse_quirks, source) if is_xacro(path) else parse_quirks)
    if not isinstance(root.tag, str) or root.tag != "robot":
        raise UserError(f"{path}:{root.sourceline or 1}: root element is <{root.tag}>, expected <robot>; "
                        "is this a URDF file?")
    semantic = [child.tag for child in root if child.tag in SRDF_ELEMENTS]
    if semantic and root.find("link") is None:
        raise UserError(f"{path}: is an SRDF (MoveIt's semantic description: <{semantic[0]}>, no <link>), not a URDF; "
                        "give the URDF it describes (sample-collisions --srdf-compare reads an SRDF)")
    read: dict[Any, list[tuple[Any, Any]]] = {}
    return Model(path=path, root=root, source_bytes=source, xml_bytes=xml_bytes,
                 is_xacro=is_xacro(path), resolver=resolver, quirks=quirks, expansion=expansion,
                 links=[read_link(element, resolver, read) for element in root.findall("link")],
                 joints=[read_joint(element, read) for element in root.findall("joint")], read_children=read)


Children = dict[Any, list[tuple[Any, Any]]]
"""What the load read: element -> its children with their tags (:attr:`Model.read_children`)."""


def _children(element, read: Children) -> list[tuple[Any, Any]]:
    """``element``'s children with their tags, read once and recorded in ``read``."""
    pairs = read[element] = [(child, child.tag) for child in element]
    return pairs


def _first_children(element, read: Children) -> dict[Any, Any]:
    """Each child tag -> the first child with it: ``element.find(tag)`` for every tag at once.

    One pass over the children instead of one ``find`` per name (lxml's ``find`` goes through its
    ElementPath machinery, ~2.5 µs a call: loading pybullet_data's 95 robots asked ~12,000 times).
    Only element tags are plain strings, so comments and namespaced children never match a URDF name.
    """
    found: dict[Any, Any] = {}
    for child, tag in _children(element, read):
        found.setdefault(tag, child)
    return found


def read_link(element, resolver: PackageResolver, read: Children) -> Link:
    """The :class:`Link` of a ``<link>`` element (its children recorded in ``read``)."""
    visuals, collisions = [], []
    inertial_element = None
    for child, tag in _children(element, read):
        if tag == "visual":
            visuals.append(child)
        elif tag == "collision":
            collisions.append(child)
        elif tag == "inertial" and inertial_element is None:
            inertial_element = child
    inertial = None
    if inertial_element is not None:
        parts = _first_children(inertial_element, read)
        mass_element = parts.get("mass")
        tensor_element = parts.get("inertia")
        tensor = None
        if tensor_element is not None:
            values = [parse_float(tensor_element.get(key)) for key in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")]
            if all(v is not None for v in values):
                tensor = tuple(values)  # type: ignore[assignment]
        inertial = Inertial(
            origin=Origin.from_element(parts.get("origin")),
            mass=parse_float(mass_element.get("value")) if mass_element is not None else None,
            tensor=tensor,
            element=inertial_element,
            parts=parts,
        )
    return Link(
        name=element.get("name", ""),
        inertial=inertial,
        visuals=tuple(_read_shape(e, "visual", resolver, read) for e in visuals),
        collisions=tuple(_read_shape(e, "collision", resolver, read) for e in collisions),
        element=element,
    )


def _read_shape(element, role: str, resolver: PackageResolver, read: Children) -> Shape:
    parts = _first_children(element, read)
    return Shape(role=role, origin=Origin.from_element(parts.get("origin")),
                 geometry=_read_geometry(parts.get("geometry"), resolver, read), element=element)


def _read_geometry(container, resolver: PackageResolver, read: Children) -> Geometry:
    """The shape in a ``<geometry>`` element (None: the shape has none)."""
    if container is None:
        return Geometry(None, {}, None)
    children = [child for child, tag in _children(container, read) if isinstance(tag, str)]
    if not children:
        return Geometry(None, {}, container)
    element = children[0]
    kind = element.tag
    if kind == "box":
        return Geometry(kind, {"size": parse_floats(element.get("size"), 3)}, element)
    if kind in ("cylinder", "capsule"):
        return Geometry(kind, {"radius": parse_float(element.get("radius")),
                               "length": parse_float(element.get("length"))}, element)
    if kind == "sphere":
        return Geometry(kind, {"radius": parse_float(element.get("radius"))}, element)
    if kind == "mesh":
        filename = element.get("filename")
        scale_text = element.get("scale")
        scale: tuple[float, ...] | None = (1.0, 1.0, 1.0)
        if scale_text is not None:
            scale = parse_floats(scale_text)
            if scale is not None and len(scale) == 1:
                scale = scale * 3  # pybullet accepts one number (with a warning)
            elif scale is not None and len(scale) != 3:
                scale = None
        resolution = resolver.resolve(filename) if filename else None
        return Geometry(kind, {"scale": scale}, element, filename, resolution)
    return Geometry(None, {"tag": kind}, element)


def read_joint(element, read: Children) -> Joint:
    """The :class:`Joint` of a ``<joint>`` element (its children recorded in ``read``)."""
    parts = _first_children(element, read)
    limit_element = parts.get("limit")
    limit = None
    if limit_element is not None:
        limit = Limit(*(parse_float(limit_element.get(key)) for key in ("lower", "upper", "effort", "velocity")),
                      element=limit_element,
                      **{key: parse_float(limit_element.get(key)) for key in ("acceleration", "deceleration", "jerk")})
    axis_element = parts.get("axis")
    axis = parse_floats(axis_element.get("xyz"), 3) if axis_element is not None else None
    mimic_element = parts.get("mimic")
    mimic = None
    if mimic_element is not None:
        mimic = Mimic(mimic_element.get("joint", ""),
                      _finite_or(parse_float(mimic_element.get("multiplier")), 1.0),
                      _finite_or(parse_float(mimic_element.get("offset")), 0.0), mimic_element)
    parent = parts.get("parent")
    child = parts.get("child")
    return Joint(
        name=element.get("name", ""),
        type=element.get("type", ""),
        parent=parent.get("link") if parent is not None else None,
        child=child.get("link") if child is not None else None,
        origin=Origin.from_element(parts.get("origin")),
        axis=axis or (1.0, 0.0, 0.0),  # type: ignore[arg-type]
        axis_given=axis_element is not None,
        limit=limit,
        mimic=mimic,
        element=element,
        parts=parts,
    )


def _finite_or(value: float | None, default: float) -> float:
    return value if value is not None and math.isfinite(value) else default
