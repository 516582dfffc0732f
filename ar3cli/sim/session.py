"""The PyBullet session: connecting, capturing pybullet's C output, loading, link frames, contacts.

:class:`Session` and :class:`Body` own what every command needs the same way: the connection
(DIRECT, output captured), loading a Model, the joint table, setting and
reading joint positions, link frames, masses and inertias as PyBullet uses them, self-contacts,
removing a body. Commands make their domain-specific calls (camera images, motors, IK, friction,
collision filters, ...) through ``session.p``, always with ``physicsClientId=session.client``.

Everything here follows measured behaviour (``shared/docs/pybullet-facts.md``), not tutorials:

- pybullet is imported and used inside :func:`~ar3cli.sim.capture.capture_fds`, so nothing it prints
  from C reaches stdout; what it says is kept in :attr:`Session.messages`.
- pybullet caches files by name for the whole session, so a URDF rewritten by a fixer would load
  with its OLD content under the same name: every load gets a fresh file name, so the URDF itself is
  never stale. Meshes (which no command rewrites) are read once: caching is on by default, because
  off it reads every mesh each time it is named (measured: the panda loads in 0.20 s cached, 0.42 s
  uncached, as the visual and collision shapes name the same files; the 95 models of pybullet_data
  in 2.7 s against 12.1 s). ``file_caching=False`` is there for a caller that rewrites meshes.
- Meshes are resolved by ar3cli (``package://`` included) and handed to pybullet as absolute
  paths, in a temporary copy of the document: xacro files load the same way.
- Joint types come from the URDF: pybullet reports continuous joints as revolute with the
  limits (0, -1).
- Link frames are ``getLinkState(...)[4:6]``, not ``[0:2]`` (that is the centre of mass), and the
  base link frame is the base COM pose moved back by its local inertial frame.
- A load failure quotes pybullet's real reason (the missing mesh), not "Cannot load URDF file".
- ``getContactPoints`` reports faces resting on each other (depth ~1e-16 m) and points at a small
  positive distance: a pair *collides* only when it penetrates deeper than
  :data:`PENETRATION_TOLERANCE` (``Body.contacts(min_depth=...)``).
"""

from __future__ import annotations

import contextlib
import itertools
import math
import re
import tempfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.infra.isolation import report_stage
from ar3cli.sim.capture import capture_fds
from ar3cli.sim.loadable_copy import LineMap, user_lines
from ar3cli.urdf.home import home_value, sample_range
from ar3cli.urdf.model import ACTUATED_JOINT_TYPES, Joint, Model

Result = TypeVar("Result")
Pose = tuple[tuple[float, float, float], tuple[float, float, float, float]]
"""(position xyz, quaternion xyzw) in the world frame."""

SELF_COLLISION_ALL_PAIRS = "all-pairs"
"""``Session.load(self_collision=...)``: every pair of links, a link and its parent included."""
SELF_COLLISION_DEFAULT = "default"
"""``Session.load(self_collision=...)``: pybullet's own ``URDF_USE_SELF_COLLISION``, every pair but a
link and its direct parent."""
PENETRATION_TOLERANCE = 1e-6
"""m: two links *collide* when their deepest contact point penetrates more than this.

Measured (3,000 uniform samples each of pybullet_data's panda and kuka_iiwa and the AR3, every
pair): resting faces report depths within 1e-16 m of 0 (the AR3's fingers on the gripper base),
and no pair ever reports a depth between 1 nm and 1 um; 30 / 6 / 41 pair-configurations
penetrate by 1 um to 0.5 mm (real overlaps that have just begun, found again by
``getClosestPoints``). 1 um is ten orders of magnitude above resting noise and below every real
overlap; a 0.5 mm threshold would hide those overlaps. Used by lint-urdf's P002, render and
sample-collisions alike."""
_load_counter = itertools.count()


def import_pybullet():
    """Import pybullet with its build banner kept off the terminal; raises UserError if missing."""
    with capture_fds():
        try:
            import pybullet
        except ImportError as exc:
            raise UserError(f"pybullet is not installed ({exc}); run: pip install pybullet") from None
    return pybullet


