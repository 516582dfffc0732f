"""Mass properties of a link from its geometry.

Primitives use :mod:`ar3cli.maths.mass_properties` (exact, analytic). Meshes use trimesh: scale
and COLLADA ``<unit meter>`` applied (as PyBullet does; trimesh reads the unit but leaves it out),
exact signed-tetrahedra volume when the mesh is watertight, otherwise its convex hull with the
hull/mesh volume ratio reported. Each shape's ``<origin>`` is applied and the shapes of
a link are combined with the parallel-axis theorem. Everything is computed at density 1 (so the
``mass`` field of a :class:`GeometryMass` is a volume in m^3) and scaled to a mass afterwards.

Collision geometry is used when the link has any, else visual geometry: collision shapes are
what the physics engine sees. trimesh is imported inside functions (static paths stay fast).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ar3cli.maths import mass_properties as mp
from ar3cli.urdf.bounds import mesh_unit
from ar3cli.urdf.model import Link, Model, Shape

FRAME_LINK_MASS = 1e-6
"""kg written for a frame link (no geometry, fixed joint); see docs/commands/fix-inertia.md."""
FRAME_LINK_INERTIA = 1e-12
"""kg*m^2 on each diagonal entry of a frame link's tensor."""


class GeometryError(Exception):
    """The geometry cannot give mass properties (missing mesh, bad dimensions...)."""


@dataclass
class GeometryMass:
    """Unit-density mass properties of a link's geometry (``props.mass`` is the volume)."""

    props: mp.MassProperties
    sources: list[str] = field(default_factory=list)
    role: str = "collision"

    @property
    def volume(self) -> float:
        return self.props.mass


def _fmt(value: float) -> str:
    return f"{value:.6g}"


def shape_mass(shape: Shape, cache: dict | None = None) -> tuple[mp.MassProperties, str]:
    """Unit-density mass properties of one shape in the link frame, and where they came from; a
    shape whose numbers overflow or vanish in the arithmetic (a radius of 1e200 or 1e-320) is a
    :class:`GeometryError` like any other unusable shape."""
    try:
        return _shape_mass(shape, cache)
    except (ArithmeticError, ValueError) as exc:
        raise GeometryError(f"{shape.geometry.kind or 'geometry'} cannot be measured ({exc})") from None


def _shape_mass(shape: Shape, cache: dict | None) -> tuple[mp.MassProperties, str]:
    geometry = shape.geometry
    params = geometry.params
    kind = geometry.kind
    if kind == "box":
        size = params.get("size")
        if not size or not all(map(_positive, size)):
            raise GeometryError(f"box size {size!r} is not usable")
        props, source = mp.box(size, density=1.0), f"box {'x'.join(_fmt(s) for s in size)} analytic"
    elif kind in ("cylinder", "capsule"):
        radius, length = params.get("radius"), params.get("length")
        min_length_ok = _positive(length) or (kind == "capsule" and length == 0)  # a capsule may be a sphere
        if not _positive(radius) or not min_length_ok:
            raise GeometryError(f"{kind} radius {radius!r} length {length!r} is not usable")
        if kind == "cylinder":
            props, source = mp.cylinder(radius, length, density=1.0), f"cylinder r={_fmt(radius)} l={_fmt(length)} analytic"
        else:
            props, source = capsule(radius, length), f"capsule r={_fmt(radius)} l={_fmt(length)} analytic"
    elif kind == "sphere":
        radius = params.get("radius")
        if not _positive(radius):
            raise GeometryError(f"sphere radius {radius!r} is not usable")
        props, source = mp.sphere(radius, density=1.0), f"sphere r={_fmt(radius)} analytic"
    elif kind == "mesh":
        props, source = mesh_mass(shape, cache if cache is not None else {})
    else:
        raise GeometryError(f"geometry <{params.get('tag', 'missing')}> has no volume")
    return mp.transformed(props, shape.origin.xyz, shape.origin.rpy), source


def _positive(value: float | None) -> bool:
    """A usable dimension: a finite number above zero (NaN and inf are not)."""
    return value is not None and math.isfinite(value) and value > 0


def capsule(radius: float, length: float) -> mp.MassProperties:
    """Unit-density capsule along z (:func:`ar3cli.maths.mass_properties.capsule`, closed form)."""
    return mp.capsule(radius, length, density=1.0)


def mesh_mass(shape: Shape, cache: dict) -> tuple[mp.MassProperties, str]:
    """Unit-density mass properties of a mesh with its scale (not yet its origin)."""
    geometry = shape.geometry
    resolution = geometry.resolution
    if resolution is None or not resolution.found:
        raise GeometryError(f"mesh {geometry.filename!r} not found" + (f" ({resolution.explain()})" if resolution else ""))
    scale = geometry.params.get("scale")
    if scale is None or not all(math.isfinite(value) and value != 0 for value in scale):
        raise GeometryError(f"mesh {geometry.filename!r} has a malformed scale")
    unit = mesh_unit(geometry)
    if unit is None:
        raise GeometryError(f"mesh {geometry.filename!r}: its COLLADA <unit meter> is not a positive number, "
                            "so its size in metres is unknown")
    key = (str(resolution.path), tuple(scale), unit)
    if key not in cache:
        cache[key] = _mesh_mass_uncached(Path(resolution.path), tuple(scale), unit)
    return cache[key]


