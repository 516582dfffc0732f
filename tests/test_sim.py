"""The PyBullet session: joint table, link frames vs COM, load errors, caching, clean stdout."""

from __future__ import annotations

import json
import math
import re
import textwrap

import pytest

from ar3cli.errors import UserError
from ar3cli.sim.capture import split_bullet_messages
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model

OFFSET_COM = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base">
    <inertial><origin xyz="0.1 0 0"/><mass value="2"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
  <joint name="hinge" type="continuous">
    <parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-100" upper="100" effort="10" velocity="3"/>
  </joint>
  <link name="arm">
    <inertial><origin xyz="0 0 0.25"/><mass value="1"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0 0 0.25"/><geometry><cylinder radius="0.02" length="0.5"/></geometry></collision>
  </link>
</robot>
"""


def test_joint_table_knows_continuous_from_urdf(session, write_urdf):
    body = session.load(load_model(write_urdf(OFFSET_COM)))
    (hinge,) = body.actuated_joints
    assert hinge.urdf_type == "continuous" and hinge.continuous
    assert hinge.lower is None and hinge.upper is None  # the fake +-100 is not a limit
    assert hinge.sample_range() == (-math.pi, math.pi)
    assert hinge.effort == 10 and hinge.velocity == 3


def test_link_frame_is_not_com(session, write_urdf):
    body = session.load(load_model(write_urdf(OFFSET_COM)))
    body.set_positions([math.pi / 2])
    frames = body.link_frames()
    assert frames["arm"][0] == pytest.approx((0, 0, 0.5), abs=1e-9)  # link frame: the hinge origin
    p = session.p
    com = p.getLinkState(body.id, 0, computeForwardKinematics=True)[0]
    assert com == pytest.approx((0.25, 0, 0.5), abs=1e-9)  # COM swung 0.25 m along +x about +y


def test_floating_base_frame_undoes_inertial_offset(session, write_urdf):
    body = session.load(load_model(write_urdf(OFFSET_COM)), fixed_base=False, base_position=(1, 2, 3))
    position, orientation = body.base_frame()
    assert position == pytest.approx((1, 2, 3), abs=1e-9)
    com_position = session.p.getBasePositionAndOrientation(body.id)[0]
    assert com_position == pytest.approx((1.1, 2, 3), abs=1e-9)


def test_panda_frames_and_self_collision(session, pybullet_data_dir):
    body = session.load(load_model(pybullet_data_dir / "franka_panda" / "panda.urdf"), self_collision="all-pairs")
    assert len(body.actuated_joints) == 9
    assert body.actuated_joints[3].sample_range() == pytest.approx((-3.1416, 0.0))
    body.set_positions([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0, 0.02, 0.02])
    frames = body.link_frames()
    assert set(frames) == set(body.link_names)
    assert frames["panda_link1"][0] == pytest.approx((0, 0, 0.333), abs=1e-6)
    pairs = {(a, b) for a, b, _ in body.contacts()}
    assert ("panda_link0", "panda_link1") in pairs  # parent-child pairs are checked with all-pairs


def test_missing_mesh_error_quotes_the_real_reason(session, write_urdf):
    path = write_urdf(OFFSET_COM.replace('<cylinder radius="0.02" length="0.5"/>', '<mesh filename="gone.stl"/>'))
    with pytest.raises(UserError) as info:
        session.load(load_model(path))
    message = str(info.value)
    assert "gone.stl" in message and "Cannot load URDF file" not in message
    assert str(path.parent / "gone.stl") in message  # the places tried


def test_revolute_without_limits_error(session, write_urdf):
    path = write_urdf(OFFSET_COM.replace('type="continuous"', 'type="revolute"').replace(
        '<limit lower="-100" upper="100" effort="10" velocity="3"/>', ""))
    with pytest.raises(UserError, match="does not specify limits"):
        session.load(load_model(path))


def test_rewritten_file_reloads_new_content(session, write_urdf):
    path = write_urdf(OFFSET_COM)
    first = session.load(load_model(path))
    path.write_text(OFFSET_COM.replace('<mass value="1"/>', '<mass value="3"/>'))
    second = session.load(load_model(path))
    assert session.p.getDynamicsInfo(first.id, 0)[0] == 1.0
    assert session.p.getDynamicsInfo(second.id, 0)[0] == 3.0


def test_warnings_are_kept_as_messages(session, write_urdf):
    path = write_urdf(OFFSET_COM.replace(
        '<inertial><origin xyz="0 0 0.25"/><mass value="1"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"/></inertial>', ""))
    session.load(load_model(path))
    assert any("No inertial data for link 'arm'" in m for m in session.messages)


def test_split_bullet_messages():
    raw = ("b3Warning[a.cpp,126]:\nNo inertial data for link, using mass=1, x frameb3Warning[a.cpp,126]:\nlink_a"
           "b3Warning[b.h,102]:\n/x.urdf:1: cannot find 'm.stl' in any directory in urdf path\n")
    assert split_bullet_messages(raw) == ["No inertial data for link 'link_a', using mass=1, x frame",
                                          "/x.urdf:1: cannot find 'm.stl' in any directory in urdf path"]


def test_nothing_of_pybullet_reaches_stdout(cli, tmp_path):
    """pybullet prints from C; a script using the session must still print clean JSON."""
    robot = tmp_path / "r.urdf"
    robot.write_text(OFFSET_COM.replace(
        '<inertial><origin xyz="0 0 0.25"/><mass value="1"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"/></inertial>', ""))
    script = tmp_path / "s.py"
    script.write_text(textwrap.dedent(f"""
        import json
        from ar3cli.urdf.model import load_model
        from ar3cli.sim.session import Session
        with Session() as s:
            body = s.load(load_model({str(robot)!r}))
            print(json.dumps({{"links": body.link_names, "messages": len(s.messages)}}))
    """))
    import os
    import subprocess
    import sys

    from tests.conftest import REPO

    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(REPO)})
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["links"] == ["base", "arm"] and data["messages"] >= 1
    assert "b3Warning" not in done.stdout and "pybullet build time" not in done.stderr


def test_every_pybullet_data_model_loads_or_explains(pybullet_data_dir):
    """Every URDF outside random_urdfs: loads, or fails with pybullet's real reason (never a traceback)."""
    files = sorted(path for path in pybullet_data_dir.rglob("*.urdf") if "random_urdfs" not in path.parts)
    assert len(files) >= 90
    failures = {}
    with Session(file_caching=True) as session:
        for path in files:
            try:
                body = session.load(load_model(path))
                body.link_frames()
            except UserError as exc:
                failures[path.relative_to(pybullet_data_dir).as_posix()] = str(exc)
    # These three are broken in pybullet_data itself (raw pybullet refuses them too).
    assert set(failures) == {"kuka_iiwa/model_for_sdf.urdf", "torus_deform.urdf", "toys/concave_box.urdf"}
    assert "meshes/coarse/link_0.stl" in failures["kuka_iiwa/model_for_sdf.urdf"]
    assert "torus.vtk" in failures["torus_deform.urdf"]
    assert "concave_box.cdf" in failures["toys/concave_box.urdf"]


