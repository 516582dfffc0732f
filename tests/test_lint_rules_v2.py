"""lint-urdf v2 (issue 16): the new rules on the cases that set their limits, the false alarms removed
from J005, J011, I006 and G006, the mesh facts behind the geometry rules, and the rule metadata.

Each case is a small robot written to tmp_path; the real-robot counts are in the report of the
change, and tests/test_lint_pybullet_data.py keeps the pybullet_data ones honest.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.lint.rules import FAMILY_ORDER, REGISTRY, RULES, inertia
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from ar3cli.urdf import meshinfo
from tests.conftest import ASSETS
from tests.test_lint_rules import MESHES, TETRAHEDRON, ascii_stl, binary_stl, codes_for, u_shape_stl, write_fixture


def findings(path: Path) -> list:
    options = LintOptions()
    return lint_file(path, options.rules(), options).findings


def rules_of(path: Path) -> set[str]:
    return {f.rule for f in findings(path)}


def tensor(ixx, iyy, izz, mass=1.0) -> str:
    return (f'<inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" '
            f'izz="{izz}"/></inertial>')


def fixed_child(link_extra: str, name: str = "flange") -> str:
    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="{name}">{link_extra}</link>
        <joint name="{name}_joint" type="fixed"><parent link="base"/><child link="{name}"/></joint>""")


def mesh_link(filename: str, role: str = "collision", extra: str = "") -> str:
    return robot(f'<link name="part">{LINK_INERTIAL}<{role}{extra}><geometry><mesh filename="{filename}"/>'
                 f'</geometry></{role}></link>')


# ---- the AR3 stays clean --------------------------------------------------------------------------

def test_the_ar3_stays_clean():
    assert findings(ASSETS / "ar3" / "ar3.urdf") == []


# ---- J005: degrees, not multi-turn radians ---------------------------------------------------------

@pytest.mark.parametrize("lower,upper", [(-3 * math.pi, 3 * math.pi), (-3.05433, 6.80678), (-10, 10), (-6.3, 6.3),
                                         (-1e16, 1e16), (-2.53073, 9.25025), (-12.5, 12.5)],
                         ids=["pm3pi-anymal", "tiago-hand", "pm10-solo", "pm6.3", "unlimited", "tiago-mrl", "pm12.5"])
