"""Geometry rules (G): mesh files, their formats and units, and missing collision shapes."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, robot, rule
from ar3cli.urdf.bounds import scaled_mesh_bounds

PYBULLET_MESH_FORMATS = (".stl", ".obj", ".dae")
"""What PyBullet's URDF importer loads (anything else: "invalid mesh filename extension")."""
MAX_PLAUSIBLE_EXTENT = 5.0
"""A robot part larger than this many metres after scaling is almost always a mesh in millimetres."""
MIN_PLAUSIBLE_EXTENT = 1e-3
"""A part smaller than a millimetre after scaling was probably scaled twice (or is in km)."""
FLAT_RATIO = 0.01
"""Meshes whose smallest extent is below this fraction of the largest are planes (ground, walls)."""


def _meshes(ctx):
    """(link, shape, geometry) for every mesh with a filename."""
    for link, shape in ctx.model.meshes():
        if shape.geometry.filename:
            yield link, shape, shape.geometry


def _mesh_robot(filename: str, scale: str = "") -> str:
    scale_attr = f' scale="{scale}"' if scale else ""
    return robot(f"""
        <link name="base">
          {LINK_INERTIAL}
          <visual><geometry><mesh filename="{filename}"{scale_attr}/></geometry></visual>
          <collision><geometry><mesh filename="{filename}"{scale_attr}/></geometry></collision>
        </link>""")


@rule("G001", "mesh-not-found", "error", "Mesh file not found",
      why="""PyBullet refuses the whole file with "Cannot load URDF file" (the real reason, the missing
      mesh, only goes to C stdout); RViz shows nothing. ar3cli resolves package:// like ROS
      (--package-path, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH, package.xml in ancestors) and relative
      paths like PyBullet, and lists every place it looked.""",
      fix="Fix the path, or tell ar3cli where the package is with --package-path NAME=DIR.",
      bad=_mesh_robot("meshes/missing.stl"), good=_mesh_robot("meshes/base.stl"))