@dataclass(frozen=True)
class JointRecord:
    """One pybullet joint, with its type and limits as the URDF states them.

    ``lower``/``upper`` are None for continuous joints and for joints PyBullet treats as
    unlimited; :meth:`sample_range` is the range a sampler should draw from.
    """

    index: int
    name: str
    urdf_type: str
    link_name: str
    lower: float | None
    upper: float | None
    effort: float
    velocity: float
    urdf: Joint | None

    @property
    def movable(self) -> bool:
        """A 1-DOF joint (:data:`~ar3cli.urdf.model.ACTUATED_JOINT_TYPES`): one position, one motor."""
        return self.urdf_type in ACTUATED_JOINT_TYPES

    @property
    def continuous(self) -> bool:
        return self.urdf_type == "continuous" or (self.urdf_type == "revolute" and self.lower is None)

    def sample_range(self) -> tuple[float, float]:
        """Where a uniform sampler should draw: [-pi, pi) for continuous or unlimited revolute joints."""
        return sample_range(self.urdf_type, self.lower, self.upper)

    def home(self) -> float:
        """0, or mid-range when 0 is outside the limits (MoveIt's convention: :mod:`ar3cli.urdf.home`)."""
        return home_value(*self.sample_range())


@dataclass(frozen=True)
class Dynamics:
    """Mass properties of one link as PyBullet uses them (``getDynamicsInfo``).

    ``inertia_diagonal`` is in the inertial frame (principal axes), which sits at
    ``inertial_position`` / ``inertial_orientation`` in the link frame.
    """

    mass: float
    inertia_diagonal: tuple[float, float, float]
    inertial_position: tuple[float, float, float]
    inertial_orientation: tuple[float, float, float, float]


