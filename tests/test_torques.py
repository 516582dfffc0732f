"""``ar3cli info --torques``: the gravity torque each actuated joint needs, against its declared effort.

The expectations are worked out by hand (m g l), not by ar3cli: a vertical lift carrying a
two-link arm whose links are horizontal at home, the worst pose for both revolute joints (their
limits keep the cosines positive, so every lever is longest at 0).
"""

from __future__ import annotations

import json
import math

import pytest

from tests.conftest import ASSETS

G = 9.81
ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="carriage"><inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0.3 0 0"/><mass value="1.0"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.2 0 0"/><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="lift" type="prismatic"><parent link="base"/><child link="carriage"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.1" effort="0" velocity="1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="carriage"/><child link="upper"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="1"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.6 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
"""
SHOULDER = G * (1.0 * 0.3 + 0.5 * (0.6 + 0.2))
"""6.867 N m: the upper arm's 1 kg at 0.3 m and the forearm's 0.5 kg at 0.8 m; effort 5: too weak."""
ELBOW = G * 0.5 * 0.2
"""0.981 N m; effort 10: ok."""
LIFT = G * (0.5 + 1.0 + 0.5)
"""19.62 N, the same in every pose: everything above the lift; effort 0: no effort declared."""


def torques(cli, path, *options):
    result = cli("info", str(path), "--torques", "--format", "json", *options)
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)["torques"]
    return data, {joint["joint"]: joint for joint in data["joints"]}


def test_hand_computed_arm(cli, write_urdf):
    data, joints = torques(cli, write_urdf(ARM))
    assert joints["shoulder"]["needed"] == pytest.approx(SHOULDER, rel=1e-6)
    assert joints["elbow"]["needed"] == pytest.approx(ELBOW, rel=1e-6)
    assert joints["lift"]["needed"] == pytest.approx(LIFT, rel=1e-6)
    assert joints["shoulder"]["at"] == joints["elbow"]["at"] == joints["lift"]["at"] == "home"
    assert joints["shoulder"]["at_configuration"] == {"lift": 0.0, "shoulder": 0.0, "elbow": 0.0}
    assert joints["shoulder"]["status"] == "too weak" and joints["shoulder"]["margin"] == pytest.approx(5 / SHOULDER)
    assert joints["elbow"]["status"] == "ok" and joints["elbow"]["margin"] == pytest.approx(10 / ELBOW)
    assert joints["lift"]["status"] == "no effort declared" and joints["lift"]["margin"] is None
    assert joints["lift"]["unit"] == "N" and joints["shoulder"]["unit"] == "N m"
    assert data["too_weak"] == ["shoulder"] and data["no_effort"] == ["lift"]
    # home + each of 3 joints at lower/upper (lift at lower is home: dropped) + all at lower / upper
    assert data["samples"] == 200 and data["configurations"] == 200 + data["limit_configurations"]


def test_text_table_and_warning(cli, write_urdf):
    result = cli("info", str(write_urdf(ARM)), "--torques", "--samples", "20")
    assert result.code == 0 and result.stderr == "", result.stderr
    out = result.stdout
    assert "gravity torques: worst of" in out and "20 samples, seed 0" in out
    assert "warning: joint shoulder is too weak: it needs 6.867 N m to hold the robot at 'home' but declares " \
           "effort 5 N m" in out
    assert "no effort declared (limit effort missing or 0): lift" in out
    assert out.count("warning:") == 1


MIMIC = """<robot name="m">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="spin" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 1 0"/>
    <limit effort="100" velocity="1"/></joint>
  <joint name="follow" type="revolute"><parent link="a"/><child link="b"/><origin xyz="1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><mimic joint="spin" multiplier="-0.5" offset="0.25"/></joint>
</robot>"""
"""spin needs g (2 cos q + 0.1 cos(q / 2 + 0.25)) with follow = -q / 2 + 0.25: the worst is near, not at, home."""


def test_continuous_and_mimic_joints(cli, write_urdf):
    """A continuous joint is sampled over [-pi, pi); a mimic joint is set as its source says in every
    configuration, the worst ones included."""
    data, joints = torques(cli, write_urdf(MIMIC), "--samples", "100")
    assert data["limit_configurations"] == 1  # continuous: home only; the mimic follows
    for joint in joints.values():
        q = joint["at_configuration"]
        assert q["follow"] == pytest.approx(-0.5 * q["spin"] + 0.25)
        assert -math.pi <= q["spin"] < math.pi
    home = G * (2 + 0.1 * math.cos(0.25))
    assert home <= joints["spin"]["needed"] <= G * 2.1
    assert joints["follow"]["mimic_of"] == "spin" and joints["follow"]["status"] == "ok"


def test_same_seed_same_result(cli, write_urdf):
    path = write_urdf(MIMIC)
    first, _ = torques(cli, path, "--samples", "50", "--seed", "7")
    again, _ = torques(cli, path, "--samples", "50", "--seed", "7")
    assert first == again
    other, _ = torques(cli, path, "--samples", "50", "--seed", "8")
    assert other["joints"] != first["joints"]


def test_the_ar3_holds_itself_up(cli):
    data, joints = torques(cli, ASSETS / "ar3" / "ar3.urdf")
    assert data["too_weak"] == [] and data["no_effort"] == []
    assert all(joint["status"] == "ok" for joint in joints.values())
    assert joints["joint_1"]["needed"] == 0 and joints["joint_1"]["at"] == "any"  # vertical axis
    assert joints["joint_2"]["needed"] > joints["joint_3"]["needed"] > 0


def test_panda_against_its_efforts(cli, pybullet_data_dir):
    data, joints = torques(cli, pybullet_data_dir / "franka_panda" / "panda.urdf")
    assert joints["panda_joint2"]["effort"] == 87 and joints["panda_joint6"]["effort"] == 12
    assert data["too_weak"] == [] and 30 < joints["panda_joint2"]["needed"] < 87
    assert joints["panda_finger_joint2"]["mimic_of"] == "panda_finger_joint1"


def test_gravity_torques_in_process_matches_the_hand_value(write_urdf):
    """The library call, without the CLI: the same numbers."""
    from ar3cli.info.torques import gravity_torques
    from ar3cli.urdf.model import load_model

    check = gravity_torques(load_model(write_urdf(ARM)), samples=5, seed=1)
    needed = {joint.name: joint.needed for joint in check.joints}
    assert needed == pytest.approx({"lift": LIFT, "shoulder": SHOULDER, "elbow": ELBOW}, rel=1e-6)
    assert [joint.name for joint in check.too_weak] == ["shoulder"]
