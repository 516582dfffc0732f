"""The document ar3cli hands to pybullet: a copy of the model that pybullet 3.2.7 loads right.

pybullet is given a temporary copy, never the user's file, because the file as written trips
pybullet in three measured ways (``docs/pybullet-facts.md``, sections 7 and 10):

- mesh URIs: ``package://`` is not understood, so every filename is made absolute (the resolver's
  answer; xacro documents load the same way);
- very long lines: a valid one-line URDF of ~11,000 characters fails with
  XML_ERROR_PARSING_ATTRIBUTE, so the copy is indented, one element per line;
- a ``<robot>`` without a name is refused by pybullet ("Expected a name for robot"): the copy
  gets one;
- link order: with ``URDF_MAINTAIN_LINK_ORDER`` (which ar3cli passes so that pybullet's link
  indices follow the file), pybullet crashes in C when the root link is not the first ``<link>``
  element (every UR arm of example-robot-data, TIAGo, Talos, PR2, Romeo) and gives NaN frames to a
  link declared before its parent. The copy lists the links parent first, root first, otherwise in
  the file's order, so both cannot happen;
- meshes pybullet cannot load (a file not found, a format it does not read): one makes pybullet refuse
  the whole robot. By default the copy keeps them (pybullet's refusal is what lint-urdf --sim reports);
  with ``leave_out_unloadable`` the ``<visual>`` or ``<collision>`` holding one is left out and listed
  (:class:`LeftOut`), so that work that needs no meshes (frames, masses) goes on, and work that does
  says what it could not check;
- URDF 1.1 orientations: pybullet ignores ``<origin quat_xyzw>`` (measured: the frame stays
  unrotated), so each one becomes the ``rpy`` of the same rotation (full precision), the rotation
  ar3cli's own FK uses. ``<capsule>`` needs nothing: pybullet reads it as urdfdom does (radius,
  cylinder ``length`` along z, hemispherical caps; measured with ``getAABB``).

Only the ``<link>`` elements move (into the slots links held before); joints and everything else
stay where they were. Names and geometry are untouched, so every command's link naming is the
file's. Line numbers are not: pybullet quotes lines of the copy ("invalid mesh filename extension"),
so :func:`loadable_document` can fill a line map (copy line -> the user's file and line, through
xacro's origins for a xacro) and :func:`user_lines` rewrites pybullet's messages with it.
"""

from __future__ import annotations

import bisect
import copy
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any, NamedTuple

from ar3cli.urdf.meshinfo import PYBULLET_MESH_FORMATS, leave_out_unloadable_mesh
from ar3cli.urdf.model import Model, read_quaternion

UNNAMED_ROBOT = "robot"
"""The name given to a ``<robot>`` without one (UR3 and hector's quadrotor in example-robot-data):
pybullet refuses to load it, and the name is used for nothing else."""


class Place(NamedTuple):
    """A line of the user's file (the xacro source, or a file it includes, for a xacro)."""

    file: str
    line: int


LineMap = dict[int, Place]
"""Line of the loadable copy -> where the element starting on it was written."""


class LeftOut(NamedTuple):
    """A ``<visual>`` or ``<collision>`` left out of the copy: pybullet cannot load its mesh."""

    link: str
    role: str
    """``visual`` or ``collision``."""
    reason: str
    """``mesh meshes/link_3.stl: file not found``, or the format pybullet does not read (lint-urdf's G001
    and G004 say where it looked and what to do)."""
    place: Place | None

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "role": self.role, "reason": self.reason,
                "file": self.place.file if self.place else None, "line": self.place.line if self.place else None}


def unloadable_mesh_reason(mesh: Any, resolver: Any) -> str | None:
    """Why pybullet cannot load the geometry element ``mesh`` (a ``<mesh>``, or PyBullet's ``<cdf>``): its
    file is not found, or a mesh format pybullet does not read (the whole robot is then refused); None
    when it can, or when the element names no file."""
    uri = (mesh.get("filename") or "").strip()
    if not uri:
        return None
    resolution = resolver.resolve(uri)
    if not resolution.found:
        return f"{mesh.tag} {uri}: {resolution.problem or 'file not found'}"
    if mesh.tag != "mesh":
        return None
    suffix = Path(uri).suffix.lower()
    if suffix not in PYBULLET_MESH_FORMATS:
        return f"pybullet cannot load '{suffix or 'no extension'}' meshes ({uri})"
    return None


def unloadable_shapes(model: Model, roles: Iterable[str] = ("visual", "collision")) -> list[LeftOut]:
    """The ``<visual>``/``<collision>`` elements (of ``roles``) of ``model.root`` whose mesh pybullet cannot
    load: what ``loadable_document(..., leave_out_unloadable=True)`` leaves out, with the user's file and line."""
    found = _unloadable(model.root, model, set(roles))
    places = _expansion_places(model) if found else None
    return [LeftOut(link, role, reason, _place_in(model, places, shape)) for shape, link, role, reason in found]


