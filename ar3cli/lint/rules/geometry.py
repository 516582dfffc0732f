"""Geometry rules (G): mesh files, their formats and units, and missing collision shapes."""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import lru_cache
from pathlib import Path

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, robot, rule
from ar3cli.urdf.meshinfo import PYBULLET_MESH_FORMATS

MAX_PLAUSIBLE_EXTENT = 5.0
"""A robot part larger than this many metres after scaling is almost always a mesh in millimetres."""
MIN_PLAUSIBLE_EXTENT = 1e-3
"""A part smaller than a millimetre after scaling was probably scaled twice (or is in km)."""
FLAT_RATIO = 0.01
"""Meshes whose smallest extent is below this fraction of the largest are planes (ground, walls)."""
NON_SPEC_MESH_FORMATS = (".cdf", ".vtk")
"""Mesh extensions PyBullet's URDF importer accepts beyond .stl/.obj/.dae (G010, not G004)."""
ZERO_THICKNESS = 1e-9
"""A mesh whose thinnest extent is below this fraction of its largest has no volume (G012)."""
HULL_RATIO = 2.0
"""Convex hull volume / mesh volume above which a collision mesh collides as a much fatter body (G013)."""


@lru_cache(maxsize=4096)
def _path_facts(name: str) -> tuple[bool, str]:
    """``(Path(name).is_absolute(), Path(name).suffix.lower())`` of a mesh filename, computed once per
    name: G003, G004 and G010 ask for every mesh, and robots share meshes (pybullet_data's 95 robots:
    1,700 paths built for 155 meshes)."""
    path = Path(name)
    return path.is_absolute(), path.suffix.lower()


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
            tried = "; looked in " + resolution.places() if resolution.tried else ""
            yield Hit(f"link '{link.name}' mesh {resolution.uri}: {resolution.problem or 'not found'}{tried}",
                      geometry.element)


@rule("G002", "empty-package", "error", "package:/// URI with an empty package name",
      why="""package:///meshes/x.stl has an empty package name (three slashes). ROS cannot resolve it;
      PyBullet only finds the file by its fallback search relative to the URDF.""",
      fix="Write package://PACKAGE_NAME/meshes/x.stl, or a path relative to the URDF.",
      bad=_mesh_robot("package:///meshes/base.stl"), good=_mesh_robot("meshes/base.stl"),
      fixed_by="fix-mesh-paths --package NAME=DIR")
