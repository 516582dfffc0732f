"""The shared loader: real files, messy files, bad input, xacro, package:// resolution."""

from __future__ import annotations

from pathlib import Path

import pytest

from ar3cli.errors import UserError
from ar3cli.urdf.model import load_model, parse_floats
from ar3cli.urdf.packages import PackageResolver, parse_package_paths

ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/>
    <child link="upper"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
  </joint>
  <link name="upper">
    <inertial><mass value="0.5"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.2"/></geometry></collision>
  </link>
  <joint name="spin" type="continuous">
    <parent link="upper"/>
    <child link="tool"/>
    <axis xyz="0 0 1"/>
  </joint>
  <link name="tool">
    <visual><geometry><mesh filename="package://fakepkg/meshes/tool.stl" scale="0.001"/></geometry></visual>
  </link>
</robot>
"""


def test_loads_pybullet_data_panda_with_lines(pybullet_data_dir):
    model = load_model(pybullet_data_dir / "franka_panda" / "panda.urdf")
    assert model.name == "panda"
    assert len(model.links) == 13 and len(model.joints) == 12
    assert model.root_link.name == "panda_link0"
    joint = model.joint("panda_joint4")
    assert joint.type == "revolute"
    assert joint.limit.lower == pytest.approx(-3.1416) and joint.limit.upper == pytest.approx(0.0)
    text_line = model.text_lines[joint.line - 1]
    assert 'name="panda_joint4"' in text_line
    meshes = [shape.geometry for _, shape in model.meshes()]
    assert meshes and all(geometry.resolution.found for geometry in meshes)
    # panda's package://meshes/... only resolves through pybullet's own search rule
    assert {geometry.resolution.via for geometry in meshes} == {"pybullet-search"}


def test_loads_version_0_0_file_and_records_quirk(pybullet_data_dir):
    model = load_model(pybullet_data_dir / "sphere_small.urdf")
    assert [q.code for q in model.quirks] == ["version-0.0"]
    assert model.links[0].collisions[0].geometry.kind == "sphere"


def test_typed_views(write_urdf):
    model = load_model(write_urdf(ARM))
    upper = model.link("upper")
    assert upper.inertial.mass == 0.5
    assert upper.inertial.tensor == (0.01, 0.0, 0.0, 0.01, 0.0, 0.01)
    assert upper.collisions[0].geometry.params["size"] == (0.1, 0.1, 0.2)
    assert model.joint("j1").origin.xyz == (0.0, 0.0, 0.1)
    spin = model.joint("spin")
    assert spin.type == "continuous" and spin.limit is None and spin.moves
    mesh = model.link("tool").visuals[0].geometry
    assert mesh.params["scale"] == (0.001, 0.001, 0.001)
    assert not mesh.resolution.found and "fakepkg" in mesh.resolution.explain()
    assert [j.name for j in model.child_joints("upper")] == ["spin"]
    assert model.parent_joint("tool").name == "spin"
    assert model.column_of(model.joint("j1").element) == 3


def test_elements_alike_on_one_line_each_have_their_own_column(write_urdf):
    """The column was the first ``<link`` of the line for every link on it: findings on the second were
    placed (and an editor's underline drawn) on the first."""
    model = load_model(write_urdf('<robot name="r">\n  <link name="a"/><links/><link name="b"/>\n</robot>\n'))
    assert [model.column_of(link.element) for link in model.links] == [3, 27]


@pytest.mark.parametrize(
    ("mangle", "quirk"),
    [
        (lambda b: b"\xef\xbb\xbf" + b, "bom"),
        (lambda b: b.replace(b"\n", b"\r\n"), "crlf"),
        (lambda b: b"\n\n" + b, "leading-junk"),
        (lambda b: b + b"\x00\x00\x00\x00", "trailing-junk"),
        (lambda b: b + b"<extra/>", "trailing-junk"),
        (lambda b: b.replace(b'version="1.0"', b'version="0.0"'), "version-0.0"),
        (lambda b: b.replace(b'version="1.0"', b'version="1.0" encoding="ISO-8859-1"').replace(b"tool", b"t\xe9l"),
         "non-utf8-encoding"),
    ],
)
def test_messy_files_load_and_keep_line_numbers(tmp_path, mangle, quirk):
    data = mangle(ARM.encode())
    model = load_model(_write(tmp_path / "messy.urdf", data))
    assert quirk in [q.code for q in model.quirks]
    assert len(model.links) == 3
    line_in_file = data.count(b"\n", 0, data.index(b'<joint name="j1"')) + 1
    assert model.joint("j1").line == line_in_file


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (None, "no such file"),
        (b"", "empty"),
        (bytes(range(256)) * 4, "not well-formed XML"),
        (b'<robot name="a"><link name="x">', "robot.urdf:1: not well-formed XML"),
        (b'<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;">]>\n'
         b'<robot name="&b;"/>', "entity"),
        (b'<?xml version="1.0"?><!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]><robot name="&x;"/>',
         "entity"),
        (b'<sdf version="1.6"><model/></sdf>', "expected <robot>"),
    ],
)
def test_bad_input_is_one_line_user_error(tmp_path, data, expected):
    path = tmp_path / "robot.urdf"
    if data is not None:
        path.write_bytes(data)
    with pytest.raises(UserError) as info:
        load_model(path)
    assert expected in str(info.value)
    assert "\n" not in str(info.value)
    assert "root:" not in str(info.value)  # nothing of /etc/passwd leaks