def _unloadable(root: Any, model: Model, roles: set[str]) -> list[tuple[Any, str, str, str]]:
    """(shape element, link name, role, reason) for each shape under ``root`` whose mesh pybullet cannot load."""
    found = []
    for link in root.iter("link"):
        for shape in link:
            if shape.tag not in roles:
                continue
            for geometry in shape.iter("geometry"):
                reasons = (unloadable_mesh_reason(element, model.resolver) for element in geometry)
                reason = next((reason for reason in reasons if reason is not None), None)
                if reason is not None:
                    found.append((shape, link.get("name") or "", shape.tag, reason))
                    break
    return found


def left_out_summary(left_out: list[LeftOut], most: int = 2) -> str:
    """``1 collision shape left out (link 'a', robot.urdf:12: mesh x.stl: file not found)``: the first ``most``
    and a count, for a command's one warning line."""
    roles = sorted({item.role for item in left_out})
    shown = [f"link '{item.link}'" + (f", {Path(item.place.file).name}:{item.place.line}" if item.place else "")
             + f": {item.reason}" for item in left_out[:most]]
    more = f"; and {len(left_out) - most} more" if len(left_out) > most else ""
    plural = "s" if len(left_out) > 1 else ""
    return f"{len(left_out)} {' and '.join(roles)} shape{plural} left out ({'; '.join(shown)}{more})"


def loadable_document(model: Model, visuals: bool = True, lines: LineMap | None = None,
                      leave_out_unloadable: bool = False) -> bytes:
    """The bytes of the copy pybullet loads: absolute mesh paths, links parent-first, indented.

    ``visuals=False`` leaves the ``<visual>`` elements out, for work that never draws: reading the
    visual meshes is most of a load (measured on pybullet_data's panda: 0.09-0.30 s with them,
    0.014-0.028 s without). ``lines``, when given, is filled with the copy's :data:`LineMap`.
    ``leave_out_unloadable`` leaves out each shape of :func:`unloadable_shapes` (the caller says so).
    """
    from lxml import etree

    root = copy.deepcopy(model.root)
    if not visuals:
        for element in list(root.iter("visual")):
            element.getparent().remove(element)
    if leave_out_unloadable:
        for shape, _link, _role, _reason in _unloadable(root, model, {"visual", "collision"}):
            shape.getparent().remove(shape)
    if not root.get("name"):
        root.set("name", UNNAMED_ROBOT)  # pybullet refuses a <robot> without one ("Expected a name for robot")
    _order_links_parent_first(root, ((joint.parent, joint.child) for joint in model.joints))
    _quaternions_as_rpy(root)
    etree.indent(root, space=" ")
    for element in list(root.iter()):
        uri = element.get("filename")
        if not uri:
            continue
        resolution = model.resolver.resolve(uri)
        if resolution.found:
            element.set("filename", str(resolution.path))
            leave_out_unloadable_mesh(element, resolution.path)  # over the mesh cap, or a FIFO: lint's G011
        elif resolution.refused is not None:  # a FIFO, a device or a folder where the mesh should be: G001
            leave_out_unloadable_mesh(element, resolution.refused)
    document = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    if lines is not None:
        lines.update(line_map(model, root, document))
    return document


def _quaternions_as_rpy(root: Any) -> None:
    """Replace every ``<origin quat_xyzw>`` by the ``rpy`` the Model read for it (see :class:`~ar3cli.urdf.model.Origin`):
    pybullet ignores the quaternion. An origin that also has ``rpy`` keeps it (the Model reads that),
    and an unusable quaternion leaves no rotation, as the Model does."""
    for element in root.iter("origin"):
        text = element.get("quat_xyzw")
        if text is None:
            continue
        del element.attrib["quat_xyzw"]
        quat = read_quaternion(text)
        if element.get("rpy") is None and quat is not None:
            element.set("rpy", " ".join(repr(angle) for angle in quat[1]))


def write_loadable_copy(model: Model, path: Path, visuals: bool = True, lines: LineMap | None = None,
                        leave_out_unloadable: bool = False) -> Path:
    """Write :func:`loadable_document` to ``path`` (filling ``lines``) and return it."""
    path.write_bytes(loadable_document(model, visuals, lines, leave_out_unloadable))
    return path


