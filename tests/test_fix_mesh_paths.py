"""ar3cli fix-mesh-paths: machine-bound mesh URIs become package://NAME/..., checked twice."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS
from tests.fixer_helpers import changed_old_lines, lint_findings

CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x, y, z in [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1),
                                      (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]]
    + ["f 1 3 2", "f 1 4 3", "f 5 6 7", "f 5 7 8", "f 1 2 6", "f 1 6 5", "f 2 3 7", "f 2 7 6",
       "f 3 4 8", "f 3 8 7", "f 4 1 5", "f 4 5 8"]) + "\n"
INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'


def robot_text(root: Path) -> str:
    return f"""<?xml version="1.0"?>
<robot name="m">
  <material name="painted"><texture filename="../meshes/paint.png"/></material>
  <link name="base">
    {INERTIAL}
    <visual><geometry><mesh filename="{root}/my_pkg/meshes/cube.obj" scale="0.05 0.05 0.05"/></geometry></visual>
    <collision><geometry><mesh scale="0.05 0.05 0.05" filename='file://{root}/my_pkg/meshes/cube.obj'/></geometry></collision>
  </link>
  <link name="arm">
    {INERTIAL}
    <visual><geometry><mesh filename="../meshes/arm.obj" scale="0.05 0.05 0.05"/></geometry></visual>
    <visual><geometry><mesh filename="package:///my_pkg/meshes/arm.obj" scale="0.05 0.05 0.05"/></geometry></visual>
    <collision><geometry><mesh filename="package://my_pkg/meshes/arm.obj" scale="0.05 0.05 0.05"/></geometry></collision>
    <collision><geometry><mesh filename="{root}/other/elsewhere.obj" scale="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
  </joint>