class Body:
    """A robot loaded in a :class:`Session`: its joints, links and frames."""

    def __init__(self, session: Session, body_id: int, model: Model) -> None:
        self.session = session
        self.id = body_id
        self.model = model
        p = session.p
        self.joints: list[JointRecord] = [self._record(p.getJointInfo(body_id, i, physicsClientId=session.client))
                                          for i in range(p.getNumJoints(body_id, physicsClientId=session.client))]
        self.base_name: str = p.getBodyInfo(body_id, physicsClientId=session.client)[0].decode("utf-8")
        self.link_index: dict[str, int] = {self.base_name: -1}
        self.link_index.update({joint.link_name: joint.index for joint in self.joints})
        self._name_of: dict[int, str] = {index: name for name, index in self.link_index.items()}
        self._order: dict[str, int] = {name: order for order, name in enumerate(self.link_names)}
        self.removed = False

    def _record(self, info: tuple) -> JointRecord:
        name = info[1].decode("utf-8")
        urdf = self.model.joint(name)
        urdf_type = urdf.type if urdf is not None else _PYBULLET_TYPES.get(info[2], "unknown")
        lower, upper = float(info[8]), float(info[9])
        limited = lower <= upper and urdf_type != "continuous"
        return JointRecord(
            index=int(info[0]), name=name, urdf_type=urdf_type, link_name=info[12].decode("utf-8"),
            lower=lower if limited else None, upper=upper if limited else None,
            effort=float(info[10]), velocity=float(info[11]), urdf=urdf,
        )

    @property
    def actuated_joints(self) -> list[JointRecord]:
        """The 1-DOF joints (revolute, continuous, prismatic): what a configuration sets, in pybullet order."""
        return [joint for joint in self.joints if joint.movable]

    @property
    def link_names(self) -> list[str]:
        """Base first, then links in pybullet index order."""
        return [self.base_name, *(joint.link_name for joint in self.joints)]

    def set_positions(self, positions: Mapping[str, float] | Sequence[float]) -> None:
        """Teleport joints (resetJointState); a sequence is in :attr:`actuated_joints` order."""
        p, client = self.session.p, self.session.client
        if isinstance(positions, Mapping):
            by_name = {joint.name: joint for joint in self.joints}
            for name, value in positions.items():
                p.resetJointState(self.id, by_name[name].index, float(value), physicsClientId=client)
            return
        joints = self.actuated_joints
        if len(positions) != len(joints):
            raise ValueError(f"expected {len(joints)} joint positions, got {len(positions)}")
        for joint, value in zip(joints, positions):
            p.resetJointState(self.id, joint.index, float(value), physicsClientId=client)

    def positions(self) -> list[float]:
        """Current positions of :attr:`actuated_joints`."""
        return [position for position, _ in self.joint_states()]

    def joint_states(self) -> list[tuple[float, float]]:
        """(position, velocity) of each of :attr:`actuated_joints`."""
        p, client = self.session.p, self.session.client
        indices = [joint.index for joint in self.actuated_joints]
        if not indices:
            return []
        states = p.getJointStates(self.id, indices, physicsClientId=client)
        return [(float(state[0]), float(state[1])) for state in states]

    def dynamics(self, link_name: str) -> Dynamics:
        """Mass, principal inertia and inertial frame PyBullet uses for ``link_name`` (base included)."""
        info = self.session.p.getDynamicsInfo(self.id, self.link_index[link_name], physicsClientId=self.session.client)
        return Dynamics(float(info[0]), tuple(float(v) for v in info[2]),  # type: ignore[arg-type]
                        tuple(float(v) for v in info[3]), tuple(float(v) for v in info[4]))  # type: ignore[arg-type]

    def remove(self) -> None:
        """Take the body out of the world (safe to call twice)."""
        if not self.removed and self.session.client >= 0:
            self.session.p.removeBody(self.id, physicsClientId=self.session.client)
        self.removed = True

    def release_motors(self) -> None:
        """Turn off the velocity motor pybullet attaches to every joint (target 0, max impulse 1)."""
        p, client = self.session.p, self.session.client
        indices = [joint.index for joint in self.actuated_joints]
        if indices:
            p.setJointMotorControlArray(self.id, indices, p.VELOCITY_CONTROL, forces=[0.0] * len(indices),
                                        physicsClientId=client)

    def base_frame(self) -> Pose:
        """The base *link frame*: pybullet's base pose is its COM, so undo the local inertial offset."""
        p, client = self.session.p, self.session.client
        com_position, com_orientation = p.getBasePositionAndOrientation(self.id, physicsClientId=client)
        dynamics = p.getDynamicsInfo(self.id, -1, physicsClientId=client)
        inverse_position, inverse_orientation = p.invertTransform(dynamics[3], dynamics[4])
        position, orientation = p.multiplyTransforms(com_position, com_orientation,
                                                     inverse_position, inverse_orientation)
        return tuple(position), tuple(orientation)  # type: ignore[return-value]

    def link_frames(self) -> dict[str, Pose]:
        """World pose of every URDF link frame (``getLinkState(...)[4:6]``), base included."""
        p, client = self.session.p, self.session.client
        frames: dict[str, Pose] = {self.base_name: self.base_frame()}
        indices = [joint.index for joint in self.joints]
        if indices:
            states = p.getLinkStates(self.id, indices, computeForwardKinematics=True, physicsClientId=client)
            for joint, state in zip(self.joints, states):
                frames[joint.link_name] = (tuple(state[4]), tuple(state[5]))  # type: ignore[assignment]
        return frames

    def nonfinite_links(self, frames: Mapping[str, Pose] | None = None) -> list[str]:
        """Links whose frame (``frames``, default: the current :meth:`link_frames`) holds a NaN or inf."""
        frames = self.link_frames() if frames is None else frames
        return [name for name, (position, orientation) in frames.items()
                if not all(math.isfinite(value) for value in (*position, *orientation))]

    def contacts(self, distance: float = 0.0, min_depth: float | None = None) -> list[tuple[str, str, float]]:
        """Self-contacts after a fresh collision pass: (link_a, link_b, deepest signed distance in m).

        Negative distances penetrate. Without ``min_depth`` every reported point counts (resting
        faces and points up to the contact threshold apart included); with it, only pairs that
        penetrate deeper than ``min_depth`` (use :data:`PENETRATION_TOLERANCE`). ``link_a``
        comes before ``link_b`` in :attr:`link_names` order.
        """
        p, client = self.session.p, self.session.client
        p.performCollisionDetection(physicsClientId=client)
        names, order = self._name_of, self._order
        seen: dict[tuple[str, str], float] = {}
        points = (p.getClosestPoints(self.id, self.id, distance, physicsClientId=client) if distance > 0
                  else p.getContactPoints(self.id, self.id, physicsClientId=client))
        for point in points:
            a, b = names[point[3]], names[point[4]]
            if a == b:
                continue
            key = (a, b) if order[a] < order[b] else (b, a)
            seen[key] = min(seen.get(key, math.inf), float(point[8]))
        limit = math.inf if min_depth is None else -min_depth
        return [(a, b, depth) for (a, b), depth in sorted(seen.items()) if depth < limit]