def mesh_not_found(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and not resolution.found and not resolution.problem.startswith("empty package"):
            tried = "; looked in " + ", ".join(resolution.tried) if resolution.tried else ""
            yield Hit(f"link '{link.name}' mesh {resolution.uri}: {resolution.problem or 'not found'}{tried}",
                      geometry.element)


@rule("G002", "empty-package", "error", "package:/// URI with an empty package name",
      why="""package:///meshes/x.stl has an empty package name (three slashes). ROS cannot resolve it;
      PyBullet only finds the file by its fallback search relative to the URDF.""",
      fix="Write package://PACKAGE_NAME/meshes/x.stl, or a path relative to the URDF.",
      bad=_mesh_robot("package:///meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def empty_package(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        if geometry.filename.strip().startswith("package:///"):
            yield Hit(f"link '{link.name}' mesh {geometry.filename} names no package", geometry.element)


@rule("G003", "absolute-path", "warning", "Absolute mesh path",
      why="An absolute path (/home/me/... or file:///...) works on one machine only.",
      fix="Use package://PACKAGE/... or a path relative to the URDF file.",
      bad=_mesh_robot("/home/me/robot/meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def absolute_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        name = geometry.filename.strip()
        if name.startswith("file://") or Path(name).is_absolute():
            yield Hit(f"link '{link.name}' mesh {name} is an absolute path", geometry.element)


@rule("G004", "mesh-format", "error", "Mesh format PyBullet cannot load",
      why="""PyBullet loads .stl, .obj and .dae meshes only; a .ply or Ogre .mesh makes it refuse the
      whole file ("invalid mesh filename extension").""",
      fix="Convert the mesh to .stl or .obj (e.g. with trimesh or MeshLab).",
      bad=_mesh_robot("meshes/base.ply"), good=_mesh_robot("meshes/base.stl"))
def mesh_format(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        suffix = Path(geometry.filename.strip()).suffix.lower()
        if suffix not in PYBULLET_MESH_FORMATS:
            yield Hit(f"link '{link.name}' mesh {geometry.filename}: PyBullet cannot load '{suffix or 'no extension'}' "
                      "meshes", geometry.element)


@rule("G005", "lfs-pointer", "error", "Mesh is a Git LFS pointer file",
      why="""The repository stores meshes in Git LFS and they were never pulled: the file is a
      130-byte text pointer. Loaders report a corrupt or empty mesh, or crash.""",
      fix="Run git lfs install && git lfs pull in the repository.",
      bad=_mesh_robot("meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def lfs_pointer(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import is_lfs_pointer

    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and resolution.found and is_lfs_pointer(resolution.path):
            yield Hit(f"link '{link.name}' mesh {resolution.path} is a Git LFS pointer, not a mesh", geometry.element)


@rule("G006", "mesh-units", "warning", "Mesh size suggests wrong units",
      why="""URDF meshes are in metres. A mesh exported in millimetres loads silently 1000x too large
      in PyBullet (a 30 cm link becomes 300 m); one scaled twice becomes sub-millimetre. Flat meshes
      (ground planes, walls) are exempt.""",
      fix='Add scale="0.001 0.001 0.001" for a millimetre mesh, or re-export it in metres.',
      bad=_mesh_robot("meshes/base_mm.stl"), good=_mesh_robot("meshes/base_mm.stl", "0.001 0.001 0.001"))
def mesh_units(ctx) -> Iterator[Hit]:
    seen: set[tuple] = set()
    for link, _shape, geometry in _meshes(ctx):
        bounds = scaled_mesh_bounds(geometry)
        if bounds is None:
            continue
        extent = [b - a for a, b in zip(*bounds)]
        if any(map(math.isnan, extent)):
            continue  # a nan scale: F007 reports it
        key = (str(geometry.resolution.path), tuple(geometry.params.get("scale") or ()), link.name)
        if key in seen:
            continue
        seen.add(key)
        largest, smallest = max(extent), min(extent)
        shown = " x ".join(f"{e:.4g}" for e in extent)
        if largest > MAX_PLAUSIBLE_EXTENT and smallest > FLAT_RATIO * largest:
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is {shown} m after scaling: millimetres?",
                      geometry.element)
        elif 0 < largest < MIN_PLAUSIBLE_EXTENT:
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is only {shown} m after scaling: scaled twice?",
                      geometry.element, hint="Check the scale attribute: the mesh may already be in metres.")


@rule("G007", "scalar-scale", "warning", "Mesh scale is a single number",
      why="""The spec's scale is three numbers. PyBullet accepts one (with "Scale should be a
      vector3"), urdfdom and yourdfpy refuse or misread it.""",
      fix='Repeat it: scale="0.001 0.001 0.001".',
      bad=_mesh_robot("meshes/base.stl", "0.001"), good=_mesh_robot("meshes/base.stl", "0.001 0.001 0.001"))
def scalar_scale(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        text = geometry.element.get("scale")
        if text is not None and len(text.split()) == 1:
            yield Hit(f"link '{link.name}' mesh scale=\"{text}\" is one number", geometry.element,
                      hint=f'Write scale="{text} {text} {text}".')


@rule("G008", "no-collision", "warning", "Link with visual but no collision geometry",
      why="""A link you can see but that has no <collision> passes through everything in simulation
      (no contacts, no self-collision checks), and PyBullet's default inertia comes from the
      collision shape, so it falls back to a tiny default box.""",
      fix="Add a <collision> (a primitive or a simplified mesh).",
      bad=robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="1 1 1"/></geometry></visual></link>'),
      good=robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="1 1 1"/></geometry></visual>'
                 '<collision><geometry><box size="1 1 1"/></geometry></collision></link>'))
def no_collision(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        if link.visuals and not link.collisions:
            yield Hit(f"link '{link.name}' has {len(link.visuals)} visual shape(s) but no <collision>", link.element)


@rule("G009", "pybullet-only-path", "info", "Mesh found only by PyBullet's fallback search",
      why="""The mesh resolves only because PyBullet also looks for package://NAME/x relative to the
      URDF and a few folders above it. ROS (RViz, MoveIt, Gazebo) resolves package://NAME through
      the package index and will not find it.""",
      fix="Use a path relative to the URDF, or make NAME a real package (a package.xml) or pass --package-path.",
      bad=_mesh_robot("package://meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def pybullet_only_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and resolution.found and resolution.via == "pybullet-search":
            yield Hit(f"link '{link.name}' mesh {resolution.uri} is found only by PyBullet's fallback search; "
                      "ROS tools will not find it", geometry.element)


RULES = (mesh_not_found, empty_package, absolute_path, mesh_format, lfs_pointer, mesh_units, scalar_scale,
         no_collision, pybullet_only_path)