def test_body_dynamics_joint_states_and_remove(session, write_urdf):
    body = session.load(load_model(write_urdf(OFFSET_COM)))
    base, arm = body.dynamics("base"), body.dynamics("arm")
    assert base.mass == 0 and arm.mass == 1  # a fixed base has mass 0 in PyBullet
    assert arm.inertia_diagonal == pytest.approx((0.02, 0.02, 0.001))  # from the file (default load flags)
    assert base.inertial_position == pytest.approx((0.1, 0, 0)) and arm.inertial_position == pytest.approx((0, 0, 0.25))
    body.set_positions([0.7])
    ((position, velocity),) = body.joint_states()
    assert position == pytest.approx(0.7) and velocity == 0
    p = session.p
    assert p.getNumBodies(physicsClientId=session.client) == 1
    body.remove()
    body.remove()  # twice is harmless
    assert p.getNumBodies(physicsClientId=session.client) == 0


TOUCHING = """<?xml version="1.0"?>
<robot name="stack">
  <link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="b"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="c"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="ab" type="fixed"><parent link="a"/><child link="b"/><origin xyz="0 0 0.1"/></joint>
  <joint name="ac" type="fixed"><parent link="a"/><child link="c"/><origin xyz="0 0.095 0"/></joint>
</robot>
"""


def test_contacts_min_depth_skips_resting_and_separated_points(session, write_urdf):
    """a-b rest face to face (depth ~1e-17), a-c overlap by 5 mm; min_depth keeps only the overlap."""
    body = session.load(load_model(write_urdf(TOUCHING)), self_collision="all-pairs")
    everything = {(a, b): depth for a, b, depth in body.contacts()}
    assert abs(everything[("a", "b")]) < 1e-12 and everything[("a", "c")] == pytest.approx(-0.005, abs=1e-9)
    deep = body.contacts(min_depth=1e-6)
    assert [(a, b) for a, b, _ in deep] == [("a", "c")]


def _chain(joints: int, robot_name: str = "chain") -> str:
    """A one-line URDF chain of ``joints`` revolute joints about x (one line: ~90 characters a joint)."""
    inertial = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
    parts = [f'<link name="l0">{inertial}</link>']
    parts += [f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/><origin xyz="0 0 0.01"/>'
              f'<axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
              f'<link name="l{i}">{inertial}</link>' for i in range(1, joints + 1)]
    return f'<robot name="{robot_name}">' + "".join(parts) + "</robot>"