def load_welded_mesh(path: Path):
    """The trimesh mesh of ``path`` with its vertices welded by position (OBJ files split them by
    texture coordinate and normal); GeometryError when it cannot be read or has no triangle."""
    import io

    from ar3cli.infra.held_import import import_holding_interrupts

    trimesh = import_holding_interrupts("trimesh")

    from ar3cli.errors import UserError
    from ar3cli.urdf.meshinfo import read_mesh

    try:  # the capped, non-blocking reader: never a FIFO, never a multi-GB mesh
        data = read_mesh(path)
    except UserError as exc:
        raise GeometryError(f"mesh {path.name}: {exc.message.removeprefix(f'{path}: ')}") from None
    try:
        mesh = trimesh.load(io.BytesIO(data), file_type=path.suffix.lower().lstrip("."), force="mesh", process=True)
    except Exception as exc:  # noqa: BLE001 - trimesh raises many types for unreadable files
        raise GeometryError(f"mesh {path.name}: cannot read: {exc}") from None
    if mesh is None or len(getattr(mesh, "faces", ())) == 0:
        raise GeometryError(f"mesh {path.name} has no triangles")
    mesh.merge_vertices(merge_tex=True, merge_norm=True)
    return mesh


def _mesh_mass_uncached(path: Path, scale: tuple[float, float, float],
                        unit: float = 1.0) -> tuple[mp.MassProperties, str]:
    """``unit``: metres per file unit (a COLLADA ``<unit meter>``; trimesh reads it but does not apply it)."""
    mesh = load_welded_mesh(path)
    if tuple(scale) != (1.0, 1.0, 1.0) or unit != 1.0:
        mesh.apply_transform(np.diag([*(s * unit for s in scale), 1.0]))
    scale_note = "" if tuple(scale) == (1.0, 1.0, 1.0) else f" scale {' '.join(_fmt(s) for s in scale)}"
    if unit != 1.0:
        scale_note += f" COLLADA unit {_fmt(unit)} m"
    watertight = mesh.is_watertight
    if watertight or is_closed(mesh):
        if mesh.volume < 0:
            mesh.invert()
        if not mesh.volume > 0:
            raise GeometryError(f"mesh {path.name} encloses no volume")
        props = _trimesh_props(mesh)
        kind = "watertight" if watertight else "closed (some edges shared by more than 2 faces)"
        return props, f"mesh {path.name}{scale_note} {kind}, exact"
    try:
        hull = mesh.convex_hull
    except Exception as exc:  # noqa: BLE001 - qhull raises its own types (a flat or degenerate mesh)
        raise GeometryError(f"mesh {path.name}{scale_note}: no convex hull ({type(exc).__name__})") from None
    mesh_volume = abs(float(mesh.volume))
    ratio = hull.volume / mesh_volume if mesh_volume > 0 else float("inf")
    props = _trimesh_props(hull)
    return props, (f"mesh {path.name}{scale_note} not watertight: convex hull, hull/mesh volume "
                   f"{ratio:.3g} (mesh volume of an open mesh is approximate)")


def is_closed(mesh) -> bool:
    """True when every directed edge a->b is matched by as many b->a: the surface bounds a volume.

    That is exactly what the divergence theorem behind the signed-tetrahedra volume needs. It
    is weaker than trimesh's ``is_watertight`` (every edge in exactly two faces): CAD exports
    such as the AR3 STLs have edges shared by four faces where two solids touch, and are
    still closed, so their volume integral is exact (it equals their CAD mass at 1000 kg/m^3).
    """
    edges = np.asarray(mesh.edges)
    if len(edges) == 0:
        return False
    forward = edges[:, 0] < edges[:, 1]
    key = np.where(forward[:, None], edges, edges[:, ::-1])
    sign = np.where(forward, 1, -1)
    _, inverse = np.unique(key, axis=0, return_inverse=True)
    return bool(np.all(np.bincount(inverse.reshape(-1), weights=sign) == 0))


def _trimesh_props(mesh) -> mp.MassProperties:
    mesh.density = 1.0
    properties = mesh.mass_properties
    return mp.MassProperties(float(properties["volume"]), np.asarray(properties["center_mass"], dtype=float),
                             np.asarray(properties["inertia"], dtype=float))


def geometry_mass(link: Link, cache: dict | None = None) -> GeometryMass | None:
    """Unit-density mass properties of the link's collision geometry (visual when none).

    ``None`` when the link has no geometry at all; :class:`GeometryError` when some shape
    cannot be measured.
    """
    shapes, role = (link.collisions, "collision") if link.collisions else (link.visuals, "visual")
    if not shapes:
        return None
    cache = cache if cache is not None else {}
    parts, sources = [], []
    for shape in shapes:
        props, source = shape_mass(shape, cache)
        parts.append(props)
        sources.append(source)
    return GeometryMass(mp.combine(parts), sources, role)


# ---- which links need new inertia ------------------------------------------------------------
def is_frame_link(model: Model, link: Link) -> bool:
    """A pure frame (tool0, flange, tcp): no geometry, attached to its parent by a fixed joint."""
    joint = model.parent_joint(link.name)
    return not link.has_geometry and joint is not None and joint.type == "fixed"
