"""``ar3cli diff``: semantic differences between two robot descriptions, on a small hand-written arm."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import pytest

from tests.conftest import run_cli

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base_link">
    <inertial><origin xyz="0 0 0.05" rpy="0 0 0"/><mass value="2.0"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base_link"/><child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.0" upper="2.0" effort="10" velocity="1.5"/>
  </joint>
  <link name="upper">
    <inertial><origin xyz="0 0 0.15" rpy="0 0 0"/><mass value="1.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
    <visual><origin xyz="0 0 0.15" rpy="0 0 0"/><geometry><cylinder radius="0.03" length="0.3"/></geometry></visual>
    <collision><origin xyz="0 0 0.15" rpy="0 0 0"/><geometry><cylinder radius="0.03" length="0.3"/></geometry></collision>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/>
    <origin xyz="0 0 0.3" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="5" velocity="2"/>
  </joint>
  <link name="fore">
    <inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial>
    <collision><origin xyz="0 0 0.1" rpy="0 0 0"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision>
  </link>
  <joint name="finger_joint" type="prismatic">
    <parent link="fore"/><child link="finger"/>
    <origin xyz="0 0 0.2" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.02" effort="1" velocity="0.1"/>
  </joint>
  <link name="finger">
    <inertial><origin xyz="0 0 0.01" rpy="0 0 0"/><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <collision><geometry><box size="0.01 0.01 0.02"/></geometry></collision>
  </link>
  <joint name="finger_mirror_joint" type="prismatic">
    <parent link="fore"/><child link="finger_mirror"/>
    <origin xyz="0 0 0.2" rpy="0 0 3.141592653589793"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.02" effort="1" velocity="0.1"/>
    <mimic joint="finger_joint" multiplier="1" offset="0"/>
  </joint>
  <link name="finger_mirror">
    <inertial><origin xyz="0 0 0.01" rpy="0 0 0"/><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <collision><geometry><box size="0.01 0.01 0.02"/></geometry></collision>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="fore"/><child link="tool"/><origin xyz="0 0 0.25" rpy="0 3.141592653589793 0"/>
  </joint>
  <link name="tool"/>
</robot>
"""

REFORMATTED = """<?xml version='1.0' encoding='utf-8'?>
<!-- the same arm, written differently: comments, attribute order, number spelling, equal rotations -->
<robot name="arm">
  <link name="base_link">
    <inertial>
      <mass value="2"/>
      <origin rpy="0.0 0 -0" xyz="0.0 0.000 5e-2"/>
      <inertia izz="1e-2" iyz="0.0" iyy="0.010" ixz="-0" ixy="0" ixx=".01"/>
    </inertial>
    <collision><geometry><box size="0.20 0.2 1e-1"/></geometry></collision>
  </link>
  <!-- joints in another order -->
  <joint name="elbow" type="revolute">
    <child link="fore"/><parent link="upper"/>
    <axis xyz="0.0 1 0"/>
    <origin rpy="0 0 0" xyz="0 0 .3"/>
    <limit velocity="2.0" effort="5.0" upper="1.50" lower="-1.5"/>
  </joint>
  <joint type="revolute" name="shoulder">
    <parent link="base_link"/>
    <child link="upper"/>
    <origin rpy="0 0 0" xyz="0 0 0.1"/>
    <axis xyz="0 0 1.0"/>
    <limit lower="-2" upper="2" effort="10" velocity="1.5"/>
  </joint>
  <link name="upper">
    <!-- the same tensor about axes turned 90 degrees about z -->
    <inertial><origin xyz="0 0 0.15" rpy="0 0 1.5707963267948966"/><mass value="1.0"/>
      <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.003"/></inertial>
    <visual><origin xyz="0 0 0.15"/><geometry><cylinder length="0.3" radius="0.03"/></geometry></visual>
    <collision><origin xyz="0 0 0.15"/><geometry><cylinder length="0.3" radius="0.03"/></geometry></collision>
  </link>
  <link name="fore">
    <inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0005"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.04 0.04 0.2"/></geometry></collision>
  </link>
  <joint name="finger_joint" type="prismatic">
    <parent link="fore"/><child link="finger"/>
    <origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.02" effort="1" velocity="0.1"/>
  </joint>
  <link name="finger">
    <inertial><origin xyz="0 0 0.01"/><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <collision><geometry><box size="0.01 0.01 0.02"/></geometry></collision>
  </link>
  <joint name="finger_mirror_joint" type="prismatic">
    <parent link="fore"/><child link="finger_mirror"/>
    <origin xyz="0 0 0.2" rpy="0 0 -3.141592653589793"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.02" effort="1" velocity="0.1"/>
    <mimic joint="finger_joint"/>
  </joint>
  <link name="finger_mirror">
    <inertial><origin xyz="0 0 0.01"/><mass value="0.05"/>
      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
    <collision><geometry><box size="0.01 0.01 0.02"/></geometry></collision>
  </link>
  <joint name="tool_joint" type="fixed">
    <parent link="fore"/><child link="tool"/><origin xyz="0 0 0.25" rpy="3.141592653589793 0 3.141592653589793"/>
  </joint>
  <link name="tool"/>
</robot>
"""


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def diff_json(*args: str, cwd: Path | None = None, code: int | None = None) -> dict:
    result = run_cli("diff", *args, "--format", "json", "--samples", "8", cwd=cwd)
    assert result.code in ((0, 1) if code is None else (code,)), result.stderr
    return json.loads(result.stdout)