def test_directory_is_refused(tmp_path):
    with pytest.raises(UserError, match="is a directory"):
        load_model(tmp_path)


def test_size_cap(tmp_path, monkeypatch):
    from ar3cli.infra import safe_read

    monkeypatch.setattr(safe_read, "MAX_FILE_BYTES", 100)
    path = _write(tmp_path / "big.urdf", ARM.encode())
    with pytest.raises(UserError, match="larger than"):
        load_model(path)


def test_parse_floats():
    assert parse_floats("1 2 3", 3) == (1.0, 2.0, 3.0)
    assert parse_floats("1 2", 3) is None
    assert parse_floats("1 x 3", 3) is None
    assert parse_floats(None) is None


# ---- package:// resolution -------------------------------------------------------------------

@pytest.fixture
def package_tree(tmp_path):
    package = tmp_path / "ws" / "src" / "my_robot"
    (package / "meshes").mkdir(parents=True)
    (package / "urdf").mkdir()
    (package / "meshes" / "base.stl").write_bytes(b"solid x\nendsolid x\n")
    (package / "package.xml").write_text("<package><name>my_robot</name></package>")
    return package


def test_package_found_from_ancestor_package_xml(package_tree):
    resolver = PackageResolver(package_tree / "urdf")
    found = resolver.resolve("package://my_robot/meshes/base.stl")
    assert found.path == package_tree / "meshes" / "base.stl" and found.via == "package"


def test_package_path_option_wins(package_tree, tmp_path):
    other = tmp_path / "elsewhere"
    (other / "meshes").mkdir(parents=True)
    (other / "meshes" / "base.stl").write_bytes(b"x")
    resolver = PackageResolver(package_tree / "urdf", parse_package_paths([f"my_robot={other}"]))
    assert resolver.resolve("package://my_robot/meshes/base.stl").path == other / "meshes" / "base.stl"


def test_ros_and_ament_paths(package_tree, tmp_path):
    elsewhere = tmp_path / "robot_file_dir"
    elsewhere.mkdir()
    ros = PackageResolver(elsewhere, environ={"ROS_PACKAGE_PATH": str(package_tree.parent)})
    assert ros.resolve("package://my_robot/meshes/base.stl").found
    share = tmp_path / "install" / "share" / "my_robot" / "meshes"
    share.mkdir(parents=True)
    (share / "base.stl").write_bytes(b"x")
    ament = PackageResolver(elsewhere, environ={"AMENT_PREFIX_PATH": str(tmp_path / "install")})
    assert ament.resolve("package://my_robot/meshes/base.stl").path == share / "base.stl"


def test_unresolved_package_lists_places_tried(tmp_path):
    resolver = PackageResolver(tmp_path, {"nope": tmp_path / "missing"}, environ={})
    result = resolver.resolve("package://nope/meshes/x.stl")
    assert not result.found
    assert str(tmp_path / "missing") in result.explain()
    assert "package 'nope' not found" in result.explain()
    empty = resolver.resolve("package:///meshes/x.stl")
    assert not empty.found and "empty package name" in empty.problem


def test_relative_and_file_uris(package_tree):
    resolver = PackageResolver(package_tree / "urdf")
    assert resolver.resolve("../meshes/base.stl").found
    assert resolver.resolve(f"file://{package_tree}/meshes/base.stl").found
    assert not resolver.resolve("http://example.com/x.stl").found


