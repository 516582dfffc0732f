"""xacro errors that real packages hit, each with the true fix and the line (issue 36, item 10).

- example-robot-data's hector ``quadrotor_base.xacro`` includes ``package://...``: xacro reads that as a
  relative file name, so the error is a file not found; the fix is ``$(find PKG)``.
- an ``<xacro:arg>`` without ``default``: xacro refuses it even when the argument is given, so the
  old hint ("pass --xacro-arg") could not help.
"""

from __future__ import annotations

from pathlib import Path

XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def test_package_uri_in_an_include_names_the_line_and_find(cli, tmp_path: Path) -> None:
    package = tmp_path / "quad_description"
    (package / "urdf").mkdir(parents=True)
    (package / "package.xml").write_text("<package><name>quad_description</name></package>")
    (package / "urdf" / "base.urdf.xacro").write_text(f'<robot {XACRO_NS}><link name="base"/></robot>')
    robot = package / "robot.xacro"
    robot.write_text(f'<?xml version="1.0"?>\n<robot name="quad" {XACRO_NS}>\n'
                     '  <xacro:include filename="package://quad_description/urdf/base.urdf.xacro"/>\n</robot>\n')
    result = cli("info", str(robot))
    assert result.code == 2 and result.stderr.count("\n") == 1
    assert f"{robot}:3" in result.stderr
    assert result.stderr.rstrip().endswith("write $(find quad_description)/urdf/base.urdf.xacro")
    (package / "urdf" / "base.urdf.xacro").unlink()  # hector's case: the path names a folder that is not there
    result = cli("info", str(robot))
    assert result.stderr.rstrip().endswith("write $(find quad_description)/urdf/base.urdf.xacro (no such file there "
                                           "either: check the path)")


def test_an_arg_without_default_says_xacro_needs_one(cli, tmp_path: Path) -> None:
    robot = tmp_path / "robot.urdf.xacro"
    robot.write_text(f'<robot name="r" {XACRO_NS}>\n  <xacro:arg name="prefix"/>\n'
                     '  <link name="$(arg prefix)base"/>\n</robot>\n')
    result = cli("info", str(robot), "--xacro-arg", "prefix:=left_")
    assert result.code == 2 and result.stderr.count("\n") == 1
    assert f'<xacro:arg name="prefix"> at {robot}:2 has no default' in result.stderr
    assert 'add default="..."' in result.stderr and "pass the ones it needs" not in result.stderr