def test_one_line_file_of_many_kilobytes_loads_and_every_joint_is_set(session, write_urdf):
    """pybullet's parser fails on very long lines; the session hands it an indented copy."""
    body = session.load(load_model(write_urdf(_chain(121))))
    body.set_positions([0.01] * 121)
    assert body.positions() == pytest.approx([0.01] * 121)  # the 121st joint too


@pytest.mark.parametrize(("joints", "message"), [(125, "125 movable joints"), (130, "130 joints")])
def test_bodies_beyond_pybullets_state_limits_are_refused(session, write_urdf, joints, message):
    with pytest.raises(UserError, match=message):
        session.load(load_model(write_urdf(_chain(joints))))


def test_names_that_crash_pybullet_are_refused(session, write_urdf):
    with pytest.raises(UserError, match="1500 characters long"):
        session.load(load_model(write_urdf(_chain(1, robot_name="x" * 1500))))


PLY_TRIANGLE = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
PLY_ROBOT = """<?xml version="1.0"?>
<!-- comments and blank lines: the loadable copy (indented, without them) has other line numbers -->
<robot name="ply">

  <!-- the base -->
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <visual><origin xyz="0 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>


  <link name="tip"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><mesh filename="tri.ply"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


def _quoted_line(message: str, path) -> int:
    """The line number ``message`` quotes for ``path`` (``PATH:LINE:``)."""
    head = f"{path}:"
    assert head in message, message
    return int(re.match(r"\d+", message.split(head, 1)[1]).group())


@pytest.mark.parametrize("visuals", [True, False])
def test_load_error_quotes_the_line_of_the_users_file(session, write_urdf, visuals):
    """pybullet names lines of the loadable copy; the user sees the line of their file holding the '.ply'."""
    path = write_urdf(PLY_ROBOT, "ply.urdf")
    (path.parent / "tri.ply").write_text(PLY_TRIANGLE)
    with pytest.raises(UserError) as caught:
        session.load(load_model(path), visuals=visuals)
    message = caught.value.message
    assert "invalid mesh filename extension '.ply'" in message
    line = _quoted_line(message.split("cannot load it: ", 1)[1], path)
    assert ".ply" in PLY_ROBOT.splitlines()[line - 1]


def test_load_error_quotes_the_line_of_the_xacro_source(session, tmp_path):
    """Through xacro's origins: the line of the .xacro that wrote the <mesh>, not of the expansion or the copy."""
    source = textwrap.dedent("""\
        <?xml version="1.0"?>
        <robot name="ply" xmlns:xacro="http://www.ros.org/wiki/xacro">
          <xacro:property name="unit" value="0.01"/>
          <xacro:macro name="part" params="name">
            <link name="${name}">
              <inertial><mass value="1"/><inertia ixx="${unit}" ixy="0" ixz="0" iyy="${unit}" iyz="0" izz="${unit}"/></inertial>

              <collision><geometry><mesh filename="tri.ply"/></geometry></collision>
            </link>
          </xacro:macro>
          <link name="base"/>
          <xacro:part name="tip"/>
          <joint name="j" type="fixed"><parent link="base"/><child link="tip"/></joint>
        </robot>
        """)
    path = tmp_path / "ply.urdf.xacro"
    path.write_text(source)
    (tmp_path / "tri.ply").write_text(PLY_TRIANGLE)
    with pytest.raises(UserError) as caught:
        session.load(load_model(path))
    line = _quoted_line(caught.value.message.split("cannot load it: ", 1)[1], path)
    assert "tri.ply" in source.splitlines()[line - 1]


@pytest.mark.parametrize("inside, reason, marker", [
    ('<inertial><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>',
     "its <inertial> has no <mass> (lint-urdf I003)", "<inertial>"),
    ('<collision>\n      <origin xyz="0 0 0"/>\n    </collision>', "a <collision> has no <geometry>", "<collision>"),
    ('<visual><geometry>\n      <mesh/></geometry></visual>', "the <mesh> of a <visual> has no filename attribute", "<mesh/>"),
])
def test_failed_to_parse_link_names_the_link_the_line_and_the_reason(session, write_urdf, inside, reason, marker):
    """pybullet says only "failed to parse link"; ar3cli finds the culprit in the file (the line holding it)."""
    text = f"""<?xml version="1.0"?>
<robot name="r">
  <link name="base"/>

  <link name="tip">
    {inside}
  </link>
  <joint name="j" type="fixed"><parent link="base"/><child link="tip"/></joint>
</robot>
"""
    path = write_urdf(text)
    with pytest.raises(UserError) as caught:
        session.load(load_model(path))
    message = caught.value.message
    assert f"link 'tip' ({path}:" in message and message.endswith(reason), message
    assert marker in text.splitlines()[_quoted_line(message.split("cannot load it: ", 1)[1], path) - 1]
