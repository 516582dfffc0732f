"""MuJoCo rules (M, with ``--sim --engine mujoco|all``): compile the model in MuJoCo and see what it does.

The model is compiled once per file (:class:`~ar3cli.sim.mujoco_session.MjRobot`, kept on the lint
context) from the copy :mod:`ar3cli.sim.mujoco_copy` writes: ``package://`` resolved as for PyBullet,
meshes MuJoCo cannot read replaced by their boxes (M002) so the rest is still checked. MuJoCo's
messages name a link or joint ("Element name 'arm'"): the finding points at its line in the user's file.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from typing import Any

from ar3cli.errors import UserError
from ar3cli.lint.rules.base import (
    LINK_INERTIAL,
    Hit,
    arm,
    elements_reported,
    error_explained,
    refusal_explained,
    robot,
    rule,
)
from ar3cli.lint.rules.pybullet_sim import built_touching, depth_text, srdf_hint, unstable_hit

SETTLE_SECONDS = 1.0
MAX_SETTLE_SPEED = 100.0
"""rad/s or m/s: as P004, a joint faster than this after one second under gravity has exploded."""
PENETRATION = 1e-6
"""m: as P002 (``sim.session.PENETRATION_TOLERANCE``), contacts shallower than this are resting faces."""
_COMPILED = "_ar3cli_mujoco"
STATIC_MESH_RULES = ("G001", "G004", "G011", "F006")
"""Static rules that already report a collision mesh MuJoCo cannot read (missing, unexpanded, a format or bytes
no engine reads): M002 does not say it again."""


def _compiled(ctx: Any) -> tuple[Any, UserError | None]:
    """The file's MjRobot (compiled once, kept on the context), or (None, the compile error)."""
    if not hasattr(ctx, _COMPILED):
        from ar3cli.sim.mujoco_session import MjRobot

        try:
            setattr(ctx, _COMPILED, (MjRobot(ctx.model, fuse=False), None))
        except UserError as exc:
            setattr(ctx, _COMPILED, (None, exc))
    return getattr(ctx, _COMPILED)



TOO_LIGHT = ('<inertial><mass value="1e-16"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
             '</inertial>')
"""M001's example: a mass below mjMINVAL, which no static rule calls an error (I014 warns that it is light)."""


@rule("M001", "mujoco-compile-failed", "error", "MuJoCo refuses to compile the model",
      engines=("mujoco",), refused_by=("mujoco",), breaks="MuJoCo refuses the file (measured: ar3cli compiles it).",
      why="""Most robot learning now trains in MuJoCo (and MJX, MuJoCo Warp). Its compiler is stricter than
      PyBullet's loader: a moving body whose mass or inertia is below mjMINVAL (a link without <inertial>
      and without collision geometry), an inertia breaking A + B >= C, a zero joint axis. ar3cli quotes
      MuJoCo's reason at the link or joint it names; when a static error that MuJoCo refuses (I005,
      I006, J009, ...) already names the cause at its line, or a static error is about the very link
      MuJoCo names (I001 on a link without <inertial>, S019 on an <inertial> without <inertia>), M001 adds
      nothing.""",
      fix="Fix the reason quoted in the message (often an I or J finding of the same element).",
      bad=arm(link_extra=TOO_LIGHT), good=arm(), needs_sim=True,
      references="MuJoCo 4.0 user_objects.cc: 'mass and inertia of moving bodies must be larger than mjMINVAL'")
def mujoco_compile_failed(ctx) -> Iterator[Hit]:
    from ar3cli.sim.mujoco_session import MujocoCompileError

    robot, error = _compiled(ctx)
    if error is not None and refusal_explained(ctx, "mujoco") is None:  # else a static error says why
        if isinstance(error, MujocoCompileError) and error_explained(ctx, error.element) is not None:
            return  # the link MuJoCo names is a static error's already (I001, S019: the same cause)
        if isinstance(error, MujocoCompileError):
            yield Hit(f"MuJoCo cannot compile it: {error.reason}",
                      error.element if error.element is not None else ctx.model.root)
        else:
            yield Hit(error.message.removeprefix(f"{ctx.model.path}: "), ctx.model.root)


_DAE = robot(f"""
    <link name="base">{LINK_INERTIAL}<collision><geometry><mesh filename="part.dae"/></geometry></collision></link>""")