def line_map(model: Model, copied: Any, document: bytes) -> LineMap:
    """Each line of ``document`` that starts an element -> where that element was written.

    ``copied`` is the tree ``document`` serialises: deep copies keep their original ``sourceline``
    (lxml copies it), and the serialised document re-parsed has the same elements in the same
    order, so walking both side by side pairs each copy line with its line in the user's text. For a
    xacro that text is the expansion, whose lines are mapped on to the xacro source by xacro's
    recorded origins (an element xacro made itself keeps the expansion's nearest known line).
    """
    from lxml import etree

    source = _expansion_places(model)
    shown = str(model.path)
    result: LineMap = {}
    reparsed = etree.fromstring(document, etree.XMLParser(huge_tree=True))
    for written, original in zip(_elements(reparsed), _elements(copied)):
        if written.sourceline and original.sourceline and written.sourceline not in result:
            place = source.get(original.sourceline) if source is not None else Place(shown, original.sourceline)
            if place is not None:
                result[written.sourceline] = place
    return result


def _elements(root: Any) -> list[Any]:
    return [node for node in root.iter() if isinstance(node.tag, str)]


def _expansion_places(model: Model) -> dict[int, Place] | None:
    """For a xacro: line of the expansion -> the xacro file and line its first element came from (None for a URDF)."""
    if not model.is_xacro:
        return None
    from ar3cli.urdf.xacro_expand import origins

    found = origins(model.xml_bytes) or []
    elements = _elements(model.root)
    places: dict[int, Place] = {}
    if len(found) == len(elements):
        for element, origin in zip(elements, found):
            if origin is not None and element.sourceline and element.sourceline not in places:
                places[element.sourceline] = Place(origin.file, origin.line)
    return places


def user_place(model: Model, element: Any) -> Place | None:
    """Where ``element`` of ``model.root`` was written: the file and line the user sees (None if unknown)."""
    return _place_in(model, _expansion_places(model), element)


def _place_in(model: Model, places: dict[int, Place] | None, element: Any) -> Place | None:
    """:func:`user_place` with the xacro's :func:`_expansion_places` computed once by the caller."""
    line = element.sourceline
    if not line:
        return None
    return Place(str(model.path), line) if places is None else places.get(line)


def user_lines(message: str, copy_path: Path, lines: LineMap, shown: str) -> str:
    """``message`` with every ``COPY:LINE`` pybullet wrote turned into ``FILE:LINE`` of the user's file.

    A line that starts no element (a closing tag) takes the nearest element line above it; the copy's
    name without a known line becomes ``shown`` (the user's path), so no line of the copy is ever shown.
    """
    known = sorted(lines)

    def place(match: re.Match) -> str:
        at = bisect.bisect_right(known, int(match.group(1))) - 1
        if at < 0:
            return shown
        found = lines[known[at]]
        return f"{found.file}:{found.line}"

    message = re.sub(re.escape(str(copy_path)) + r":(\d+)", place, message)
    return message.replace(str(copy_path), shown)


def parent_first_order(names: list[str], edges: Iterable[tuple[str | None, str | None]]) -> list[str]:
    """``names`` reordered so that each link comes after its parent (the file's order otherwise).

    A link is preceded by the chain of its not yet listed ancestors, so the root comes first and a
    file already in order is unchanged. ``edges`` are (parent, child) pairs; a link with several
    parents keeps the first, and a cycle is cut where it closes (lint reports both), so this always
    returns every name exactly once.
    """
    known = set(names)
    parent_of: dict[str, str] = {}
    for parent, child in edges:
        if parent in known and child in known and child not in parent_of and parent != child:
            parent_of[child] = parent
    placed: set[str] = set()
    ordered: list[str] = []
    for name in names:
        chain: list[str] = []
        node: str | None = name
        while node is not None and node not in placed and node not in chain:
            chain.append(node)
            node = parent_of.get(node)
        for link in reversed(chain):
            placed.add(link)
            ordered.append(link)
    return ordered


def _order_links_parent_first(root: Any, edges: Iterable[tuple[str | None, str | None]]) -> None:
    """Permute the ``<link>`` children of ``root`` in place into :func:`parent_first_order`."""
    links = [child for child in root if child.tag == "link"]
    names = [link.get("name") or "" for link in links]
    if len(set(names)) != len(names):
        return  # duplicate names (lint's S001): no order is right, pybullet refuses the file anyway
    order = parent_first_order(names, edges)
    if order == names:
        return
    by_name = {link.get("name"): link for link in links}
    slots = [root.index(link) for link in links]
    placeholders = []
    for slot in slots:  # free the slots first, so that moving one link cannot shift another's index
        placeholder = root.makeelement("ar3cli-slot", {})
        root.replace(root[slot], placeholder)
        placeholders.append(placeholder)
    for placeholder, name in zip(placeholders, order):
        root.replace(placeholder, by_name[name])
