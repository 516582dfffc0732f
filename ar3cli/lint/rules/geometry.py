"""Geometry rules (G): mesh files, their formats and units, and missing collision shapes."""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import lru_cache
from pathlib import Path

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, robot, rule
from ar3cli.lint.rules.file import SUBSTITUTION
from ar3cli.urdf.meshinfo import PYBULLET_MESH_FORMATS
from ar3cli.urdf.model import parse_floats
from ar3cli.urdf.packages import split_places

MAX_PLAUSIBLE_EXTENT = 5.0
"""A robot part larger than this many metres after scaling is almost always a mesh in millimetres."""
MIN_PLAUSIBLE_EXTENT = 1e-3
"""A part smaller than a millimetre after scaling was probably scaled twice (or is in km)."""
FLAT_RATIO = 0.01
"""Meshes whose smallest extent is below this fraction of the largest are planes (ground, walls)."""
SPAN_FACTOR = 3.0
"""A mesh larger than MAX_PLAUSIBLE_EXTENT is still metres when it is at most this many times the robot's own
kinematic span (its longest prismatic travel, its furthest joint frame): a gantry lab's 46 m rail for a 37 m
travel. A millimetre mesh on a metre robot is hundreds of times its span."""
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
    """(link, shape, geometry) for every mesh with a filename; a filename holding an unexpanded
    substitution (``$(find pkg)/x.stl``) is F006's alone: one cause, one finding."""
    for link, shape in ctx.model.meshes():
        filename = shape.geometry.filename
        if filename and not ("$" in filename and SUBSTITUTION.search(filename)):
            yield link, shape, shape.geometry


def _mesh_robot(filename: str, scale: str = "") -> str:
    scale_attr = f' scale="{scale}"' if scale else ""
    return robot(f"""
        <link name="base">
          {LINK_INERTIAL}
          <visual><geometry><mesh filename="{filename}"{scale_attr}/></geometry></visual>
          <collision><geometry><mesh filename="{filename}"{scale_attr}/></geometry></collision>
        </link>""")


G001_FIX = "Fix the path, or tell ar3cli where the package is with --package-path NAME=DIR."


@rule("G001", "mesh-not-found", "error", "Mesh file not found",
      refused_by=("pybullet", "mujoco"),
      breaks='PyBullet refuses the file ("Cannot load URDF file"); RViz and MoveIt draw and collide nothing for '
             "the link.",
      why="""PyBullet refuses the whole file with "Cannot load URDF file" (the real reason, the missing
      mesh, only goes to C stdout); RViz shows nothing. ar3cli resolves package:// like ROS
      (--package-path, ROS_PACKAGE_PATH, AMENT_PREFIX_PATH, package.xml in ancestors) and relative
      paths like PyBullet; the message names the first place it looked and the hint every one. MuJoCo looks elsewhere: in the
      <mujoco><compiler meshdir> of the file, by the mesh's base name; for a robot meant for MuJoCo
      only (--target mujoco) a mesh found there is not reported.""",
      fix=G001_FIX,
      bad=_mesh_robot("meshes/missing.stl"), good=_mesh_robot("meshes/base.stl"),
      references="MuJoCo src/xml/xml_urdf.cc (mesh file names stripped to their base name, looked up in "
                 "<mujoco><compiler meshdir>).")
def mesh_not_found(ctx) -> Iterator[Hit]:
    meshdir = ctx.shared("mujoco-meshdir", mujoco_meshdir) if "mujoco" in ctx.targets else None
    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and not resolution.found and not resolution.problem.startswith("empty package"):
            tried, hint = "", None
            if places := resolution.places():  # the message names the first place, the hint every one (11 on a line)
                named, _hidden = split_places(resolution.tried, resolution.folder)
                more = len(resolution.tried) - 1
                tried = (f"; looked in {places[0]}" + (f" and {more} more place{'s' if more > 1 else ''}" if more else "")
                         if named else f"; looked in {places[0]}")  # only places outside: their count
                hint = f"{G001_FIX} Looked in: " + "; ".join(places) + "."
            also = ""
            if meshdir is not None and ctx.model.resolver.is_file(meshdir / _base_name(resolution.uri)):
                others = [target for target in ctx.targets if target != "mujoco"]
                if not others:
                    continue  # MuJoCo, the only target, finds it through its own meshdir
                also = f" (only MuJoCo finds it, in its <compiler meshdir=\"{_written_meshdir(ctx.model)}\">)"
            yield Hit(f"link '{link.name}' mesh {resolution.uri}: {resolution.problem or 'not found'}{also}{tried}",
                      geometry.element, hint=hint)


