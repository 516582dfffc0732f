"""Target-engine rules (T): what each engine silently changes in a robot it loads.

These rules run only for the engines ``lint-urdf --target`` names (default: pybullet and ros) or when
``--select`` names their code. Each one says which engine, which version and where that was seen.
"""

from __future__ import annotations

import re
from collections import deque
from collections.abc import Iterator
from pathlib import PurePosixPath

from ar3cli.lint.rules.base import ENGINES, LINK_INERTIAL, Hit, arm, robot, rule

TARGETS = ENGINES
"""Engines ``--target`` accepts: the ones a rule can be about."""
DEFAULT_TARGETS = ("pybullet", "ros")

_MIMIC = arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/>').replace(
    "</robot>", f"""  <link name="finger">{LINK_INERTIAL}</link>
  <joint name="j2" type="revolute"><parent link="arm"/><child link="finger"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/><mimic joint="j1"/></joint>
</robot>""")


def _mimics(ctx):
    for joint in ctx.model.joints:
        if joint.mimic is not None:
            yield joint


@rule("T001", "pybullet-mimic-ignored", "info", "<mimic> joint: PyBullet's loadURDF ignores it",
      why="""PyBullet 3.2.7's loadURDF reads no <mimic>: the follower joint is an independent free
      joint (measured: it stays where gravity and contacts put it while the leader moves). Code that
      drives the robot in PyBullet must couple the joints itself (createConstraint with
      JOINT_GEAR, or a position target per step). ar3cli's own samplers follow mimic joints.""",
      fix="In PyBullet, add p.createConstraint(..., jointType=p.JOINT_GEAR, ...) with gearRatio=-multiplier, or "
          "command the follower from the leader each step.",
      bad=_MIMIC, good=arm(), targets=("pybullet",),
      references="pybullet 3.2.7 (measured; UrdfParser.cpp has no mimic); docs/pybullet-facts.md.")
def pybullet_mimic_ignored(ctx) -> Iterator[Hit]:
    for joint in _mimics(ctx):
        yield Hit(f"joint '{joint.name}' mimics '{joint.mimic.joint}': PyBullet's loadURDF leaves it a free joint",
                  joint.mimic.element)


@rule("T002", "mujoco-mimic", "info", "<mimic> joint: MuJoCo before 4.0 drops it",
      why="""MuJoCo 4.0's URDF import turns <mimic> into a joint equality constraint (measured: neq=1, the
      follower tracks the leader); earlier releases dropped it without a word (mujoco #3527), leaving
      the follower free.""",
      fix="Use MuJoCo 4.0 or later, or add an <equality><joint joint1=... joint2=... polycoef=...> to the MJCF.",
      bad=_MIMIC, good=arm(), targets=("mujoco",),
      references="google-deepmind/mujoco #3527; MuJoCo 4.0.0 (measured).")
def mujoco_mimic(ctx) -> Iterator[Hit]:
    for joint in _mimics(ctx):
        yield Hit(f"joint '{joint.name}' mimics '{joint.mimic.joint}': MuJoCo before 4.0 drops the coupling",
                  joint.mimic.element)


def _mesh_robot(first: str, second: str) -> str:
    return robot(f"""
        <link name="base">{LINK_INERTIAL}<visual><geometry><mesh filename="{first}"/></geometry></visual></link>
        <link name="arm">{LINK_INERTIAL}<visual><geometry><mesh filename="{second}"/></geometry></visual></link>
        <joint name="j" type="fixed"><parent link="base"/><child link="arm"/></joint>""")


def _mesh_file(geometry) -> str | None:
    if geometry.kind != "mesh" or not geometry.filename:
        return None
    return geometry.filename.strip()