_PYBULLET_TYPES = {0: "revolute", 1: "prismatic", 2: "spherical", 3: "planar", 4: "fixed"}


class Session:
    """One pybullet physics client (DIRECT by default); use as a context manager.

    >>> with Session() as session:                                      # doctest: +SKIP
    ...     body = session.load(load_model("assets/ar3/ar3.urdf"))
    ...     frames = body.link_frames()
    """

    def __init__(self, gui: bool = False, gravity: float = 0.0, timestep: float = 1.0 / 240.0,
                 file_caching: bool = True) -> None:
        self.p = import_pybullet()
        self.messages: list[str] = []
        mode = self.p.GUI if gui else self.p.DIRECT
        with capture_fds() as captured:
            self.client = self.p.connect(mode)
        self.messages.extend(captured.messages)
        if self.client < 0:
            raise UserError("pybullet could not connect (GUI needs a display; drop --gui)")
        self._tmp = tempfile.TemporaryDirectory(prefix="ar3cli-")
        self.p.setPhysicsEngineParameter(enableFileCaching=int(file_caching), physicsClientId=self.client)
        self.p.setGravity(0, 0, gravity, physicsClientId=self.client)
        self.p.setTimeStep(timestep, physicsClientId=self.client)

    def __enter__(self) -> Session:
        return self

    def __exit__(self, *exc_info: Any) -> None:
        self.close()

    def close(self) -> None:
        """Disconnect and remove temporary files; safe to call twice."""
        if getattr(self, "client", -1) >= 0:
            with capture_fds(), contextlib.suppress(Exception):  # already gone (a GUI window the user closed)
                self.p.disconnect(physicsClientId=self.client)
            self.client = -1
        if hasattr(self, "_tmp"):
            self._tmp.cleanup()

    def load(
        self,
        model: Model,
        fixed_base: bool = True,
        flags: int | None = None,
        base_position: Iterable[float] = (0.0, 0.0, 0.0),
        base_orientation: Iterable[float] = (0.0, 0.0, 0.0, 1.0),
        self_collision: str | None = None,
        maximal_coordinates: bool = False,
        allow_nan_frames: bool = False,
        visuals: bool = True,
        leave_out_unloadable: bool = False,
    ) -> Body:
        """Load ``model`` with explicit flags; raises UserError quoting pybullet's reason on failure.

        Default flags: ``URDF_USE_INERTIA_FROM_FILE`` (pybullet's default recomputes every tensor
        from the collision AABB) and ``URDF_MAINTAIN_LINK_ORDER``. ``self_collision="all-pairs"``
        adds ``URDF_USE_SELF_COLLISION | URDF_USE_SELF_COLLISION_INCLUDE_PARENT``, ``"default"``
        adds ``URDF_USE_SELF_COLLISION`` alone (no pair of a link and its direct parent).
        ``maximal_coordinates=True`` loads a free object as a plain rigid body instead of a
        multibody (``useMaximalCoordinates``): its contacts are cheaper to solve.
        A body whose link frames are NaN at the zero configuration (a zero joint axis, say) is
        refused with a UserError, so that no command computes with NaN; ``allow_nan_frames=True``
        is for the lint rules that report exactly that. ``visuals=False`` loads without the
        ``<visual>`` elements, several times faster, for work that never draws (frames, contacts,
        dynamics). ``leave_out_unloadable=True`` loads without the shapes whose mesh pybullet cannot load
        (a file not found: :func:`~ar3cli.sim.loadable_copy.unloadable_shapes` lists them, for the caller's
        warning) instead of failing: link frames and masses do not depend on meshes.
        """
        p = self.p
        refuse_what_crashes_pybullet(model)
        if model.looks_like_xacro:
            raise UserError(f"{model.path}: is a xacro source (it holds <xacro:...> elements) with a .urdf name: "
                            "rename it to .xacro, or expand it first (xacro FILE > robot.urdf)")
        if flags is None:
            flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_MAINTAIN_LINK_ORDER
        if self_collision == SELF_COLLISION_ALL_PAIRS:
            flags |= p.URDF_USE_SELF_COLLISION | p.URDF_USE_SELF_COLLISION_INCLUDE_PARENT
        elif self_collision == SELF_COLLISION_DEFAULT:
            flags |= p.URDF_USE_SELF_COLLISION
        lines: LineMap = {}
        urdf_path = self._write_loadable_copy(model, visuals, lines, leave_out_unloadable)
        report_stage("loading it")
        with capture_fds() as captured:
            try:
                body_id = p.loadURDF(str(urdf_path), list(base_position), list(base_orientation),
                                     useFixedBase=fixed_base, flags=flags,
                                     useMaximalCoordinates=maximal_coordinates, physicsClientId=self.client)
            except p.error:
                body_id = -1
        messages = [user_lines(message, urdf_path, lines, str(model.path)) for message in captured.messages]
        self.messages.extend(messages)
        if body_id < 0:
            raise UserError(f"{model.path}: pybullet cannot load it: {load_failure_reason(model, messages)}")
        report_stage("simulating it")
        body = Body(self, body_id, model)
        too_many = (f"{len(body.joints)} joints; pybullet cannot report the states of a body with "
                    f"{MAX_PYBULLET_JOINTS} or more (getJointState fails)" if len(body.joints) >= MAX_PYBULLET_JOINTS
                    else f"{len(body.actuated_joints)} movable joints; pybullet silently ignores resetJointState "
                         f"beyond {MAX_PYBULLET_DOF}" if len(body.actuated_joints) > MAX_PYBULLET_DOF else "")
        if too_many:
            body.remove()
            raise UserError(f"{model.path}: {too_many}, so no simulation of it can be trusted")
        broken = [] if allow_nan_frames else body.nonfinite_links()
        if broken:
            body.remove()
            raise UserError(f"{model.path}: pybullet computes non-finite (NaN) frames for {_listing(broken)} at the "
                            "zero configuration (a zero joint axis or a non-finite number in the file?), so no "
                            "simulation of it can be trusted; see ar3cli lint-urdf")
        return body

    def _write_loadable_copy(self, model: Model, visuals: bool = True, lines: LineMap | None = None,
                             leave_out_unloadable: bool = False) -> Path:
        """Write the copy pybullet loads (:mod:`ar3cli.sim.loadable_copy`) under a fresh name, filling ``lines``."""
        from ar3cli.sim.loadable_copy import write_loadable_copy

        # only safe characters: pybullet takes a UTF-8 path, and a file name need not be UTF-8 (byte 0xff)
        stem = re.sub(r"[^A-Za-z0-9_.-]", "_", model.path.stem.replace(".urdf", ""))
        name = f"{next(_load_counter)}_{stem}.urdf"
        return write_loadable_copy(model, Path(self._tmp.name) / name, visuals, lines, leave_out_unloadable)

    def step(self, count: int = 1) -> None:
        for _ in range(count):
            self.p.stepSimulation(physicsClientId=self.client)