</robot>
"""


@pytest.fixture
def tree(tmp_path) -> tuple[Path, str]:
    """tmp/my_pkg/{urdf/robot.urdf, meshes/cube.obj, meshes/arm.obj, meshes/paint.png}, tmp/other/elsewhere.obj."""
    for relative in ("my_pkg/meshes/cube.obj", "my_pkg/meshes/arm.obj", "other/elsewhere.obj"):
        (tmp_path / relative).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / relative).write_text(CUBE_OBJ)
    (tmp_path / "my_pkg" / "meshes" / "paint.png").write_bytes(b"not read by these tests")
    (tmp_path / "my_pkg" / "urdf").mkdir()
    text = robot_text(tmp_path)
    path = tmp_path / "my_pkg" / "urdf" / "robot.urdf"
    path.write_text(text)
    return path, text


def test_every_kind_rewritten_and_outside_reported(cli, tree):
    path, text = tree
    package = f"my_pkg={path.parent.parent}"
    assert {f["rule"] for f in lint_findings(cli, path, "G002,G003")} == {"G002", "G003"}
    result = cli("fix-mesh-paths", str(path), "--package", package, "--format", "json")
    assert result.code == 1, result.stderr  # one mesh lies outside my_pkg
    file = json.loads(result.stdout)["files"][0]
    rows = [(c["element"], c["field"], c["new"], c["source"].split(" path")[0]) for c in file["changes"]]
    assert rows == [
        ("material painted", "texture filename", "package://my_pkg/meshes/paint.png", "relative"),
        ("link base visual", "mesh filename", "package://my_pkg/meshes/cube.obj", "absolute"),
        ("link base collision", "mesh filename", "package://my_pkg/meshes/cube.obj", "file://"),
        ("link arm visual 1", "mesh filename", "package://my_pkg/meshes/arm.obj", "relative"),
        ("link arm visual 2", "mesh filename", "package://my_pkg/meshes/arm.obj", "package:///"),
    ]
    (skipped,) = file["skipped"]
    assert skipped["element"] == "link arm collision 2" and "outside every --package folder" in skipped["reason"]
    assert file["verification"]["verified"] is True
    fixed = path.read_text()
    # only the filename values changed: the rest of each line, the other lines, byte for byte
    old_lines, new_lines = text.splitlines(), fixed.splitlines()
    assert changed_old_lines(text, fixed) == [2, 5, 6, 10, 11]
    for number in (2, 5, 6, 10, 11):
        before, after = old_lines[number].split("filename="), new_lines[number].split("filename=")
        assert before[0] == after[0] and before[1][0] == after[1][0]  # same quote
        assert before[1].split(before[1][0])[2:] == after[1].split(after[1][0])[2:]
    model = load_model(path, {"my_pkg": path.parent.parent})
    assert all(shape.geometry.resolution.found for _, shape in model.meshes())
    assert lint_findings(cli, path, "G002,G003", "--package-path", package) != []  # the outside one stays
    again = cli("fix-mesh-paths", str(path), "--package", package, "--format", "json")
    assert again.code == 1 and json.loads(again.stdout)["files"][0]["changes"] == []  # idempotent
    both = cli("fix-mesh-paths", str(path), "--package", package, "--package", f"other={path.parents[2] / 'other'}")
    assert both.code == 0, both.stdout
    assert "package://other/elsewhere.obj" in path.read_text()
    assert lint_findings(cli, path, "G001,G002,G003", "--package-path", package,
                         "--package-path", f"other={path.parents[2] / 'other'}") == []
    assert cli("fix-mesh-paths", str(path), "--package", package, "--check").code == 0


def test_a_uri_only_pybullet_finds_is_rewritten_as_g009_says(cli, tmp_path):
    """``package://meshes/cube.obj`` next to the URDF: 'meshes' is no package, only PyBullet's fallback
    search finds it (G009); the hint names fix-mesh-paths and the package it cannot find, and the fix works."""
    (tmp_path / "my_pkg" / "meshes").mkdir(parents=True)
    (tmp_path / "my_pkg" / "meshes" / "cube.obj").write_text(CUBE_OBJ)
    path = tmp_path / "my_pkg" / "robot.urdf"
    path.write_text(f'<robot name="m"><link name="base">{INERTIAL}<visual><geometry>'
                    '<mesh filename="package://meshes/cube.obj"/></geometry></visual></link></robot>\n')
    (finding,) = lint_findings(cli, path, "G009")
    assert "'meshes' is no package ROS can find: ar3cli fix-mesh-paths --package PKG=DIR" in finding["hint"]
    assert "NAME" not in finding["hint"]
    package = f"my_pkg={path.parent}"
    result = cli("fix-mesh-paths", str(path), "--package", package, "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    (change,) = json.loads(result.stdout)["files"][0]["changes"]
    assert change["new"] == "package://my_pkg/meshes/cube.obj"
    assert lint_findings(cli, path, "G001,G009", "--package-path", package) == []
    below = tmp_path / "my_pkg" / "urdf" / "robot.urdf"  # a relative path PyBullet finds one folder up
    below.parent.mkdir()
    below.write_text(f'<robot name="m"><link name="base">{INERTIAL}<visual><geometry>'
                     '<mesh filename="meshes/cube.obj"/></geometry></visual></link></robot>\n')
    (relative,) = lint_findings(cli, below, "G009")
    assert relative["hint"].startswith("the path is not there relative to the URDF")


def test_diff_check_and_unresolvable(cli, tree):
    path, text = tree
    broken = text.replace("../meshes/arm.obj", "../meshes/missing.obj")
    path.write_text(broken)
    package = f"my_pkg={path.parent.parent}"
    diff = cli("fix-mesh-paths", str(path), "--package", package, "--diff")
    removed = [line for line in diff.stdout.splitlines() if line.startswith("-") and not line.startswith("---")]
    assert diff.code == 1 and len(removed) == 4 and not any("missing.obj" in line for line in removed)
    assert "does not resolve" in diff.stderr and "missing.obj" in diff.stderr
    check = cli("fix-mesh-paths", str(path), "--package", package, "--check", "--format", "json")
    assert check.code == 1 and json.loads(check.stdout)["mode"] == "check"
    assert path.read_text() == broken


def test_bad_input_exits_2(cli, tree, tmp_path):
    path, _ = tree
    for args, message in [((), "Missing option '--package'"),
                          (("--package", "nodir"), "expects NAME=DIR"),
                          (("--package", f"x={tmp_path / 'absent'}"), "is not a folder")]:
        result = cli("fix-mesh-paths", str(path), *args)
        assert result.code == 2 and message in result.stderr, result.stderr
    xacro = cli("fix-mesh-paths", str(ASSETS / "ar3" / "ar3.urdf.xacro"), "--package", f"x={tmp_path}", "--check")
    assert xacro.code in (0, 1) and "Traceback" not in xacro.stderr  # a xacro source is read (tests/test_xacro_fix.py)
    missing = cli("fix-mesh-paths", str(tmp_path / "nope.urdf"), "--package", f"x={tmp_path}")
    assert missing.code == 2 and missing.stderr.startswith("ar3cli: error:")
