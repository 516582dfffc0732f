"""Which links are adjacent, and which collide at the home pose: one answer for every command.

lint-urdf --sim (P002), render and sample-collisions all ask "are two links that are not adjacent
interpenetrating?". They use the same two definitions, from here:

- **Adjacent** is MoveIt Setup Assistant's rule (``compute_default_collisions.cpp``): two links
  with collision geometry joined by a joint, links *without* collision geometry being transparent
  (removed, their neighbours joined). pybullet_data's panda_link7 and panda_hand are adjacent
  through the geometry-less panda_link8: a URDF cannot put geometry between them, so their
  overlap is by construction, not a modelling error.
- **Colliding** is penetrating deeper than :data:`ar3cli.sim.session.PENETRATION_TOLERANCE` (1 um):
  resting faces (depth ~1e-16 m) and points at a positive distance do not count.

:func:`direct_parent_child` is something else: the pairs PyBullet's ``URDF_USE_SELF_COLLISION``
flag skips, used where ar3cli explains what that flag does.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from ar3cli.urdf.model import Model


def collision_links(model: Model) -> list[str]:
    """Links with at least one ``<collision>`` whose geometry parses, in file order."""
    return [link.name for link in model.links
            if any(shape.geometry.kind is not None for shape in link.collisions)]


def unloadable_collision_links(model: Model) -> list[str]:
    """Links with a collision shape pybullet cannot load (a mesh not found), in file order.

    sample-collisions loads the robot without those shapes (:mod:`ar3cli.sim.loadable_copy`), so such a
    link would seem never to touch anything: it is left out of the matrix instead. None of its pairs is
    classified, so none is disabled (MoveIt keeps checking them); a box guessed around a mesh nobody
    can read would be a claim about a shape ar3cli has not seen. It keeps its place in the adjacency.
    """
    from ar3cli.sim.loadable_copy import unloadable_shapes

    return list(dict.fromkeys(item.link for item in unloadable_shapes(model, roles=("collision",))))


def adjacent_pairs(model: Model, with_geometry: Iterable[str] | None = None) -> set[frozenset[str]]:
    """Pairs of links with geometry joined by a joint, looking through links without geometry.

    Walks the joint graph (undirected) from each link with geometry (default:
    :func:`collision_links`), passing through links without geometry, stopping at the first link
    with geometry on each path: panda_link7 - (link8) - panda_hand is adjacent.
    """
    solid = set(collision_links(model) if with_geometry is None else with_geometry)
    neighbours: dict[str, set[str]] = {}
    for joint in model.joints:
        if joint.parent and joint.child:
            neighbours.setdefault(joint.parent, set()).add(joint.child)
            neighbours.setdefault(joint.child, set()).add(joint.parent)
    pairs: set[frozenset[str]] = set()
    for start in solid:
        seen, frontier = {start}, [start]
        while frontier:
            link = frontier.pop()
            for other in neighbours.get(link, ()):
                if other in seen:
                    continue
                seen.add(other)
                if other in solid:
                    pairs.add(frozenset((start, other)))
                else:
                    frontier.append(other)
    return pairs


def direct_parent_child(model: Model) -> set[frozenset[str]]:
    """Pairs a joint joins directly: the only ones URDF_USE_SELF_COLLISION leaves out."""
    return {frozenset((j.parent, j.child)) for j in model.joints if j.parent and j.child}


def rigid_groups(model: Model, moving: Iterable[str]) -> dict[str, str]:
    """Each link's rigid group: links joined only by joints not in ``moving`` share one.

    Two links of a group keep the same relative pose whatever the moving joints do, so a
    self-collision test between them has the same answer in every configuration. Returns
    link name -> the group's first link in file order.
    """
    moving = set(moving)
    order = {link.name: index for index, link in enumerate(model.links)}
    group = {name: name for name in order}

    def root(name: str) -> str:
        while group[name] != name:
            group[name] = group[group[name]]
            name = group[name]
        return name

    for joint in model.joints:
        if joint.name not in moving and joint.parent in group and joint.child in group:
            a, b = root(joint.parent), root(joint.child)
            first, second = sorted((a, b), key=order.__getitem__)
            group[second] = first
    return {name: root(name) for name in group}


def nonadjacent_collisions(body: Any, model: Model | None = None) -> list[tuple[str, str, float]]:
    """Non-adjacent pairs penetrating deeper than the tolerance at the body's *current* pose.

    ``body`` must be loaded with ``self_collision="all-pairs"``; ``model`` (default
    ``body.model``) gives the adjacency. Returns (link_a, link_b, depth in m, negative).
    """
    from ar3cli.sim.session import PENETRATION_TOLERANCE

    adjacent = adjacent_pairs(model or body.model)
    return [(a, b, depth) for a, b, depth in body.contacts(min_depth=PENETRATION_TOLERANCE)
            if frozenset((a, b)) not in adjacent]