MAX_PYBULLET_JOINTS = 128
"""pybullet 3.2.7 loads a body with 128+ joints but getJointState/getLinkState then fail (measured)."""
MAX_PYBULLET_DOF = 121
"""pybullet 3.2.7's state vector holds 128 values, 7 of them the base: resetJointState on joint index
121 or later does nothing and getJointState reads 0 (measured on a 125-joint chain)."""
MAX_PYBULLET_NAME = 1000
"""Longest robot/link/joint name handed to pybullet: it segfaults on a robot name of 1040
characters and on link names of a few thousand (measured, pybullet 3.2.7)."""


def refuse_what_crashes_pybullet(model: Model) -> None:
    """Raise UserError for inputs that crash pybullet's C code (a segfault cannot be caught)."""
    names = [("robot", model.name or ""), *(("link", link.name) for link in model.links),
             *(("joint", joint.name) for joint in model.joints)]
    for kind, name in names:
        if len(name) > MAX_PYBULLET_NAME:
            raise UserError(f"{model.path}: {kind} name {name[:20]}... is {len(name)} characters long; pybullet "
                            f"crashes on names this long: keep names under {MAX_PYBULLET_NAME} characters")


def run_pybullet(work: Callable[[], Result], model: Model, timeout: float | None = None,
                 meanwhile: Callable[[], None] | None = None) -> Result:
    """``work()`` (pybullet work on ``model``) in a forked child: a crash in pybullet's C code becomes
    a one-line :class:`~ar3cli.infra.isolation.CrashError` (exit 2) naming the file, what pybullet was
    doing, and the element known to cause it, instead of killing ar3cli. The child has the limits of
    :mod:`ar3cli.infra.child_limits`; after ``timeout`` seconds (None: the command's ``--timeout``) it
    is stopped and that is a CrashError too (``... timed out after 120 s while loading it; ...``).
    ``meanwhile()`` runs in this process while the child works (:func:`~ar3cli.infra.isolation.run_isolated`)."""
    from ar3cli.infra.isolation import run_isolated

    return run_isolated(work, str(model.path), cause=lambda: known_crash_cause(model), timeout=timeout,
                        meanwhile=meanwhile)


