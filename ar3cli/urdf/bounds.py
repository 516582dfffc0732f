"""Axis-aligned boxes around a link's shapes, in the link frame, in metres: primitives exactly,
meshes from their file bounds (:mod:`ar3cli.urdf.meshinfo`, cached) times their scale and, for
COLLADA, the file's ``<unit meter>`` (PyBullet and assimp apply it: a 6-unit cube in inches is
15 cm to them, and to every rule that judges sizes from these boxes).

Used by the lint rules (plausible sizes, inertia against geometry) and by ``render`` (framing the
camera on what is drawn).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ar3cli.urdf.model import rpy_rotation

Vector = tuple[float, float, float]
Box = tuple[Vector, Vector]
"""An axis-aligned box: (min corner, max corner)."""


def shape_bounds(shape, mesh_box=None) -> Box | None:
    """Axis-aligned box of one visual/collision shape in its link's frame, or None if unknown.

    ``mesh_box`` is :func:`scaled_mesh_bounds` (the default) or a cached version of it (the lint context's).

    The shape's own box (centre ``c``, half-extents ``h``) moved by its origin ``(xyz, R)`` is
    centred on ``R c + xyz`` with half-extents ``|R| h``: the box around its 8 rotated corners.
    """
    geometry = shape.geometry
    params = geometry.params
    half: Vector | None = None
    centre: Vector = (0.0, 0.0, 0.0)
    if geometry.kind == "box" and params.get("size"):
        half = tuple(abs(float(v)) / 2 for v in params["size"])  # type: ignore[assignment]
    elif geometry.kind in ("cylinder", "capsule") and params.get("radius") is not None \
            and params.get("length") is not None:
        r, length = abs(params["radius"]), abs(params["length"])
        half = (r, r, length / 2 + (r if geometry.kind == "capsule" else 0.0))
    elif geometry.kind == "sphere" and params.get("radius") is not None:
        half = (abs(params["radius"]),) * 3
    elif geometry.kind == "mesh":
        scaled = metric_mesh_bounds(geometry, mesh_box)
        if scaled is None:
            return None
        low, high = scaled
        centre = tuple((a + b) / 2 for a, b in zip(low, high))  # type: ignore[assignment]
        half = tuple((b - a) / 2 for a, b in zip(low, high))  # type: ignore[assignment]
    if half is None or not all(map(math.isfinite, half)):
        return None
    return box_around(centre, half, rpy_rotation(shape.origin.rpy), shape.origin.xyz)


def box_around(centre: Sequence[float], half: Sequence[float], rotation, translation: Sequence[float]) -> Box:
    """The axis-aligned box around the box (``centre``, half-extents ``half``) rotated by ``rotation``
    (rows) and moved by ``translation``: centred on ``R c + t``, half-extents ``|R| h``.

    Shapes in their link's frame (:func:`shape_bounds`) and boxes moved along a joint chain (G014)
    both go through it."""
    cx, cy, cz = centre
    hx, hy, hz = half
    # sum() of three-element lists: the same additions, in the same order, as sum() over the row's
    # products (a generator per row cost more than the arithmetic; the box is asked for 1,400 times
    # in a lint of pybullet_data's 95 robots)
    world_centre = [sum([r0 * cx, r1 * cy, r2 * cz]) + t for (r0, r1, r2), t in zip(rotation, translation)]
    world_half = [sum([abs(r0) * hx, abs(r1) * hy, abs(r2) * hz]) for r0, r1, r2 in rotation]
    return (tuple([c - h for c, h in zip(world_centre, world_half)]),  # type: ignore[return-value]
            tuple([c + h for c, h in zip(world_centre, world_half)]))


def mesh_unit(geometry) -> float | None:
    """Metres per unit of the mesh file: a COLLADA file's ``<unit meter>`` (1.0 when it states none),
    1.0 for the other formats (they carry no unit); None when a .dae states one that is not a
    positive number (then its size in metres is unknown)."""
    from ar3cli.urdf.meshinfo import collada_unit

    resolution = geometry.resolution
    if resolution is None or not resolution.found or resolution.path.suffix.lower() != ".dae":
        return 1.0
    return collada_unit(resolution.path)


def metric_mesh_bounds(geometry, mesh_box=None) -> Box | None:
    """The mesh's box in the shape frame in metres (file bounds times scale times the COLLADA unit),
    or None when it cannot be read or its unit is unknown. ``mesh_box``: as for :func:`shape_bounds`."""
    scaled = (mesh_box or scaled_mesh_bounds)(geometry)
    unit = mesh_unit(geometry) if scaled is not None else None
    if scaled is None or unit is None:
        return None
    if unit == 1.0:  # every format but COLLADA, and most COLLADA files: v * 1.0 is v
        return scaled
    low, high = scaled
    return tuple(v * unit for v in low), tuple(v * unit for v in high)  # type: ignore[return-value]


def scaled_mesh_bounds(geometry) -> Box | None:
    """The mesh's box in the shape frame in file units times scale (the COLLADA unit not applied:
    :func:`metric_mesh_bounds` does), or None when it cannot be read."""
    from ar3cli.urdf.meshinfo import mesh_bounds

    resolution = geometry.resolution
    scale = geometry.params.get("scale")
    if resolution is None or not resolution.found or scale is None:
        return None
    bounds = mesh_bounds(resolution.path)
    if bounds is None:
        return None
    a = [v * s for v, s in zip(bounds[0], scale)]
    b = [v * s for v, s in zip(bounds[1], scale)]
    return tuple(map(min, a, b)), tuple(map(max, a, b))  # type: ignore[return-value]


def link_bounds(link, shape_box=shape_bounds) -> Box | None:
    """Box around the link's collision shapes (visual shapes when it has no collision).

    None when no shape has a known box, or when one is placed at a non-finite origin (nan/inf:
    F007 reports the number; a box built from it would mean nothing). ``shape_box`` is
    :func:`shape_bounds` or a cached version of it (the lint context's).
    """
    boxes = [b for b in (shape_box(s) for s in (link.collisions or link.visuals)) if b is not None]
    if not boxes or not all(all(map(math.isfinite, corner)) for box in boxes for corner in box):
        return None
    return box_union(boxes)


def box_union(boxes: Sequence[Box]) -> Box:
    """The box around ``boxes`` (at least one)."""
    if len(boxes) == 1:  # most links have one shape of a kind: the box itself, as the general case gives it
        low, high = boxes[0]
        return tuple(low), tuple(high)
    lows, highs = zip(*boxes)
    return tuple(map(min, zip(*lows))), tuple(map(max, zip(*highs)))  # type: ignore[return-value]