def mujoco_meshdir(model) -> Path | None:
    """The folder MuJoCo looks for this file's meshes in: ``<mujoco><compiler meshdir="..."/>`` under
    ``<robot>``, relative to the file's folder; None without one."""
    written = _written_meshdir(model)
    return model.resolver.base_dir / written if written else None


def _written_meshdir(model) -> str | None:
    """``<compiler meshdir>`` as the file writes it (what a message shows: never the machine's folders)."""
    for block in model.root.findall("mujoco"):
        for compiler in block.findall("compiler"):
            folder = compiler.get("meshdir")
            if folder and folder.strip():
                return folder.strip()
    return None


def _base_name(uri: str) -> str:
    """The mesh's file name as MuJoCo's URDF import keeps it: everything after the last slash."""
    return uri.strip().replace("\\", "/").rsplit("/", 1)[-1]


@rule("G002", "empty-package", "error", "package:/// URI with an empty package name",
      engines=("ros",), breaks="ROS (RViz, MoveIt, Gazebo) cannot resolve the URI: the link has no mesh there.",
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
      why="""An absolute path (/home/me/... or file:///...) works on one machine only. file://meshes/x.stl
      (two slashes) is not absolute: PyBullet and ar3cli read the rest as a path next to the URDF.""",
      fix="Use package://PACKAGE/... or a path relative to the URDF file.",
      bad=_mesh_robot("/home/me/robot/meshes/base.stl"), good=_mesh_robot("meshes/base.stl"),
      fixed_by="fix-mesh-paths --package NAME=DIR")
def absolute_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        name = geometry.filename.strip()
        if _path_facts(name.removeprefix("file://"))[0]:  # file:///a is /a; file://meshes/a is meshes/a
            yield Hit(f"link '{link.name}' mesh {name} is an absolute path", geometry.element)


@rule("G004", "mesh-format", "error", "Mesh format PyBullet cannot load",
      engines=("pybullet", "mujoco"),
      refused_by=("pybullet", "mujoco"),
      breaks='PyBullet refuses the file ("invalid mesh filename extension"); MuJoCo cannot read the mesh either.',
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
      breaks="Every mesh loader gets a 130-byte text file: PyBullet reports a corrupt or empty mesh.",
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
      (ground planes, walls) are exempt, and so is a large mesh on a robot whose own joints span as much
      (a gantry lab whose rail travels 37 m: its 46 m rail is metres; in millimetres it would be 4.6 cm). A COLLADA file states its own unit (<unit meter="0.0254"/>
      for inches), which PyBullet and assimp (RViz, MoveIt) apply: the size is judged after it. Judged
      against the link itself too: a collision mesh about 1000 times larger or smaller than its own
      visual (a scale="0.001" kept on one and not the other) is in the other unit, whatever its size;
      the one further from the robot's typical link size is the one reported.""",
      fix='Add scale="0.001 0.001 0.001" for a millimetre mesh, or re-export it in metres.',
      bad=_mesh_robot("meshes/base_mm.stl"), good=_mesh_robot("meshes/base_mm.stl", "0.001 0.001 0.001"),
      thresholds="Largest extent after scale (and COLLADA unit) above MAX_PLAUSIBLE_EXTENT = 5 m with the smallest "
                 "above FLAT_RATIO = 0.01 of it and the largest above SPAN_FACTOR = 3 times the robot's kinematic span "
                 "(longest prismatic travel, furthest link frame from the root at the zero pose), or below "
                 "MIN_PLAUSIBLE_EXTENT = 1 mm; or a link's collision meshes "
                 "SCALE_MISMATCH = 250 to 4000 times larger or smaller than its visual meshes (box diagonals).",
      references="PyBullet LoadMeshFromCollada.cpp (applies <unit meter>); COLLADA 1.4.1 spec, <asset>/<unit>.")
