"""The document ar3cli hands to MuJoCo: a copy of the model that MuJoCo's URDF compiler reads right.

MuJoCo is given a temporary copy, never the user's file, because the file as written trips MuJoCo
4.0 in ways measured on pybullet_data and example-robot-data (``shared/docs/anchors.md``):

- ``package://`` is not understood ("Error opening file 'package:/meshes/...'"), and by default the
  compiler strips every mesh path to its file name (``strippath``), so two ``link0.obj`` in different
  folders would be one mesh. Each mesh file the resolver finds is linked into a private folder
  under a unique name (``<n>_<name>``) and named by that absolute path, with
  ``<mujoco><compiler strippath="false"/></mujoco>``.
- MuJoCo reads binary STL, OBJ and MSH only: a COLLADA file (or any other format) is an "Error
  opening file" that stops the whole compile, as is a missing file or an ASCII STL. Such a mesh is replaced by its box
  (:func:`~ar3cli.urdf.bounds.metric_mesh_bounds`, centred where the mesh is), or left out when
  its size is unknown, and reported (:class:`Substitution`), so the rest is still checked.
- Visuals are dropped (MuJoCo's URDF default ``discardvisual="true"`` does the same; dropping them
  spares reading their meshes).
- ``fusestatic``: MuJoCo's URDF default fuses links joined by fixed joints into their parent. The
  copy says which (``fuse``): cross-check compiles unfused, so every URDF link is a body with a frame.

Names are untouched, so MuJoCo's "Element name 'arm'" names the user's link or joint.
"""

from __future__ import annotations

import copy
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ar3cli.urdf.model import Model

MUJOCO_MESH_SUFFIXES = (".stl", ".obj", ".msh")
"""What MuJoCo 4.0's compiler reads from a URDF ``<mesh filename>`` (anything else: "Error opening file")."""
SMALLEST_BOX = 1e-4
"""m: a replacement box is at least this thick (MuJoCo refuses a box with a zero size)."""


@dataclass(frozen=True)
class Substitution:
    """A mesh MuJoCo cannot read, and what the copy put in its place."""

    link: str
    uri: str
    reason: str
    replacement: str
    element: Any
    """The ``<mesh>`` element of the user's model (for file:line)."""


@dataclass
class MujocoCopy:
    """The document MuJoCo compiles, the meshes it replaced, and which user element each linked mesh came from."""

    document: bytes
    substitutions: list[Substitution]
    mesh_elements: dict[str, Any]
    """Linked mesh path (as MuJoCo quotes it) -> the user's ``<mesh>`` element."""
    lines: dict[int, Any]
    """Line of the copy that starts an element -> :class:`~ar3cli.sim.loadable_copy.Place` in the user's file."""


def mujoco_copy(model: Model, folder: Path, fuse: bool = True) -> MujocoCopy:
    """Build the copy MuJoCo compiles, linking mesh files into ``folder`` (a private temporary folder)."""
    from lxml import etree

    root = copy.deepcopy(model.root)
    twin = {original: copied for original, copied in zip(model.root.iter(), root.iter())}
    substitutions: list[Substitution] = []
    mesh_elements: dict[str, Any] = {}
    linked: dict[Path, str] = {}
    for link in model.links:
        for shape in link.collisions:
            geometry = shape.geometry
            if geometry.kind != "mesh" or geometry.element is None:
                continue
            mesh = geometry.element.find("mesh") if geometry.element.tag != "mesh" else geometry.element
            if mesh is None or mesh not in twin:
                continue
            resolution = geometry.resolution
            if resolution is not None and resolution.found and mujoco_reads(resolution.path):
                if resolution.path not in linked:
                    linked[resolution.path] = _link_file(resolution.path, folder, len(linked))
                twin[mesh].set("filename", linked[resolution.path])
                mesh_elements[linked[resolution.path]] = mesh
                continue
            reason = (f"'{geometry.filename}' is not found ({resolution.explain()})"
                      if resolution is None or not resolution.found else
                      f"'{geometry.filename}' is an ASCII STL: MuJoCo reads binary STL only"
                      if resolution.path.suffix.lower() == ".stl" else
                      f"'{geometry.filename}' is {resolution.path.suffix or 'a file without suffix'}: MuJoCo reads "
                      "STL, OBJ and MSH meshes only")
            replacement = _replace_with_box(shape, twin[mesh], twin.get(shape.element))
            substitutions.append(Substitution(link.name, geometry.filename or "", reason, replacement, mesh))
    for element in list(root.iter("visual")):
        element.getparent().remove(element)
    _set_compiler(root, fuse)
    etree.indent(root, space=" ")  # one element per line, so MuJoCo's "line N" names one element
    document = etree.tostring(root, xml_declaration=True, encoding="utf-8")
    from ar3cli.sim.loadable_copy import line_map

    return MujocoCopy(document, substitutions, mesh_elements, line_map(model, root, document))


