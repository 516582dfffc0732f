"""ar3cli fix-joints: inverted limits, degrees, axes and missing effort/velocity, byte for byte."""

from __future__ import annotations

import json

from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS, REPO
from tests.fixer_helpers import element_lines, lint_findings, only_within

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'
ROBOT = f"""<?xml version="1.0"?>
<!-- hand-written: one defect per joint -->
<robot name="j">
  <link name="base"/>
  <link name="a">{INERTIAL}</link>
  <link name="b">{INERTIAL}</link>
  <link name="c">{INERTIAL}</link>
  <link name="d">{INERTIAL}</link>
  <joint name="inverted" type="prismatic">
    <parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/>
    <limit lower='0.5' upper = '-0.25'  effort="5" velocity="2"/>
  </joint>
  <joint name="degrees" type="revolute">
    <parent link="a"/><child link="b"/>
    <axis xyz="0 1 0"/>
    <limit lower="-90" upper="180" effort="5" velocity="2"/>
  </joint>
  <joint name="long_axis" type="revolute">
    <parent link="b"/><child link="c"/>
    <axis xyz="0  0 -2"/>
    <limit lower="-1" upper="1"/>
  </joint>
  <joint name="ok" type="revolute">
    <parent link="c"/><child link="d"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
  </joint>
</robot>
"""
TARGETED = "J003,J005,J007,J009,J010"


def joint_lines(text: str, *names: str) -> list[tuple[int, int]]:
    return [element_lines(text, rf'<joint name="{name}"', "</joint>") for name in names]


