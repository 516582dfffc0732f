"""Visual and collision geometry of corresponding links, shape by shape in file order: shapes
added or removed, kind, mesh file, scale, primitive dimensions, origin, and for meshes the bounds
of the file (:func:`~ar3cli.urdf.bounds.shape_bounds`: a mesh whose content changed under the same
name). Mesh files are compared by the name the robot file writes, not by where they resolve (a
revision's copy lives in a temporary folder)."""

from __future__ import annotations

from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import Change
from ar3cli.robot_diff.tolerance import distance, origin_changed
from ar3cli.urdf.model import Link, Shape

DIMENSIONS = ("size", "radius", "length")


def shape_changes(pair: Pair, link: str, index: int, old: Shape, new: Shape) -> list[Change]:
    name = f"link '{link}' {new.role} {index + 1}"
    at = new.geometry.element if new.geometry.element is not None else new.element
    tolerance = pair.tolerance
    changes: list[Change] = []

    def add(what: str, before, after, amount: float | None = None, unit: str = "", where=at) -> None:
        changes.append(pair.change("geometry", name, what, before, after, amount, unit, at=where))

    if old.geometry.kind != new.geometry.kind:
        add("kind", old.geometry.kind or "-", new.geometry.kind or "-")
        return changes
    if old.geometry.filename != new.geometry.filename:
        add("mesh", old.geometry.filename or "-", new.geometry.filename or "-")
    old_scale, new_scale = old.geometry.params.get("scale"), new.geometry.params.get("scale")
    if (old_scale is None) != (new_scale is None) or (old_scale and new_scale and any(
            tolerance.relative_change(a, b) is not None for a, b in zip(old_scale, new_scale))):
        add("scale", old_scale, new_scale)
    for key in DIMENSIONS:
        before, after = old.geometry.params.get(key), new.geometry.params.get(key)
        if isinstance(before, tuple) or isinstance(after, tuple):
            amount = distance(before, after) if before and after else float("inf")
            if before != after and not amount <= tolerance.length:
                add(key, before, after, amount, "m")
        else:
            amount = tolerance.absolute_change(before, after, tolerance.length)
            if amount is not None:
                add(key, before, after, amount, "m")
    moved = origin_changed(old.origin, new.origin, tolerance)
    if moved is not None:
        metres, radians = moved
        translated = not metres <= tolerance.length
        add("origin", f"xyz {_text(old.origin.xyz)} rpy {_text(old.origin.rpy)}",
            f"xyz {_text(new.origin.xyz)} rpy {_text(new.origin.rpy)}", metres if translated else radians,
            "m" if translated else "rad", where=new.element)
    if not changes and new.geometry.kind == "mesh":
        changes += _bounds_change(pair, name, old, new, at)
    return changes


def _text(values) -> str:
    from ar3cli.robot_diff.records import show

    return show(values)


def _bounds_change(pair: Pair, name: str, old: Shape, new: Shape, at) -> list[Change]:
    """The mesh's box when nothing else about the shape changed (so its file's content did)."""
    from ar3cli.urdf.bounds import shape_bounds

    before, after = shape_bounds(old), shape_bounds(new)
    if before is None or after is None:
        return [] if before is after else [pair.change("geometry", name, "bounds", "unknown" if before is None else "known",
                                                       "unknown" if after is None else "known", at=at)]
    amount = max(distance(before[0], after[0]), distance(before[1], after[1]))
    if amount <= pair.tolerance.length:
        return []
    return [pair.change("geometry", name, "bounds", f"{_text(before[0])} .. {_text(before[1])}",
                        f"{_text(after[0])} .. {_text(after[1])}", amount, "m", at=at)]


def link_geometry_changes(pair: Pair, old: Link, new: Link) -> list[Change]:
    changes: list[Change] = []
    for role, before, after in (("visual", old.visuals, new.visuals), ("collision", old.collisions, new.collisions)):
        for index, (old_shape, new_shape) in enumerate(zip(before, after)):
            changes += shape_changes(pair, new.name, index, old_shape, new_shape)
        if len(before) != len(after):
            extra = after[len(before):] if len(after) > len(before) else ()
            changes.append(pair.change("geometry", f"link '{new.name}'", f"{role} shapes", len(before), len(after),
                                       at=extra[0].element if extra else new.element))
    return changes


def geometry_changes(pair: Pair) -> list[Change]:
    changes: list[Change] = []
    for old_name, new_name in pair.matching.links.items():
        old, new = pair.old.link(old_name), pair.new.link(new_name)
        if old is not None and new is not None:
            changes += link_geometry_changes(pair, old, new)
    return changes