def mesh_units(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.meshinfo import collada_unit

    judged: set[int] = set()  # meshes whose unit their own link's other meshes already showed
    for link in ctx.model.links:
        for shape, factor, ratio, other in scale_mismatches(ctx, link):
            judged.add(id(shape.geometry.element))
            scale = " ".join(number_text(v * factor) for v in shape.geometry.params.get("scale") or (1.0, 1.0, 1.0))
            looks = "like millimetres" if factor < 1 else "scaled to metres twice"
            yield Hit(f"link '{link.name}' {shape.role} mesh {shape.geometry.filename} is {ratio:.0f}x "
                      f"{'larger' if factor < 1 else 'smaller'} than the link's {other} mesh: it looks {looks}, its "
                      f"{other} is in metres (scale=\"{scale}\"?)", shape.geometry.element,
                      hint=f'Write scale="{scale}" on this mesh, as its {other} says.')
    seen: set[tuple] = set()
    for link, _shape, geometry in _meshes(ctx):
        if id(geometry.element) in judged:
            continue
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
        if largest > MAX_PLAUSIBLE_EXTENT and smallest > FLAT_RATIO * largest \
                and largest > SPAN_FACTOR * ctx.kinematic_span():
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is {shown}: millimetres?",
                      geometry.element)
        elif 0 < largest < MIN_PLAUSIBLE_EXTENT:
            yield Hit(f"link '{link.name}' mesh {geometry.filename} is only {shown}: scaled twice?",
                      geometry.element, hint="Check the scale attribute: the mesh may already be in metres.")


SCALE_MISMATCH = (250.0, 4000.0)
"""A link's collision meshes this many times larger or smaller than its visual meshes (box diagonals): one
of the two is in millimetres and the other in metres (G006)."""


def scale_mismatches(ctx, link) -> list[tuple[object, float, float, str]]:
    """(mesh shape at fault, the factor its scale needs, how many times off it is, the role it disagrees with)
    for each of the link's meshes that is about 1000x (:data:`SCALE_MISMATCH`) larger or smaller than its
    counterpart of the other role: the visual mesh of the same file for a collision mesh, else the link's
    visual meshes together. Of the two, the one whose size is further from the median of the robot's other
    links is at fault; with no other link to compare with, the one outside the sizes a part can have
    (MIN_PLAUSIBLE_EXTENT to MAX_PLAUSIBLE_EXTENT), else the collision (people look at the visual, not at
    the collision). Empty when the link's visual and collision meshes agree."""
    visuals = [shape for shape in link.visuals if shape.geometry.kind == "mesh"]
    collisions = [shape for shape in link.collisions if shape.geometry.kind == "mesh"]
    if not visuals or not collisions:
        return []
    scale = _median_of_others(ctx, link)
    found: dict[int, tuple[object, float, float, str]] = {}
    for collision in collisions:
        twin = [v for v in visuals if _same_file(v.geometry, collision.geometry)]
        counterpart = twin or visuals
        sizes = [_size([ctx.shape_bounds(collision)]), _size([ctx.shape_bounds(shape) for shape in counterpart])]
        if None in sizes:
            continue
        ratio = max(sizes) / min(sizes)
        if not SCALE_MISMATCH[0] <= ratio <= SCALE_MISMATCH[1]:
            continue
        big_is_collision = sizes[0] > sizes[1]
        big, small = max(sizes), min(sizes)
        if scale is not None:
            blame_big = abs(math.log(big / scale)) >= abs(math.log(small / scale))
        else:
            plausible = [MIN_PLAUSIBLE_EXTENT <= size <= MAX_PLAUSIBLE_EXTENT for size in (big, small)]
            blame_big = big_is_collision if plausible[0] == plausible[1] else not plausible[0]
        factor = 1e-3 if blame_big else 1e3
        if blame_big == big_is_collision:
            found.setdefault(id(collision), (collision, factor, ratio, "visual"))
        else:
            for shape in counterpart:
                found.setdefault(id(shape), (shape, factor, ratio, "collision"))
    return list(found.values())