def test_each_change_kind_only_the_attributes_change(cli, write_urdf):
    path = write_urdf(ROBOT)
    assert {f["rule"] for f in lint_findings(cli, path, TARGETED)} == {"J003", "J005", "J007", "J010"}
    result = cli("fix-joints", str(path), "--effort", "7", "--velocity", "1.5", "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    document = json.loads(result.stdout)
    (file,) = document["files"]
    changes = {(c["element"], c["field"]): (c["old"], c["new"]) for c in file["changes"]}
    assert changes == {
        ("joint inverted", "limit lower"): ("0.5", "-0.25"),
        ("joint inverted", "limit upper"): ("-0.25", "0.5"),
        ("joint degrees", "limit lower"): ("-90", "-1.570796327"),
        ("joint degrees", "limit upper"): ("180", "3.141592654"),
        ("joint long_axis", "axis xyz"): ("0  0 -2", "0 0 -1"),
        ("joint long_axis", "limit effort"): (None, "7"),
        ("joint long_axis", "limit velocity"): (None, "1.5"),
    }
    assert all(c["line"] > 0 and c["source"] for c in file["changes"])
    assert file["verification"]["verified"] is True
    fixed = path.read_text()
    assert fixed == (ROBOT.replace("lower='0.5' upper = '-0.25'", "lower='-0.25' upper = '0.5'")
                     .replace('lower="-90" upper="180"', 'lower="-1.570796327" upper="3.141592654"')
                     .replace('<axis xyz="0  0 -2"/>', '<axis xyz="0 0 -1"/>')
                     .replace('<limit lower="-1" upper="1"/>', '<limit lower="-1" upper="1" effort="7" velocity="1.5"/>'))
    assert only_within(ROBOT, fixed, joint_lines(ROBOT, "inverted", "degrees", "long_axis"))
    assert lint_findings(cli, path, TARGETED) == []
    joint = load_model(path).joint("degrees")
    assert (joint.limit.lower, joint.limit.upper) == (-1.570796327, 3.141592654)
    again = cli("fix-joints", str(path), "--effort", "7", "--velocity", "1.5")  # idempotent
    assert again.code == 0 and "nothing to change" in again.stdout and path.read_text() == fixed


def test_diff_and_check_write_nothing(cli, write_urdf):
    path = write_urdf(ROBOT)
    diff = cli("fix-joints", str(path), "--diff", "--effort", "7", "--velocity", "1.5")
    assert diff.code == 0, diff.stderr
    removed = [line[1:] for line in diff.stdout.splitlines() if line.startswith("-") and not line.startswith("---")]
    assert removed == ["    <limit lower='0.5' upper = '-0.25'  effort=\"5\" velocity=\"2\"/>",
                       '    <limit lower="-90" upper="180" effort="5" velocity="2"/>',
                       '    <axis xyz="0  0 -2"/>', '    <limit lower="-1" upper="1"/>']
    assert "would change" in diff.stderr
    check = cli("fix-joints", str(path), "--check", "--effort", "7", "--velocity", "1.5", "--format", "json")
    assert check.code == 1 and json.loads(check.stdout)["mode"] == "check"
    assert path.read_text() == ROBOT
    output = path.parent / "out.urdf"
    written = cli("fix-joints", str(path), "-o", str(output), "--effort", "7", "--velocity", "1.5", "--no-verify")
    assert written.code == 0 and path.read_text() == ROBOT
    assert cli("fix-joints", str(output), "--check").code == 0


def test_missing_effort_is_reported_with_the_option_to_pass(cli, write_urdf):
    path = write_urdf(ROBOT)
    result = cli("fix-joints", str(path), "--format", "json", "--no-verify")
    assert result.code == 1  # the other fixes are written; the joint without effort/velocity is reported
    file = json.loads(result.stdout)["files"][0]
    assert {(s["element"], s["reason"].split(":")[0]) for s in file["skipped"]} == {
        ("joint long_axis", "<limit> has no effort"), ("joint long_axis", "<limit> has no velocity")}
    assert all("pass --" in s["reason"] for s in file["skipped"])
    assert [f["rule"] for f in lint_findings(cli, path, TARGETED)] == ["J007"]


def test_limits_from_yaml_before_the_options(cli, write_urdf, tmp_path):
    path = write_urdf(ROBOT)
    limits = tmp_path / "joint_limits.yaml"
    limits.write_text("joint_limits:\n  long_axis: {has_effort_limits: true, max_effort: 12,"
                      " has_velocity_limits: false}\n  ghost: {has_effort_limits: true, max_effort: 1}\n")
    result = cli("fix-joints", str(path), "--limits-from", str(limits), "--velocity", "3", "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    file = json.loads(result.stdout)["files"][0]
    sources = {c["field"]: (c["new"], c["source"]) for c in file["changes"] if c["element"] == "joint long_axis"}
    assert sources["limit effort"] == ("12", "joint_limits.yaml: max_effort (added)")
    assert sources["limit velocity"] == ("3", "--velocity (added)")
    assert any("'ghost' is not in" in note for note in file["notes"])


def test_zero_axis_is_refused_with_what_to_do(cli, write_urdf):
    text = ROBOT.replace('<axis xyz="1 0 0"/>', '<axis xyz="0 0 0"/>')
    path = write_urdf(text)
    result = cli("fix-joints", str(path), "--effort", "7", "--velocity", "1.5", "--format", "json")
    assert result.code == 1
    file = json.loads(result.stdout)["files"][0]
    (skipped,) = file["skipped"]
    assert skipped["element"] == "joint ok" and "set the joint's real axis by hand" in skipped["reason"]
    assert file["verification"]["verified"] is True  # the other joints were written and read back
    assert '<axis xyz="0 0 0"/>' in path.read_text()
    text_run = cli("fix-joints", str(path))
    assert text_run.code == 1 and "not fixed" in text_run.stdout and "nothing written" in text_run.stdout


def test_bad_input_exits_2(cli, tmp_path):
    xacro = cli("fix-joints", str(ASSETS / "ar3" / "ar3.urdf.xacro"), "--check")  # a xacro source is read
    assert xacro.code == 0 and "nothing to change" in xacro.stdout, xacro.stderr
    missing = cli("fix-joints", str(tmp_path / "nope.urdf"))
    assert missing.code == 2 and missing.stderr.startswith("ar3cli: error:")
    negative = cli("fix-joints", str(tmp_path / "nope.urdf"), "--effort", "-1")
    assert negative.code == 2 and "must be positive" in negative.stderr


def test_clean_file_nothing_to_do(cli, tmp_path):
    path = tmp_path / "ar3.urdf"
    path.write_bytes((ASSETS / "ar3" / "ar3.urdf").read_bytes())
    result = cli("fix-joints", str(path), "--format", "json")
    assert result.code == 0 and json.loads(result.stdout)["files"][0]["changes"] == []


# ---- issue 30: floating bases and PyBullet's "no limit" idiom are not defects to convert ----------
JOINT_DATA = REPO / "tests" / "data" / "joints"


def test_floating_hand_virtual_joints_are_not_converted(cli, write_urdf):
    """Six virtual base joints share -20..20 (metres on the prismatic ones): only the finger's degrees change."""
    text = (JOINT_DATA / "floating_hand.urdf").read_text()
    path = write_urdf(text)
    result = cli("fix-joints", str(path), "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    (file,) = json.loads(result.stdout)["files"]
    assert {(c["element"], c["field"], c["new"]) for c in file["changes"]} == {
        ("joint finger_joint", "limit upper", "1.570796327")}
    fixed = path.read_text()
    assert fixed == text.replace('lower="0" upper="90"', 'lower="0" upper="1.570796327"')
    assert fixed.count('lower="-20" upper="20"') == 6


def test_pybullet_no_limit_idiom_is_left_alone_and_named(cli, write_urdf):
    text = (JOINT_DATA / "pybullet_unlimited.urdf").read_text()
    path = write_urdf(text)
    result = cli("fix-joints", str(path), "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    (file,) = json.loads(result.stdout)["files"]
    assert {(c["element"], c["field"]) for c in file["changes"]} == {
        ("joint shoulder", "limit lower"), ("joint shoulder", "limit upper")}
    assert path.read_text() == text.replace('lower="1.2" upper="-0.8"', 'lower="-0.8" upper="1.2"')
    (idiom,) = [note for note in file["notes"] if "alone: lower > upper" in note]
    assert "x_to_world, z_to_x" in idiom and "J014" in idiom
    assert file["verification"]["verified"] is True