def changes(document: dict, index: int = 0) -> dict[tuple[str, str], dict]:
    return {(change["element"], change["what"]): change for change in document["robots"][index]["changes"]}


def test_moved_joint_origin_moves_the_end_effectors_and_names_the_joint(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new = write(tmp_path, "new.urdf", ARM.replace('<origin xyz="0 0 0.3" rpy="0 0 0"/>', '<origin xyz="0 0 0.34" rpy="0 0 0"/>'))
    document = diff_json(str(old), str(new), code=1)
    robot = document["robots"][0]
    assert document["changed"] and robot["changed"]
    moved = {entry["link"]: entry for entry in robot["kinematics"]}
    assert set(moved) == {"fore", "finger", "finger_mirror", "tool"}  # the hand the fingers slide on, and the leaves
    for entry in moved.values():
        assert entry["home_m"] == pytest.approx(0.04, abs=1e-12) and entry["home_rad"] == pytest.approx(0, abs=1e-12)
        assert entry["max_m"] == pytest.approx(0.04, abs=1e-12)  # a pure translation along the upper arm
        assert entry["cause"] == "joint 'elbow' origin"
    origin = changes(document)[("joint 'elbow'", "origin")]
    assert origin["section"] == "kinematics" and origin["amount"] == pytest.approx(0.04)
    assert origin["file"].endswith("new.urdf") and origin["line"] == ARM.splitlines().index(
        '  <joint name="elbow" type="revolute">') + 1
    assert document["seed"] == 0 and document["samples"] == 8


def test_reformatted_copy_is_no_change(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new = write(tmp_path, "new.urdf", REFORMATTED)
    result = run_cli("diff", str(old), str(new), "--samples", "8")
    assert result.code == 0, result.stdout + result.stderr
    assert "no semantic change" in result.stdout
    document = diff_json(str(old), str(new), code=0)
    robot = document["robots"][0]
    assert not robot["changes"] and not robot["kinematics"] and not robot["findings"]


def test_a_change_below_the_tolerance_is_none(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new = write(tmp_path, "new.urdf", ARM.replace('xyz="0 0 0.3"', 'xyz="0 0 0.3000001"'))
    assert diff_json(str(old), str(new), code=1)["changed"]
    assert not run_cli("diff", str(old), str(new), "--tolerance-m", "1e-6", "-n", "4").code


def test_renamed_link_and_joint_are_matched_by_their_place_in_the_tree(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    renamed = ARM.replace('"elbow"', '"elbow_joint"').replace('link="fore"', 'link="forearm"').replace(
        'name="fore"', 'name="forearm"')
    new = write(tmp_path, "new.urdf", renamed)
    document = diff_json(str(old), str(new), code=1)
    found = changes(document)
    assert found[("joint 'elbow_joint'", "renamed")]["old"] == "elbow"
    assert found[("link 'forearm'", "renamed")]["old"] == "fore"
    assert {what for _, what in found} == {"renamed"}, found  # nothing else: same robot, new names
    assert not document["robots"][0]["kinematics"]


def test_added_and_removed_elements_and_type_change(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new_text = ARM.replace('<joint name="tool_joint" type="fixed">\n    <parent link="fore"/><child link="tool"/>'
                           '<origin xyz="0 0 0.25" rpy="0 3.141592653589793 0"/>\n  </joint>\n  <link name="tool"/>\n',
                           "")
    new_text = new_text.replace('name="shoulder" type="revolute"', 'name="shoulder" type="continuous"')
    new = write(tmp_path, "new.urdf", new_text)
    found = changes(diff_json(str(old), str(new), code=1))
    assert ("link 'tool'", "removed") in found and ("joint 'tool_joint'", "removed") in found
    assert found[("joint 'shoulder'", "type")]["new"] == "continuous"
    assert found[("joint 'shoulder'", "type")]["section"] == "structure"


def test_dynamics_limits_mimic_and_geometry(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new_text = (ARM.replace('<mass value="0.5"/>', '<mass value="0.6"/>')
                .replace('ixx="0.001" ixy="0" ixz="0" iyy="0.002"', 'ixx="0.001" ixy="0" ixz="0" iyy="0.0025"')
                .replace('lower="-1.5" upper="1.5" effort="5"', 'lower="-1.4" upper="1.5" effort="6"')
                .replace('<mimic joint="finger_joint" multiplier="1"', '<mimic joint="finger_joint" multiplier="-1"')
                .replace('<box size="0.04 0.04 0.2"/>', '<box size="0.05 0.04 0.2"/>'))
    new = write(tmp_path, "new.urdf", new_text)
    found = changes(diff_json(str(old), str(new), code=1))
    assert found[("link 'fore'", "mass")]["amount"] == pytest.approx(0.1 / 0.6)
    assert found[("link 'upper'", "inertia")]["section"] == "dynamics"
    assert "moments 0.001 0.0025 0.003" in found[("link 'upper'", "inertia")]["new"]
    assert found[("robot", "total mass")]["new"] == "3.7"
    assert found[("joint 'elbow'", "lower")]["amount"] == pytest.approx(0.1)
    assert found[("joint 'elbow'", "effort")]["section"] == "limits"
    assert found[("joint 'finger_mirror_joint'", "mimic multiplier")]["new"] == "-1"
    assert found[("link 'fore' collision 1", "size")]["amount"] == pytest.approx(0.01)


def test_lint_findings_new_and_fixed_matched_by_element_not_line(tmp_path):
    inertial = ('<link name="finger">\n    <inertial><origin xyz="0 0 0.01" rpy="0 0 0"/><mass value="0.05"/>\n'
                '      <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>\n')
    assert inertial in ARM
    broken = ARM.replace(inertial, '<link name="finger">\n')
    old = write(tmp_path, "old.urdf", "<!-- a\nfew\nlines\nmore -->\n" + ARM.split("\n", 1)[1])
    new = write(tmp_path, "new.urdf", broken)
    document = diff_json(str(old), str(new))
    findings = document["robots"][0]["findings"]
    assert findings and all(f["status"] == "new" and "'finger'" in f["message"] for f in findings), findings
    back = diff_json(str(new), str(old))["robots"][0]["findings"]
    assert {f["rule"] for f in back} == {f["rule"] for f in findings} and all(f["status"] == "fixed" for f in back)


def test_markdown_and_github_formats(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    new = write(tmp_path, "new.urdf", ARM.replace('xyz="0 0 0.3"', 'xyz="0 0 0.34"'))
    markdown = run_cli("diff", str(old), str(new), "-n", "4", "--format", "markdown")
    assert markdown.code == 1 and markdown.stdout.startswith("## ar3cli diff\n")
    assert "| kinematics | joint 'elbow' | origin |" in markdown.stdout and "| tool | 0.04 |" in markdown.stdout
    summary = tmp_path / "summary.md"
    github = run_cli("diff", str(old), str(new), "-n", "4", "--format", "github", env={"GITHUB_STEP_SUMMARY": str(summary)})
    assert github.code == 1
    lines = github.stdout.splitlines()
    assert lines and all(line.startswith("::warning file=") for line in lines)
    assert any(",line=" in line and "joint 'elbow' origin" in line for line in lines)
    assert "## ar3cli diff" in summary.read_text(encoding="utf-8")


@pytest.mark.parametrize(("args", "message"), [
    (["only-one.urdf"], "two robot files"),
    (["missing.urdf", "other.urdf"], "missing.urdf: no such file"),
    (["HEAD:x.urdf", "y.urdf"], "not in a git working tree"),
    (["a.urdf", "b.urdf", "--tolerance", "-1"], "must be zero or positive"),
])
def test_usage_errors_are_one_line_and_exit_2(tmp_path, args, message):
    result = run_cli("diff", *args, cwd=tmp_path)
    assert result.code == 2, result.stderr
    assert result.stderr.count("\n") == 1 and message in result.stderr and not result.stdout


# -- git revisions --------------------------------------------------------------------------------------------

ROBOT_XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="reach" default="0.3"/>
  <xacro:include filename="$(find fixture_arm)/urdf/parts.xacro"/>
  <link name="base_link"/>
  <xacro:segment name="upper" parent="base_link" z="0.1"/>
  <xacro:segment name="fore" parent="upper" z="$(arg reach)"/>
</robot>
"""
PARTS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="segment" params="name parent z">
    <joint name="${name}_joint" type="revolute">
      <parent link="${parent}"/><child link="${name}"/>
      <origin xyz="0 0 ${z}"/><axis xyz="0 1 0"/>
      <limit lower="-1" upper="1" effort="5" velocity="1"/>
    </joint>
    <link name="${name}">
      <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
      <collision><geometry><box size="0.05 0.05 0.2"/></geometry></collision>
    </link>
  </xacro:macro>
</robot>
"""
PACKAGE_XML = "<package format=\"2\"><name>fixture_arm</name><version>0.0.0</version></package>\n"


def git(repo: Path, *args: str) -> None:
    subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@example.com", "-c", "commit.gpgsign=false",
                    "-C", str(repo), *args], check=True, capture_output=True)


@pytest.fixture
def repo(tmp_path) -> Path:
    """A git repository with a xacro robot in a ROS package: committed, then its included file edited."""
    repo = tmp_path / "repo"
    write(repo, "fixture_arm/package.xml", PACKAGE_XML)
    write(repo, "fixture_arm/urdf/arm.urdf.xacro", ROBOT_XACRO)
    write(repo, "fixture_arm/urdf/parts.xacro", PARTS)
    write(repo, "other/still.urdf", ARM)
    git(repo, "init", "-q")
    git(repo, "add", "-A")
    git(repo, "commit", "-qm", "arm")
    write(repo, "fixture_arm/urdf/parts.xacro", PARTS.replace('<origin xyz="0 0 ${z}"/>', '<origin xyz="0.02 0 ${z}"/>'))
    return repo


def _private_tmp(tmp_path: Path) -> dict[str, str]:
    folder = tmp_path / "tmpdir"
    folder.mkdir(exist_ok=True)
    return {"TMPDIR": str(folder)}


def test_changed_since_compares_the_changed_robots_with_their_version_at_ref(repo, tmp_path):
    env = _private_tmp(tmp_path)
    result = run_cli("diff", "--changed-since", "HEAD", "--format", "json", "-n", "4", cwd=repo, env=env)
    assert result.code == 1, result.stderr
    document = json.loads(result.stdout)
    assert [robot["new"] for robot in document["robots"]] == ["fixture_arm/urdf/arm.urdf.xacro"]  # not still.urdf
    robot = document["robots"][0]
    assert robot["old"] == "HEAD:fixture_arm/urdf/arm.urdf.xacro"
    origins = [c for c in robot["changes"] if c["what"] == "origin"]
    assert {c["element"] for c in origins} == {"joint 'upper_joint'", "joint 'fore_joint'"}
    assert all(c["file"].endswith("parts.xacro") and c["line"] == 4 for c in origins)  # where the macro writes it
    assert {m["link"]: m["cause"] for m in robot["kinematics"]} == {"upper": "joint 'upper_joint' origin",
                                                                   "fore": "joint 'upper_joint' origin"}
    assert robot["kinematics"][0]["home_m"] == pytest.approx(0.02)
    assert not list((tmp_path / "tmpdir").iterdir()), "the revision's copy is removed"


def test_rev_path_side_with_xacro_args(repo, tmp_path):
    env = _private_tmp(tmp_path)
    git(repo, "checkout", "--", ".")  # the working tree is HEAD again
    same = run_cli("diff", "HEAD:fixture_arm/urdf/arm.urdf.xacro", "fixture_arm/urdf/arm.urdf.xacro", "-n", "4",
                   cwd=repo, env=env)
    assert same.code == 0, same.stdout + same.stderr
    longer = run_cli("diff", "HEAD:fixture_arm/urdf/arm.urdf.xacro", "fixture_arm/urdf/arm.urdf.xacro", "-n", "4",
                     "--xacro-arg", "reach:=0.35", "--format", "json", cwd=repo, env=env)
    assert longer.code == 0, "the same argument reaches both sides"
    missing = run_cli("diff", "HEAD:fixture_arm/urdf/nothing.urdf", "other/still.urdf", cwd=repo, env=env)
    assert missing.code == 2 and "HEAD has no file fixture_arm/urdf/nothing.urdf" in missing.stderr
    unknown = run_cli("diff", "nosuchrev:other/still.urdf", "other/still.urdf", cwd=repo, env=env)
    assert unknown.code == 2 and "unknown git revision" in unknown.stderr
    assert not list((tmp_path / "tmpdir").iterdir())


def test_a_folder_named_like_rev_path_never_becomes_the_old_side(repo, tmp_path):
    """A pull request committed a folder ``HEAD:other`` holding its own copy of the changed file:
    ``REV:path`` was looked up on disk first, so the diff compared the new file with itself ("no
    semantic change" while the mass went 1 -> 50 kg). A revision wins whenever REV resolves, and
    the command says which it read; ``./REV:path`` and ``--old-rev`` spell out either reading."""
    env = _private_tmp(tmp_path)
    heavy = ARM.replace('<mass value="2.0"/>', '<mass value="50"/>', 1)
    assert heavy != ARM
    write(repo, "other/still.urdf", heavy)
    write(repo, "HEAD:other/still.urdf", heavy)  # the planted old side
    for args in (["--changed-since", "HEAD", "other"], ["HEAD:other/still.urdf", "other/still.urdf"],
                 ["--old-rev", "HEAD", "other/still.urdf"]):
        result = run_cli("diff", *args, "-f", "json", "-n", "2", cwd=repo, env=env)
        assert result.code == 1, (args, result.stdout, result.stderr)
        [robot] = json.loads(result.stdout)["robots"]
        assert robot["old"] == "HEAD:other/still.urdf" and any(c["what"] == "mass" for c in robot["changes"]), args
    noted = run_cli("diff", "HEAD:other/still.urdf", "other/still.urdf", "-n", "2", cwd=repo, env=env)
    commit = subprocess.run(["git", "-C", str(repo), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    assert noted.stderr.splitlines() == [
        f"ar3cli: note: OLD HEAD:other/still.urdf: the file other/still.urdf as git revision HEAD ({commit[:12]}) "
        "holds it (not the file of that name: write ./HEAD:other/still.urdf for it)"]
    as_file = run_cli("diff", "./HEAD:other/still.urdf", "other/still.urdf", "-n", "2", cwd=repo, env=env)
    assert as_file.code == 0 and "the file of that name (./HEAD is no git revision here)" in as_file.stderr
    assert not list((tmp_path / "tmpdir").iterdir())


def test_changed_since_reports_an_added_robot_file(repo, tmp_path):
    write(repo, "other/new_robot.urdf", ARM)
    document = json.loads(run_cli("diff", "--changed-since", "HEAD", "other", "-f", "json", cwd=repo).stdout)
    assert [(r["old"], r["new"]) for r in document["robots"]] == [("(none)", "other/new_robot.urdf")]


# -- the pieces ------------------------------------------------------------------------------------------------

def test_equal_rotations_written_differently_have_angle_zero():
    from ar3cli.robot_diff.tolerance import rotation_angle

    assert rotation_angle((math.pi, 0, math.pi), (0, math.pi, 0)) < 1e-12
    assert rotation_angle((0, 0, 0), (0.0, 0, -0.0)) == 0.0
    assert rotation_angle((0, 0, 0), (0, 0, 1e-10)) == pytest.approx(1e-10, rel=1e-6)


def test_no_temporary_folder_is_left_when_git_is_missing(tmp_path):
    env = {**_private_tmp(tmp_path), "PATH": str(tmp_path / "empty")}
    result = run_cli("diff", "HEAD:a.urdf", "b.urdf", cwd=tmp_path, env=env)
    assert result.code == 2 and "needs git" in result.stderr
    assert os.listdir(tmp_path / "tmpdir") == []


def test_nan_never_reaches_the_output_and_a_floating_joint_is_a_note(tmp_path):
    old = write(tmp_path, "old.urdf", ARM)
    nan = write(tmp_path, "nan.urdf", ARM.replace('xyz="0 0 0.3"', 'xyz="nan 0 0.3"').replace(
        '<mass value="0.5"/>', '<mass value="nan"/>'))
    text = run_cli("diff", str(old), str(nan), "-n", "3", env={"COLUMNS": "1000"})  # a row a line: no wrapped message
    assert text.code == 1 and "| nan " not in text.stdout.replace("nan.urdf", "")
    document = diff_json(str(old), str(nan), code=1)  # json.loads refuses nothing: NaN would be written as NaN
    assert "NaN" not in json.dumps(document)
    assert document["robots"][0]["kinematics"][0]["home_m"] is None
    floating = write(tmp_path, "floating.urdf", ARM.replace('name="shoulder" type="revolute"', 'name="shoulder" type="floating"'))
    robot = diff_json(str(old), str(floating), code=1)["robots"][0]
    assert robot["notes"] and "kinematics not compared" in robot["notes"][0]


def _star(count: int, prefix: str) -> str:
    body = ['<link name="base"/>']
    for index in range(count):
        body.append(f'<link name="{prefix}l{index}"><collision><geometry><box size="0.1 0.1 0.1"/></geometry>'
                    f'</collision></link><joint name="{prefix}j{index}" type="revolute"><parent link="base"/>'
                    f'<child link="{prefix}l{index}"/><origin xyz="{index * 0.01:.2f} {index % 7 * 0.1:.1f} 0"/>'
                    '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')
    return '<robot name="star">' + "".join(body) + "</robot>"


def test_a_renamed_star_is_matched_in_near_linear_work(tmp_path, monkeypatch):
    """A 1,000-child star whose children were all renamed took 28-34 s (every pair of children was
    scored: 2,000 took 127 s and 585 MB). Beyond a few thousand pairs only candidate pairs are scored;
    the matching is the same (here, and byte for byte on the real robots and a 1,000-child star)."""
    from ar3cli.robot_diff import match as matching
    from ar3cli.urdf.model import load_model

    scored = []
    original = matching._score
    monkeypatch.setattr(matching, "_score", lambda *args: scored.append(1) or original(*args))
    for count in (40, 400):
        (tmp_path / "old.urdf").write_text(_star(count, "a"))
        (tmp_path / "new.urdf").write_text(_star(count, "b"))
        scored.clear()
        result = matching.match(load_model(tmp_path / "old.urdf"), load_model(tmp_path / "new.urdf"))
        assert result.joints == {f"aj{index}": f"bj{index}" for index in range(count)}
        assert result.links == {"base": "base", **{f"al{index}": f"bl{index}" for index in range(count)}}
        assert len(scored) == (count * count if count * count <= matching.EXACT_PAIRS else len(scored))
    assert len(scored) < 40 * 400  # all pairs would be 160,000
