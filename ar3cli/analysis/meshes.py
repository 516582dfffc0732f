"""The robot's geometry as triangle meshes, each in its link's frame: what a viewer uploads once per
load and then only moves.

Every ``<visual>`` and ``<collision>`` becomes one or more :class:`Part` (a COLLADA file with several
geometries gives one part per geometry, each with its own colour): boxes, cylinders, spheres and
capsules are tessellated by trimesh; meshes are read the way lint reads them (the capped,
non-blocking reader of :func:`ar3cli.urdf.meshinfo.read_mesh`: never a FIFO, never a mesh over the
cap) and parsed by trimesh from those bytes, so a mesh cannot make trimesh open another file (an OBJ's
material library, a COLLADA texture). Mesh ``scale`` and a COLLADA file's ``<unit meter>`` are
applied (:func:`ar3cli.urdf.bounds.mesh_unit`, as every size ar3cli computes), then the shape's
``<origin>``.

Colours: a visual's ``<material>`` colour (its own ``<color rgba>``, or the robot-level material it
names), else the colour the mesh file gives its geometry, else none (the viewer's default). A shape
that cannot be drawn (a missing or unreadable mesh, a dimension that does not parse) is left out
and :attr:`RobotMeshes.notes` says why, one line each.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.errors import UserError
from ar3cli.urdf.model import Model, Shape

Rgba = tuple[float, float, float, float]

CYLINDER_SECTIONS = 32
"""Sides of a tessellated cylinder or capsule: round enough at any size a viewer shows."""
SPHERE_SUBDIVISIONS = 3
"""An icosphere of 642 vertices."""
NOTES_SHOWN = 50
"""Notes kept per load (a robot whose 300 meshes are all missing says so in one line more)."""


@dataclass(frozen=True)
class Part:
    """One drawable piece of a link's visual or collision geometry, in the link frame (metres).

    ``vertices`` is (N, 3) float32, ``faces`` (M, 3) uint32 (counter-clockwise seen from outside);
    ``index`` is the shape's position among the link's visuals (or collisions), ``line`` its
    ``<visual>``/``<collision>`` line in the parsed document.
    """

    link: str
    role: str
    index: int
    vertices: Any = field(repr=False)
    faces: Any = field(repr=False)
    rgba: Rgba | None = None
    line: int = 0


@dataclass(frozen=True)
class RobotMeshes:
    """Every part of every link, in file order, and what could not be drawn."""

    parts: list[Part]
    notes: list[str]

    def of(self, link: str, role: str | None = None) -> list[Part]:
        return [part for part in self.parts if part.link == link and (role is None or part.role == role)]


@question
def link_meshes(analysis: RobotAnalysis) -> RobotMeshes:
    """The visual and collision parts of every link (a mesh file read once however often it is named)."""
    model = analysis.require_model()
    materials = _named_materials(model)
    loaded: dict[tuple[str, tuple[float, ...], float], list[tuple[Any, Any, Rgba | None]]] = {}
    parts: list[Part] = []
    notes: list[str] = []
    for link in model.links:
        for role, shapes in (("visual", link.visuals), ("collision", link.collisions)):
            for index, shape in enumerate(shapes):
                try:
                    pieces = _pieces(shape, loaded)
                except UserError as exc:
                    if len(notes) < NOTES_SHOWN:
                        notes.append(f"link {link.name}: {role} {index + 1} not drawn: {exc.message}")
                    continue
                colour = _material_colour(shape, materials) if role == "visual" else None
                line = (shape.element.sourceline or 0) if shape.element is not None else 0
                parts += [Part(link.name, role, index, vertices, faces, colour or own, line)
                          for vertices, faces, own in pieces]
    return RobotMeshes(parts, notes)


def _pieces(shape: Shape, loaded: dict) -> list[tuple[Any, Any, Rgba | None]]:
    """(vertices in the link frame, faces, the mesh's own colour) of each piece of ``shape``."""
    import numpy as np

    geometry = shape.geometry
    if geometry.kind is None:
        raise UserError("it has no geometry ar3cli can read")
    if geometry.kind == "mesh":
        pieces = _mesh_pieces(geometry, loaded)
    else:
        pieces = [(*_primitive(geometry.kind, geometry.params), None)]
    rotation = np.asarray(shape.origin.rotation, dtype=float)
    translation = np.asarray(shape.origin.xyz, dtype=float)
    if not (np.isfinite(rotation).all() and np.isfinite(translation).all()):
        raise UserError("its <origin> is not finite")
    return [((vertices @ rotation.T + translation).astype(np.float32), faces, colour)
            for vertices, faces, colour in pieces]


def _primitive(kind: str, params: dict) -> tuple[Any, Any]:
    """Vertices and faces of a URDF box, cylinder, sphere or capsule (centred, axis along z)."""
    import numpy as np

    from ar3cli.infra.held_import import import_holding_interrupts

    creation = import_holding_interrupts("trimesh.creation")
    if kind == "box":
        size = params.get("size")
        if size is None or not all(math.isfinite(v) and v > 0 for v in size):
            raise UserError(f"box size {_shown(size)} is not three positive numbers")
        mesh = creation.box(extents=size)
    else:
        radius, length = params.get("radius"), params.get("length")
        values = [radius] if kind == "sphere" else [radius, length]
        if not all(v is not None and math.isfinite(v) and v > 0 for v in values):
            raise UserError(f"{kind} dimensions {_shown(values)} are not positive numbers")
        if kind == "sphere":
            mesh = creation.icosphere(subdivisions=SPHERE_SUBDIVISIONS, radius=radius)
        elif kind == "cylinder":
            mesh = creation.cylinder(radius=radius, height=length, sections=CYLINDER_SECTIONS)
        else:
            mesh = creation.capsule(height=length, radius=radius, count=[CYLINDER_SECTIONS, CYLINDER_SECTIONS])
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.uint32)


