"""The facts ``ar3cli info`` shows, as plain dataclasses: tree, joints, DOF, mass, centre of mass,
bounding box, meshes and end effectors. No pybullet, no trimesh.

The zero configuration is every joint at 0 (a ``<mimic>`` joint at its source's value times its
multiplier plus its offset). Link frames come from the caller (``zero_frames``): the command
hands in :func:`ar3cli.kinematics.fk.urdf_link_frames`, since features never import each other.
Floating, planar and spherical joints are the identity at zero, so the FK sees them as fixed.
When the frames cannot be computed (several root links, a loop, a zero axis),
everything else is still reported and the centre of mass and bounding box say why they are missing.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.info.meshes import MeshFacts, mesh_facts
from ar3cli.maths.tensor_math import exact_sum
from ar3cli.urdf.bounds import shape_bounds
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Link, Model, Shape

ZeroFrames = Callable[[Model], Mapping[str, Any]]
"""Model -> the 4x4 world frame (array-like) of every link it can place at the zero configuration."""

JOINT_DOF = {"revolute": 1, "continuous": 1, "prismatic": 1, "planar": 3, "floating": 6, "spherical": 3}
"""Degrees of freedom per joint type; planar is x, y and the angle, as MoveIt and PyBullet count it."""

QUICK_MESH_SUFFIXES = (".stl", ".obj")
"""Mesh formats :mod:`ar3cli.urdf.meshinfo` bounds in plain Python (others need trimesh)."""
MULTI_DOF_TYPES = ("floating", "planar", "spherical")

NO_INERTIAL = "no inertial"
PYBULLET_DEFAULT_MASS = 1.0
"""kg PyBullet gives a link without ``<inertial>`` (``UrdfParser.cpp`` parseLink), except one named ``world`` (0)."""
NO_MASS = "no <mass>"
BAD_MASS = "mass is not a finite number"


@dataclass
class JointInfo:
    name: str
    type: str
    parent: str | None
    child: str | None
    axis: tuple[float, float, float] | None
    """None for joints that do not move along an axis (fixed, floating, spherical)."""
    axis_given: bool
    lower: float | None
    upper: float | None
    effort: float | None
    velocity: float | None
    mimic: dict[str, Any] | None
    """``{"joint", "multiplier", "offset"}`` of the joint this one follows."""
    dof: int
    """0 for fixed and mimic joints (they follow another joint)."""
    line: int

    @property
    def moves(self) -> bool:
        return self.type in JOINT_DOF

    @property
    def unlimited(self) -> bool:
        return self.type == "continuous"

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "type": self.type, "parent": self.parent, "child": self.child,
                "axis": _finite_list(self.axis), "axis_given": self.axis_given,
                "lower": None if self.unlimited else _finite(self.lower),
                "upper": None if self.unlimited else _finite(self.upper),
                "effort": _finite(self.effort), "velocity": _finite(self.velocity), "unlimited": self.unlimited,
                "mimic": self.mimic, "dof": self.dof, "line": self.line}


@dataclass
class LinkInfo:
    name: str
    parent_joint: str | None
    child_joints: list[str]
    mass: float | None
    """The ``<mass value>``; None when the link has none (``mass_note`` says why)."""
    mass_note: str
    """Empty, or ``no inertial``, ``no <mass>``, ``mass is not a finite number``."""
    centre_of_mass: tuple[float, float, float] | None
    """The link's centre of mass at the zero configuration, in the root link's frame (m)."""
    line: int

    @property
    def is_leaf(self) -> bool:
        return not self.child_joints

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "parent_joint": self.parent_joint, "child_joints": self.child_joints,
                "mass_kg": self.mass, "mass_note": self.mass_note, "centre_of_mass_m": _finite_list(self.centre_of_mass),
                "leaf": self.is_leaf, "line": self.line}


@dataclass
class BoundingBox:
    low: tuple[float, float, float]
    high: tuple[float, float, float]
    shapes: int
    """Shapes inside the box (see :func:`box_shapes` for which)."""
    collision_links: list[str]
    """Links measured by their collision shapes rather than their visual ones."""
    shapes_left_out: int
    """Shapes of unknown size (a mesh that did not resolve or could not be read, a malformed size) or
    on a link the frames do not place."""

    @property
    def size(self) -> tuple[float, float, float]:
        return tuple(b - a for a, b in zip(self.low, self.high))  # type: ignore[return-value]

    def to_dict(self) -> dict[str, Any]:
        return {"min": list(self.low), "max": list(self.high), "size": list(self.size),
                "shapes": self.shapes, "collision_links": self.collision_links,
                "shapes_left_out": self.shapes_left_out}


@dataclass
class Summary:
    path: Path
    name: str | None
    roots: list[str]
    links: list[LinkInfo]
    joints: list[JointInfo]
    meshes: MeshFacts
    centre_of_mass: tuple[float, float, float] | None = None
    bounding_box: BoundingBox | None = None
    unreachable: list[str] = field(default_factory=list)
    """Links no root reaches (a joint names an undeclared parent, or the joints form a loop)."""
    notes: list[str] = field(default_factory=list)

    @property
    def dof(self) -> int:
        return sum(joint.dof for joint in self.joints)

    @property
    def movable_joints(self) -> list[JointInfo]:
        return [joint for joint in self.joints if joint.moves]

    @property
    def total_mass(self) -> float:
        """Sum of the ``<mass>`` values; links without one count 0; inf past the largest float (masses of 1e308 kg)."""
        return exact_sum([link.mass for link in self.links if link.mass is not None])

    def pybullet_mass(self, fixed_base: bool) -> float:
        """The total mass PyBullet simulates: each link without ``<inertial>`` weighs
        :data:`PYBULLET_DEFAULT_MASS` (one named ``world`` 0), and with ``useFixedBase`` the base (the
        root link) weighs 0 whatever the file says (measured, ``docs/pybullet-facts.md`` section 1)."""
        root = self.roots[0] if len(self.roots) == 1 else None
        masses = []
        for link in self.links:
            if fixed_base and link.name == root:
                continue
            if link.mass is not None:
                masses.append(link.mass)
            elif link.mass_note == NO_INERTIAL and link.name != "world":
                masses.append(PYBULLET_DEFAULT_MASS)
        return exact_sum(masses)

    @property
    def massless_links(self) -> list[LinkInfo]:
        return [link for link in self.links if link.mass_note]

    @property
    def end_effectors(self) -> list[str]:
        """Leaf links: no joint has them as parent."""
        return [link.name for link in self.links if link.is_leaf]

    def to_dict(self) -> dict[str, Any]:
        return {
            "path": str(self.path), "name": self.name, "root_links": self.roots,
            "link_count": len(self.links), "joint_count": len(self.joints), "dof": self.dof,
            "movable_joint_count": len(self.movable_joints),
            "total_mass_kg": _finite(self.total_mass),
            "pybullet_mass_kg": {"floating": _finite(self.pybullet_mass(False)),
                                 "fixed_base": _finite(self.pybullet_mass(True))},
            "links_without_mass": [{"link": link.name, "why": link.mass_note} for link in self.massless_links],
            "centre_of_mass_m": _finite_list(self.centre_of_mass),
            "bounding_box_m": self.bounding_box.to_dict() if self.bounding_box else None,
            "end_effectors": self.end_effectors,
            "meshes": self.meshes.to_dict(),
            "unreachable_links": self.unreachable,
            "notes": self.notes,
            "links": [link.to_dict() for link in self.links],
            "joints": [joint.to_dict() for joint in self.joints],
        }


def summarize(model: Model, zero_frames: ZeroFrames) -> Summary:
    """Everything ``info`` reports about ``model``; ``zero_frames`` places the links (see module doc)."""
    children: dict[str, list[str]] = {}
    for joint in model.joints:
        if joint.parent is not None:
            children.setdefault(joint.parent, []).append(joint.name)
    parent_joint = {}
    for joint in model.joints:
        if joint.child is not None:
            parent_joint.setdefault(joint.child, joint.name)
    summary = Summary(
        path=model.path, name=model.name, roots=[link.name for link in model.root_links()],
        links=[_link_info(link, parent_joint.get(link.name), children.get(link.name, [])) for link in model.links],
        joints=[_joint_info(joint, model) for joint in model.joints],
        meshes=mesh_facts(model),
    )
    summary.unreachable, closing = _walk(summary, model)
    if closing is not None:
        # urdf_link_frames walks the joints without a visited set: a loop would never end.
        summary.notes.append(f"centre of mass and bounding box not computed: joint {closing.name!r} (line "
                             f"{closing.line}) leads back to link {closing.child!r}, which is already in the tree")
        return summary
    try:
        frames = zero_frames(_free_joints_fixed(model))
    except UserError as exc:
        summary.notes.append(f"centre of mass and bounding box not computed: {exc.message}")
        return summary
    _place(summary, model, frames)
    return summary


def _link_info(link: Link, parent_joint: str | None, child_joints: list[str]) -> LinkInfo:
    mass, note = None, ""
    if link.inertial is None:
        note = NO_INERTIAL
    elif link.inertial.element.find("mass") is None:
        note = NO_MASS
    elif link.inertial.mass is None or not math.isfinite(link.inertial.mass):
        note = BAD_MASS
    else:
        mass = link.inertial.mass
    return LinkInfo(name=link.name, parent_joint=parent_joint, child_joints=child_joints, mass=mass, mass_note=note,
                    centre_of_mass=None, line=link.line)


def _joint_info(joint: Joint, model: Model) -> JointInfo:
    limit = joint.limit
    mimic = None
    if joint.mimic is not None:
        mimic = {"joint": joint.mimic.joint, "multiplier": joint.mimic.multiplier, "offset": joint.mimic.offset}
    follows = mimic is not None and model.joint(joint.mimic.joint) is not None  # type: ignore[union-attr]
    return JointInfo(
        name=joint.name, type=joint.type, parent=joint.parent, child=joint.child,
        axis=joint.axis if joint.type in (*ACTUATED_JOINT_TYPES, "planar") else None, axis_given=joint.axis_given,
        lower=limit.lower if limit else None, upper=limit.upper if limit else None,
        effort=limit.effort if limit else None, velocity=limit.velocity if limit else None,
        mimic=mimic, dof=0 if follows else JOINT_DOF.get(joint.type, 0), line=joint.line)


def _walk(summary: Summary, model: Model) -> tuple[list[str], Joint | None]:
    """The links no root reaches, and the first joint that leads to a link already reached (a
    loop, or a link with a second parent), if any."""
    child_joints: dict[str, list[Joint]] = {}
    for joint in model.joints:
        child_joints.setdefault(joint.parent or "", []).append(joint)
    reached: set[str] = set(summary.roots)
    stack = list(summary.roots)
    closing = None
    while stack:
        name = stack.pop()
        for joint in child_joints.get(name, []):
            if joint.child is None:
                continue
            if joint.child in reached:
                closing = closing or joint
                continue
            reached.add(joint.child)
            stack.append(joint.child)
    return [link.name for link in summary.links if link.name not in reached], closing


def _free_joints_fixed(model: Model) -> Model:
    """The model with its floating, planar and spherical joints made fixed: at the zero
    configuration they do not move their child, and the FK only handles 1-DOF and fixed joints."""
    if not any(joint.type in MULTI_DOF_TYPES for joint in model.joints):
        return model
    joints = [replace(joint, type="fixed") if joint.type in MULTI_DOF_TYPES else joint for joint in model.joints]
    return replace(model, joints=joints)


def _place(summary: Summary, model: Model, frames: Mapping[str, Any]) -> None:
    """Centre of mass of each link and of the robot, and the bounding box, from the link frames."""
    import numpy as np

    weighted, placed_mass, unplaced = np.zeros(3), 0.0, []
    for info, link in zip(summary.links, model.links):
        frame = frames.get(link.name)
        if frame is None:
            if info.mass:
                unplaced.append(link.name)
            continue
        frame = np.asarray(frame, dtype=float)
        offset = link.inertial.origin.xyz if link.inertial is not None else (0.0, 0.0, 0.0)
        centre = frame[:3, :3] @ np.asarray(offset, dtype=float) + frame[:3, 3]
        if np.isfinite(centre).all():
            info.centre_of_mass = tuple(float(v) for v in centre)  # type: ignore[assignment]
            if info.mass is not None:
                weighted += info.mass * centre
                placed_mass += info.mass
    if unplaced:
        summary.notes.append(f"centre of mass leaves out {len(unplaced)} link(s) FK could not place: "
                             + listed(unplaced))
    if placed_mass > 0:
        centre = weighted / placed_mass
        summary.centre_of_mass = tuple(float(v) for v in centre)  # type: ignore[assignment]
    elif summary.total_mass == 0:
        summary.notes.append("centre of mass undefined: the total mass is 0")
    summary.bounding_box = _bounding_box(model, frames)


def _bounding_box(model: Model, frames: Mapping[str, Any]) -> BoundingBox | None:
    """Box around the shapes :func:`box_shapes` picks at the zero configuration: each shape's box
    in its link frame, its 8 corners moved to the root frame."""
    import numpy as np

    signs = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    corners, shapes, skipped, collision_links = [], 0, 0, []
    for link in model.links:
        frame = frames.get(link.name)
        chosen = box_shapes(link)
        if chosen and chosen[0].role == "collision":
            collision_links.append(link.name)
        for shape in chosen:
            box = shape_bounds(shape) if frame is not None else None
            if box is None:
                skipped += 1
                continue
            low, high = np.asarray(box[0], dtype=float), np.asarray(box[1], dtype=float)
            local = low + signs * (high - low)
            frame = np.asarray(frame, dtype=float)
            world = local @ frame[:3, :3].T + frame[:3, 3]
            if not np.isfinite(world).all():
                skipped += 1
                continue
            corners.append(world)
            shapes += 1
    if not corners:
        return None
    stacked = np.concatenate(corners)
    return BoundingBox(tuple(float(v) for v in stacked.min(axis=0)),  # type: ignore[arg-type]
                       tuple(float(v) for v in stacked.max(axis=0)), shapes, collision_links, skipped)  # type: ignore[arg-type]


def box_shapes(link: Link) -> tuple[Shape, ...]:
    """The shapes that stand for ``link`` in the bounding box: its visual shapes, or its collision
    shapes when it has no visual or when only the collision meshes are :data:`QUICK_MESH_SUFFIXES`
    (a COLLADA visual with an STL collision, as on the UR arms: bounding a COLLADA file needs
    trimesh, ~2 s for the UR5's first run, then the mesh-bounds disk cache answers)."""
    if not link.visuals or (link.collisions and not _quick(link.visuals) and _quick(link.collisions)):
        return link.collisions
    return link.visuals


def _quick(shapes: tuple[Shape, ...]) -> bool:
    """True when bounding ``shapes`` reads no mesh with trimesh."""
    return all(shape.geometry.kind != "mesh" or shape.geometry.resolution is None
               or not shape.geometry.resolution.found
               or shape.geometry.resolution.path.suffix.lower() in QUICK_MESH_SUFFIXES  # type: ignore[union-attr]
               for shape in shapes)


def _finite(value: float | None) -> float | None:
    """JSON has no nan or inf: a non-finite number is reported as null."""
    return value if value is not None and math.isfinite(value) else None


def _finite_list(values) -> list[float | None] | None:
    return None if values is None else [_finite(v) for v in values]