def mujoco_reads(path: Path) -> bool:
    """Whether MuJoCo's compiler reads this mesh file: OBJ, MSH, or a *binary* STL (an ASCII STL is refused:
    "stl_decoder: number of faces should be between 1 and 200000 ...; perhaps this is an ASCII file?",
    measured on example-robot-data's simple_humanoid). A binary STL is 84 bytes plus 50 per triangle."""
    suffix = path.suffix.lower()
    if suffix not in MUJOCO_MESH_SUFFIXES:
        return False
    if suffix != ".stl":
        return True
    try:
        size = path.stat().st_size
        with path.open("rb") as handle:
            header = handle.read(84)
    except OSError:
        return False
    return len(header) == 84 and size == 84 + 50 * int.from_bytes(header[80:84], "little")


def _link_file(path: Path, folder: Path, index: int) -> str:
    """A unique name for ``path`` in ``folder`` (a symlink, a copy where links are refused); its absolute path."""
    import shutil

    target = folder / f"{index}_{path.name}"
    try:
        os.symlink(path, target)
    except OSError:
        shutil.copyfile(path, target)
    return str(target)


def _replace_with_box(shape: Any, mesh: Any, collision: Any) -> str:
    """Turn the copied ``<mesh>`` into the mesh's box (its origin moved to the box centre), or drop the
    copied collision when the size is unknown; what was done, in words."""
    from ar3cli.maths.tensor_math import rpy_to_matrix
    from ar3cli.urdf.bounds import metric_mesh_bounds

    box = metric_mesh_bounds(shape.geometry)
    if box is None or not all(math.isfinite(value) for corner in box for value in corner):
        if collision is not None and collision.getparent() is not None:
            collision.getparent().remove(collision)
        return "left out (its size is unknown)"
    low, high = box
    size = [max(b - a, SMALLEST_BOX) for a, b in zip(low, high)]
    centre = [(a + b) / 2 for a, b in zip(low, high)]
    rotation = rpy_to_matrix(shape.origin.rpy)
    moved = [xyz + sum(rotation[row][k] * centre[k] for k in range(3)) for row, xyz in enumerate(shape.origin.xyz)]
    parent = mesh.getparent()
    box_element = parent.makeelement("box", {"size": " ".join(f"{value:.9g}" for value in size)})
    parent.replace(mesh, box_element)
    if collision is not None:
        origin = collision.find("origin")
        if origin is None:
            origin = collision.makeelement("origin", {})
            collision.insert(0, origin)
        origin.set("xyz", " ".join(f"{value:.9g}" for value in moved))
        origin.set("rpy", " ".join(f"{value:.9g}" for value in shape.origin.rpy))
    return "replaced by its " + " x ".join(f"{value:.3g}" for value in size) + " m box"


def _set_compiler(root: Any, fuse: bool) -> None:
    """Give the copy the ``<mujoco><compiler/></mujoco>`` settings above (a user's element is kept, these set)."""
    extension = root.find("mujoco")
    if extension is None:
        extension = root.makeelement("mujoco", {})
        root.insert(0, extension)
    compiler = extension.find("compiler")
    if compiler is None:
        compiler = extension.makeelement("compiler", {})
        extension.insert(0, compiler)
    for name in ("meshdir", "assetdir"):
        compiler.attrib.pop(name, None)
    compiler.set("strippath", "false")
    compiler.set("discardvisual", "true")
    compiler.set("fusestatic", "true" if fuse else "false")
