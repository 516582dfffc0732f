"""Why pybullet refused a link: found in the file itself, since pybullet's own words do not say.

pybullet 3.2.7 ends every link it cannot parse with "failed to parse link", and the lines before it
name neither the link's line nor, for shapes, the link ("Mesh filename is empty", "Could not parse
collision element for Link 'tip'"). The parser's requirements are few and were measured one by one
(tests/test_sim.py): an ``<inertial>`` needs ``<mass value>`` and an ``<inertia>`` with all six
attributes; a ``<visual>`` or ``<collision>`` needs a ``<geometry>`` holding one known shape with its
attributes; a visual's ``<material>`` needs a name. :func:`link_culprit` checks them in file order
and names the first broken element: link, the user's line and the reason.
"""

from __future__ import annotations

from typing import Any

from ar3cli.urdf.model import Model

SHAPE_ATTRIBUTES = {"box": ("size",), "sphere": ("radius",), "cylinder": ("length", "radius"),
                    "capsule": ("length", "radius"), "mesh": ("filename",), "plane": (), "cdf": ("filename",)}
"""The shapes pybullet's URDF parser knows, with the attributes it refuses to go without."""
INERTIA_ATTRIBUTES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def link_culprit(model: Model) -> str | None:
    """``link 'NAME' (FILE:LINE): REASON`` for the first element pybullet cannot parse, or None."""
    from ar3cli.sim.loadable_copy import user_place

    for link in model.links:
        for element, reason in _problems(link.element):
            place = user_place(model, element)
            where = f" ({place.file}:{place.line})" if place is not None else ""
            return f"link '{link.name}'{where}: {reason}"
    return None


def _problems(link: Any):
    """(element, reason) for each part of a ``<link>`` element pybullet's parser refuses, in file order."""
    for child in link:
        if child.tag == "inertial":
            yield from _inertial_problems(child)
        elif child.tag in ("visual", "collision"):
            yield from _shape_problems(child)


def _inertial_problems(inertial: Any):
    mass = inertial.find("mass")
    if mass is None:
        yield inertial, "its <inertial> has no <mass> (lint-urdf I003)"
    elif mass.get("value") is None:
        yield mass, "its <mass> has no value attribute (lint-urdf I003)"
    inertia = inertial.find("inertia")
    if inertia is None:
        yield inertial, "its <inertial> has no <inertia> (lint-urdf I006)"
    else:
        missing = [name for name in INERTIA_ATTRIBUTES if inertia.get(name) is None]
        if missing:
            yield inertia, f"its <inertia> lacks {', '.join(missing)} (pybullet needs all six attributes)"


def _shape_problems(shape: Any):
    role = shape.tag
    geometry = shape.find("geometry")
    if geometry is None:
        yield shape, f"a <{role}> has no <geometry>"
        return
    kinds = [child for child in geometry if isinstance(child.tag, str)]
    if not kinds:
        yield geometry, f"the <geometry> of a <{role}> is empty"
        return
    kind = kinds[0]
    if kind.tag not in SHAPE_ATTRIBUTES:
        yield kind, (f"a <{role}> has a <{kind.tag}> geometry, which pybullet does not know "
                     f"({', '.join(SHAPE_ATTRIBUTES)})")
        return
    missing = [name for name in SHAPE_ATTRIBUTES[kind.tag] if not (kind.get(name) or "").strip()]
    if missing:
        yield kind, f"the <{kind.tag}> of a <{role}> has no {' or '.join(missing)} attribute"
    material = shape.find("material")
    if role == "visual" and material is not None and material.get("name") is None:
        yield material, "a <visual>'s <material> has no name attribute"