def _median_of_others(ctx, link) -> float | None:
    """The median size (:meth:`Context.link_size`) of the robot's links other than ``link``: the sizes
    sorted once per file, this link's taken out by index (a 20,000-link robot asks for every link)."""
    import bisect

    sizes = ctx.shared("link-sizes", lambda model: sorted(
        size for other in model.links if (size := ctx.link_size(other)) and math.isfinite(size)))
    own = ctx.link_size(link)
    index = bisect.bisect_left(sizes, own) if own and math.isfinite(own) else None
    count = len(sizes) - (index is not None)
    if count <= 0:
        return None
    middle = count // 2
    return sizes[middle + 1] if index is not None and middle >= index else sizes[middle]


def _same_file(a, b) -> bool:
    """Two mesh geometries that name the same file (resolved, else as written)."""
    if a.resolution is not None and b.resolution is not None and a.resolution.found and b.resolution.found:
        return a.resolution.path == b.resolution.path
    return (a.filename or "").strip() == (b.filename or "").strip()


def _size(boxes) -> float | None:
    """The diagonal of the box around ``boxes``; None when one is unknown or the size is not positive."""
    if not boxes or any(box is None for box in boxes):
        return None
    size = math.dist(*union_box(boxes))
    return size if size > 0 and math.isfinite(size) else None


def union_box(boxes):
    """The box around ``boxes`` (none of them None)."""
    return (tuple(min(box[0][i] for box in boxes) for i in range(3)),
            tuple(max(box[1][i] for box in boxes) for i in range(3)))


def number_text(value: float) -> str:
    """A scale factor as URDF text: 0.001, not 0.0010000000000000002."""
    return f"{value:.6g}"


