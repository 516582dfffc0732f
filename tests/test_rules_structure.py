"""Structure rules (S): references and transmissions, S014/S015, and the bundled AR3 staying clean.

Each case is a small robot written to tmp_path; tests/test_lint_pybullet_data.py keeps the real-robot
counts honest.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from ar3cli.lint.rules import REGISTRY
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from tests.conftest import ASSETS
from tests.lint_helpers import findings
from tests.test_lint_rules import codes_for, write_fixture

# ---- the AR3 stays clean --------------------------------------------------------------------------

def test_the_ar3_stays_clean():
    assert findings(ASSETS / "ar3" / "ar3.urdf") == []


# ---- S007, S012, S013: references, transmissions ---------------------------------------------------------

def test_ros2_control_and_gazebo_references(tmp_path):
    text = arm().replace("</robot>", """  <ros2_control name="hw" type="system"><hardware><plugin>mock</plugin></hardware>
    <joint name="j1"><command_interface name="position"/></joint>
    <joint name="j9"><command_interface name="position"/></joint></ros2_control>
  <gazebo reference="arm"><mu1>0.5</mu1></gazebo>
  <gazebo reference="j1"><provideFeedback>true</provideFeedback></gazebo>
  <gazebo><static>false</static></gazebo>
  <gazebo reference="wheel_{side}_joint"/>
</robot>""")
    found = codes_for(write_fixture(tmp_path, text), "S007")
    assert sorted(f.message for f in found) == [
        "<gazebo reference=\"wheel_{side}_joint\"> names no link or joint: Gazebo applies it to nothing",
        "ros2_control 'hw' names unknown joint 'j9'"]


def test_transmissions(tmp_path):
    assert codes_for(write_fixture(tmp_path, REGISTRY["S012"].bad), "S012")
    (duplicate,) = codes_for(write_fixture(tmp_path, REGISTRY["S013"].bad), "S013")
    assert "'m1', already driven by transmission 't1'" in duplicate.message
    # PAL's Hey5 hand: one motor, several finger joints, by design
    shared = REGISTRY["S013"].bad.replace("transmission_interface/SimpleTransmission", "tiago_transmissions/Hey5Reducer")
    assert codes_for(write_fixture(tmp_path, shared), "S013") == []


# ---- S014, S015 ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("text,tag", [
    (arm().replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><axis xyz="0 1 0"/>'), "axis"),
    (arm().replace('<axis xyz="0 0 1"/>', '<origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><origin xyz="0 0 0.2"/>'), "origin"),
    (arm(link_extra=LINK_INERTIAL * 2), "inertial"),
    (arm(link_extra='<inertial><mass value="1"/><mass value="2"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
                    'iyz="0" izz="0.01"/></inertial>'), "mass"),
])
def test_duplicate_single_children(tmp_path, text, tag):
    (finding,) = codes_for(write_fixture(tmp_path, text), "S014")
    assert f"2 <{tag}> elements" in finding.message


def test_transmission_joints_are_not_duplicate_joint_children(tmp_path):
    assert codes_for(write_fixture(tmp_path, REGISTRY["S012"].good), "S014") == []


def test_link_order(tmp_path):
    root_last = robot("""<link name="a"/><link name="b"/><link name="base"/>
        <joint name="j1" type="fixed"><parent link="base"/><child link="a"/></joint>
        <joint name="j2" type="fixed"><parent link="a"/><child link="b"/></joint>""")
    (finding,) = codes_for(write_fixture(tmp_path, root_last), "S015")
    assert "crashes" in finding.message and "1 link declared before their parent" in finding.message
    child_first = robot("""<link name="base"/><link name="b"/><link name="a"/>
        <joint name="j1" type="fixed"><parent link="base"/><child link="a"/></joint>
        <joint name="j2" type="fixed"><parent link="a"/><child link="b"/></joint>""")
    (finding,) = codes_for(write_fixture(tmp_path, child_first), "S015")
    assert "'b' is declared before its parent 'a'" in finding.message and "NaN" in finding.message


def test_link_order_fixtures_of_the_pybullet_facts():
    data = Path(__file__).parent / "data" / "link_order"
    assert codes_for(data / "in_order.urdf", "S015") == []
    for name in ("root_last.urdf", "root_middle.urdf", "child_before_parent.urdf"):
        assert codes_for(data / name, "S015"), name