def test_radian_ranges_of_multi_turn_joints_are_not_degrees(tmp_path, lower, upper):
    text = arm(joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/>')
    assert codes_for(write_fixture(tmp_path, text), "J005") == []


@pytest.mark.parametrize("lower,upper", [(-90, 90), (0, 180), (-170, 170), (-360, 360), (-135, 45), (-720, 720)])
def test_typed_degrees_are_reported(tmp_path, lower, upper):
    text = arm(joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="10" velocity="1"/>')
    (finding,) = codes_for(write_fixture(tmp_path, text), "J005")
    assert "look like degrees" in finding.message and f"{math.radians(upper):.4f}" in finding.hint


# ---- J011: arms, not casters, gears, pendulums or virtual bases --------------------------------------

def _chain(kinds: list[str], names: list[str], shapes: list[str], root_shape: str = "box") -> str:
    geometry = {"box": '<box size="0.1 0.1 0.3"/>', "cylinder": '<cylinder radius="0.05" length="0.02"/>',
                "sphere": '<sphere radius="0.05"/>', "none": ""}

    def link(name: str, shape: str) -> str:
        body = f"<collision><geometry>{geometry[shape]}</geometry></collision>" if shape != "none" else ""
        return f'<link name="{name}">{LINK_INERTIAL}{body}</link>'

    parts = [link("base", root_shape)]
    parent = "base"
    for i, (kind, name, shape) in enumerate(zip(kinds, names, shapes)):
        limit = '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind in ("revolute", "prismatic") else ""
        parts.append(link(name, shape))
        parts.append(f'<joint name="j{i}" type="{kind}"><parent link="{parent}"/><child link="{name}"/>'
                     f'<axis xyz="0 0 1"/>{limit}</joint>')
        parent = name
    return robot("\n".join(parts))


def test_cad_exported_arm_is_flagged(tmp_path):
    text = _chain(["continuous"] * 4, ["link_1", "link_2", "link_3", "link_4"], ["box"] * 4)
    found = codes_for(write_fixture(tmp_path, text), "J011")
    assert [f.message.split("'")[1] for f in found] == ["j0", "j1", "j2"]  # the last one carries nothing


@pytest.mark.parametrize("kinds,names,shapes,root", [
    (["continuous", "continuous"], ["caster_swivel_link", "caster_wheel_link"], ["box", "cylinder"], "box"),
    (["continuous", "continuous"], ["swivel_1_link", "swivel_2_link"], ["box", "cylinder"], "box"),  # by geometry
    (["continuous", "continuous", "continuous"], ["link1", "link2", "link3"], ["sphere"] * 3, "none"),  # pendulum
    (["continuous", "continuous"], ["diff_ring", "diff_spider"], ["cylinder", "cylinder"], "box"),  # differential
    (["prismatic", "continuous", "revolute"], ["x_slider", "torso", "leg"], ["none", "box", "box"], "none"),  # planar base
], ids=["caster-by-name", "caster-by-geometry", "pendulum", "differential", "virtual-planar-base"])
def test_joints_that_spin_by_design_are_not_flagged(tmp_path, kinds, names, shapes, root):
    assert codes_for(write_fixture(tmp_path, _chain(kinds, names, shapes, root)), "J011") == []


# ---- I006 / I008: zero tensors, moving or welded; effectively zero --------------------------------------

def test_zero_tensor_on_a_fixed_link_is_info_and_on_a_moving_link_an_error(tmp_path):
    path = write_fixture(tmp_path, fixed_child(tensor(0, 0, 0)))
    (info,) = codes_for(path, "I008")
    assert info.severity == Severity.INFO and "on fixed joint 'flange_joint'" in info.message
    assert codes_for(path, "I006") == []
    moving = write_fixture(tmp_path, arm(link_extra=tensor(0, 0, 0)))
    (error,) = codes_for(moving, "I006")
    assert error.severity == Severity.ERROR and codes_for(moving, "I008") == []


def test_missing_inertia_element_is_an_error_even_on_a_fixed_link(tmp_path):
    path = write_fixture(tmp_path, fixed_child('<inertial><mass value="1"/></inertial>'))
    assert codes_for(path, "I006") and codes_for(path, "I008") == []


def test_effectively_zero_tensor_is_called_so_not_a_triangle_or_definiteness_problem(tmp_path):
    # icub.urdf r_ankle_1 and l_ankle_2: rounding noise around zero
    for link_extra in (tensor(4.888e-21, 3.547e-20, 5.45e-20, 0.746), tensor(1.355e-20, -1.355e-20, 0, 0.2675)):
        path = write_fixture(tmp_path, arm(link_extra=link_extra))
        (finding,) = codes_for(path, "I006")
        assert "effectively zero" in finding.message
        assert codes_for(path, "I004") == [] and codes_for(path, "I005") == [] and codes_for(path, "I009") == []


# ---- I009: near-singular -------------------------------------------------------------------------

def test_near_singular_tensor_on_a_moving_link(tmp_path):
    path = write_fixture(tmp_path, arm(link_extra=tensor(2.2e-18, 0.215, 0.215)))
    (finding,) = codes_for(path, "I009")
    assert "mjMINVAL" in finding.message and finding.severity == Severity.ERROR
    assert codes_for(path, "I005") == [] and codes_for(path, "I004") == []
    relative = write_fixture(tmp_path, arm(link_extra=tensor(1e-11, 0.2, 0.2)))
    (finding,) = codes_for(relative, "I009")
    assert "of the largest" in finding.message


def test_near_singular_tensor_on_a_fixed_link_is_left_alone(tmp_path):
    assert codes_for(write_fixture(tmp_path, fixed_child(tensor(2.2e-18, 0.215, 0.215))), "I009") == []


def test_a_line_is_a_triangle_violation_that_says_so(tmp_path):
    path = write_fixture(tmp_path, arm(link_extra=tensor(2.118e-22, 2.118e-22, 3e-06)))  # hyq, anymal, go1 base
    (finding,) = codes_for(path, "I005")
    assert "mjMINVAL" in finding.message
    assert codes_for(path, "I009") == []


def test_a_thin_real_rod_is_not_near_singular(tmp_path):
    # 1 kg, 1 m long, 5 mm radius: (1.25e-5, 0.0833, 0.0833), a ratio of 1.5e-4
    assert codes_for(write_fixture(tmp_path, arm(link_extra=tensor(1.25e-5, 0.0833, 0.0833))), "I009") == []


# ---- I010, I011, I012 ---------------------------------------------------------------------------------

def test_mass_zero_with_inertia(tmp_path):
    flange = write_fixture(tmp_path, fixed_child(tensor(0.1, 0.1, 0.1, mass=0)))
    (finding,) = codes_for(flange, "I010")
    assert "adds nothing to the parent" in finding.message and "1 kg sphere in Drake" in finding.message
    static = write_fixture(tmp_path, robot(f'<link name="table">{tensor(1, 1, 1, mass=0)}</link>'))
    assert "static body" in codes_for(static, "I010")[0].message
    assert codes_for(write_fixture(tmp_path, fixed_child(tensor(0, 0, 0, mass=0))), "I010") == []
    moving = write_fixture(tmp_path, arm(link_extra=tensor(0.1, 0.1, 0.1, mass=0)))
    assert codes_for(moving, "I010") == [] and codes_for(moving, "I003")


def test_world_inertial_and_root_without_inertial(tmp_path):
    world = write_fixture(tmp_path, REGISTRY["I011"].bad)
    assert codes_for(world, "I011") and codes_for(world, "I012") == []
    for root in ("base_footprint", "world"):  # frames by convention, with or without geometry
        text = robot(f'<link name="{root}"><visual><geometry><box size="1 1 1"/></geometry></visual></link>')
        assert codes_for(write_fixture(tmp_path, text), "I012") == []
    frame_root = robot(f"""<link name="base"/><link name="chassis">{LINK_INERTIAL}</link>
        <joint name="j" type="fixed"><parent link="base"/><child link="chassis"/></joint>""")
    assert codes_for(write_fixture(tmp_path, frame_root), "I012") == []
    (finding,) = codes_for(write_fixture(tmp_path, REGISTRY["I012"].bad), "I012")
    assert "if this robot floats" in finding.message and "fix-inertia --links chassis" in finding.hint


# ---- J012, J013 ---------------------------------------------------------------------------------------

def _mimic(follower: str, leader: str, target: str = "left_finger") -> str:
    def limit(kind):
        return '<limit lower="-1" upper="1" effort="10" velocity="1"/>' if kind in ("revolute", "prismatic") else ""

    return robot(f"""
        <link name="base">{LINK_INERTIAL}</link><link name="l">{LINK_INERTIAL}</link><link name="r">{LINK_INERTIAL}</link>
        <joint name="left_finger" type="{leader}"><parent link="base"/><child link="l"/><axis xyz="0 1 0"/>{limit(leader)}</joint>
        <joint name="right_finger" type="{follower}"><parent link="base"/><child link="r"/><axis xyz="0 1 0"/>{limit(follower)}
          <mimic joint="{target}"/></joint>""")


@pytest.mark.parametrize("follower,leader", [("fixed", "revolute"), ("revolute", "fixed"), ("fixed", "fixed"),
                                             ("prismatic", "floating")])
def test_mimic_needs_single_dof_joints(tmp_path, follower, leader):
    assert codes_for(write_fixture(tmp_path, _mimic(follower, leader)), "J012")


def test_mimic_of_a_missing_joint_is_s007_only(tmp_path):
    path = write_fixture(tmp_path, _mimic("revolute", "revolute", target="nope"))
    assert codes_for(path, "S007") and codes_for(path, "J012") == []
    assert codes_for(write_fixture(tmp_path, _mimic("prismatic", "revolute")), "J012") == []


def test_planar_and_floating_joints_are_a_portability_note(tmp_path):
    for kind in ("planar", "floating"):
        (finding,) = codes_for(write_fixture(tmp_path, arm(joint_type=kind, joint_extra="")), "J013")
        assert finding.severity == Severity.INFO and "PyBullet" in finding.message
    spherical = write_fixture(tmp_path, arm(joint_type="spherical", joint_extra=""))
    assert codes_for(spherical, "J013") == [] and codes_for(spherical, "S010")


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


# ---- G010: geometry outside the spec ---------------------------------------------------------------------

@pytest.mark.parametrize("geometry,says", [
    ('<capsule radius="0.05" length="0.2"/>', "urdfdom refuses the whole file"),
    ('<plane normal="0 0 1"/>', "only PyBullet reads it"),
    ('<cdf filename="box.cdf"/>', "only PyBullet reads it"),
    ('<mesh filename="meshes/body.vtk"/>', "Drake reads .vtk"),
    ('<cone radius="1" length="1"/>', "no engine"),
])
def test_non_spec_geometry(tmp_path, geometry, says):
    text = robot(f'<link name="b">{LINK_INERTIAL}<collision><geometry>{geometry}</geometry></collision></link>')
    path = write_fixture(tmp_path, text, {"meshes/body.vtk": b"# vtk DataFile Version 2.0\n"})
    (finding,) = codes_for(path, "G010")
    assert says in finding.message
    assert codes_for(path, "G004") == []  # PyBullet accepts the .vtk name: not "cannot load"


def test_drake_extension_is_named_with_its_prefix(tmp_path):
    text = robot(f'''<link name="b">{LINK_INERTIAL}<collision><geometry><drake:capsule radius="0.1" length="0.2"/>
        </geometry></collision></link>''').replace('<robot name="r">', '<robot name="r" xmlns:drake="http://drake.mit.edu">')
    (finding,) = codes_for(write_fixture(tmp_path, text), "G010")
    assert "<drake:capsule> is not URDF: only Drake reads it" in finding.message


# ---- G011: meshes engines cannot read, by content --------------------------------------------------------

@pytest.mark.parametrize("name,data,says", [
    ("part.stl", ascii_stl(), "ASCII STL"),
    ("part.STL", ascii_stl(), "ASCII STL"),
    ("part.stl", binary_stl(TETRAHEDRON)[:-50], "neither a binary STL"),
    ("part.stl", binary_stl([]), "no triangles"),
    ("part.obj", (MESHES / "points.obj").read_bytes(), "no faces"),
])
def test_unreadable_meshes(tmp_path, name, data, says):
    path = write_fixture(tmp_path, mesh_link(f"meshes/{name}", "visual"), {f"meshes/{name}": data})
    (finding,) = codes_for(path, "G011")
    assert says in finding.message


def test_lfs_pointers_are_g005s_not_g011s(tmp_path):
    from tests.test_lint_rules import LFS_POINTER

    path = write_fixture(tmp_path, mesh_link("meshes/part.stl"), {"meshes/part.stl": LFS_POINTER})
    assert codes_for(path, "G005") and codes_for(path, "G011") == []


def test_binary_stl_whose_header_starts_with_solid_is_readable(tmp_path):
    data = binary_stl(TETRAHEDRON, header=b"solid exported by a CAD tool")
    path = write_fixture(tmp_path, mesh_link("meshes/part.stl"), {"meshes/part.stl": data})
    assert codes_for(path, "G011") == []


# ---- G012: flat collision meshes --------------------------------------------------------------------------

def test_flat_collision_meshes(tmp_path):
    files = {f"meshes/{n}": (MESHES / n).read_bytes() for n in ("flat.obj", "tilted_flat.obj")}
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/flat.obj"), files), "G012")
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/tilted_flat.obj"), files), "G012")
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/flat.obj", "visual"), files), "G012") == []
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/base.stl")), "G012") == []


# ---- G013: hull much larger than the mesh -----------------------------------------------------------------

def test_hull_ratio(tmp_path):
    files = {"meshes/u.stl": u_shape_stl()}
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/u.stl"), files), "G013")
    assert "3.3x" in finding.message and finding.severity == Severity.INFO
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/u.stl", "visual"), files), "G013") == []
    concave = mesh_link("meshes/u.stl", extra=' concave="yes"')
    assert codes_for(write_fixture(tmp_path, concave, files), "G013") == []
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/base.stl")), "G013") == []


def test_decomposed_obj_is_one_hull_per_object(tmp_path):
    def cube(offset: float, first: int) -> str:
        corners = [(x + offset, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
        faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),
                 (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
        return ("".join(f"v {x} {y} {z}\n" for x, y, z in corners)
                + "".join(f"f {a + first} {b + first} {c + first}\n" for a, b, c in faces))

    two_parts = cube(0, 1) + cube(4, 9)  # one object: PyBullet makes one hull over both cubes
    decomposed = "o a\n" + cube(0, 1) + "o b\n" + cube(4, 9)  # two objects: a hull each
    files = {"meshes/one.obj": two_parts.encode(), "meshes/two.obj": decomposed.encode()}
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/one.obj"), files), "G013")
    assert "2.5x" in finding.message
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/two.obj"), files), "G013") == []


# ---- G006: COLLADA units -----------------------------------------------------------------------------------

def test_collada_in_inches_is_not_millimetres(tmp_path):
    inches = (MESHES / "cube_inches.dae").read_bytes()
    files = {"meshes/cube.dae": inches, "meshes/cube_m.dae": inches.replace(b'meter="0.0254"', b'meter="1"')}
    assert codes_for(write_fixture(tmp_path, mesh_link("meshes/cube.dae"), files), "G006") == []
    (finding,) = codes_for(write_fixture(tmp_path, mesh_link("meshes/cube_m.dae"), files), "G006")
    assert "6 x 6 x 6 m" in finding.message


# ---- mesh facts ----------------------------------------------------------------------------------------

def test_mesh_content_and_units(tmp_path):
    cases = {"a.stl": ascii_stl(), "b.stl": binary_stl(TETRAHEDRON), "t.stl": binary_stl(TETRAHEDRON)[:-1],
             "e.stl": binary_stl([]), "p.obj": (MESHES / "points.obj").read_bytes(),
             "f.obj": (MESHES / "flat.obj").read_bytes()}
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
    kinds = {name: meshinfo.mesh_content(tmp_path / name) for name in cases}
    assert kinds == {"a.stl": ("stl-ascii", None, None), "b.stl": ("stl-binary", 4, None),
                     "t.stl": ("stl-broken", None, None), "e.stl": ("stl-binary", 0, None),
                     "p.obj": ("obj", 0, 0), "f.obj": ("obj", 2, 1)}
    assert meshinfo.collada_unit(MESHES / "cube_inches.dae") == 0.0254
    (tmp_path / "nounit.dae").write_text('<COLLADA><asset><up_axis>Z_UP</up_axis></asset></COLLADA>')
    assert meshinfo.collada_unit(tmp_path / "nounit.dae") == 1.0
    (tmp_path / "bad.dae").write_text('<COLLADA><asset><unit meter="-1"/></asset></COLLADA>')
    assert meshinfo.collada_unit(tmp_path / "bad.dae") is None


def test_hull_facts(tmp_path):
    (tmp_path / "u.stl").write_bytes(u_shape_stl())
    facts = meshinfo.hull_facts(tmp_path / "u.stl")
    assert facts["closed"] and facts["hull_volume"] / facts["volume"] == pytest.approx(20 / 6, rel=1e-4)
    (tmp_path / "open.stl").write_bytes(binary_stl(TETRAHEDRON[:3]))  # a missing face: not closed
    assert meshinfo.hull_facts(tmp_path / "open.stl")["closed"] is False
    (tmp_path / "flipped.stl").write_bytes(binary_stl([TETRAHEDRON[0][::-1], *TETRAHEDRON[1:]]))
    assert meshinfo.hull_facts(tmp_path / "flipped.stl")["closed"] is False  # inconsistent winding
    (tmp_path / "big.stl").write_bytes(binary_stl(TETRAHEDRON) + b"\0" * meshinfo.HULL_MAX_BYTES)
    assert meshinfo.hull_facts(tmp_path / "big.stl") is None


def test_plain_python_and_numpy_hull_paths_agree(tmp_path):
    for data in (u_shape_stl(), binary_stl(TETRAHEDRON), binary_stl(TETRAHEDRON[:3])):
        (tmp_path / "m.stl").write_bytes(data)
        corners = meshinfo._corners(tmp_path / "m.stl", "stl-binary")
        plain, fast = meshinfo._closed_volume_and_hull(corners), meshinfo._numpy_closed_volume_and_hull(corners)
        assert plain["closed"] == fast["closed"]
        assert plain["volume"] == pytest.approx(fast["volume"], rel=1e-9)
        assert plain["hull_volume"] == pytest.approx(fast["hull_volume"], rel=0.05)


def test_hull_volume_is_exact_for_a_box_and_zero_for_a_plane():
    box = [(x, y, z) for x in (0, 2) for y in (0, 3) for z in (0, 4)] + [(1, 1, 1), (1, 1.5, 4)]
    assert meshinfo._hull_volume(box, 10) == pytest.approx(24, rel=1e-5)
    assert meshinfo._hull_volume([(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0), (0.5, 0.5, 0)], 2) == 0.0


# ---- metadata ------------------------------------------------------------------------------------------

def test_fix_inertia_fixes_exactly_the_rules_that_say_so():
    for rule in inertia.FIXED_BY_FIX_INERTIA:
        assert rule.fixed_by and rule.fixed_by.startswith("fix-inertia"), rule.code
    for rule in inertia.NOT_FIXED_BY_FIX_INERTIA:
        assert rule.fixed_by is None, rule.code
    assert inertia.FIXED_BY_FIX_INERTIA[-1].code == "I007"  # fix-inertia reads I007 as "nothing invalid": it must come last
    assert {r.code for r in RULES if r.fixed_by and r.fixed_by.startswith("fix-inertia")} == \
        {r.code for r in inertia.FIXED_BY_FIX_INERTIA}


def test_metadata_reaches_the_docs_and_the_rule_object():
    from ar3cli.lint.rules.docs import generate

    text = generate()
    assert "**Fixed by.** `ar3cli fix-continuous --limits-from joint_limits.yaml`." in text
    assert "**Thresholds.** Smallest principal moment below MJ_MINVAL = 1e-15" in text
    assert "**References.** MuJoCo include/mujoco/mjtnum.h" in text
    assert REGISTRY["J006"].fixed_by == "fix-continuous"
    codes = [r.code for r in RULES]
    assert codes == sorted(codes, key=lambda c: (FAMILY_ORDER.index(c[0]), c))


# ---- J005 and J003/J014 on virtual base joints and PyBullet's "no limit" idiom (issue 30) ----------
JOINT_DATA = Path(__file__).parent / "data" / "joints"


def _hand(massive_dummies: bool = False, prismatic_range: str = "-20 20") -> str:
    """The floating hand fixture, with heavier dummy links or other prismatic limits."""
    text = (JOINT_DATA / "floating_hand.urdf").read_text()
    if massive_dummies:
        for name in ("dummy_x", "dummy_y", "dummy_z", "dummy_ry"):
            text = text.replace(f'<link name="{name}"/>', f'<link name="{name}">{tensor(0.01, 0.01, 0.01, 0.5)}</link>')
    lower, upper = prismatic_range.split()
    for axis in "xyz":
        start = text.index(f'<joint name="virtual_{axis}"')
        end = text.index("</joint>", start)
        text = text[:start] + text[start:end].replace('lower="-20" upper="20"', f'lower="{lower}" upper="{upper}"') \
            + text[end:]
    return text


@pytest.mark.parametrize("massive_dummies,prismatic_range", [(False, "-20 20"), (True, "-20 20"), (False, "-1 1")],
                         ids=["both-kinds-of-evidence", "shared-range-only", "massless-chain-only"])
def test_virtual_base_joints_are_not_degrees(tmp_path, massive_dummies, prismatic_range):
    text = _hand(massive_dummies, prismatic_range)
    (finding,) = codes_for(write_fixture(tmp_path, text), "J005")
    assert "'finger_joint'" in finding.message  # the real degree typo of the same hand is still reported


def test_heavy_dummies_with_other_ranges_are_judged_as_usual(tmp_path):
    """Neither shared limits nor a massless chain: nothing says 'virtual', so ±20 still looks like degrees."""
    reported = codes_for(write_fixture(tmp_path, _hand(True, "-1 1")), "J005")
    assert sorted(f.message.split("'")[1] for f in reported) == ["finger_joint", "virtual_rx", "virtual_ry", "virtual_rz"]


def test_first_joint_from_an_empty_root_is_still_judged(tmp_path):
    """An empty root link alone (no moving joint between dummies) is no floating chain."""
    text = arm(joint_extra='<limit lower="-170" upper="170" effort="10" velocity="1"/>')
    assert len(codes_for(write_fixture(tmp_path, text), "J005")) == 1


def test_pybullet_no_limit_idiom_is_explained_not_inverted(tmp_path):
    path = write_fixture(tmp_path, (JOINT_DATA / "pybullet_unlimited.urdf").read_text())
    (inverted,) = codes_for(path, "J003")
    assert "'shoulder'" in inverted.message
    idioms = codes_for(path, "J014")
    assert [f.message.split("'")[1] for f in idioms] == ["x_to_world", "z_to_x"]
    assert all(f.severity == Severity.INFO and "no limit" in f.message for f in idioms)


@pytest.mark.parametrize("lower,upper,code", [(1, -1, "J014"), (0, -1, "J014"), (1.5, -1.5, "J003"), (2, -1, "J003")])
def test_only_the_exact_idiom_pairs_are_pybullets(tmp_path, lower, upper, code):
    text = arm(joint_type="prismatic", joint_extra=f'<limit lower="{lower}" upper="{upper}" effort="1" velocity="1"/>')
    path = write_fixture(tmp_path, text)
    assert len(codes_for(path, code)) == 1 and codes_for(path, {"J003": "J014", "J014": "J003"}[code]) == []


# ---- COLLADA <unit meter> in the boxes every size rule uses (issue 30 item 16) ----------------------

def _inch_cube_link(tmp_path: Path, inertial: str) -> Path:
    """A link whose collision is tests/data/meshes/cube_inches.dae: 6 units of 0.0254 m, a 15.24 cm cube."""
    return write_fixture(tmp_path, robot(f'<link name="part">{inertial}<collision><geometry>'
                                         '<mesh filename="cube_inches.dae"/></geometry></collision></link>'),
                         files={"cube_inches.dae": (MESHES / "cube_inches.dae").read_bytes()})


def test_collada_unit_is_applied_to_link_bounds(tmp_path):
    from ar3cli.urdf.bounds import link_bounds, scaled_mesh_bounds
    from ar3cli.urdf.model import load_model

    link = load_model(_inch_cube_link(tmp_path, LINK_INERTIAL)).link("part")
    low, high = link_bounds(link)
    assert low == (0.0, 0.0, 0.0) and high == pytest.approx((0.1524,) * 3, rel=1e-9)
    assert scaled_mesh_bounds(link.collisions[0].geometry)[1] == pytest.approx((6.0,) * 3)  # file units, for G006


def test_implausible_inertia_is_judged_in_metres_for_an_inch_mesh(tmp_path):
    """I = 1 kg·m² on 1 kg: a radius of gyration of 1 m, 7x a 15 cm cube (but not 6 m, the size in file units)."""
    (finding,) = codes_for(_inch_cube_link(tmp_path, tensor(1, 1, 1)), "I007")
    assert "half-diagonal 0.132 m" in finding.message


# ---- --fix-hint asks for a mass source only where fix-inertia needs one (issue 30 item 13) ----------

def test_fix_hint_asks_no_density_for_frame_links(tmp_path):
    from ar3cli.lint.fix_hints import fix_commands

    frame_only = findings(write_fixture(tmp_path / "frame", fixed_child("")))
    assert [f.rule for f in frame_only if f.rule.startswith("I")] == ["I002"]
    assert fix_commands("robot.urdf", frame_only) == ["ar3cli fix-inertia robot.urdf  # I002"]
    part = findings(write_fixture(tmp_path / "part", fixed_child(
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>')))
    assert fix_commands("robot.urdf", [f for f in part if f.rule == "I002"]) == [
        "ar3cli fix-inertia robot.urdf --density KG_PER_M3  # I002"]