def test_bad_package_path_option():
    with pytest.raises(ValueError, match="NAME=DIR"):
        parse_package_paths(["nodir"])


# ---- xacro -------------------------------------------------------------------------------------

XACRO = """<?xml version="1.0"?>
<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="length" default="0.5"/>
  <xacro:property name="len" value="$(arg length)"/>
  <link name="base"/>
  <joint name="j" type="prismatic">
    <parent link="base"/><child link="slider"/>
    <limit lower="0" upper="${len}" effort="1" velocity="1"/>
  </joint>
  <link name="slider">
    <visual><geometry><mesh filename="$(find my_robot)/meshes/base.stl"/></geometry></visual>
  </link>
</robot>
"""


def test_xacro_with_args_and_find(package_tree):
    path = package_tree / "urdf" / "robot.urdf.xacro"
    path.write_text(XACRO)
    model = load_model(path, xacro_args={"length": "0.25"})
    assert model.is_xacro
    assert model.joint("j").limit.upper == 0.25
    assert model.link("slider").visuals[0].geometry.resolution.found
    assert load_model(path).joint("j").limit.upper == 0.5


def test_xacro_error_is_one_line(tmp_path):
    path = tmp_path / "bad.xacro"
    path.write_text('<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="${undefined_thing}"/></robot>')
    with pytest.raises(UserError) as info:
        load_model(path)
    assert "xacro error" in str(info.value) and "undefined_thing" in str(info.value)
    assert "\n" not in str(info.value)


def test_xacro_unknown_package(tmp_path):
    path = tmp_path / "bad.xacro"
    path.write_text('<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<link name="a"><visual><geometry><mesh filename="$(find nowhere_pkg)/m.stl"/></geometry>'
                    '</visual></link></robot>')
    with pytest.raises(UserError, match="nowhere_pkg.*--package-path") as info:
        load_model(path)
    assert str(info.value).count("package not found") == 1 and "class" not in str(info.value)


def test_xacro_missing_include_is_said_once(tmp_path):
    path = tmp_path / "inc.xacro"
    path.write_text('<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<xacro:include filename="gone.xacro"/><link name="a"/></robot>')
    with pytest.raises(UserError) as info:
        load_model(path)
    assert f"cannot read {tmp_path / 'gone.xacro'}: No such file or directory" in str(info.value)
    assert str(info.value).count("No such file") == 1


def test_joint_type_sets_are_defined_once(write_urdf):
    """ACTUATED (pybullet's 1-DOF joints) is a subset of MOVING; a spherical joint moves its child."""
    from ar3cli.urdf import model as model_module

    assert model_module.ACTUATED_JOINT_TYPES == ("revolute", "continuous", "prismatic")
    assert set(model_module.ACTUATED_JOINT_TYPES) < set(model_module.MOVING_JOINT_TYPES)
    assert {"planar", "floating", "spherical"} <= set(model_module.MOVING_JOINT_TYPES)
    text = ARM.replace('name="spin" type="continuous"', 'name="spin" type="spherical"')
    model = load_model(write_urdf(text))
    assert model.joint("spin").moves and model.joint("spin") in model.movable_joints()


def test_pybullet_search_climbs_every_folder_and_reads_empty_package_names(tmp_path):
    """PyBullet 3.2.7 finds ``pkg/m.obj``, ``package://pkg/m.obj`` and ``package:///pkg/m.obj`` from a URDF
    20 folders below ``pkg``'s folder (measured). ar3cli searched 3 folders and refused ``package:///``,
    so Talos (example-robot-data's talos_full_v2, 93 such meshes) "could not be loaded" by pybullet,
    which loads it."""
    mesh = tmp_path / "pkg" / "m.obj"
    mesh.parent.mkdir()
    mesh.write_text("v 0 0 0\n")
    deep = tmp_path.joinpath(*[f"a{i}" for i in range(6)])
    deep.mkdir(parents=True)
    resolver = PackageResolver(deep)
    for uri in ("pkg/m.obj", "package://pkg/m.obj", "package:///pkg/m.obj"):
        found = resolver.resolve(uri)
        assert found.path == mesh and found.via == "pybullet-search", uri
    missing = resolver.resolve("package:///pkg/gone.obj")
    assert not missing.found and missing.problem == "empty package name in package:/// URI"