@rule("T003", "mujoco-same-mesh-name", "warning", "Two meshes with the same file name in different folders",
      why="""MuJoCo's URDF import names each mesh asset after its file name without folder or
      extension, so meshes/arm/link1.stl and meshes/hand/link1.stl become one asset: the second
      part is drawn and collides with the first one's shape (mujoco #1432).""",
      fix="Give the mesh files unique names (or convert with a tool that renames the assets).",
      bad=_mesh_robot("meshes/base.stl", "other/base.stl"), good=_mesh_robot("meshes/base.stl", "meshes/base.stl"),
      targets=("mujoco",), references="google-deepmind/mujoco #1432; MuJoCo src/xml/xml_urdf.cc (mesh asset names).")
def mujoco_same_mesh_name(ctx) -> Iterator[Hit]:
    seen: dict[str, str] = {}
    reported: set[str] = set()
    for _link, shape in ctx.model.meshes():
        filename = _mesh_file(shape.geometry)
        if filename is None:
            continue
        stem = PurePosixPath(filename.replace("\\", "/")).stem
        first = seen.setdefault(stem, filename)
        if first != filename and filename not in reported:
            reported.add(filename)
            yield Hit(f"mesh {filename} and {first} have the same name '{stem}': MuJoCo keeps one of them",
                      shape.geometry.element)


@rule("T004", "mujoco-collada", "warning", "COLLADA mesh: MuJoCo cannot read it",
      why="""MuJoCo reads STL, OBJ and MSH meshes (and, since 3.x, a few more through plugins), but not
      COLLADA: a URDF with .dae meshes fails to compile in MuJoCo.""",
      fix="Convert the .dae files to .obj or .stl (e.g. with trimesh or Blender) and point the URDF at them.",
      bad=_mesh_robot("meshes/base.dae", "meshes/base.stl"), good=_mesh_robot("meshes/base.stl", "meshes/base.stl"),
      targets=("mujoco",), references="MuJoCo documentation, XML reference (mesh: file formats).")
def mujoco_collada(ctx) -> Iterator[Hit]:
    for link, shape in ctx.model.meshes():
        filename = _mesh_file(shape.geometry)
        if filename is not None and filename.lower().endswith(".dae"):
            yield Hit(f"link '{link.name}' {shape.role} mesh {filename} is COLLADA: MuJoCo cannot read it",
                      shape.geometry.element)


@rule("T005", "isaac-empty-root", "warning", "Empty root link: Isaac Sim's importer fails on it",
      why="""Isaac Sim's URDF importer crashes or produces a broken articulation when the root link has no
      inertial, visual or collision (IsaacSim #532); a root named world is a fixed-base convention
      Isaac handles with its "fix base" option instead.""",
      fix="Drop the empty root link (and its joint) and use Isaac's fix-base option, or give the root an <inertial>.",
      bad=robot(f"""<link name="root"/><link name="base">{LINK_INERTIAL}</link>
          <joint name="j" type="fixed"><parent link="root"/><child link="base"/></joint>"""),
      good=robot(f'<link name="base">{LINK_INERTIAL}</link>'),
      targets=("isaac",), references="isaac-sim/IsaacSim #532.")
def isaac_empty_root(ctx) -> Iterator[Hit]:
    roots = ctx.model.root_links()
    if len(roots) == 1:
        root = roots[0]
        if root.inertial is None and not root.has_geometry:
            yield Hit(f"root link '{root.name}' has no <inertial>, <visual> or <collision>", root.element)