_STL = robot(f"""
    <link name="base">{LINK_INERTIAL}<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>""")


@rule("M002", "mujoco-mesh-unreadable", "warning", "A collision mesh MuJoCo cannot read",
      engines=("mujoco",),
      why="""MuJoCo reads STL, OBJ and MSH meshes only: a COLLADA (.dae) collision mesh, or one that is not found,
      stops its whole compile with "Error opening file". ar3cli replaces the mesh by its bounding box (or leaves
      it out when its size is unknown) so the other checks still run, and says so here, for the meshes no
      static rule reports already (G001 a missing mesh, F006 an unexpanded path, G004 a format, G011 bytes
      no engine reads): in practice a COLLADA collision mesh, which PyBullet reads.""",
      fix="Export the collision mesh as STL or OBJ (keep the .dae for visuals, which MuJoCo discards).",
      bad=_DAE, good=_STL, needs_sim=True)
def mujoco_mesh_unreadable(ctx) -> Iterator[Hit]:
    robot, error = _compiled(ctx)
    if robot is None:
        return
    known = elements_reported(ctx, STATIC_MESH_RULES)
    for substitution in robot.substitutions:
        if substitution.element in known:
            continue  # a missing, unexpanded, unreadable or unloadable mesh: the static rule says so at it
        yield Hit(f"link '{substitution.link}': {substitution.reason}; {substitution.replacement} for MuJoCo",
                  substitution.element)


M003_FIX = ("Fix the collision geometry or the joint origin; if the overlap is by design, exclude the pair "
            "(<contact><exclude> in MJCF, or an SRDF for MoveIt).")


@rule("M003", "mujoco-self-collision-home", "warning", "Links collide in MuJoCo at the home pose",
      engines=("mujoco",),
      why="""MuJoCo collides every pair of bodies but a parent and its child (no URDF_USE_SELF_COLLISION flag
      to forget): two links interpenetrating at the home pose are pushed apart the moment the simulation
      starts, which puts energy into a robot at rest. Pairs adjacent in MoveIt's sense or joined only by
      fixed joints are not reported, as for P002, nor the pairs an SRDF disables (--srdf, else the
      package's own SRDF for this robot), nor the contacts a robot is built with (a joint cluster, one
      linkage, two branches touching by at most 3 mm, a placeholder collision: P002 explains each). Nor is a pair where a link collides through a box ar3cli
      put in place of a mesh MuJoCo cannot read (M002: a COLLADA collision mesh): boxes around concave
      parts overlap where the parts do not, so such a contact says nothing about the robot.""",
      fix=M003_FIX,
      bad=robot("""
        <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
          <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
        <link name="mid"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
          <collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
        <link name="tip"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
          <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="mid"/><origin xyz="0 0 0.3"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="mid"/><child link="tip"/><origin xyz="0 0 -0.25"/>
          <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"""),
      good=arm(), needs_sim=True,
      thresholds="Deeper than PENETRATION = 1e-6 m; the contacts a robot is built with as for P002.")
def mujoco_self_collision_home(ctx) -> Iterator[Hit]:
    from ar3cli.sim.adjacency import adjacent_pairs, rigid_groups
    from ar3cli.sim.mujoco_session import home_pose

    robot, _ = _compiled(ctx)
    if robot is None:
        return
    robot.set_positions(home_pose(ctx.model))
    adjacent = adjacent_pairs(ctx.model)
    group = rigid_groups(ctx.model, robot.joint_ids)
    stand_ins = {substitution.link for substitution in robot.substitutions}
    disabled, note = ctx.disabled_pairs()
    for a, b, depth in robot.contacts(PENETRATION):
        if frozenset((a, b)) in adjacent or disabled.covers(a, b) or \
                (a in group and group[a] == group.get(b)):
            continue
        if a in stand_ins or b in stand_ins:
            continue  # a box ar3cli put in place of a mesh MuJoCo cannot read (M002): not the robot's shape
        if built_touching(ctx, a, b, -depth) is not None:
            continue
        link = ctx.model.link(b) or ctx.model.link(a)
        yield Hit(f"links '{a}' and '{b}' interpenetrate by {depth_text(-depth)} at the home pose in MuJoCo",
                  link.element if link else None, hint=srdf_hint(M003_FIX, note))


