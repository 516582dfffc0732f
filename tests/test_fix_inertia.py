"""ar3cli fix-inertia on textbook shapes, real meshes and real robots with injected defects."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

from ar3cli.fix.geometry_mass import capsule
from ar3cli.fix.inertia_plan import links_needing_inertia
from ar3cli.maths import mass_properties as mp
from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS
from tests.fixer_helpers import element_lines, lint_findings, only_within, remove_inertial, replace_in_link, write

KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")

TEXTBOOK = """<?xml version="1.0"?>
<robot name="textbook">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="box"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="box">
    <collision><geometry><box size="0.1 0.2 0.4"/></geometry></collision>
  </link>
  <joint name="j2" type="revolute"><parent link="box"/><child link="cyl"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="cyl">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="5"/></inertial>
    <collision><geometry><cylinder radius="0.1" length="0.4"/></geometry></collision>
  </link>
  <joint name="j3" type="continuous"><parent link="cyl"/><child link="ball"/></joint>
  <link name="ball">
    <inertial>
      <mass value="1"/>
      <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>
    </inertial>
    <visual><geometry><sphere radius="0.1"/></geometry></visual>
  </link>
</robot>
"""


def inertial_of(path: Path, link: str) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass, com, 3x3 tensor) of a link as written in the file."""
    inertial = load_model(path).link(link).inertial
    return inertial.mass, np.array(inertial.origin.xyz), np.array(inertial.matrix())


def test_textbook_values_are_exact(cli, write_urdf):
    path = write_urdf(TEXTBOOK)
    result = cli("fix-inertia", str(path), "--mass", "box=2", "--format", "json")
    assert result.code == 0, result.stderr
    sources = {(c["element"], c["field"]): c["source"] for c in json.loads(result.stdout)["files"][0]["changes"]}
    expected = {"box": (2.0, (1 / 30, 0.085 / 3, 0.025 / 3)), "cyl": (1.0, (0.19 / 12, 0.19 / 12, 0.005)),
                "ball": (1.0, (0.004, 0.004, 0.004))}
    for link, (mass, diagonal) in expected.items():
        got_mass, com, tensor = inertial_of(path, link)
        assert got_mass == mass
        np.testing.assert_allclose(tensor, np.diag(diagonal), rtol=0, atol=1e-9)
        np.testing.assert_allclose(com, 0, atol=0)
    assert np.isclose(inertial_of(path, "box")[2][0, 0], 0.0333333333333, atol=1e-12)
    assert sources[("link box <inertial>", "inertia")] == "collision: box 0.1x0.2x0.4 analytic"
    assert sources[("link box <inertial>", "mass")] == "--mass box=2"
    assert sources[("link cyl <inertial>", "inertia")] == "collision: cylinder r=0.1 l=0.4 analytic"
    second = cli("fix-inertia", str(path), "--check")
    assert second.code == 0 and "nothing to change" in second.stdout


def test_capsule_matches_a_fine_trimesh_capsule():
    import trimesh

    mesh = trimesh.creation.capsule(height=0.3, radius=0.05, count=[128, 128])
    props = capsule(0.05, 0.3)
    assert props.mass == pytest.approx(mesh.volume, rel=2e-3)
    np.testing.assert_allclose(props.inertia, mesh.moment_inertia, rtol=5e-3, atol=1e-12)


def test_scaled_rotated_mesh_from_pybullet_data(cli, write_urdf, pybullet_data_dir):
    """cube.obj (unit cube, vertices split by texture coords) scaled to 0.1x0.2x0.3, rotated and offset."""
    cube = pybullet_data_dir / "cube.obj"
    path = write_urdf(f"""<robot name="m">
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a">
    <collision><origin xyz="0.1 0 0.05" rpy="0.3 0 0.5"/>
      <geometry><mesh filename="{cube}" scale="0.1 0.2 0.3"/></geometry></collision>
  </link>
</robot>
""")
    result = cli("fix-inertia", str(path), "--density", "1000", "--format", "json")
    assert result.code == 0, result.stderr
    sources = {c["source"] for c in json.loads(result.stdout)["files"][0]["changes"]}
    assert any("cube.obj scale 0.1 0.2 0.3 watertight, exact" in s for s in sources)
    expected = mp.transformed(mp.box((0.1, 0.2, 0.3), density=1000.0), (0.1, 0, 0.05), (0.3, 0, 0.5))
    mass, com, tensor = inertial_of(path, "a")
    assert mass == pytest.approx(6.0, abs=1e-9)
    np.testing.assert_allclose(com, expected.com, atol=1e-9)
    np.testing.assert_allclose(tensor, expected.inertia, atol=1e-9)


