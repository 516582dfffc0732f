"""Text-level fixers on xacro sources, and ``ar3cli expand`` (issue 36, item 7).

``tests/data/xacro_fix/my_pkg/urdf/robot.urdf.xacro`` holds, for each fixer, a value written as
literal text once in the file (fixed in the source), one computed by xacro (``${...}``), one written
in a file it includes, and one written once in a macro body that two calls use: each of those is
listed as not fixed with the reason, and every other byte of the source stays as it was.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from tests.fixer_helpers import changed_old_lines

DATA = Path(__file__).parent / "data" / "xacro_fix" / "my_pkg"


@pytest.fixture
def package(tmp_path: Path) -> Path:
    copy = tmp_path / "my_pkg"
    shutil.copytree(DATA, copy)
    return copy


def _run(cli, *args: str) -> dict:
    result = cli(*args, "--format", "json")
    assert result.code in (0, 1), result.stderr
    return json.loads(result.stdout)["files"][0]


def test_fix_mesh_paths_edits_the_literal_uris_of_the_source(cli, package: Path) -> None:
    robot = package / "urdf" / "robot.urdf.xacro"
    before = robot.read_text()
    file = _run(cli, "fix-mesh-paths", str(robot), "--package", f"my_pkg={package}")
    assert [(change["element"], change["line"]) for change in file["changes"]] == [
        ("link base visual", 21), ("link left_link visual", 11), ("link right_link visual", 11)]
    reasons = {skipped["element"]: (skipped["line"], skipped["reason"]) for skipped in file["skipped"]}
    assert reasons["link base collision"][0] == 22
    assert 'filename="${mesh_dir}/cube.obj"' in reasons["link base collision"][1]
    assert "is computed by xacro" in reasons["link base collision"][1]
    assert "parts.xacro:7, a file the xacro includes: fix it there" in reasons["link arm visual"][1]
    assert file["verification"]["status"] == "verified"
    after = robot.read_text()
    assert changed_old_lines(before, after) == [10, 20]  # the macro body's mesh once, base's visual
    assert after.count("package://my_pkg/meshes/cube.obj") == 2
    assert (package / "urdf" / "parts.xacro").read_text() == (DATA / "urdf" / "parts.xacro").read_text()


def test_fix_joints_says_why_a_computed_limit_is_left_alone(cli, package: Path) -> None:
    robot = package / "urdf" / "robot.urdf.xacro"
    file = _run(cli, "fix-joints", str(robot), "--diff")
    assert [(c["element"], c["line"], c["field"], c["new"]) for c in file["changes"]] == [
        ("joint tip_joint", 38, "axis xyz", "0 0 1")]
    (skipped,) = file["skipped"]
    assert skipped["element"] == "joint flap_joint" and skipped["line"] == 43
    assert 'lower="${low}"' in skipped["reason"] and "computed by xacro" in skipped["reason"]
    assert not any("swapped joint(s) flap_joint" in note for note in file["notes"])
    assert robot.read_text() == (DATA / "urdf" / "robot.urdf.xacro").read_text()  # --diff writes nothing


def test_fix_continuous_leaves_a_macro_body_used_twice_alone(cli, package: Path) -> None:
    robot = package / "urdf" / "robot.urdf.xacro"
    file = _run(cli, "fix-continuous", str(robot))
    assert {(c["element"], c["field"]) for c in file["changes"]} == {
        ("joint spinner_joint", "limit lower"), ("joint spinner_joint", "limit upper")}
    skipped = {s["element"]: s["reason"] for s in file["skipped"]}
    assert set(skipped) == {"joint left_joint", "joint right_joint"}
    assert "written once and used 2 times (a macro body)" in skipped["joint left_joint"]
    assert file["verification"]["status"] == "verified"
    assert '<limit effort="5" velocity="1"/>' in robot.read_text()


def test_a_fixer_that_computes_values_refuses_xacro_and_names_expand(cli, package: Path) -> None:
    result = cli("fix-inertia", str(package / "urdf" / "robot.urdf.xacro"), "--check")
    assert result.code == 2 and result.stderr.count("\n") == 1
    assert "ar3cli expand robot.urdf.xacro -o robot.urdf" in result.stderr


def test_expand_prints_the_urdf_ar3cli_checks(cli, package: Path, tmp_path: Path) -> None:
    from ar3cli.urdf.model import load_model

    robot = package / "urdf" / "robot.urdf.xacro"
    printed = cli("expand", str(robot))
    assert printed.code == 0, printed.stderr
    assert printed.stdout.encode() == load_model(robot).xml_bytes
    target = tmp_path / "robot.urdf"
    written = cli("expand", str(robot), "-o", str(target), "--format", "json")
    data = json.loads(written.stdout)
    assert target.read_bytes() == printed.stdout.encode() and data["xacro"] and "urdf" not in data
    assert [Path(name).name for name in data["included"]] == ["parts.xacro"]
    assert "J010" in cli("lint-urdf", "--select", "J010", str(target)).stdout  # it lints as the xacro does


def test_expand_stays_in_safe_mode(cli, tmp_path: Path) -> None:
    hostile = tmp_path / "robot.urdf.xacro"
    hostile.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                       '<link name="$(env HOME)"/></robot>')
    result = cli("expand", str(hostile))
    assert result.code == 2 and result.stdout == "" and "--xacro-env" in result.stderr
