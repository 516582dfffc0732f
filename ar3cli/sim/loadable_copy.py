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
  the file's order, so both cannot happen.

Only the ``<link>`` elements move (into the slots links held before); joints and everything else
stay where they were. Names and geometry are untouched, so every command's link naming is the
file's.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ar3cli.urdf.meshinfo import leave_out_unloadable_mesh
from ar3cli.urdf.model import Model

UNNAMED_ROBOT = "robot"
"""The name given to a ``<robot>`` without one (UR3 and hector's quadrotor in example-robot-data):
pybullet refuses to load it, and the name is used for nothing else."""


def loadable_document(model: Model, visuals: bool = True) -> bytes:
    """The bytes of the copy pybullet loads: absolute mesh paths, links parent-first, indented.

    ``visuals=False`` leaves the ``<visual>`` elements out, for work that never draws: reading the
    visual meshes is most of a load (measured on pybullet_data's panda: 0.09-0.30 s with them,
    0.014-0.028 s without).
    """
    from lxml import etree

    root = copy.deepcopy(model.root)
    if not visuals:
        for element in list(root.iter("visual")):
            element.getparent().remove(element)
    if not root.get("name"):
        root.set("name", UNNAMED_ROBOT)  # pybullet refuses a <robot> without one ("Expected a name for robot")
    _order_links_parent_first(root, ((joint.parent, joint.child) for joint in model.joints))
    etree.indent(root, space=" ")
    for element in list(root.iter()):
        uri = element.get("filename")
        if not uri:
            continue
        resolution = model.resolver.resolve(uri)
        if resolution.found:
            element.set("filename", str(resolution.path))
            leave_out_unloadable_mesh(element, resolution.path)  # over the mesh cap, or a FIFO: lint's G011
    return etree.tostring(root, xml_declaration=True, encoding="utf-8")


def write_loadable_copy(model: Model, path: Path, visuals: bool = True) -> Path:
    """Write :func:`loadable_document` to ``path`` and return it."""
    path.write_bytes(loadable_document(model, visuals))
    return path


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