def _mesh_pieces(geometry, loaded: dict) -> list[tuple[Any, Any, Rgba | None]]:
    """The mesh file's geometries, scaled to metres (``scale`` times the COLLADA unit)."""
    import numpy as np

    from ar3cli.urdf.bounds import mesh_unit

    resolution = geometry.resolution
    if resolution is None or not resolution.found:
        raise UserError(f"mesh {resolution.explain() if resolution is not None else 'without a filename'}")
    scale = geometry.params.get("scale")
    if scale is None or not all(math.isfinite(v) for v in scale):
        raise UserError(f"mesh {geometry.filename}: its scale is not three numbers")
    unit = mesh_unit(geometry)
    if unit is None:
        raise UserError(f"mesh {geometry.filename}: its COLLADA <unit meter> is not a positive number")
    key = (str(resolution.path), tuple(scale), unit)
    if key not in loaded:
        factors = np.asarray(scale, dtype=float) * unit
        mirrored = bool(np.prod(np.sign(factors)) < 0)
        loaded[key] = [(vertices * factors, faces[:, ::-1] if mirrored else faces, colour)
                       for vertices, faces, colour in _read_mesh_file(resolution.path)]
    return loaded[key]


def _read_mesh_file(path) -> list[tuple[Any, Any, Rgba | None]]:
    """(vertices, faces, colour or None) of each geometry in the mesh file at ``path`` (file units)."""
    import io

    import numpy as np

    from ar3cli.infra.held_import import import_holding_interrupts
    from ar3cli.urdf.meshinfo import read_mesh

    trimesh = import_holding_interrupts("trimesh")
    data = read_mesh(path)  # UserError: over the cap, not a regular file, unreadable
    try:
        loaded = trimesh.load(io.BytesIO(data), file_type=path.suffix.lower().lstrip("."), process=False)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for files it cannot read
        raise UserError(f"mesh {path.name}: cannot read: {type(exc).__name__}: {exc}"[:300]) from None
    meshes = loaded.dump(concatenate=False) if hasattr(loaded, "dump") else [loaded]
    pieces = []
    for mesh in meshes:
        vertices = np.asarray(getattr(mesh, "vertices", ()), dtype=float).reshape(-1, 3)
        faces = np.asarray(getattr(mesh, "faces", ()), dtype=np.int64).reshape(-1, 3)
        if not len(faces) or not np.isfinite(vertices).all() or faces.min() < 0 or faces.max() >= len(vertices):
            continue
        pieces.append((vertices, faces.astype(np.uint32), _own_colour(mesh)))
    if not pieces:
        raise UserError(f"mesh {path.name}: no triangles with finite vertices")
    return pieces


def _own_colour(mesh) -> Rgba | None:
    """The colour a mesh file gives a geometry (COLLADA's diffuse colour, a PLY's vertex colours),
    None when it gives none."""
    visual = getattr(mesh, "visual", None)
    colour = None
    try:
        if getattr(visual, "kind", None) == "texture":
            colour = visual.material.main_color
        elif getattr(visual, "defined", False):
            colour = visual.main_color
    except Exception:  # noqa: BLE001 - a material trimesh cannot summarise: draw the default colour
        return None
    if colour is None or len(colour) < 3:
        return None
    values = [float(v) / 255.0 for v in list(colour)[:4]] + [1.0]
    return tuple(values[:4])  # type: ignore[return-value]


def _named_materials(model: Model) -> dict[str, Rgba]:
    """The robot-level ``<material name>`` elements with a usable ``<color rgba>``."""
    found: dict[str, Rgba] = {}
    for element in model.root.findall("material"):
        colour = _rgba(element.find("color"))
        if colour is not None and element.get("name") is not None:
            found.setdefault(element.get("name"), colour)
    return found


def _material_colour(shape: Shape, materials: dict[str, Rgba]) -> Rgba | None:
    """A visual's colour: its material's own ``<color>``, else the robot-level material it names."""
    element = shape.element.find("material") if shape.element is not None else None
    if element is None:
        return None
    return _rgba(element.find("color")) or materials.get(element.get("name") or "")


def _rgba(element) -> Rgba | None:
    from ar3cli.urdf.model import parse_floats

    values = parse_floats(element.get("rgba"), 4) if element is not None else None
    if values is None or not all(math.isfinite(v) for v in values):
        return None
    return tuple(min(max(v, 0.0), 1.0) for v in values)  # type: ignore[return-value]


def _shown(values) -> str:
    return "missing" if values is None else " ".join(f"{v:g}" if v is not None else "?" for v in values)
