"""The MuJoCo side of simulation: import, compile a Model, read frames, masses, dynamics, contacts.

MuJoCo is an optional extra (``pip install 'ar3cli[mujoco]'``): :func:`import_mujoco` turns its
absence into one line (exit 2). Everything else follows measured behaviour of mujoco 4.0.0:

- the copy compiled is :mod:`ar3cli.sim.mujoco_copy`'s (meshes linked, unreadable ones boxed);
- a refused model raises ``ValueError("Error: <what>\\nElement name 'arm', id 2")``: the name is
  the user's link or joint, so :func:`named_element` finds its line in the user's file;
- compiler warnings go through ``mujoco.set_mju_user_warning`` (kept in :attr:`MjRobot.warnings`,
  never written to MUJOCO_LOG.TXT in the current folder);
- a URDF root link is welded to the world (as PyBullet's ``useFixedBase``); ``<mimic>`` becomes
  an equality constraint (``mjEQ_JOINT``: the follower tracks the leader);
- 1-DOF joints keep their URDF names; their ``qpos``/``dof`` addresses come from ``jnt_qposadr`` /
  ``jnt_dofadr``.

MuJoCo runs in a forked child like PyBullet (:func:`run_mujoco`): a crash in its C code is a message.
"""

from __future__ import annotations

import math
import re
import tempfile
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any, TypeVar

from ar3cli.errors import UserError
from ar3cli.infra.isolation import CrashError, report_stage
from ar3cli.urdf.model import Model

Result = TypeVar("Result")
INSTALL_HINT = "pip install 'ar3cli[mujoco]'"
_ELEMENT = re.compile(r"Element name '([^']*)'")
_LINE = re.compile(r"Element '[^']*', line (\d+)")


def import_mujoco() -> Any:
    """Import mujoco; raises a one-line UserError naming the extra to install when it is missing."""
    try:
        import mujoco
    except ImportError as exc:
        raise UserError(f"MuJoCo is not installed ({exc}); run: {INSTALL_HINT}") from None
    return mujoco


def mujoco_available() -> bool:
    """True when ``import mujoco`` works (checked without importing it for good)."""
    import importlib.util

    return importlib.util.find_spec("mujoco") is not None


class MujocoCompileError(UserError):
    """MuJoCo refused the model: ``reason`` is its first line, ``element`` the user's element it names (or None)."""

    def __init__(self, message: str, reason: str, element: Any) -> None:
        super().__init__(message)
        self.reason = reason
        self.element = element


def named_element(model: Model, message: str, mesh_elements: Mapping[str, Any] | None = None) -> Any:
    """The user's element MuJoCo's ``message`` is about: the link or joint it names, or the mesh whose file it quotes."""
    found = _ELEMENT.search(message)
    if found:
        item = model.link(found.group(1)) or model.joint(found.group(1))
        if item is not None:
            return item.element
    for path, element in (mesh_elements or {}).items():
        if path in message:
            return element
    return None


def home_pose(model: Model) -> dict[str, float]:
    """The home pose from the URDF alone (no PyBullet body): each 1-DOF joint at 0, or mid-range where 0 is
    outside its limits (MoveIt's convention, as :func:`ar3cli.sim.sampling.home_positions`); mimic joints follow."""
    import numpy as np

    from ar3cli.urdf.mimic import driven_values

    home = {}
    for joint in model.movable_joints():
        limit = joint.limit
        lower, upper = (limit.lower, limit.upper) if limit is not None else (None, None)
        inside = lower is None or upper is None or not lower <= upper or lower <= 0.0 <= upper
        home[joint.name] = 0.0 if inside else (lower + upper) / 2.0
    given = {name: np.array([value]) for name, value in home.items() if model.joint(name).mimic is None}
    home.update({name: float(values[0]) for name, values in driven_values(model, given, 1).items()})
    return home


def _element_at(model: Model, line: int) -> Any:
    """The first element of the user's (URDF) model starting on ``line``, for the lint finding; None for a xacro."""
    if model.is_xacro:
        return None
    return next((node for node in model.root.iter() if isinstance(node.tag, str) and node.sourceline == line), None)


