"""What a lint rule sees: :class:`Context`, the model plus lazily built shared helpers."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeVar

from ar3cli.maths.tensor_math import symmetric_eigenvalues
from ar3cli.urdf.bounds import Box, box_around, box_union, link_bounds, scaled_mesh_bounds, shape_bounds
from ar3cli.urdf.model import Link, Model, Shape

if TYPE_CHECKING:
    from ar3cli.urdf.srdf_read import DisabledPairs

T = TypeVar("T")
Matrix = tuple[tuple[float, float, float], ...]
IDENTITY: Matrix = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@dataclass(frozen=True)
class RigidBody:
    """Links welded together by fixed joints, as every engine simulates them: one body (MuJoCo fuses
    them, PyBullet's and Drake's articulated solvers carry their inertia together).

    ``top`` is the member whose parent joint moves (or the root); ``moments`` are the principal
    moments of the members' composite inertia about their common centre of mass (parallel-axis terms
    included), ascending; NaN when a member's numbers are not finite.
    """

    top: str
    members: tuple[str, ...]
    mass: float
    moments: tuple[float, float, float]


def _matmul(a: Matrix, b: Matrix) -> Matrix:
    return tuple(tuple(sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _apply(rotation: Matrix, vector, translation=(0.0, 0.0, 0.0)) -> tuple[float, float, float]:
    return tuple(sum(rotation[i][k] * vector[k] for k in range(3)) + translation[i] for i in range(3))  # type: ignore[return-value]


class Context:
    """The model a rule checks, with the link boxes and the PyBullet session built once per file
    and shared by every rule that asks (pybullet is imported only when a ``--sim`` rule does)."""

    def __init__(self, model: Model, srdf_disabled: DisabledPairs | None = None,
                 targets: tuple[str, ...] = ("pybullet", "ros")) -> None:
        self.model = model
        self.srdf_disabled = srdf_disabled
        """Pairs the user's SRDF disables (``lint-urdf --srdf``), None when none was given."""
        self.targets = targets
        """The engines the robot is meant for (``lint-urdf --target``): a rule whose verdict depends on
        the engine (a mesh MuJoCo finds through its own ``meshdir``) asks here."""
        self._shape_bounds: dict[int, Box | None] = {}
        self._mesh_bounds: dict[tuple, Box | None] = {}
        self._session: Any = None
        self._shared: dict[str, Any] = {}
        self._link_memos: dict[str, dict[Any, Any]] = {}
        """Answers about one link each, by ``id(link)`` (the model, and with it every link, lives as long as
        this context): its boxes (not by name: two links may share one, S002), radius of gyration, density."""
        self._structure: dict[str, Any] = {}

    def inherit(self, earlier: Context, kept: list[Link]) -> None:
        """Start from what ``earlier`` (the check of the text before an edit that kept every element: a value,
        a line break) computed about the links in ``kept`` and their shapes, the objects the edit did not
        touch, the same in both models (:mod:`ar3cli.lint.reuse`), and about the tree's structure
        (:meth:`structure`)."""
        link_ids = {id(link) for link in kept}
        shape_ids = {id(shape) for link in kept for shape in (*link.visuals, *link.collisions)}
        self._shape_bounds = {key: box for key, box in earlier._shape_bounds.items() if key in shape_ids}
        self._mesh_bounds = dict(earlier._mesh_bounds)  # by file and scale: a changed file is a full check
        self._link_memos = {name: {key: value for key, value in memo.items()
                                   if (key[0] if isinstance(key, tuple) else key) in link_ids}
                            for name, memo in earlier._link_memos.items()}
        self._structure = dict(earlier._structure)  # such an edit changes no element, tag or child list

    def disabled_pairs(self) -> tuple[DisabledPairs, str | None]:
        """(the link pairs MoveIt is told not to check, a note saying where they come from or None): the
        user's ``--srdf``, else the SRDF the package ships for this robot
        (:func:`~ar3cli.urdf.srdf_read.package_srdf`), else none. P002 and M003 leave those pairs alone."""
        if "disabled-pairs" not in self._shared:
            from ar3cli.urdf.srdf_read import moveit_disabled

            pairs, srdf = moveit_disabled(self.model, self.srdf_disabled)
            self._shared["disabled-pairs"] = (pairs, None if srdf is None else (
                f"pairs disabled by the package's SRDF {srdf.name} (found beside the file for this robot; "
                "--srdf FILE chooses another) are not reported"))
        return self._shared["disabled-pairs"]

    def structure(self, key: str, build: Callable[[Model], T]) -> T:
        """``build(model)``, computed once per file for every rule that asks with the same ``key``, where the
        answer depends on the elements, their tags and their children alone, never on an attribute value
        (the schema rules' walk): the check after an edit of a value keeps it (:meth:`inherit`)."""
        if key not in self._structure:
            self._structure[key] = build(self.model)
        return self._structure[key]

    def link_memo(self, name: str) -> dict[Any, Any]:
        """A dict, one per ``name`` and file, of answers about single links keyed by ``id(link)`` or a tuple
        that starts with it: answers that depend on that link's own elements only (and the mesh files they
        name), which the check after an edit keeps for the links it did not touch (:meth:`inherit`)."""
        return self._link_memos.setdefault(name, {})

    def shared(self, key: str, build: Callable[[Model], T]) -> T:
        """``build(model)``, computed once per file for every rule that asks with the same ``key``
        (the schema rules' walk of the URDF elements: five rules, one walk)."""
        if key not in self._shared:
            self._shared[key] = build(self.model)
        return self._shared[key]

    def link_bounds(self, link: Link) -> Box | None:
        """Box around the link's collision (else visual) shapes in its frame, or None."""
        known = self.link_memo("link-bounds")
        if id(link) not in known:
            known[id(link)] = link_bounds(link, self.shape_bounds)
        return known[id(link)]

    def body_bounds(self, link: Link) -> Box | None:
        """Box around every visual and collision shape of the link, in its frame, or None: the body's extent
        whichever of its shapes stands for it (Baxter's screen collides as a 1 mm placeholder sphere and is
        drawn as its real 27 cm body). What a radius of gyration is judged against (I007)."""
        known = self.link_memo("body-bounds")
        if id(link) not in known:
            boxes = [box for shape in (*link.visuals, *link.collisions) if (box := self.shape_bounds(shape)) is not None]
            finite = boxes and all(all(map(math.isfinite, corner)) for box in boxes for corner in box)
            known[id(link)] = box_union(boxes) if finite else None
        return known[id(link)]

    def shape_bounds(self, shape: Shape) -> Box | None:
        """Box around one visual or collision shape in its link's frame, or None; computed once per
        shape for every rule that asks (the geometry and consistency rules ask for the same ones)."""
        key = id(shape)  # the model, and with it every shape, lives as long as this context
        if key not in self._shape_bounds:
            self._shape_bounds[key] = shape_bounds(shape, self.scaled_mesh_bounds)
        return self._shape_bounds[key]

    def scaled_mesh_bounds(self, geometry) -> Box | None:
        """:func:`~ar3cli.urdf.bounds.scaled_mesh_bounds`, once per mesh file and scale of this file:
        a link's visual and collision often share their mesh, and G006 asks for every mesh again
        (pybullet_data's 95 robots: 1,140 questions, 311 different answers)."""
        resolution = geometry.resolution
        if resolution is None or not resolution.found:
            return None  # what scaled_mesh_bounds answers without looking
        key = (resolution.path, geometry.params.get("scale"))
        if key not in self._mesh_bounds:
            self._mesh_bounds[key] = scaled_mesh_bounds(geometry)
        return self._mesh_bounds[key]

    def link_size(self, link: Link) -> float | None:
        """The diagonal of the link's box (:meth:`link_bounds`) in metres, or None without one."""
        box = self.link_bounds(link)
        return None if box is None else math.dist(box[0], box[1])

    def robot_scale(self) -> float | None:
        """The median size (:meth:`link_size`) of the robot's links that have geometry: what "small"
        and "far" mean for this robot (a hand's links are centimetres, a truck's metres), so that
        the plausibility rules judge a value against the robot itself rather than one constant."""
        if "robot-scale" not in self._shared:
            sizes = sorted(size for link in self.model.links if (size := self.link_size(link)) is not None
                           and size > 0 and math.isfinite(size))
            self._shared["robot-scale"] = sizes[len(sizes) // 2] if sizes else None
        return self._shared["robot-scale"]

    def total_mass(self) -> float:
        """The sum of the links' positive, finite masses (kg)."""
        if "total-mass" not in self._shared:
            self._shared["total-mass"] = sum(mass for link in self.model.links if link.inertial is not None
                                             and (mass := link.inertial.mass) is not None and math.isfinite(mass)
                                             and mass > 0)
        return self._shared["total-mass"]

    def rigid_body(self, link: Link) -> RigidBody:
        """The :class:`RigidBody` ``link`` belongs to: the groups are found once per file, a group's
        composite inertia the first time one of its links is asked about (few files need any)."""
        if "rigid-groups" not in self._shared:
            self._shared["rigid-groups"] = self._rigid_groups()
        placed, groups, bodies = self._shared["rigid-groups"]
        top = placed[link.name][0]
        if top not in bodies:
            bodies[top] = RigidBody(top, tuple(groups[top]), *self._composite(groups[top], placed))
        return bodies[top]

    def _rigid_groups(self) -> tuple[dict, dict[str, list[str]], dict[str, RigidBody]]:
        """(each link's (top, rotation, origin) in the frame of the top of its chain of fixed joints (a
        loop in a broken file ends the walk), top -> its members, an empty cache of bodies)."""
        model = self.model
        placed: dict[str, tuple[str, Matrix, tuple[float, float, float]]] = {}
        for link in model.links:
            chain, name, seen = [], link.name, set()
            while name not in placed and name not in seen:
                seen.add(name)
                joint = model.parent_joint(name)
                if joint is None or joint.type != "fixed" or joint.parent is None or model.link(joint.parent) is None:
                    placed[name] = (name, IDENTITY, (0.0, 0.0, 0.0))
                    break
                chain.append((name, joint))
                name = joint.parent
            for child, joint in reversed(chain):
                top, rotation, origin = placed.get(joint.parent, (joint.parent, IDENTITY, (0.0, 0.0, 0.0)))
                placed[child] = (top, _matmul(rotation, joint.origin.rotation), _apply(rotation, joint.origin.xyz, origin))
        groups: dict[str, list[str]] = {}
        for link in model.links:
            groups.setdefault(placed[link.name][0], []).append(link.name)
        return placed, groups, {}

    def _composite(self, members, placed) -> tuple[float, tuple[float, float, float]]:
        """(mass, principal moments about the common COM) of ``members`` placed in their top's frame."""
        parts = []
        for name in members:
            inertial = self.model.link(name).inertial  # type: ignore[union-attr]
            mass = inertial.mass if inertial is not None else None
            if mass is None or not mass > 0:
                continue
            _top, rotation, origin = placed[name]
            tensor = inertial.tensor or (0.0,) * 6  # type: ignore[union-attr]
            ixx, ixy, ixz, iyy, iyz, izz = tensor
            frame = _matmul(rotation, inertial.origin.rotation)  # type: ignore[union-attr]
            local = ((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz))
            turned = _matmul(_matmul(frame, local), tuple(zip(*frame)))  # type: ignore[arg-type]
            parts.append((mass, _apply(rotation, inertial.origin.xyz, origin), turned))  # type: ignore[union-attr]
        total = sum(mass for mass, _c, _i in parts)
        if not total > 0 or not math.isfinite(total):
            return total, (0.0, 0.0, 0.0)
        centre = [sum(mass * c[i] for mass, c, _ in parts) / total for i in range(3)]
        composite = [[0.0] * 3 for _ in range(3)]
        for mass, c, turned in parts:
            d = [c[i] - centre[i] for i in range(3)]
            square = d[0] ** 2 + d[1] ** 2 + d[2] ** 2
            for i in range(3):
                for j in range(3):
                    composite[i][j] += turned[i][j] + mass * ((square if i == j else 0.0) - d[i] * d[j])
        return total, symmetric_eigenvalues(composite)

    def zero_pose_frame(self, name: str) -> tuple[Matrix, tuple[float, float, float]] | None:
        """(rotation, origin) of link ``name``'s frame in its root link's frame with every joint at 0 (the
        joint origins composed down the tree), or None for a link no root reaches or one below a joint
        origin that is not finite. Computed for every link once per file."""
        if "zero-pose-frames" not in self._shared:
            self._shared["zero-pose-frames"] = self._zero_pose_frames()
        return self._shared["zero-pose-frames"].get(name)

    def _zero_pose_frames(self) -> dict[str, tuple[Matrix, tuple[float, float, float]]]:
        model = self.model
        frames: dict[str, tuple[Matrix, tuple[float, float, float]]] = {}
        stack = [link.name for link in model.root_links()]
        for name in stack:
            frames[name] = (IDENTITY, (0.0, 0.0, 0.0))
        while stack:
            name = stack.pop()
            rotation, origin = frames[name]
            for joint in model.child_joints(name):
                child = joint.child
                if child is None or child in frames or model.link(child) is None:
                    continue  # a link reached twice or a loop: S006's
                values = (*joint.origin.xyz, *(v for row in joint.origin.rotation for v in row))
                if not all(map(math.isfinite, values)):
                    continue
                frames[child] = (_matmul(rotation, joint.origin.rotation), _apply(rotation, joint.origin.xyz, origin))
                stack.append(child)
        return frames

    def zero_pose_box(self, name: str, box: Box | None) -> Box | None:
        """``box`` (in link ``name``'s frame) as an axis-aligned box in its root's frame at the zero pose
        (:meth:`zero_pose_frame`), or None when either is unknown: where two links' shapes sit relative
        to each other, without a simulator."""
        frame = self.zero_pose_frame(name)
        if box is None or frame is None:
            return None
        centre = [(lo + hi) / 2 for lo, hi in zip(*box)]
        half = [(hi - lo) / 2 for lo, hi in zip(*box)]
        return box_around(centre, half, frame[0], frame[1])

    def kinematic_span(self) -> float:
        """Metres the robot's own joints span: the longest prismatic travel or the furthest link frame
        from its root at the zero pose, whichever is more (0 for a robot of one link). What a size is
        judged against besides the parts: a gantry whose rail travels 37 m is a building-sized robot, and
        its 46 m rail is metres, not millimetres."""
        if "kinematic-span" not in self._shared:
            span = 0.0
            for joint in self.model.joints:
                limit = joint.limit
                if joint.type == "prismatic" and limit is not None and limit.lower is not None \
                        and limit.upper is not None and math.isfinite(limit.upper - limit.lower):
                    span = max(span, limit.upper - limit.lower)
            for link in self.model.links:
                frame = self.zero_pose_frame(link.name)
                if frame is not None:
                    span = max(span, math.hypot(*frame[1]))
            self._shared["kinematic-span"] = span
        return self._shared["kinematic-span"]

    @property
    def session(self) -> Any:
        """A PyBullet session (gravity on) for ``--sim`` rules, opened on first use."""
        if self._session is None:
            from ar3cli.sim.session import Session

            self._session = Session(gravity=-9.81, file_caching=True)
        return self._session

    def close(self) -> None:
        if self._session is not None:
            self._session.close()
            self._session = None
