"""``ar3cli info``: tree, DOF, limits, masses, centre of mass, bounding box, meshes, end effectors.

The expectations are computed independently of ar3cli, from the XML with lxml (masses, DOF, leaf
links) or by hand (the small fixture's centre of mass and box).
"""

from __future__ import annotations

import json
import math
import struct
from pathlib import Path

import pytest
from lxml import etree

from tests.conftest import ASSETS

AR3 = ASSETS / "ar3" / "ar3.urdf"
AR3_XACRO = ASSETS / "ar3" / "ar3.urdf.xacro"
ONE_DOF_TYPES = ("revolute", "continuous", "prismatic")

SMALL = """<?xml version="1.0"?>
<robot name="small">
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry></visual>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></visual>
    <collision><geometry><mesh filename="tri.stl"/></geometry></collision>
  </link>
  <link name="wheel">
    <visual><geometry><mesh filename="package://not_installed/wheel.obj"/></geometry></visual>
  </link>
  <link name="finger_a"><inertial><mass value="0.25"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="finger_b"><inertial><mass value="0.25"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>
  </joint>
  <joint name="spin" type="continuous">
    <parent link="arm"/><child link="wheel"/><origin xyz="1 0 0"/><axis xyz="1 0 0"/>
    <limit effort="1" velocity="5"/>
  </joint>
  <joint name="grip" type="prismatic">
    <parent link="arm"/><child link="finger_a"/><origin xyz="1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.02" effort="5" velocity="0.1"/>
  </joint>
  <joint name="grip_mirror" type="prismatic">
    <parent link="arm"/><child link="finger_b"/><origin xyz="1 0 0"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.02" effort="5" velocity="0.1"/>
    <mimic joint="grip" multiplier="1"/>
  </joint>
</robot>
"""
"""DOF 3 (the mimic follows), 3.5 kg, 'wheel' has no inertial; COM and box worked out by hand below."""


def binary_stl(triangles: int) -> bytes:
    record = struct.pack("<12fH", *([0.0] * 3), 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0, 0)
    return b"\0" * 80 + struct.pack("<I", triangles) + record * triangles


@pytest.fixture
def small(write_urdf) -> Path:
    path = write_urdf(SMALL, "small/small.urdf")
    (path.parent / "tri.stl").write_bytes(binary_stl(3))
    return path


def xml_facts(path: Path) -> dict:
    """Masses, DOF and leaf links straight from the XML."""
    root = etree.parse(str(path)).getroot()
    masses = [float(m.get("value")) for m in root.xpath("/robot/link/inertial/mass")]
    joints = root.findall("joint")
    dof = sum(1 for j in joints if j.get("type") in ONE_DOF_TYPES and j.find("mimic") is None)
    parents = {j.find("parent").get("link") for j in joints}
    leaves = [link.get("name") for link in root.findall("link") if link.get("name") not in parents]
    return {"mass": math.fsum(masses), "dof": dof, "leaves": leaves}


def robots(pybullet_data_dir: Path, small: Path) -> dict[str, Path]:
    return {"ar3": AR3, "panda": pybullet_data_dir / "franka_panda" / "panda.urdf", "small": small}


@pytest.mark.parametrize("robot", ["ar3", "panda", "small"])
def test_json_totals_match_the_xml(cli, robot, pybullet_data_dir, small):
    path = robots(pybullet_data_dir, small)[robot]
    result = cli("info", str(path), "--format", "json")
    assert result.code == 0 and result.stderr == "", result.stderr
    data = json.loads(result.stdout)  # stdout is the JSON document and nothing else
    expected = xml_facts(path)
    assert data["total_mass_kg"] == pytest.approx(expected["mass"], abs=1e-12)
    assert data["dof"] == expected["dof"]
    assert data["end_effectors"] == expected["leaves"]
    assert len(data["links"]) == data["link_count"] and len(data["joints"]) == data["joint_count"]