USD_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""A valid USD prim name (SdfPath::IsValidIdentifier)."""


@rule("T006", "isaac-prim-name", "info", "Link or joint name that is not a valid USD prim name",
      why="""Isaac Sim turns every link and joint into a USD prim, whose name must be a letter or _
      followed by letters, digits and _. The importer rewrites other names (- . spaces, a leading
      digit) to _, so joint names in the articulation differ from the URDF's, and two names that
      differ only there collide.""",
      fix="Rename links and joints to letters, digits and _ (not starting with a digit).",
      bad=robot(f'<link name="base-link">{LINK_INERTIAL}</link>'), good=robot(f'<link name="base_link">{LINK_INERTIAL}</link>'),
      targets=("isaac",), references="OpenUSD SdfPath::IsValidIdentifier; isaaclab-robot-doctor 0.1.0 (USD-valid names).")
def isaac_prim_name(ctx) -> Iterator[Hit]:
    for kind, items in (("link", ctx.model.links), ("joint", ctx.model.joints)):
        for item in items:
            if item.name and not USD_NAME.fullmatch(item.name):
                yield Hit(f"{kind} name '{item.name}' is not a valid USD prim name: Isaac Sim renames it", item.element)


def breadth_first_joints(model) -> list[str]:
    """Joint names in the breadth-first order Isaac Sim's articulation uses (children in file order)."""
    roots = model.root_links()
    if len(roots) != 1:
        return []
    order, queue, seen = [], deque([roots[0].name]), {roots[0].name}
    while queue:
        for joint in model.child_joints(queue.popleft()):
            if joint.child and joint.child not in seen:
                seen.add(joint.child)
                order.append(joint.name)
                queue.append(joint.child)
    return order


def _branches(breadth_first: bool) -> str:
    """Two branches from the base: a1 -> a2 and b1; joints listed breadth-first or depth-first."""
    limit = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
    joints = {name: f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>{limit}</joint>'
              for name, parent, child in (("ja1", "base", "a1"), ("ja2", "a1", "a2"), ("jb1", "base", "b1"))}
    order = ("ja1", "jb1", "ja2") if breadth_first else ("ja1", "ja2", "jb1")
    links = "".join(f'<link name="{name}">{LINK_INERTIAL}</link>' for name in ("base", "a1", "a2", "b1"))
    return robot(links + "\n" + "\n".join(joints[name] for name in order))


@rule("T007", "isaac-joint-order", "info", "Isaac Sim orders these joints differently from the file",
      why="""Isaac Sim (and Isaac Lab) index an articulation's joints breadth-first from the root, while
      PyBullet, ROS and MuJoCo keep the file's (depth-first) order. On a branched robot (legs, two arms,
      a hand) a policy or controller that addresses joints by index drives the wrong joints unless it
      maps them by name.""",
      fix="Address joints by name in Isaac (articulation.find_joints), or list joints breadth-first in the file.",
      bad=_branches(breadth_first=False),
      good=_branches(breadth_first=True),
      targets=("isaac",), references="Isaac Lab documentation (articulation joint ordering: breadth-first); "
                                     "isaaclab-robot-doctor 0.1.0.")
def isaac_joint_order(ctx) -> Iterator[Hit]:
    moving = {joint.name for joint in ctx.model.joints if joint.moves}
    isaac = [name for name in breadth_first_joints(ctx.model) if name in moving]
    file_order = [joint.name for joint in ctx.model.joints if joint.name in moving]
    if sorted(isaac) != sorted(file_order) or isaac == file_order:
        return
    index = next(i for i, (a, b) in enumerate(zip(isaac, file_order)) if a != b)
    joint = ctx.model.joint(file_order[index])
    yield Hit(f"moving joint {index} is '{file_order[index]}' in the file but '{isaac[index]}' in Isaac Sim's "
              f"breadth-first order ({len(moving)} moving joints)", joint.element if joint else None)


DRAKE_IGNORED_ELEMENTS = ("calibration", "safety_controller", "mimic")


@rule("T008", "drake-ignores", "info", "Element or value Drake ignores",
      why="""Drake's URDF parser warns and ignores <calibration>, <safety_controller> and (in releases
      before mimic support) <mimic> on joints, a non-zero <dynamics friction> (MultibodyPlant has no
      joint friction), the floating joint type (the child is left a free body), and transmissions
      whose type is not SimpleTransmission. The robot then behaves differently in Drake than in the
      tools the file was written for.""",
      fix="Model friction and safety limits in the Drake controller; use a SimpleTransmission for actuators Drake should see.",
      bad=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><dynamics damping="0.1" friction="0.5"/>'),
      good=arm(joint_extra='<limit lower="-1" upper="1" effort="10" velocity="1"/><dynamics damping="0.1"/>'),
      targets=("drake",),
      references="Drake multibody/parsing/detail_urdf_parser.cc (ParseJoint: WarnUnsupportedElement calibration, mimic, "
                 "safety_controller; ParseJointDynamics: friction; floating; ParseTransmission).")
