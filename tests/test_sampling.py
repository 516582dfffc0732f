"""The shared joint-space sampler: mimic joints follow their source, seeds reproduce, limits are reachable."""

from __future__ import annotations

import json

import numpy as np
import pytest
from lxml import etree

from ar3cli.sim import sampling
from ar3cli.sim.session import Session
from ar3cli.urdf.model import load_model

BOX = '<inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial>' \
      '<collision><geometry><box size="{size}"/></geometry></collision>'

# The right finger mimics the left one: both close towards the centre together and never meet
# (closest at the left's upper limit 0.02: gap 0.07 - 2 * 0.02 - 0.01 = 0.02 m). The right joint's
# own <limit> (0.075) is wider, as mimic joints' limits often are: sampling it independently puts the
# fingers through each other whenever q_left + q_right > 0.06.
MIMIC_GRIPPER = f"""<?xml version="1.0"?>
<robot name="gripper">
  <link name="base">{BOX.format(size="0.2 0.2 0.02")}</link>
  <link name="finger_left">{BOX.format(size="0.02 0.01 0.04")}</link>
  <link name="finger_right">{BOX.format(size="0.02 0.01 0.04")}</link>
  <joint name="left" type="prismatic"><parent link="base"/><child link="finger_left"/>
    <origin xyz="0 0.04 0.1"/><axis xyz="0 -1 0"/><limit lower="0" upper="0.02" effort="10" velocity="1"/></joint>
  <joint name="right" type="prismatic"><parent link="base"/><child link="finger_right"/>
    <origin xyz="0 -0.04 0.1"/><axis xyz="0 1 0"/><limit lower="0" upper="0.075" effort="10" velocity="1"/>
    <mimic joint="left" multiplier="1" offset="0"/></joint>
</robot>
"""


@pytest.fixture
def gripper(write_urdf):
    return write_urdf(MIMIC_GRIPPER, "gripper.urdf")


def test_mimic_joint_follows_in_samples_home_and_limits(gripper):
    model = load_model(gripper)
    with Session() as session:
        space = sampling.joint_space(session.load(model))
    assert space.names == ("left", "right") and space.driving_names == ("left",) and space.dof == 1
    assert space.mimic_names == ("right",)
    configs = sampling.sample_configurations(space, 500, seed=2)
    assert configs.shape == (500, 2)
    assert np.array_equal(configs[:, 1], configs[:, 0])  # multiplier 1, offset 0
    assert configs[:, 0].max() <= 0.02  # the left joint's range, never the right's 0.075
    assert np.array_equal(configs, sampling.sample_configurations(space, 500, seed=2))
    labels = dict(sampling.limit_configurations(space))
    assert list(labels) == ["home", "left at upper"]  # "left at lower" and "all at lower" are home
    assert labels["left at upper"].tolist() == [0.02, 0.02]


def test_mimic_offset_and_multiplier(write_urdf):
    text = MIMIC_GRIPPER.replace('multiplier="1" offset="0"', 'multiplier="2" offset="0.01"')
    model = load_model(write_urdf(text, "g.urdf"))
    with Session() as session:
        space = sampling.joint_space(session.load(model))
    assert space.home.tolist() == pytest.approx([0.0, 0.01])
    configs = sampling.sample_configurations(space, 50, seed=0)
    assert configs[:, 1] == pytest.approx(2 * configs[:, 0] + 0.01)


def test_without_mimic_the_draw_is_numpys_uniform(pybullet_data_dir):
    """Same seed, same configurations as the plain default_rng(seed).uniform the commands made before."""
    model = load_model(pybullet_data_dir / "kuka_iiwa" / "model.urdf")
    with Session() as session:
        body = session.load(model)
        space = sampling.joint_space(body)
    ranges = np.array([joint.sample_range() for joint in body.actuated_joints])
    expected = np.random.default_rng(11).uniform(ranges[:, 0], ranges[:, 1], size=(400, 7))
    assert np.array_equal(sampling.sample_configurations(space, 400, 11), expected)


def test_sample_collisions_finger_pair_is_never(cli, gripper, tmp_path):
    srdf = tmp_path / "g.srdf"
    result = cli("sample-collisions", str(gripper), "-n", "400", "--seed", "1", "--srdf", str(srdf),
                 "--format", "json")
    assert result.code == 0, result.stderr
    pairs = {frozenset((p["link_a"], p["link_b"])): p for p in json.loads(result.stdout)["pairs"]}
    fingers = pairs[frozenset(("finger_left", "finger_right"))]
    assert fingers["category"] == "never" and fingers["collisions"] == 0 and fingers["limit_hits"] == []
    entries = {frozenset((e.get("link1"), e.get("link2"))): e.get("reason")
               for e in etree.parse(str(srdf)).getroot().iter("disable_collisions")}
    assert entries == {frozenset(("base", "finger_left")): "Adjacent", frozenset(("base", "finger_right")): "Adjacent",
                       frozenset(("finger_left", "finger_right")): "Never"}


def test_fk_verify_passes_on_the_mimic_gripper(cli, gripper):
    result = cli("fk-verify", str(gripper), "-n", "20", "--format", "json")
    assert result.code == 0, result.stderr
    assert set(json.loads(result.stdout)["worst"]["configuration"]) == {"left"}


def test_render_moves_the_mimic_with_its_source(cli, gripper, tmp_path):
    result = cli("render", str(gripper), "-o", str(tmp_path / "g.png"), "--config", "left=0.015",
                 "--width", "32", "--height", "32", "--format", "json")
    assert result.code == 0, result.stderr
    assert json.loads(result.stdout)["configuration"] == {"left": 0.015, "right": 0.015}