def empty_package(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        if geometry.filename.strip().startswith("package:///"):
            yield Hit(f"link '{link.name}' mesh {geometry.filename} names no package", geometry.element)


@rule("G003", "absolute-path", "warning", "Absolute mesh path",
      why="An absolute path (/home/me/... or file:///...) works on one machine only.",
      fix="Use package://PACKAGE/... or a path relative to the URDF file.",
      bad=_mesh_robot("/home/me/robot/meshes/base.stl"), good=_mesh_robot("meshes/base.stl"),
      fixed_by="fix-mesh-paths --package NAME=DIR")
def absolute_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        name = geometry.filename.strip()
        if name.startswith("file://") or _path_facts(name)[0]:
            yield Hit(f"link '{link.name}' mesh {name} is an absolute path", geometry.element)


@rule("G004", "mesh-format", "error", "Mesh format PyBullet cannot load",
      why="""PyBullet loads .stl, .obj and .dae meshes only; a .ply or Ogre .mesh makes it refuse the
      whole file ("invalid mesh filename extension").""",
      fix="Convert the mesh to .stl or .obj (e.g. with trimesh or MeshLab).",
      bad=_mesh_robot("meshes/base.ply"), good=_mesh_robot("meshes/base.stl"),
      references="PyBullet examples/Importers/ImportURDFDemo/UrdfFindMeshFile.h (\"invalid mesh filename extension\"); "
                 ".cdf and .vtk, which it accepts, are G010's.")
def mesh_format(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        suffix = _path_facts(geometry.filename.strip())[1]
        if suffix not in PYBULLET_MESH_FORMATS and suffix not in NON_SPEC_MESH_FORMATS:
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
      (ground planes, walls) are exempt. A COLLADA file states its own unit (<unit meter="0.0254"/>
      for inches), which PyBullet and assimp (RViz, MoveIt) apply: the size is judged after it.""",
      fix='Add scale="0.001 0.001 0.001" for a millimetre mesh, or re-export it in metres.',
      bad=_mesh_robot("meshes/base_mm.stl"), good=_mesh_robot("meshes/base_mm.stl", "0.001 0.001 0.001"),
      thresholds="Largest extent after scale (and COLLADA unit) above MAX_PLAUSIBLE_EXTENT = 5 m with the smallest "
                 "above FLAT_RATIO = 0.01 of it, or below MIN_PLAUSIBLE_EXTENT = 1 mm.",
      references="PyBullet LoadMeshFromCollada.cpp (applies <unit meter>); COLLADA 1.4.1 spec, <asset>/<unit>.")
def mesh_units(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import collada_unit

    seen: set[tuple] = set()
    for link, _shape, geometry in _meshes(ctx):
        bounds = ctx.scaled_mesh_bounds(geometry)
        if bounds is None:
            continue
        extent = [b - a for a, b in zip(*bounds)]
        unit = collada_unit(geometry.resolution.path) if geometry.resolution.path.suffix.lower() == ".dae" else 1.0
        if unit is None:
            continue  # an unreadable or nonsensical <unit>: no basis to judge the size
        extent = [e * unit for e in extent]
        if any(map(math.isnan, extent)):
            continue  # a nan scale: F007 reports it
        key = (str(geometry.resolution.path), tuple(geometry.params.get("scale") or ()), link.name)
        if key in seen:
            continue
        seen.add(key)
        largest, smallest = max(extent), min(extent)
        shown = " x ".join(f"{e:.4g}" for e in extent) + " m after scaling" + (
            f" and the file's COLLADA unit ({unit:g} m)" if unit != 1.0 else "")
        if largest > MAX_PLAUSIBLE_EXTENT and smallest > FLAT_RATIO * largest:
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is {shown}: millimetres?",
                      geometry.element)
        elif 0 < largest < MIN_PLAUSIBLE_EXTENT:
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is only {shown}: scaled twice?",
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
      URDF and in every folder above it. ROS (RViz, MoveIt, Gazebo) resolves package://NAME through
      the package index and will not find it.""",
      fix="Use a path relative to the URDF, or make NAME a real package (a package.xml) or pass --package-path.",
      bad=_mesh_robot("package://meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def pybullet_only_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and resolution.found and resolution.via == "pybullet-search" and \
                not geometry.filename.strip().startswith("package:///"):  # G002's (an error already)
            yield Hit(f"link '{link.name}' mesh {resolution.uri} is found only by PyBullet's fallback search; "
                      "ROS tools will not find it", geometry.element)


SPEC_SHAPES = ("box", "cylinder", "sphere", "mesh")
"""The geometry elements of the URDF spec (wiki.ros.org/urdf/XML/link)."""
READERS = {
    "capsule": "it is URDF 1.1, which the file does not declare: urdfdom 5.1+ drops this shape with a warning, "
               "older urdfdom refuses the whole file (\"Unknown geometry type 'capsule'\"), and with it "
               "robot_state_publisher, RViz, MoveIt and Pinocchio; PyBullet, Drake and MuJoCo read it",
    "plane": "only PyBullet reads it (an infinite plane); urdfdom, Drake and MuJoCo refuse the file",
    "cdf": "only PyBullet reads it; urdfdom, Drake and MuJoCo refuse the file",
    "drake:capsule": "only Drake reads it; urdfdom, PyBullet and MuJoCo refuse the file",
    "drake:ellipsoid": "only Drake reads it; urdfdom, PyBullet and MuJoCo refuse the file",
    ".vtk": "Drake reads .vtk volume meshes (hydroelastic contact); PyBullet accepts the name but extracts no "
            "mesh for a link (\"cannot extract mesh\": the shape is silently missing); MuJoCo, RViz and "
            "Pinocchio cannot read it",
    ".cdf": "PyBullet accepts the name but extracts no mesh for a link (\"cannot extract mesh\"); nothing else "
            "reads it",
}
"""What reads each geometry outside the spec (G010). Measured with pybullet 3.2.7; the others from their
parsers: urdfdom link.cpp parseGeometry, Drake detail_urdf_geometry.cc ParseGeometry, MuJoCo xml_urdf.cc Geom.
``capsule`` is spec since URDF 1.1 (urdfdom 5.1): G010 names it only where the file does not declare 1.1."""
CAPSULE_HINT = ('Declare URDF 1.1 (or later), which has <capsule>: <robot name="..." version="1.1">; or use spec '
                "1.0 shapes (a cylinder plus two spheres) for tools built on urdfdom older than 5.1.")


def _shape_elements(ctx):
    """(link, shape) for every visual and collision of every link."""
    for link in ctx.model.links:
        for shape in (*link.visuals, *link.collisions):
            yield link, shape


@rule("G010", "non-spec-geometry", "warning", "Geometry outside the URDF spec",
      why="""URDF 1.0 knows box, cylinder, sphere and mesh; URDF 1.1 adds <capsule> for files that
      declare it (<robot version="1.1">, read by urdfdom 5.1 and later). Engines extend it differently:
      <capsule> is read by PyBullet, Drake and MuJoCo, but in a file that does not declare 1.1 urdfdom
      5.1+ drops the shape and older urdfdom (and so every ROS tool and Pinocchio) refuses the whole
      file; <plane> and <cdf> are PyBullet's alone; .vtk and .cdf mesh files load in PyBullet without
      a shape. The file then works in one engine and fails, or silently loses a shape, in the next.""",
      fix="Declare <robot version=\"1.1\"> for a capsule; otherwise use a spec shape (a capsule is a cylinder plus "
          "two spheres, a plane a thin box), or keep the file for the one engine that reads it.",
      bad=robot(f'''<link name="base">{LINK_INERTIAL}<collision><geometry><capsule radius="0.05" length="0.3"/></geometry></collision></link>'''),
      good=robot(f'''<link name="base">{LINK_INERTIAL}<collision><geometry><capsule radius="0.05" length="0.3"/></geometry></collision></link>'''
                 ).replace('<robot name="r">', '<robot name="r" version="1.1">'),
      references="urdfdom urdf_parser/src/link.cpp parseGeometry and README (URDF versioning; capsule and quat_xyzw "
                 "in 1.1 since urdfdom 5.1.0, ros/urdfdom#238); Drake multibody/parsing/detail_urdf_geometry.cc; "
                 "MuJoCo src/xml/xml_urdf.cc; PyBullet UrdfParser.cpp (measured with pybullet 3.2.7).")
def non_spec_geometry(ctx) -> Iterator[Hit]:
    from lxml import etree

    for link, shape in _shape_elements(ctx):
        geometry = shape.geometry
        if geometry.element is None or geometry.element.tag == "geometry":
            continue  # no <geometry>, or an empty one
        element = geometry.element
        tag = f"{element.prefix}:{etree.QName(element).localname}" if element.prefix else element.tag
        if tag == "mesh":
            suffix = _path_facts((geometry.filename or "").strip())[1]
            if suffix in NON_SPEC_MESH_FORMATS:
                yield Hit(f"link '{link.name}' {shape.role} mesh {geometry.filename}: {READERS[suffix]}",
                          geometry.element)
        elif tag == "capsule":
            if not ctx.model.declares("capsule"):
                yield Hit(f"link '{link.name}' {shape.role} geometry <capsule>: {READERS['capsule']}", geometry.element,
                          hint=CAPSULE_HINT)
        elif tag not in SPEC_SHAPES:
            readers = READERS.get(tag, "no engine ar3cli knows reads it; urdfdom, PyBullet, Drake and MuJoCo refuse "
                                       "the file")
            yield Hit(f"link '{link.name}' {shape.role} geometry <{tag}> is not URDF: {readers}", geometry.element)


def _found_meshes(ctx):
    """(link, shape, path) for every mesh that resolved to a file that is not a Git LFS pointer."""
    from ar3cli.urdf.meshinfo import is_lfs_pointer

    for link, shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and resolution.found and not is_lfs_pointer(resolution.path):
            yield link, shape, resolution.path


@rule("G011", "mesh-unreadable", "error", "Mesh file that engines cannot read",
      why="""Judged by the file's bytes, not its name. PyBullet reads binary STL only: an ASCII STL,
      a truncated binary STL or one with no triangles loads without the shape ("cannot extract
      mesh", measured with pybullet 3.2.7: the link has no collision and no visual), and MuJoCo
      refuses such a file as a collision shape ("number of faces should be between 1 and 200000 in
      STL file ...; perhaps this is an ASCII file?"). An OBJ without faces is a point cloud, not a
      surface: PyBullet loads an empty shape for it (measured).""",
      fix="Convert the mesh to binary STL (e.g. trimesh: trimesh.load(path).export(path)), or re-export it with "
          "its faces.",
      bad=_mesh_robot("meshes/part.stl"), good=_mesh_robot("meshes/base.stl"),
      thresholds="Binary STL: size == 84 + 50 x (triangle count in the header), count >= 1; OBJ: at least one "
                 "'f' line; any mesh: a regular file of at most 64 MB (meshinfo.MAX_MESH_BYTES).",
      references="PyBullet examples/Importers/ImportMeshUtility (LoadMeshFromSTL size check); MuJoCo "
                 "src/user/user_mesh.cc LoadSTL; google-deepmind/mujoco issue #327.")
def mesh_unreadable(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import mesh_content

    for link, shape, path in _found_meshes(ctx):
        content = mesh_content(path)
        if content is None:
            continue
        kind, faces, _groups = content
        problem = None
        if kind == "stl-ascii":
            problem = "is an ASCII STL: PyBullet loads the robot without this shape, MuJoCo refuses it"
        elif kind == "stl-broken":
            problem = ("is neither a binary STL (its size is not 84 + 50 x the triangle count in its header) nor an "
                       "ASCII one: truncated or mislabelled; PyBullet drops the shape, MuJoCo refuses it")
        elif kind == "stl-binary" and faces == 0:
            problem = "holds no triangles: PyBullet drops the shape, MuJoCo refuses it"
        elif kind == "obj" and faces == 0:
            problem = "has vertices but no faces: a point cloud, not a surface"
        elif kind == "too-large":
            from ar3cli.urdf.meshinfo import MAX_MESH_BYTES

            problem = (f"is larger than ar3cli's {MAX_MESH_BYTES // 1024 // 1024} MB limit for meshes: not read, and "
                       "left out of what --sim loads; simplify or split it")
        elif kind == "not-a-file":
            problem = "is not a regular file (a pipe, socket or device): not read, and left out of what --sim loads"
        if problem:
            yield Hit(f"link '{link.name}' {shape.role} mesh {shape.geometry.filename} {problem}", shape.geometry.element)


@rule("G012", "mesh-flat", "warning", "Collision mesh with no volume",
      why="""A collision mesh whose points all lie in one plane (a ground plate, a label, a panel
      exported as a single surface) encloses no volume. MuJoCo (3.3 and later) refuses it as a
      collision shape ("mesh volume is too small ... Try setting inertia to shell") and computes no
      inertia from it; every engine makes a zero-thickness convex hull of it, which thin or fast
      objects pass through. Visual meshes may be flat.""",
      fix="Give the collision shape thickness: a thin <box>, or a solid mesh.",
      bad=robot(f'''<link name="panel">{LINK_INERTIAL}<collision><geometry><mesh filename="meshes/flat.obj"/></geometry></collision></link>'''),
      good=robot(f'''<link name="panel">{LINK_INERTIAL}<collision><geometry><box size="0.1 0.1 0.002"/></geometry></collision></link>'''),
      thresholds="Thinnest extent of the mesh's bounding box below ZERO_THICKNESS = 1e-9 of its largest, or (meshes up "
                 "to 2 MB) convex hull volume below 1e-9 of the bounding-box diagonal cubed.",
      references="google-deepmind/mujoco issue #2634 (\"mesh volume is too small\" for planar meshes from 3.3).",
      opt_in=True)
def mesh_flat(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import hull_facts, mesh_bounds

    for link, shape, path in _found_meshes(ctx):
        if shape.role != "collision":
            continue
        bounds = mesh_bounds(path)
        if bounds is None:
            continue
        extent = [b - a for a, b in zip(*bounds)]
        largest = max(extent)
        if not largest > 0 or not math.isfinite(largest):
            continue
        flat = min(extent) <= ZERO_THICKNESS * largest
        if not flat:
            facts = hull_facts(path)
            diagonal = math.sqrt(sum(e * e for e in extent))
            flat = facts is not None and facts["hull_volume"] <= ZERO_THICKNESS * diagonal ** 3
        if flat:
            yield Hit(f"link '{link.name}' collision mesh {shape.geometry.filename} is flat (no volume): MuJoCo 3.3+ "
                      "refuses it as a collision shape", shape.geometry.element)


@rule("G013", "hull-much-larger", "info", "Collision mesh much smaller than its convex hull",
      why="""PyBullet (for every moving body), MuJoCo and Drake's point contact collide a mesh as
      its convex hull. A concave part (a gripper's U, a hollow housing, two fingers in one file)
      whose hull is more than twice its volume collides as the filled-in shape: fingers cannot
      close on an object, a cup cannot hold anything, links collide with each other where nothing
      touches. Checked for closed meshes up to 2 MB (binary STL, one-object OBJ); a <collision
      concave="yes"> (PyBullet's triangle mesh for static bodies) is left alone.""",
      fix="Decompose the collision mesh into convex parts (ar3cli fix-collision does it with pybullet's V-HACD or "
          "CoACD) and list them as several <collision> elements or one multi-object OBJ (PyBullet makes one hull per "
          "object), or use primitives.",
      bad=robot(f'''<link name="gripper">{LINK_INERTIAL}<collision><geometry><mesh filename="meshes/u_shape.stl"/></geometry></collision></link>'''),
      good=robot(f'''<link name="gripper">{LINK_INERTIAL}<collision><geometry><mesh filename="meshes/base.stl"/></geometry></collision></link>'''),
      thresholds="Convex hull volume / mesh volume above HULL_RATIO = 2, for closed, consistently wound meshes of at "
                 "most HULL_MAX_BYTES = 2 MB; the hull is that of the mesh's extreme points along 100 directions, a lower "
                 "bound (median 0.97 of the exact hull on real meshes), so the ratio is never overstated "
                 "(meshinfo.hull_facts, cached on disk).",
      fixed_by="fix-collision",
      references="PyBullet BulletUrdfImporter.cpp (convex hull per mesh or OBJ object for non-static bodies); "
                 "MuJoCo documentation, Collision detection (mesh geoms collide as convex hulls).",
      opt_in=True)
def hull_much_larger(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import hull_facts

    for link, shape, path in _found_meshes(ctx):
        if shape.role != "collision" or shape.geometry.params.get("scale") is None \
                or shape.element.get("concave") == "yes":
            continue  # concave="yes": PyBullet's own flag for a static triangle mesh, chosen on purpose
        facts = hull_facts(path)
        if facts is None or not facts["closed"] or not facts["volume"] > 0:
            continue
        ratio = facts["hull_volume"] / facts["volume"]
        if ratio > HULL_RATIO:
            yield Hit(f"link '{link.name}' collision mesh {shape.geometry.filename}: its convex hull is at least "
                      f"{ratio:.1f}x its volume, and engines collide the hull", shape.geometry.element)