def _listing(names: Sequence[str], most: int = 5) -> str:
    """``link 'a'`` / ``links 'a', 'b' and 3 more``."""
    shown = listed((f"'{name}'" for name in names), most)
    return f"link{'s' if len(names) > 1 else ''} {shown}"


def known_crash_cause(model: Model) -> str | None:
    """What in ``model`` is known to crash pybullet 3.2.7 (measured), as a phrase naming the element."""
    parents: dict[str, list[Joint]] = {}
    for joint in model.joints:
        if joint.child:
            parents.setdefault(joint.child, []).append(joint)
    for link, joints in parents.items():
        if len(joints) > 1:
            names = listed(f"'{joint.name}' (line {joint.line})" for joint in joints)
            return (f"link '{link}' is the child of {len(joints)} joints ({names}), which crashes pybullet: "
                    "keep one of them")
    return None


def load_failure_reason(model: Model, messages: list[str]) -> str:
    """The most useful sentence about why pybullet refused a file."""
    for _, shape in model.meshes():
        resolution = shape.geometry.resolution
        if resolution is not None and not resolution.found:
            return f"mesh {resolution.explain()}"
    if any("failed to parse link" in message for message in messages):
        from ar3cli.sim.load_culprit import link_culprit

        culprit = link_culprit(model)
        if culprit is not None:
            return culprit
    interesting = [m for m in messages if not m.startswith("No inertial data")]
    for keyword in ("cannot find", "invalid mesh", "does not specify limits", "Cannot", "cannot", "failed"):
        for message in interesting:
            if keyword in message:
                return message
    return interesting[0] if interesting else "pybullet gave no reason (Cannot load URDF file)"