def merge_home_contacts(findings: list) -> list:
    """With ``--engine all``: one finding per pair both engines find interpenetrating at home, P002's,
    saying MuJoCo's depth too, instead of a P002 and an M003 about the same pair and line."""
    def pair(finding) -> tuple[str, int, str]:
        return finding.path, finding.line, finding.message.split(" interpenetrate by ")[0]

    mujoco = {pair(f): f for f in findings if f.rule == mujoco_self_collision_home.code}
    merged, dropped = [], set()
    for finding in findings:
        twin = mujoco.get(pair(finding)) if finding.rule == "P002" else None
        if twin is not None:
            depth = twin.message.split(" interpenetrate by ")[1].split(" at the home pose")[0]
            finding = dataclasses.replace(finding, message=f"{finding.message}; in MuJoCo too ({depth}, M003)")
            dropped.add(id(twin))
        merged.append(finding)
    return [finding for finding in merged if id(finding) not in dropped]


@rule("M004", "mujoco-unstable", "error", "NaN or exploding states in MuJoCo after 1 s under gravity",
      engines=("mujoco",), breaks="MuJoCo's joint states become NaN or explode within one simulated second (measured).",
      why="""ar3cli compiles the model (root welded to the world), puts it at the home pose and simulates one
      second under gravity with MuJoCo's default timestep (2 ms). A real robot falls limp; NaN positions,
      MuJoCo's own instability warning (mjWARN_BADQACC) or joint speeds above 100 rad/s mean an inertia too
      small for the timestep, a degenerate mass, or a negative joint damping (which MuJoCo applies and
      PyBullet ignores).""",
      fix="Look at the I and J findings for this file (inertia, mass, a negative <dynamics damping>); fix-inertia "
          "often cures it.",
      bad=arm(link_extra='<inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" '
                         'iyy="0.01" iyz="0" izz="0.01"/></inertial>',
              joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><dynamics damping="-50"/>'
              ).replace('<axis xyz="0 0 1"/>', '<axis xyz="0 1 0"/>'),
      good=arm(), needs_sim=True,
      thresholds="NaN, mjWARN_BADQACC, or a joint faster than MAX_SETTLE_SPEED = 100 rad/s or m/s after SETTLE_SECONDS = 1 s; "
                 "one finding per file, at the first such joint, naming the others (one instability drags every "
                 "joint below it along).")
def mujoco_unstable(ctx) -> Iterator[Hit]:
    from ar3cli.sim.mujoco_session import home_pose

    robot, _ = _compiled(ctx)
    if robot is None or not robot.joint_ids:
        return
    robot.set_positions(home_pose(ctx.model))
    with _warnings_kept(robot):
        robot.step(round(SETTLE_SECONDS / robot.m.opt.timestep))
    warning = robot.d.warning[int(robot.mujoco.mjtWarning.mjWARN_BADQACC)]
    bad_acceleration = int(warning.number)
    blamed = _blamed_joint(robot, int(warning.lastinfo)) if bad_acceleration else None
    states = []
    for name, (position, velocity) in zip(robot.joint_ids, robot.joint_states(list(robot.joint_ids))):
        joint = ctx.model.joint(name)
        states.append((name, joint.element if joint is not None else None, position, velocity))
    found = unstable_hit(states, f"after {SETTLE_SECONDS:g} s under gravity in MuJoCo", MAX_SETTLE_SPEED, blamed)
    if found is not None:
        yield found
    elif bad_acceleration:
        yield Hit(f"MuJoCo reported {bad_acceleration} unstable step(s) (bad acceleration; the simulation was reset)",
                  ctx.model.root)


@contextlib.contextmanager
def _warnings_kept(robot):
    """MuJoCo's warnings while the robot is simulated go to ``robot.warnings``: its default handler prints
    them and appends them to MUJOCO_LOG.TXT in the current directory, a file nobody asked for."""
    previous = robot.mujoco.get_mju_user_warning()
    robot.mujoco.set_mju_user_warning(lambda text: robot.warnings.append(str(text).strip()))
    try:
        yield
    finally:
        robot.mujoco.set_mju_user_warning(previous)


def _blamed_joint(robot, dof: int) -> str | None:
    """The joint of the degree of freedom MuJoCo's bad-acceleration warning names (its ``lastinfo``)."""
    try:
        return robot.m.joint(int(robot.m.dof_jntid[dof])).name or None
    except (IndexError, KeyError, ValueError):
        return None