class MjRobot:
    """A Model compiled by MuJoCo: its MjModel/MjData, the meshes replaced, the compiler's warnings."""

    def __init__(self, model: Model, fuse: bool = True, gravity: float = -9.81) -> None:
        from ar3cli.sim.mujoco_copy import mujoco_copy

        mujoco = self.mujoco = import_mujoco()
        self.model = model
        self.warnings: list[str] = []
        folder = Path(tempfile.mkdtemp(prefix="ar3cli-mujoco-"))
        built = mujoco_copy(model, folder, fuse)
        self.substitutions = built.substitutions
        path = folder / "robot.urdf"
        path.write_bytes(built.document)
        report_stage("compiling it in MuJoCo")
        previous = mujoco.get_mju_user_warning()
        mujoco.set_mju_user_warning(lambda text: self.warnings.append(str(text).strip()))
        try:
            self.m = mujoco.MjModel.from_xml_path(str(path))
        except ValueError as exc:
            text = str(exc).replace(str(folder) + "/", "").strip()
            for linked, mesh in built.mesh_elements.items():  # MuJoCo names a mesh by its linked file's stem
                text = re.sub(rf"(?<![\w.]){re.escape(Path(linked).stem)}(?![\w])", f"'{mesh.get('filename')}'", text)
            reason = text.removeprefix("Error: ").splitlines()[0] if text else "MuJoCo gave no reason"
            element = named_element(model, str(exc), built.mesh_elements)
            if element is None:
                element = next((mesh for linked, mesh in built.mesh_elements.items()
                                if re.search(rf"(?<![\w.]){re.escape(Path(linked).stem)}(?![\w])", str(exc))), None)
            named = f" ({element.tag} '{element.get('name')}')" if element is not None and element.get("name") else ""
            where = f"{model.path}:{element.sourceline}" if element is not None and element.sourceline else str(model.path)
            line = _LINE.search(str(exc))
            place = built.lines.get(int(line.group(1))) if line and element is None else None
            if place is not None:  # an XML error: MuJoCo quotes the copy's line; say the user's
                where = f"{place.file}:{place.line}"
                element = _element_at(model, place.line)
            raise MujocoCompileError(f"{where}: MuJoCo cannot compile it: {reason}{named}", reason + named,
                                     element) from None
        finally:
            mujoco.set_mju_user_warning(previous)
        self.m.opt.gravity[:] = (0.0, 0.0, gravity)
        self.d = mujoco.MjData(self.m)
        self.joint_ids = {self.m.jnt(i).name: i for i in range(self.m.njnt)
                          if int(self.m.jnt_type[i]) in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))}
        self.body_names = [self.m.body(i).name for i in range(self.m.nbody)]
        mujoco.mj_forward(self.m, self.d)

    # ---- configurations ---------------------------------------------------------------------
    def set_positions(self, positions: Mapping[str, float]) -> None:
        """Set the named 1-DOF joints (others keep their value), velocities zero, and recompute everything."""
        for name, value in positions.items():
            if name in self.joint_ids:
                self.d.qpos[self.m.jnt_qposadr[self.joint_ids[name]]] = float(value)
        self.d.qvel[:] = 0.0
        self.mujoco.mj_forward(self.m, self.d)

    def positions(self, names: Iterable[str]) -> list[float]:
        return [float(self.d.qpos[self.m.jnt_qposadr[self.joint_ids[name]]]) if name in self.joint_ids else math.nan
                for name in names]

    def dof_indices(self, names: Sequence[str]) -> list[int]:
        return [int(self.m.jnt_dofadr[self.joint_ids[name]]) for name in names]

    # ---- what cross-check compares -------------------------------------------------------------
    def link_frames(self) -> dict[str, tuple[tuple[float, ...], tuple[float, ...]]]:
        """World pose (xyz, quaternion xyzw) of every body but the world, by link name."""
        frames = {}
        for index, name in enumerate(self.body_names):
            if index == 0:
                continue
            w, x, y, z = (float(v) for v in self.d.xquat[index])
            frames[name] = (tuple(float(v) for v in self.d.xpos[index]), (x, y, z, w))
        return frames

    def total_mass(self) -> float:
        return float(self.m.body_subtreemass[0])

    def centre_of_mass(self, bodies: Sequence[int] | None = None) -> tuple[float, float, float]:
        """Centre of mass of ``bodies`` (indices; default: the whole robot, ``subtree_com`` of the world)."""
        if bodies is None:
            return tuple(float(v) for v in self.d.subtree_com[0])  # type: ignore[return-value]
        total = sum(float(self.m.body_mass[i]) for i in bodies) or 1.0
        return tuple(sum(float(self.m.body_mass[i]) * float(self.d.xipos[i][k]) for i in bodies) / total
                     for k in range(3))  # type: ignore[return-value]

    def mass_matrix(self, names: Sequence[str]) -> list[list[float]]:
        """The joint-space mass matrix (``mj_fullM``) restricted to and ordered as ``names``."""
        import numpy as np

        full = np.zeros((self.m.nv, self.m.nv))
        try:  # mujoco 4 reads the data; 3.x took the sparse matrix
            self.mujoco.mj_fullM(self.m, self.d, full)
        except TypeError:
            self.mujoco.mj_fullM(self.m, full, self.d.qM)
        index = self.dof_indices(names)
        return full[np.ix_(index, index)].tolist()

    def gravity_torques(self, names: Sequence[str]) -> list[float]:
        """``qfrc_bias`` at zero velocity (the torques that hold the pose against gravity), as ``names``."""
        return [float(self.d.qfrc_bias[i]) for i in self.dof_indices(names)]

    def contacts(self, min_depth: float) -> list[tuple[str, str, float]]:
        """Pairs of links penetrating deeper than ``min_depth`` now: (link_a, link_b, deepest distance, negative)."""
        seen: dict[tuple[str, str], float] = {}
        for index in range(self.d.ncon):
            contact = self.d.contact[index]
            a = self.body_names[self.m.geom_bodyid[contact.geom1]]
            b = self.body_names[self.m.geom_bodyid[contact.geom2]]
            if a == b or contact.dist >= -min_depth:
                continue
            key = (a, b) if a < b else (b, a)
            seen[key] = min(seen.get(key, math.inf), float(contact.dist))
        return [(a, b, depth) for (a, b), depth in sorted(seen.items())]

    def step(self, count: int = 1) -> None:
        for _ in range(count):
            self.mujoco.mj_step(self.m, self.d)

    def energy(self) -> float:
        """Potential plus kinetic energy (J), MuJoCo's own (``mjENBL_ENERGY``)."""
        self.mujoco.mj_energyPos(self.m, self.d)
        self.mujoco.mj_energyVel(self.m, self.d)
        return float(self.d.energy[0] + self.d.energy[1])

    def joint_states(self, names: Sequence[str]) -> list[tuple[float, float]]:
        return [(float(self.d.qpos[self.m.jnt_qposadr[self.joint_ids[n]]]),
                 float(self.d.qvel[self.m.jnt_dofadr[self.joint_ids[n]]])) for n in names if n in self.joint_ids]


def run_mujoco(work: Callable[[], Result], model: Model) -> Result:
    """``work()`` (MuJoCo work on ``model``) in a forked child (:func:`~ar3cli.infra.isolation.run_isolated`):
    a crash in MuJoCo's C code becomes a one-line CrashError (exit 2) naming the file."""
    from ar3cli.infra.isolation import run_isolated

    import_mujoco()  # a missing extra is one line here, not a child's failure
    try:
        return run_isolated(work, str(model.path))
    except CrashError as exc:
        message = re.sub(r"pybullet crashed \(([^)]*)\) while (.*?)(;|:) .*$",
                         r"MuJoCo crashed (\1) while \2: a bug in MuJoCo's C code that this file triggers",
                         exc.message)
        raise CrashError(message, exc.signal_name, exc.stage) from None