@rule("G007", "scalar-scale", "warning", "Mesh scale is a single number",
      engines=("ros",),
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


MARKER_SIZE = 0.1
"""A link whose visuals are smaller (box diagonal) than this fraction of the robot's median link is a
marker (a sensor frame drawn as a 1 cm cube, pr2's and Talos' IMU boxes), not a part to collide with."""
MARKER_MASS = 1e-4
"""A link lighter than this fraction of the whole robot (or of mass 0) is a frame with a picture (Baxter's
0.1 g display and camera links, a "nocol" marker sphere), not a body."""
FRAME_DRAWING = 0.5
"""A link with no <inertial>, welded to its parent and drawn with primitives (no mesh) smaller than this
fraction of its parent is a frame drawn for people (Fourier's 5 mm fingertip spheres, a TCP ball), not a part."""
ENCLOSED = 0.9
"""A part whose drawing lies at least this much (by volume of its box) inside its neighbours' collision shapes at
the zero pose needs no collision of its own: nothing reaches it without touching them first."""
NEIGHBOUR_DEPTH = 2
"""Joints away from a part that its neighbours may be (parent, grandparent, children, grandchildren, siblings)."""
_GRID = 4
"""Sample points per axis of a part's box when its enclosure is measured (4 x 4 x 4 cell centres)."""


@rule("G008", "no-collision", "warning", "Link with visual but no collision geometry",
      why="""A link you can see but that has no <collision> passes through everything in simulation
      (no contacts, no self-collision checks), and PyBullet's default inertia comes from the
      collision shape, so it falls back to a tiny default box. Visuals meant to be passed through are
      not reported: a zero-size placeholder (<box size="0 0 0"/>), and markers, judged against the
      robot itself: a link drawn much smaller than its other links, one that weighs next to nothing
      against the whole robot, or a frame drawn for people (no <inertial>, welded to its parent, drawn
      as spheres, or as primitives much smaller than the parent: a fingertip or TCP marker). Nor is a part whose
      drawing lies inside its neighbours' collision shapes at the zero pose (a wrist cross between
      two covered links, a cover inside the chassis' collision mesh, a caster inside a base's
      collision spheres): nothing reaches it without touching them first.""",
      fix="Add a <collision> (a primitive or a simplified mesh).",
      bad=robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="1 1 1"/></geometry></visual></link>'),
      good=robot(f'<link name="base">{LINK_INERTIAL}<visual><geometry><box size="1 1 1"/></geometry></visual>'
                 '<collision><geometry><box size="1 1 1"/></geometry></collision></link>'),
      thresholds=f"Not reported: every visual of zero volume; visuals whose box diagonal is below MARKER_SIZE = "
                 f"{MARKER_SIZE:g} of the robot's median link size; a link whose mass is at most MARKER_MASS = "
                 f"{MARKER_MASS:g} of the robot's; a link without <inertial> on a fixed joint drawn with spheres, or with "
                 f"primitives smaller than FRAME_DRAWING = {FRAME_DRAWING:g} of its parent; a link whose visual box lies at least "
                 f"ENCLOSED = {ENCLOSED:g} inside the collision shapes of the links up to NEIGHBOUR_DEPTH = "
                 f"{NEIGHBOUR_DEPTH} joints away at the zero pose.")
def no_collision(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        if link.visuals and not link.collisions and not _pass_through_visual(ctx, link) \
                and not _enclosed(ctx, link):
            yield Hit(f"link '{link.name}' has {len(link.visuals)} visual shape(s) but no <collision>", link.element)


def _pass_through_visual(ctx, link) -> bool:
    """True for a link whose visuals are a placeholder or a marker (see G008), not a part."""
    boxes = [ctx.shape_bounds(shape) for shape in link.visuals]
    if boxes and all(box is not None and math.prod(hi - lo for lo, hi in zip(*box)) == 0 for box in boxes):
        return True  # <box size="0 0 0"/>: drawn as nothing
    mass = link.inertial.mass if link.inertial is not None else None
    if mass is not None and math.isfinite(mass) and 0 <= mass <= MARKER_MASS * ctx.total_mass():
        return True
    size, scale = ctx.link_size(link), ctx.robot_scale()
    if size is not None and scale is not None and size < MARKER_SIZE * scale:
        return True
    return _drawn_frame(ctx, link, size)


def _drawn_frame(ctx, link, size: float | None) -> bool:
    """A frame drawn for people: no <inertial> (the author gave it no body), welded to its parent, drawn with
    spheres (a ball marks a point), or with primitives smaller than FRAME_DRAWING of its parent."""
    joint = ctx.model.parent_joint(link.name)
    if link.inertial is not None or joint is None or joint.type != "fixed" or size is None \
            or any(shape.geometry.kind == "mesh" for shape in link.visuals):
        return False
    if all(shape.geometry.kind == "sphere" for shape in link.visuals):
        return True  # a ball marks a point: a TCP, a fingertip
    parent = ctx.model.link(joint.parent) if joint.parent else None
    parent_size = ctx.link_size(parent) if parent is not None else None
    return parent_size is not None and size < FRAME_DRAWING * parent_size


def _neighbours(model, link, depth: int = NEIGHBOUR_DEPTH):
    """The links up to ``depth`` joints from ``link`` (parent, children, and theirs), ``link`` left out."""
    found, frontier = {link.name}, [link.name]
    for _ in range(depth):
        reached = []
        for name in frontier:
            joint = model.parent_joint(name)
            around = [joint.parent] if joint is not None and joint.parent else []
            around += [child.child for child in model.child_joints(name) if child.child]
            reached += [other for other in around if other not in found]
            found.update(around)
        frontier = reached
    found.discard(link.name)
    return [other for name in found if (other := model.link(name)) is not None]


def _enclosed(ctx, link) -> bool:
    """True when at least ENCLOSED of the link's (visual) box lies inside the collision shapes of its
    :func:`_neighbours` at the zero pose, sampled at _GRID³ cell centres."""
    own = ctx.zero_pose_box(link.name, ctx.link_bounds(link))
    if own is None:
        return False
    covers = [box for other in _neighbours(ctx.model, link) for shape in other.collisions
              if (box := ctx.zero_pose_box(other.name, ctx.shape_bounds(shape))) is not None]
    if not covers:
        return False
    steps = [(i + 0.5) / _GRID for i in range(_GRID)]
    (x0, y0, z0), (x1, y1, z1) = own
    inside = 0
    for fx in steps:
        x = x0 + fx * (x1 - x0)
        for fy in steps:
            y = y0 + fy * (y1 - y0)
            for fz in steps:
                z = z0 + fz * (z1 - z0)
                inside += any(lo[0] <= x <= hi[0] and lo[1] <= y <= hi[1] and lo[2] <= z <= hi[2] for lo, hi in covers)
    return inside >= ENCLOSED * _GRID ** 3


@rule("G009", "pybullet-only-path", "info", "Mesh found only by PyBullet's fallback search",
      engines=("ros",),
      why="""The mesh resolves only because PyBullet also looks for package://NAME/x relative to the
      URDF and in every folder above it. ROS (RViz, MoveIt, Gazebo) resolves package://NAME through
      the package index and will not find it.""",
      fix="ar3cli fix-mesh-paths --package PKG=DIR rewrites the URI to package://PKG/... (PKG your package, DIR its "
          "folder); or use a path relative to the URDF.",
      bad=_mesh_robot("package://meshes/base.stl"), good=_mesh_robot("meshes/base.stl"))
def pybullet_only_path(ctx) -> Iterator[Hit]:
    for link, _shape, geometry in _meshes(ctx):
        resolution = geometry.resolution
        if resolution is not None and resolution.found and resolution.via == "pybullet-search" and \
                not geometry.filename.strip().startswith("package:///"):  # G002's (an error already)
            yield Hit(f"link '{link.name}' mesh {resolution.uri} is found only by PyBullet's fallback search; "
                      "ROS tools will not find it", geometry.element,
                      hint=_pybullet_only_hint(resolution.uri))


def _pybullet_only_hint(uri: str) -> str:
    """G009's hint for ``uri``: which package ROS cannot find (or that the relative path is not there), and the fix."""
    package = uri.strip()[len("package://"):].split("/")[0] if uri.strip().startswith("package://") else ""
    what = (f"'{package}' is no package ROS can find" if package else
            "the path is not there relative to the URDF (PyBullet finds it in a folder above)")
    return (f"{what}: ar3cli fix-mesh-paths --package PKG=DIR rewrites the URI to package://PKG/... (PKG your "
            "package, DIR its folder).")


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
      engines=("pybullet", "mujoco"),
      refused_by=("mujoco",),
      breaks='PyBullet silently drops the shape ("cannot extract mesh", measured); MuJoCo refuses the file.',
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


ZERO_SIZE_KEYS = {"box": ("size",), "sphere": ("radius",), "cylinder": ("radius", "length"),
                  "capsule": ("radius", "length")}
"""The size attributes of each primitive (G018)."""


@rule("G018", "zero-size-collision", "error", "Collision primitive of zero size",
      engines=("mujoco",), refused_by=("mujoco",),
      breaks='MuJoCo refuses the file ("size 0 must be positive in geom"; measured with MuJoCo 4.0).',
      why="""A <collision> box, sphere, cylinder or capsule with a size of 0 (<sphere radius="0.00"/>, a
      placeholder left by an exporter) collides as nothing in PyBullet, which loads it, and stops
      MuJoCo's whole compile ("size 0 must be positive in geom", measured with MuJoCo 4.0 on ARMAR-4's
      legs and eyes). A zero-size <visual> is a placeholder every engine draws as nothing (G008 leaves it
      alone). Negative sizes are the same mistake.""",
      fix="Give the collision shape its real size, or remove the <collision>.",
      bad=robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry><sphere radius="0.00"/></geometry></collision></link>'),
      good=robot(f'<link name="base">{LINK_INERTIAL}<collision><geometry><sphere radius="0.02"/></geometry></collision></link>'),
      references="MuJoCo src/user/user_objects.cc (mjsGeom sizes must be positive); measured with MuJoCo 4.0.")
def zero_size_collision(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        for shape in link.collisions:
            element = shape.geometry.element
            keys = ZERO_SIZE_KEYS.get(shape.geometry.kind)
            if element is None or keys is None:
                continue
            values = [value for key in keys for value in (parse_floats(element.get(key)) or ())]
            if any(math.isfinite(value) and value <= 0 for value in values):  # non-finite and malformed: F007's
                written = " ".join(f'{key}="{element.get(key)}"' for key in keys if element.get(key) is not None)
                yield Hit(f"link '{link.name}' collision <{shape.geometry.kind} {written}/> has no size: MuJoCo "
                          "refuses the file (size 0 must be positive in geom), PyBullet collides nothing there",
                          element)


@rule("G013", "hull-much-larger", "info", "Collision mesh much smaller than its convex hull",
      engines=("pybullet", "mujoco", "drake"),
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