def test_watertight_pybullet_mesh_matches_trimesh(cli, write_urdf, pybullet_data_dir):
    import trimesh

    duck = pybullet_data_dir / "duck_vhacd.obj"
    path = write_urdf(f"""<robot name="d"><link name="base"/>
  <joint name="j" type="continuous"><parent link="base"/><child link="duck"/></joint>
  <link name="duck"><collision><geometry><mesh filename="{duck}" scale="0.05 0.05 0.05"/></geometry></collision></link>
</robot>""")
    assert cli("fix-inertia", str(path), "--total-mass", "0.5").code == 0
    mesh = trimesh.load(duck, force="mesh")
    mesh.apply_scale(0.05)
    mesh.density = 0.5 / mesh.volume
    mass, com, tensor = inertial_of(path, "duck")
    assert mass == pytest.approx(0.5, rel=1e-9)
    np.testing.assert_allclose(com, mesh.center_mass, atol=1e-9)
    np.testing.assert_allclose(tensor, mesh.moment_inertia, rtol=1e-6, atol=1e-12)


def test_no_mass_source_is_reported_and_left_alone(cli, write_urdf):
    path = write_urdf(TEXTBOOK)
    before = path.read_bytes()
    result = cli("fix-inertia", str(path), "--links", "box", env={"COLUMNS": "1000"})  # a row a line
    assert result.code == 1
    assert "no valid mass in the file: give --density, --mass box=KG or --total-mass" in result.stdout
    assert path.read_bytes() == before


def test_total_mass_is_spread_by_volume(cli, write_urdf):
    text = TEXTBOOK.replace('<mass value="1"/><inertia ixx="1"', '<mass value="0"/><inertia ixx="1"')
    path = write_urdf(text)  # cyl (volume 0.004 pi) loses its mass; box has none; ball keeps 1 kg
    result = cli("fix-inertia", str(path), "--total-mass", "5")
    assert result.code == 0, result.stdout + result.stderr
    box_mass, cyl_mass, ball_mass = (inertial_of(path, name)[0] for name in ("box", "cyl", "ball"))
    assert ball_mass == 1.0 and box_mass + cyl_mass == pytest.approx(4.0, rel=1e-9)
    assert box_mass / cyl_mass == pytest.approx(0.008 / (np.pi * 0.01 * 0.4), rel=1e-9)


def _load_clean_in_pybullet(path: Path, package_path: dict | None = None) -> list[str]:
    from ar3cli.sim.session import Session

    model = load_model(path, package_path)
    with Session() as session:
        session.load(model)
        return session.messages


@pytest.mark.parametrize("defect", ["remove", "zero-mass", "negative-tensor", "triangle"])
def test_injected_defects_on_ar3_asset(cli, tmp_path, defect):
    """The asset's link_4 inertial was computed from its geometry at its real mass: the fix must give it back."""
    original = (ASSETS / "ar3" / "ar3.urdf").read_text()
    if defect == "remove":
        broken, args = remove_inertial(original, "link_4"), ["--mass", "link_4=0.34936"]
    elif defect == "zero-mass":
        broken, args = replace_in_link(original, "link_4", '<mass value="0.34936"/>', '<mass value="0"/>'), \
            ["--density", "1000", "--mass", "link_4=0.34936"]
    elif defect == "negative-tensor":
        broken, args = replace_in_link(original, "link_4", 'ixx="', 'ixx="-'), []
    else:
        broken, args = replace_in_link(original, "link_4", 'izz="', 'izz="9'), []
    path = write(tmp_path / "ar3.urdf", broken)
    assert "link_4" in links_needing_inertia(load_model(path))
    result = cli("fix-inertia", str(path), *args)
    assert result.code == 0, result.stdout + result.stderr
    fixed = path.read_text()
    assert only_within(broken, fixed, [element_lines(broken, r'<link name="link_4"', "</link>")])
    assert links_needing_inertia(load_model(path)) == {}
    assert lint_findings(cli, path, "I") == []  # the real linter agrees
    want = load_model(ASSETS / "ar3" / "ar3.urdf").link("link_4").inertial
    mass, com, tensor = inertial_of(path, "link_4")
    assert mass == want.mass
    np.testing.assert_allclose(com, want.origin.xyz, atol=1e-6)
    np.testing.assert_allclose(tensor, want.matrix(), rtol=1e-6, atol=1e-10)
    assert not any("No inertial data" in m for m in _load_clean_in_pybullet(path))
    assert cli("fix-inertia", str(path), *args, "--check").code == 0