def test_small_fixture_in_detail(cli, small):
    data = json.loads(cli("info", str(small), "-f", "json").stdout)
    assert data["dof"] == 3 and data["movable_joint_count"] == 4
    assert data["links_without_mass"] == [{"link": "wheel", "why": "no inertial"}]
    joints = {joint["name"]: joint for joint in data["joints"]}
    assert joints["spin"]["unlimited"] and joints["spin"]["lower"] is None and joints["spin"]["upper"] is None
    assert joints["grip_mirror"]["mimic"] == {"joint": "grip", "multiplier": 1.0, "offset": 0.0}
    assert joints["grip_mirror"]["dof"] == 0
    assert joints["shoulder"]["lower"] == -1.5 and joints["shoulder"]["effort"] == 10
    # base 2 kg at the origin, arm 1 kg at (0.5, 0, 0.3), fingers 0.25 kg each at (1, 0, 0.3).
    assert data["centre_of_mass_m"] == pytest.approx([1.0 / 3.5, 0, 1.5 * 0.3 / 3.5])
    # base box z -0.05..0.05 and +-0.1 in x, y; the arm's box x 0..1, z 0.25..0.35; the STL is a collision
    # shape of a link with a visual, and the wheel's mesh does not resolve.
    box = data["bounding_box_m"]
    assert box["min"] == pytest.approx([-0.1, -0.1, -0.05]) and box["max"] == pytest.approx([1.0, 0.1, 0.35])
    assert box["shapes"] == 2 and box["shapes_left_out"] == 1
    meshes = data["meshes"]
    assert meshes["references"] == 2 and meshes["files"] == 2 and meshes["formats"] == {"obj": 1, "stl": 1}
    assert [item["uri"] for item in meshes["unresolved"]] == ["package://not_installed/wheel.obj"]
    assert meshes["triangles"] == 3 and meshes["triangles_counted_files"] == 1
    assert meshes["triangles_by_role"] == {"visual": None, "collision": 3}


def test_text_output_on_the_ar3(cli):
    result = cli("info", str(AR3))
    assert result.code == 0 and result.stderr == ""
    out = result.stdout
    assert "kinematic tree of ar3" in out and "base_link  (root)" in out
    assert "link_1  (joint_1: revolute, axis 0 0 1, -2.967 .. 2.967 rad)" in out
    assert "DOF 8: 8 movable joints (6 revolute, 2 prismatic)" in out
    assert "end effectors (leaf links, 3): finger_left, finger_right, tcp" in out
    assert "meshes: none" in out


def test_text_output_says_unlimited_mimic_and_unresolved(cli, small):
    out = cli("info", str(small)).stdout
    assert "wheel  (spin: continuous, axis 1 0 0, unlimited)" in out
    assert "follows grip" in out and "of which 1 mimic" in out
    assert "wheel (no inertial)" in out
    assert "unresolved meshes (1 of 2 files: package 'not_installed' not found): package://not_installed/wheel.obj" \
        in out
    assert "3 triangles (collision 3) in 1 of 2 files, counted for binary STL only" in out


def test_xacro_input(cli):
    result = cli("info", str(AR3_XACRO), "--format", "json")
    assert result.code == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["dof"] == 8 and data["total_mass_kg"] == pytest.approx(xml_facts(AR3)["mass"])


def test_missing_file_is_one_line_exit_2(cli, tmp_path):
    result = cli("info", str(tmp_path / "nope.urdf"), "--format", "json")
    assert result.code == 2 and result.stdout == ""
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("ar3cli: error: ") and "nope.urdf" in line


def test_a_loop_is_reported_not_followed(write_urdf):
    """The FK walks joints without a visited set; info must not hand it a loop (it would never end)."""
    from ar3cli.info.summary import summarize
    from ar3cli.urdf.model import load_model

    path = write_urdf("""<robot name="loop"><link name="r"/><link name="p"/><link name="q"/>
      <joint name="a" type="fixed"><parent link="r"/><child link="p"/></joint>
      <joint name="b" type="continuous"><parent link="p"/><child link="q"/></joint>
      <joint name="c" type="continuous"><parent link="q"/><child link="p"/></joint></robot>""")

    def never(_model):
        raise AssertionError("the FK must not be asked")

    summary = summarize(load_model(path), never)
    assert summary.centre_of_mass is None and "leads back to link 'p'" in summary.notes[0]