def drake_ignores(ctx) -> Iterator[Hit]:
    from ar3cli.urdf.model import parse_float

    for joint in ctx.model.joints:
        for tag in DRAKE_IGNORED_ELEMENTS:
            element = joint.first_child(tag)
            if element is not None:
                yield Hit(f"joint '{joint.name}' <{tag}>: Drake ignores it", element)
        dynamics = joint.first_child("dynamics")
        friction = parse_float(dynamics.get("friction")) if dynamics is not None else None
        if friction:
            yield Hit(f"joint '{joint.name}' <dynamics friction=\"{dynamics.get('friction')}\">: Drake has no joint "
                      "friction and ignores it", dynamics)
        if joint.type == "floating":
            yield Hit(f"joint '{joint.name}' is floating: Drake leaves '{joint.child}' a free body", joint.element)
    for transmission in ctx.model.root.iter("transmission"):
        kind = transmission.findtext("type") or transmission.get("type") or ""
        if "SimpleTransmission" not in kind:
            yield Hit(f"transmission '{transmission.get('name', '?')}' type '{kind.strip()}': Drake reads only "
                      "SimpleTransmission and ignores it", transmission)


def _quat_arm(quat: str) -> str:
    return arm(joint_extra=f'<origin xyz="0 0 0.1" quat_xyzw="{quat}"/><limit lower="-1" upper="1" effort="10" '
                           'velocity="1"/>').replace('<robot name="r">', '<robot name="r" version="1.1">')


@rule("T009", "pybullet-quat-ignored", "warning", "<origin quat_xyzw>: PyBullet ignores it",
      why="""URDF 1.1 lets an <origin> give its orientation as quat_xyzw. PyBullet 3.2.7 does not read
      it: the joint, visual, collision and inertial frames load unrotated (measured: every link frame
      of tests/data/urdf12/arm_quat.urdf comes back as the identity, where its rpy twin is rotated).
      The robot is assembled wrongly in PyBullet without a word. ar3cli's own PyBullet runs convert the
      quaternion to rpy first; your code calling loadURDF does not. An rpy given as well wins in every
      reader, and the identity quaternion changes nothing: neither is reported.""",
      fix="Write the orientation as rpy (ar3cli reads the quaternion: `ar3cli info` shows the frames), or keep "
          "quat_xyzw for ROS and convert before loading in PyBullet.",
      bad=_quat_arm("0 0 0.7071068 0.7071068"), good=_quat_arm("0 0 0 1"),
      targets=("pybullet",),
      references="pybullet 3.2.7 (measured; UrdfParser.cpp parses xyz and rpy only); docs/pybullet-facts.md; "
                 "ar3cli/sim/loadable_copy.py.")
def pybullet_quat_ignored(ctx) -> Iterator[Hit]:
    from ar3cli.lint.rules.units import origins
    from ar3cli.urdf.model import read_quaternion

    for element, where in origins(ctx.model):
        quat = element.get("quat_xyzw")
        if quat is None or element.get("rpy") is not None:
            continue
        read = read_quaternion(quat)
        if read is None or abs(abs(read[0][3]) - 1.0) < 1e-12:
            continue  # unusable (F007's) or the identity: nothing is lost
        rpy = " ".join(f"{v:.6g}" for v in read[1])
        yield Hit(f"{where} <origin quat_xyzw=\"{quat}\">: PyBullet ignores it and loads the frame unrotated "
                  f"(rpy=\"{rpy}\" says the same for every reader)", element, hint=f'Write rpy="{rpy}" instead.')