def test_frame_link_gets_a_tiny_inertial_and_leaves_gravity_torques_alone(cli, tmp_path):
    from ar3cli.sim.session import Session

    original = (ASSETS / "ar3" / "ar3.urdf").read_text()
    path = write(tmp_path / "ar3.urdf", remove_inertial(original, "tcp"))
    assert "tcp" in links_needing_inertia(load_model(path))
    assert cli("fix-inertia", str(path)).code == 0
    mass, _, tensor = inertial_of(path, "tcp")
    assert mass == 1e-6 and np.allclose(tensor, np.eye(3) * 1e-12, atol=0)
    torques = []
    for variant in (tmp_path / "ar3.urdf", ASSETS / "ar3" / "ar3.urdf"):
        with Session(gravity=-9.81) as session:
            body = session.load(load_model(variant))
            count = len(body.actuated_joints)
            torques.append(session.p.calculateInverseDynamics(body.id, [0.3] * count, [0.0] * count, [0.0] * count,
                                                              physicsClientId=session.client))
            assert not any("No inertial data" in m for m in session.messages)
    np.testing.assert_allclose(torques[0], torques[1], atol=1e-9)


def _pybullet_copy(tmp_path: Path, source: Path) -> Path:
    """Copy a pybullet_data URDF next to a symlink of its meshes folder."""
    target = tmp_path / source.name
    (tmp_path / "meshes").symlink_to(source.parent / "meshes")
    target.write_text(source.read_text())
    return target


def test_kuka_broken_tensor_recomputed_from_the_hull(cli, tmp_path, pybullet_data_dir):
    import trimesh

    path = _pybullet_copy(tmp_path, pybullet_data_dir / "kuka_iiwa" / "model.urdf")
    original = path.read_text()
    broken = replace_in_link(original, "lbr_iiwa_link_3", 'iyy="0.075"', 'iyy="0.5"')  # A+B<C
    write(path, broken)
    result = cli("fix-inertia", str(path), "--format", "json")
    assert result.code == 0, result.stderr
    doc = json.loads(result.stdout)
    changes = doc["files"][0]["changes"]
    assert {c["element"] for c in changes} == {"link lbr_iiwa_link_3 <inertial>"}
    assert any("not watertight: convex hull, hull/mesh volume" in c["source"] for c in changes)
    assert only_within(broken, path.read_text(), [element_lines(broken, r'<link name="lbr_iiwa_link_3"', "</inertial>")])
    hull = trimesh.load(pybullet_data_dir / "kuka_iiwa" / "meshes" / "link_3.stl", force="mesh").convex_hull
    hull.density = 3.0 / hull.volume
    mass, com, tensor = inertial_of(path, "lbr_iiwa_link_3")
    assert mass == 3.0
    np.testing.assert_allclose(com, hull.center_mass, atol=1e-6)
    np.testing.assert_allclose(tensor, hull.moment_inertia, rtol=1e-5, atol=1e-9)
    assert _load_clean_in_pybullet(path) is not None
    assert cli("fix-inertia", str(path), "--check").code == 0