def test_floating_joint_and_two_roots(write_urdf):
    """A floating joint is the identity at zero (the FK sees it as fixed); two roots leave COM and box
    out with the reason, and everything else is still reported."""
    from ar3cli.info.summary import summarize
    from ar3cli.kinematics.fk import urdf_link_frames
    from ar3cli.urdf.model import load_model

    def frames(model):
        return {name: value[0] for name, value in urdf_link_frames(model, {}, 1).items()}

    inertial = '<inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
    floating = write_urdf(f"""<robot name="f"><link name="world"/><link name="body">{inertial}</link>
      <joint name="free" type="floating"><parent link="world"/><child link="body"/><origin xyz="0 0 2"/></joint></robot>""")
    summary = summarize(load_model(floating), frames)
    assert summary.dof == 6 and summary.centre_of_mass == pytest.approx((0, 0, 2))
    two_roots = write_urdf(f'<robot name="t"><link name="a">{inertial}</link><link name="b">{inertial}</link></robot>',
                           "two.urdf")
    summary = summarize(load_model(two_roots), frames)
    assert summary.total_mass == 2 and summary.centre_of_mass is None and "expected one root link" in summary.notes[0]


def test_binary_stl_triangles_reads_the_header_only(tmp_path):
    from ar3cli.info.meshes import binary_stl_triangles

    (tmp_path / "b.stl").write_bytes(binary_stl(5))
    (tmp_path / "a.stl").write_text("solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                    "vertex 0 1 0\nendloop\nendfacet\nendsolid a\n")
    (tmp_path / "short.stl").write_bytes(binary_stl(5)[:-10])
    assert binary_stl_triangles(tmp_path / "b.stl") == 5
    assert binary_stl_triangles(tmp_path / "a.stl") is None
    assert binary_stl_triangles(tmp_path / "short.stl") is None
    assert binary_stl_triangles(tmp_path / "missing.stl") is None


def test_box_prefers_geometry_that_needs_no_trimesh(write_urdf):
    """A COLLADA visual with an STL collision (the UR arms) is bounded by the collision: reading the
    COLLADA file would import trimesh (seconds on a first run)."""
    from ar3cli.info.summary import box_shapes
    from ar3cli.urdf.model import load_model

    path = write_urdf("""<robot name="r">
      <link name="dae_visual"><visual><geometry><mesh filename="v.dae"/></geometry></visual>
        <collision><geometry><mesh filename="c.stl"/></geometry></collision></link>
      <link name="stl_visual"><visual><geometry><mesh filename="c.stl"/></geometry></visual>
        <collision><geometry><mesh filename="v.dae"/></geometry></collision></link>
      <link name="collision_only"><collision><geometry><box size="1 1 1"/></geometry></collision></link></robot>""")
    (path.parent / "v.dae").write_text("<COLLADA/>")
    (path.parent / "c.stl").write_bytes(binary_stl(1))
    model = load_model(path)
    assert [[shape.role for shape in box_shapes(link)] for link in model.links] == \
        [["collision"], ["visual"], ["collision"]]


def _ink(image, box=None) -> int:
    """Pixels that are not white (in ``box`` when given)."""
    region = image.convert("L") if box is None else image.convert("L").crop(box)
    return sum(count for count, value in region.getcolors(1 << 16) if value < 250)


def test_png_of_the_tree(cli, tmp_path, pybullet_data_dir):
    """The picture exists, grows with the tree (a chain is tall and narrow, the TIAGo-like hand wide),
    and is not blank."""
    from PIL import Image

    sizes = {}
    for name, path in [("ar3", AR3), ("panda", pybullet_data_dir / "franka_panda" / "panda.urdf")]:
        out = tmp_path / f"{name}.png"
        result = cli("info", str(path), "--png", str(out), "--format", "json")
        assert result.code == 0, result.stderr
        assert json.loads(result.stdout)["png"] == str(out)
        image = Image.open(out)
        assert image.format == "PNG"
        sizes[name] = image.size
        assert _ink(image) > 2000  # boxes, labels and edges were drawn
        assert _ink(image, (0, image.height // 2, image.width, image.height)) > 500  # the lower half too
    # The AR3: 9 levels, 3 leaves side by side; the panda: 12 levels (fingers under the hand).
    assert sizes["ar3"][1] > sizes["ar3"][0] and sizes["panda"][1] > sizes["ar3"][1]
    assert 200 < sizes["ar3"][0] < 600 and 600 < sizes["ar3"][1] < 1200


def test_png_of_a_wide_tree_and_a_loop(tmp_path, write_urdf):
    """60 siblings side by side: the canvas widens so no two labels overlap; a loop joint is listed."""
    from PIL import Image

    from ar3cli.info.summary import summarize
    from ar3cli.info.tree_png import tree_png
    from ar3cli.urdf.model import load_model

    links = "".join(f'<link name="leaf_{i}"/>' for i in range(60))
    joints = "".join(f'<joint name="j{i}" type="revolute"><parent link="hub"/><child link="leaf_{i}"/>'
                     '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>' for i in range(60))
    wide = write_urdf(f'<robot name="w"><link name="hub"/>{links}{joints}</robot>')
    data = tree_png(summarize(load_model(wide), lambda model: {}))
    (tmp_path / "wide.png").write_bytes(data)
    image = Image.open(tmp_path / "wide.png")
    assert image.width > 60 * 50 and image.height < 300
    loop = write_urdf("""<robot name="loop"><link name="r"/><link name="p"/><link name="q"/>
      <joint name="a" type="fixed"><parent link="r"/><child link="p"/></joint>
      <joint name="b" type="continuous"><parent link="p"/><child link="q"/></joint>
      <joint name="c" type="continuous"><parent link="q"/><child link="p"/></joint></robot>""", "loop.urdf")
    assert tree_png(summarize(load_model(loop), lambda model: {}))[:8] == b"\x89PNG\r\n\x1a\n"


def test_png_refused_before_any_work(cli, tmp_path):
    for bad, message in [(tmp_path / "tree.jpg", "--png"), (tmp_path / "nodir" / "tree.png", "does not exist")]:
        result = cli("info", str(tmp_path / "missing.urdf"), "--png", str(bad))
        assert result.code == 2 and result.stdout == "", result.stderr
        (line,) = result.stderr.strip().splitlines()
        assert message in line and "missing.urdf" not in line  # refused before the robot is read
    assert "must end in .png" in cli("info", str(AR3), "--png", str(tmp_path / "t.jpg")).stderr


def test_info_says_what_pybullet_weighs(cli, session):
    """jackal's root frame and sensor frames have no <inertial>: PyBullet gives each 1 kg (a fixed base 0)."""
    from ar3cli.urdf.model import load_model

    path = Path(__file__).parent / "data" / "inertia" / "jackal_frames.urdf"
    result = cli("info", str(path), "--format", "json")
    data = json.loads(result.stdout)
    assert data["total_mass_kg"] == pytest.approx(17.0)
    for fixed, key in ((False, "floating"), (True, "fixed_base")):
        body = session.load(load_model(path), fixed_base=fixed)
        simulated = sum(body.dynamics(name).mass for name in body.link_names)
        assert data["pybullet_mass_kg"][key] == pytest.approx(simulated)
        body.remove()
    assert data["pybullet_mass_kg"] == {"floating": pytest.approx(20.0), "fixed_base": pytest.approx(19.0)}
    text = cli("info", str(path)).stdout
    assert "PyBullet simulates 20 kg floating, 19 kg with a fixed base" in text


def test_an_srdf_is_one_line_not_empty_tables(cli):
    path = Path(__file__).parent / "data" / "srdf" / "ar3.srdf"
    result = cli("info", str(path))
    assert result.code == 2 and result.stdout == ""
    assert result.stderr.strip() == (f"ar3cli: error: {path}: is an SRDF (MoveIt's semantic description: <group>, no "
                                     "<link>), not a URDF; give the URDF it describes (sample-collisions "
                                     "--srdf-compare reads an SRDF)")