def test_panda_removed_inertial_and_placeholder_tensors(cli, tmp_path, pybullet_data_dir):
    path = _pybullet_copy(tmp_path, pybullet_data_dir / "franka_panda" / "panda.urdf")
    original = path.read_text()
    write(path, remove_inertial(original, "panda_link5"))
    # The placeholder tensors are valid but implausible (I007): recomputed only on request.
    result = cli("fix-inertia", str(path), "--mass", "panda_link5=3.0", "--include-implausible")
    assert result.code == 0, result.stdout + result.stderr
    assert [f for f in lint_findings(cli, path, "I") if f["severity"] != "info"] == []
    mass, com, tensor = inertial_of(path, "panda_link5")
    assert mass == 3.0 and mp.is_positive_definite(tensor) and mp.satisfies_triangle_inequality(tensor)
    assert 0.01 < np.linalg.norm(com) < 0.2  # the link5 mesh hangs 0.0-0.26 m below its frame
    assert not any("No inertial data" in m for m in _load_clean_in_pybullet(path))
    assert cli("fix-inertia", str(path), "--check", "--include-implausible").code == 0


def test_real_ar3_meshes_at_cad_density_give_the_cad_masses(cli, tmp_path, shared_dir):
    """The real ar3.urdf's masses are SolidWorks' at 1000 kg/m3: the STL volumes must reproduce them."""
    real = shared_dir / "models" / "ar3_description"
    original = (real / "urdf" / "ar3.urdf").read_text()
    broken = original
    for link in ("link_2", "link_6"):
        broken = remove_inertial(broken, link)
    path = write(tmp_path / "ar3.urdf", broken)
    result = cli("fix-inertia", str(path), "--density", "1000", "--package-path", f"ar3_description={real}",
                 "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    sources = {c["source"] for c in json.loads(result.stdout)["files"][0]["changes"]}
    assert "collision: mesh link_2.STL closed (some edges shared by more than 2 faces), exact" in sources
    assert "collision: mesh link_6.STL watertight, exact" in sources
    want = load_model(real / "urdf" / "ar3.urdf", {"ar3_description": real})
    for link in ("link_2", "link_6"):
        mass, com, _ = inertial_of(path, link)
        assert mass == pytest.approx(want.link(link).inertial.mass, rel=5e-3)  # STL tessellation
        np.testing.assert_allclose(com, want.link(link).inertial.origin.xyz, atol=1e-3)


def test_options_and_io_errors(cli, tmp_path, write_urdf):
    path = write_urdf(TEXTBOOK)
    before = path.read_bytes()
    diff = cli("fix-inertia", str(path), "--mass", "box=2", "--diff")
    assert diff.code == 0 and "+    <inertial>" in diff.stdout and path.read_bytes() == before
    check = cli("fix-inertia", str(path), "--mass", "box=2", "--check")
    assert check.code == 1 and path.read_bytes() == before
    out = tmp_path / "out.urdf"
    assert cli("fix-inertia", str(path), "--mass", "box=2", "-o", str(out)).code == 0
    assert path.read_bytes() == before and b'<mass value="2"/>' in out.read_bytes()
    other = write_urdf(TEXTBOOK, "other.urdf")
    for args, message in [
        (["-o", str(out), str(other)], "exactly one input"),
        (["--mass", "box"], "expected LINK=KG"),
        (["--links", "nope"], "no link named 'nope'"),
        (["--density", "-3"], "must be a density between"),
        (["--density", "inf"], "must be a finite number"),
        (["--total-mass", "inf"], "must be a finite number"),
        (["--mass", "box=1e-320"], "at least 1e-09 kg"),
        (["--total-mass", "1e-320"], "at least 1e-09 kg"),
    ]:
        result = cli("fix-inertia", str(path), *args)
        assert result.code == 2 and message in result.stderr and "Traceback" not in result.stderr
    xacro = cli("fix-inertia", str(ASSETS / "ar3" / "ar3.urdf.xacro"))
    assert xacro.code == 2 and "xacro" in xacro.stderr and "ar3cli expand" in xacro.stderr
    missing = cli("fix-inertia", str(tmp_path / "missing.urdf"))
    assert missing.code == 2 and "no such file" in missing.stderr
    assert sorted(os.listdir(tmp_path)) == ["other.urdf", "out.urdf", "robot.urdf"]  # no stray temp
    assert not [name for name in os.listdir(tmp_path) if "ar3cli-tmp" in name]


def test_real_ar3_link_3_com_one_metre_away_is_fixed_on_request(cli, tmp_path, shared_dir):
    """The real ar3.urdf puts link_3's COM at z = -1.047 m (-π/3: an angle typed into xyz), on a 10 cm part.
    I016 says so; fix-inertia does not guess the COM meant, so it is fixed with --links: mass kept, COM and
    tensor recomputed, and I016 is quiet afterwards."""
    real = shared_dir / "models" / "ar3_description"
    original = (real / "urdf" / "ar3.urdf").read_text()
    path = write(tmp_path / "ar3.urdf", original)
    package = f"ar3_description={real}"
    com_rule = json.loads(cli("lint-urdf", "--no-cache", "--select", "I016", "--format", "json", "--package-path", package,
                              str(path)).stdout)["findings"]
    assert [f["message"].split("'")[1] for f in com_rule] == ["link_3"] and "-π/3" in com_rule[0]["message"]
    check = cli("fix-inertia", str(path), "--links", "link_3", "--check", "--package-path", package,
                "--format", "json")
    assert check.code == 1
    changes = json.loads(check.stdout)["files"][0]["changes"]
    assert {(c["element"], c["field"]) for c in changes} == {("link link_3 <inertial>", "origin xyz"),
                                                              ("link link_3 <inertial>", "inertia")}
    assert cli("fix-inertia", str(path), "--links", "link_3", "--package-path", package).code == 0
    assert only_within(original, path.read_text(), [element_lines(original, r'name="link_3"', "</inertial>")])
    mass, com, _ = inertial_of(path, "link_3")
    assert mass == 0.1787 and np.linalg.norm(com) < 0.1
    assert cli("fix-inertia", str(path), "--links", "link_3", "--check", "--package-path", package).code == 0
    assert json.loads(cli("lint-urdf", "--no-cache", "--select", "I016", "--format", "json", "--package-path", package,
                          str(path)).stdout)["findings"] == []


@pytest.mark.parametrize("geometry", ['<cylinder radius="0.1" length="0"/>', '<cylinder radius="nan" length="0.2"/>',
                                      '<sphere radius="nan"/>', '<box size="0.1 inf 0.1"/>'])
def test_degenerate_primitives_are_skipped_with_a_reason(cli, write_urdf, geometry):
    path = write_urdf('<robot name="d"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>'
                      '<child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                      f'</joint><link name="b"><collision><geometry>{geometry}</geometry></collision></link></robot>')
    before = path.read_bytes()
    result = cli("fix-inertia", str(path), "--density", "1000", "--format", "json")
    assert result.code == 1, result.stderr
    (skipped,) = json.loads(result.stdout)["files"][0]["skipped"]
    assert "is not usable" in skipped["reason"]
    assert path.read_bytes() == before and "internal error" not in result.stderr


PLACEHOLDER = """<?xml version="1.0"?>
<robot name="placeholder">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="bare"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="bare">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="j2" type="revolute"><parent link="bare"/><child link="tuned"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="tuned">
    <!-- hand-tuned for the controller: keep -->
    <inertial><mass value="0.1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>
"""
LEFT_ALONE = ("left 1 link(s) with valid but implausible inertia alone (I007): tuned; "
              "add --include-implausible to recompute them")


def _link_text(text: str, link: str) -> str:
    start = text.index(f'<link name="{link}">')
    return text[start:text.index("</link>", start)]


def test_default_fixes_invalid_links_and_leaves_implausible_ones_alone(cli, write_urdf):
    """bare has no <inertial> (I001, invalid); tuned's I = 1 on 0.1 kg is valid but 37x too wide for
    its 10 cm box (I007): by default only bare is written, tuned stays byte for byte."""
    path = write_urdf(PLACEHOLDER)
    codes = {name: reason.split()[0] for name, reason in links_needing_inertia(load_model(path)).items()}
    assert codes == {"bare": "I001", "tuned": "I007"}
    result = cli("fix-inertia", str(path), "--density", "1000")
    assert result.code == 0, result.stdout + result.stderr
    assert LEFT_ALONE in result.stdout and "3 field(s) changed" in result.stdout
    fixed = path.read_text()
    assert _link_text(fixed, "tuned") == _link_text(PLACEHOLDER, "tuned")
    assert only_within(PLACEHOLDER, fixed, [element_lines(PLACEHOLDER, r'<link name="bare"', "</link>")])
    assert inertial_of(path, "bare")[0] == pytest.approx(1.0, rel=1e-12)  # 0.001 m3 x 1000 kg/m3
    # What is left alone does not make --check fail; JSON carries the same note.
    check = cli("fix-inertia", str(path), "--check", "--format", "json")
    assert check.code == 0, check.stdout + check.stderr
    doc = json.loads(check.stdout)
    assert doc["ok"] and doc["files"][0]["changes"] == [] and doc["files"][0]["skipped"] == []
    assert doc["files"][0]["notes"] == [LEFT_ALONE]
    (tuned,) = doc["files"][0]["left_alone"]
    assert tuned["link"] == "tuned" and tuned["code"] == "I007" and "radius of gyration" in tuned["reason"]
    text = cli("fix-inertia", str(path), "--check")
    assert text.code == 0 and LEFT_ALONE in text.stdout and "nothing to change" in text.stdout
    assert path.read_text() == fixed


def test_include_implausible_recomputes_them_too(cli, write_urdf):
    path = write_urdf(PLACEHOLDER)
    check = cli("fix-inertia", str(path), "--density", "1000", "--include-implausible", "--check",
                "--format", "json")
    assert check.code == 1
    (file,) = json.loads(check.stdout)["files"]
    assert {c["element"] for c in file["changes"]} == {"link bare <inertial>", "link tuned <inertial>"}
    assert file["notes"] == [] and "left_alone" not in file
    result = cli("fix-inertia", str(path), "--density", "1000", "--include-implausible")
    assert result.code == 0, result.stdout + result.stderr
    assert "inertia alone" not in result.stdout and "4 field(s) changed" in result.stdout
    mass, com, tensor = inertial_of(path, "tuned")
    assert mass == 0.1  # a valid mass in the file is kept: only the tensor was wrong
    np.testing.assert_allclose(tensor, np.eye(3) * 0.1 * 0.02 / 12, rtol=1e-9, atol=0)
    assert "hand-tuned for the controller" in path.read_text()  # the comment is not part of the edit
    assert links_needing_inertia(load_model(path)) == {}
    assert cli("fix-inertia", str(path), "--include-implausible", "--check").code == 0


def test_implausible_links_by_hand_and_option_conflicts(cli, write_urdf):
    path = write_urdf(PLACEHOLDER)
    # --mass names the link: that is a request to recompute it.
    by_mass = cli("fix-inertia", str(path), "--density", "1000", "--mass", "tuned=0.2", "--check",
                  "--format", "json")
    (file,) = json.loads(by_mass.stdout)["files"]
    assert {c["element"] for c in file["changes"]} == {"link bare <inertial>", "link tuned <inertial>"}
    assert file["notes"] == []
    # --links and --all work as before, implausible or not.
    by_links = cli("fix-inertia", str(path), "--links", "tuned", "--check", "--format", "json")
    assert by_links.code == 1 and {c["element"] for c in json.loads(by_links.stdout)["files"][0]["changes"]} == \
        {"link tuned <inertial>"}
    by_all = cli("fix-inertia", str(path), "--all", "--density", "1000", "--check", "--format", "json")
    assert by_all.code == 1 and {c["element"] for c in json.loads(by_all.stdout)["files"][0]["changes"]} == \
        {"link bare <inertial>", "link tuned <inertial>"}
    for other in (["--links", "tuned"], ["--all"]):
        result = cli("fix-inertia", str(path), "--include-implausible", *other)
        assert result.code == 2 and "--include-implausible widens the default selection" in result.stderr
    assert path.read_text() == PLACEHOLDER


def test_the_fixer_says_what_lint_still_finds_after_the_fix(cli, tmp_path):
    """Issue 17: after a fix the result is linted again (from the new bytes, nothing extra written)."""
    import shutil

    path = tmp_path / "arm.urdf"
    shutil.copy(ASSETS / "examples" / "ar3_no_inertia.urdf", path)
    result = cli("fix-inertia", str(path), "--density", "1200", "--check", "--format", "json")
    (entry,) = json.loads(result.stdout)["files"]
    assert entry["remaining"]["error"] == 0 and "I001" not in entry["remaining"]["rules"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.urdf"]
    text = cli("fix-inertia", str(path), "--density", "1200", "--diff")
    assert "after the fix, ar3cli lint-urdf" in text.stderr + text.stdout


def test_collada_unit_gives_the_volume_in_metres(cli, tmp_path):
    """cube_inches.dae is a 6-unit cube in inches: 0.1524 m a side, 3.54 kg at 1000 kg/m3 (not 216 t)."""
    (tmp_path / "cube_inches.dae").write_bytes((Path(__file__).parent / "data" / "meshes" / "cube_inches.dae").read_bytes())
    path = write(tmp_path / "inch.urdf", """<?xml version="1.0"?>
<robot name="inch"><link name="part"><collision><geometry><mesh filename="cube_inches.dae"/></geometry></collision></link></robot>
""")
    result = cli("fix-inertia", str(path), "--links", "part", "--density", "1000", "--format", "json")
    assert result.code == 0, result.stdout + result.stderr
    mass, com, tensor = inertial_of(path, "part")
    side = 6 * 0.0254
    assert mass == pytest.approx(1000 * side ** 3, rel=1e-6)
    assert com == pytest.approx([side / 2] * 3, rel=1e-6)
    assert tensor[0, 0] == pytest.approx(mass * side ** 2 / 6, rel=1e-6)
    sources = {c["source"] for c in json.loads(result.stdout)["files"][0]["changes"]}
    assert any("COLLADA unit 0.0254 m" in source for source in sources)


# ---- issue 30 item 13: --total-mass goes to physical parts, not to visual-only markers -------------
MARKER_ROBOT = Path(__file__).parent / "data" / "inertia" / "base_with_marker.urdf"


def test_total_mass_skips_visual_only_markers_and_says_so(cli, tmp_path):
    path = write(tmp_path / "robot.urdf", MARKER_ROBOT.read_text())
    result = cli("fix-inertia", str(path), "--total-mass", "10", "--format", "json")
    assert result.code == 1, result.stdout + result.stderr  # the marker is reported as not fixed
    file = json.loads(result.stdout)["files"][0]
    body, wheel = (inertial_of(path, name)[0] for name in ("body", "wheel"))
    assert body + wheel == pytest.approx(10.0, rel=1e-9)
    assert body / wheel == pytest.approx(0.4 * 0.3 * 0.1 / (np.pi * 0.1 ** 2 * 0.05), rel=1e-9)
    assert load_model(path).link("ee_marker").inertial is None
    (skipped,) = file["skipped"]
    assert skipped["element"] == "link ee_marker <inertial>" and "visual geometry only" in skipped["reason"]
    assert "--mass ee_marker=KG" in skipped["reason"]
    (note,) = [n for n in file["notes"] if n.startswith("--total-mass")]
    assert "body 88.4%, wheel 11.6%" in note and "left out (visual geometry only, no <collision>): ee_marker" in note
    assert inertial_of(path, "imu_link")[0] == 1e-6  # the frame link needs no mass source


def test_total_mass_names_unselected_massless_parts(cli, tmp_path):
    text = MARKER_ROBOT.read_text().replace('<link name="world"/>', "")
    text = text[:text.index('  <joint name="world_to_body"')] + text[text.index('  <joint name="wheel_joint"'):]
    path = write(tmp_path / "robot.urdf", text)  # body is now the root: I012 (info), which fix-inertia does not fix
    result = cli("fix-inertia", str(path), "--total-mass", "10", "--format", "json")
    (note,) = [n for n in json.loads(result.stdout)["files"][0]["notes"] if n.startswith("--total-mass")]
    assert "wheel 100.0%" in note and "not selected, and weighing nothing in the file: body" in note
