"""Quiet where nothing is wrong, and one cause reported once (issue 35): each false-alarm class of the
issue on a small fixture of tests/data/quiet/ (README.md there says where each pattern comes from)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from ar3cli.findings import Severity
from ar3cli.lint.engine import LintOptions, lint_file

DATA = Path(__file__).parent / "data" / "quiet"


def _lint(name: str, select=("ALL",), targets=("pybullet", "ros"), sim: bool = False, engines=("pybullet",)) -> list:
    options = LintOptions(select=list(select), targets=targets, sim=sim, engines=engines)
    return lint_file(DATA / name, options.rules(), options).findings


def _codes(findings) -> list[str]:
    return [f.rule for f in findings]


def _line(name: str, needle: str) -> int:
    return next(i for i, line in enumerate((DATA / name).read_text().splitlines(), 1) if needle in line)


def test_a_redundant_inertia_twin_is_quiet_and_a_contradicting_one_is_reported():
    (finding,) = [f for f in _lint("inertia_twins.urdf") if f.rule == "S017"]
    assert finding.line == _line("inertia_twins.urdf", 'iyx="0.004"')
    assert "iyx=\"0.004\" and ixy=\"0\"" in finding.message and "parsers read ixy" in finding.message


def test_a_two_slash_file_uri_is_relative():
    assert _lint("file_uri_relative.urdf") == []


def test_a_mimic_follower_has_no_actuator_of_its_own():
    findings = _lint("mimic_gripper.urdf")
    assert "J008" not in _codes(findings)
    assert "T001" in _codes(findings)  # PyBullet's loadURDF still ignores the <mimic>: that is said


def test_placeholder_and_marker_visuals_need_no_collision_but_a_real_part_does():
    (finding,) = [f for f in _lint("markers.urdf") if f.rule == "G008"]
    assert "'bumper'" in finding.message


def test_a_virtual_root_welded_to_a_body_with_inertia_is_an_info():
    findings = _lint("virtual_root.urdf")
    i006 = [f for f in findings if f.rule == "I006"]
    assert [f.line for f in i006] == [_line("virtual_root.urdf", '<mass value="0.7"/>')]  # the hip is a point mass
    welded = {f.message.split("'")[1]: f for f in findings if f.rule == "I008"}
    assert set(welded) == {"base", "ankle"} and all(f.severity is Severity.INFO for f in welded.values())
    assert "'trunk'" in welded["base"].message and "'foot'" in welded["ankle"].message


def test_a_light_link_between_two_joints_is_carried_by_the_finger_below():
    assert "I014" not in _codes(_lint("finger_cross.urdf"))


def test_xacro_in_a_comment_needs_no_namespace():
    assert _lint("commented_xacro.urdf") == []


def test_meshes_mujoco_finds_through_its_meshdir():
    mujoco_only = _lint("mujoco_meshdir/robot.urdf", targets=("mujoco",))
    assert "G001" not in _codes(mujoco_only)
    also_ros = [f for f in _lint("mujoco_meshdir/robot.urdf", targets=("mujoco", "ros")) if f.rule == "G001"]
    assert len(also_ros) == 2 and all("only MuJoCo finds it" in f.message for f in also_ros)
    assert all(str(DATA) not in f.message for f in also_ros)  # the meshdir as written, not the machine's folder
    default = [f for f in _lint("mujoco_meshdir/robot.urdf") if f.rule == "G001"]  # PyBullet and ROS do not
    assert len(default) == 2 and all(f.severity is Severity.ERROR for f in default)


def test_an_unexpanded_mesh_path_is_one_finding():
    findings = _lint("unexpanded_mesh.urdf")
    assert _codes(findings) == ["F006", "F006"]
    assert "no tool can find the mesh" in findings[0].message


def test_an_empty_robot_is_one_finding():
    (finding,) = _lint("empty_robot.urdf")
    assert finding.rule == "S011" and "no name" in finding.message


def test_a_joint_that_cannot_move_is_one_finding():
    (finding,) = [f for f in _lint("locked_joint.urdf") if f.rule.startswith("J")]
    assert finding.rule == "J004" and "effort=0 and velocity=0" in finding.message


def test_a_tensor_no_body_has_is_not_also_implausible():
    assert [f.rule for f in _lint("bad_tensor.urdf") if f.rule.startswith("I")] == ["I005"]


def test_an_inertial_without_children_is_one_finding_per_element():
    findings = _lint("inertial_without_children.urdf")
    assert _codes(findings) == ["S019", "S019"]
    assert "no <mass> and no <inertia>" in findings[0].message and "no <inertia>" in findings[1].message


def test_an_inertial_under_robot_belongs_in_a_link():
    (finding,) = _lint("misplaced_inertial.urdf")
    assert finding.rule == "S016" and "belongs in <link>" in finding.message and "material" not in finding.message


def test_unexpanded_substitution_names_the_prefix_not_the_namespace_uri():
    (finding,) = [f for f in _lint("xacro_in_urdf.urdf") if f.rule == "F006"]
    assert "<xacro:property value=" in finding.message and "{http" not in finding.message


@pytest.mark.slow
def test_one_instability_is_one_finding(tmp_path, monkeypatch):
    pytest.importorskip("mujoco", reason="MuJoCo is an optional extra")
    monkeypatch.chdir(tmp_path)
    findings = _lint("unstable_chain.urdf", select=("M004",), sim=True, engines=("mujoco",))
    (finding,) = findings
    assert finding.line == _line("unstable_chain.urdf", 'name="shoulder"') and "more joint" in finding.message
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()  # MuJoCo's warning did not become a file in the cwd


def test_a_load_failure_a_static_error_explains_is_not_restated():
    findings = _lint("mujoco_meshdir/robot.urdf", select=("G001", "P001"), sim=True)
    assert set(_codes(findings)) == {"G001"}


# The classes the quietness judge found next (docs/quietness.md, "New"), each at its cause.


def test_a_limit_with_one_bound_says_what_each_tool_reads():
    findings = {f.message.split("'")[1]: f for f in _lint("one_sided_limits.urdf") if f.rule == "J002"}
    assert "finger_joint" not in findings  # upper only: every tool reads 0..0.04, the spec's default lower
    assert "excludes 0" in findings["rail_joint"].message and "-9.65..-1" in findings["rail_joint"].message
    assert "unlimited" in findings["flap_joint"].message and "-0.5..0" in findings["flap_joint"].message
    assert "no lower or upper" in findings["wheel_joint"].message and "locked" in findings["wheel_joint"].message


def test_a_mesh_as_large_as_the_robots_own_travel_is_metres():
    assert "G006" not in _codes(_lint("gantry_hall.urdf"))  # a 46 m rail for a 37 m travel
    (finding,) = [f for f in _lint("arm_with_mm_tool.urdf") if f.rule == "G006"]  # a 46 m tool on a 1 m arm
    assert "millimetres?" in finding.message


def test_a_collision_kept_on_a_companion_link_covers_the_part():
    findings = [f for f in _lint("companion_collision.urdf") if f.rule == "G015"]
    assert [f.message.split("'")[1] for f in findings] == ["wrist"]  # 'elbow' is covered by 'elbow_collision'


def test_parts_inside_their_neighbours_collision_and_drawn_frames_need_no_collision():
    findings = [f for f in _lint("enclosed_parts.urdf") if f.rule == "G008"]
    assert [f.message.split("'")[1] for f in findings] == ["handle"]


def test_an_inertia_is_judged_against_the_body_as_drawn_when_it_collides_as_a_placeholder():
    findings = [f for f in _lint("placeholder_collision.urdf") if f.rule == "I007"]
    assert [f.message.split("'")[1] for f in findings] == ["tag"]  # 'screen' is as large as drawn


def _by_file(folder: str, sim: bool = False) -> dict[str, list]:
    options = LintOptions(select=["ALL"], sim=sim)
    from ar3cli.lint.engine import lint_paths

    return {Path(r.path).name: r.findings for r in lint_paths([DATA / folder], options, use_cache=False, jobs=1)}


def test_libraries_and_include_bodies_are_one_info_line_and_entry_failures_stay_errors():
    found = _by_file("fragments")
    assert _codes(found["body.xacro"]) == ["F008"] and "$(arg mesh_dir) without declaring it" in found["body.xacro"][0].message
    assert _codes(found["legacy_macros.xacro"]) == ["F008"]  # <property> without the xacro: prefix
    (library,) = found["needs_workspace.xacro"]
    assert library.rule == "F008" and library.severity is Severity.INFO and "absent_resources" in library.message
    assert _codes(found["entry_without_arg.xacro"]) == ["F004"]  # it declares its argument: its own failure
    assert _codes(found["entry_missing_include.xacro"]) == ["F004"]  # xacro's include failure, not F001
    assert found["robot.urdf.xacro"] == []


def test_a_broken_robot_stays_an_error_whatever_includes_it(tmp_path):
    """A fragment is an info only where a file that includes it expands: a broken robot that another file
    includes (a *_gazebo wrapper), or one whose name a working file includes from elsewhere, stayed a
    passing F008 when pre-commit linted it alone (found in review)."""
    xacro = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    (tmp_path / "robot.urdf.xacro").write_text(
        f'<robot name="r" {xacro}><link name="base"><inertial><mass value="${{undefined_mass}}"/>'
        '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>')
    (tmp_path / "robot_gazebo.urdf.xacro").write_text(
        f'<robot name="r" {xacro}><xacro:include filename="robot.urdf.xacro"/></robot>')
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "robot.urdf.xacro").write_text(f'<robot {xacro}><link name="x"/></robot>')
    (tmp_path / "decoy.urdf.xacro").write_text(
        f'<robot name="d" {xacro}><xacro:include filename="other/robot.urdf.xacro"/></robot>')
    options = LintOptions(select=["ALL"])
    (finding,) = lint_file(tmp_path / "robot.urdf.xacro", options.rules(), options).findings
    assert finding.rule == "F004" and finding.severity is Severity.ERROR, finding.message


@pytest.mark.slow
def test_a_macro_library_is_one_info_line_with_the_pybullet_rules_too():
    found = _by_file("fragments", sim=True)
    assert _codes(found["legacy_macros.xacro"]) == ["F008"] and _codes(found["needs_workspace.xacro"]) == ["F008"]


def test_a_frame_welded_to_the_root_is_the_bases_one_info_and_a_tool_frame_stays_a_warning():
    findings = [f for f in _lint("mounting_plate.urdf") if f.rule in ("I002", "I012")]
    assert [(f.rule, f.severity) for f in findings] == [("I012", Severity.INFO), ("I002", Severity.WARNING)]
    assert findings[0].line == _line("mounting_plate.urdf", "<link name=\"base_link\">")  # the base it is about
    assert "'plate_top_centre'" in findings[0].message and "if this robot floats" in findings[0].message
    assert "'tool0'" in findings[1].message


def test_a_planar_bases_virtual_links_are_an_info_for_pybullet_and_an_error_for_mujoco():
    default = [(f.rule, f.message.split("'")[1]) for f in _lint("planar_base.urdf") if f.rule in ("I001", "I017")]
    assert sorted(default) == [("I001", "slider"), ("I017", "virtual1"), ("I017", "virtual2")]
    mujoco = [f for f in _lint("planar_base.urdf", targets=("mujoco",)) if f.rule in ("I001", "I017")]
    assert sorted(f.message.split("'")[1] for f in mujoco) == ["slider", "virtual1", "virtual2"]
    assert {f.rule for f in mujoco} == {"I001"}
    assert "I015" not in _codes(_lint("planar_base.urdf"))  # a light link between two joints is carried


def test_a_light_link_between_two_joints_is_carried_and_a_light_tip_is_not():
    findings = [f for f in _lint("biped_sliders.urdf") if f.rule == "I015"]
    assert [f.message.split("'")[1] for f in findings] == ["feeler_joint"]


def test_an_identity_origin_where_none_is_read_loses_nothing():
    findings = [f for f in _lint("ignored_origin.urdf") if f.rule == "S016"]
    assert [f.line for f in findings] == [_line("ignored_origin.urdf", '<origin xyz="0 0 0.05"/>')]


def test_a_quirk_of_a_xacro_expansion_points_into_the_source_or_nowhere():
    from ar3cli.urdf.xmlsource import Quirk, source_lines

    expanded = [Quirk("undeclared-prefix", "namespace prefix drake is used but never declared", 393),
                Quirk("trailing-junk", "content after the root element", 400)]
    source = b'<?xml version="1.0"?>\n<robot name="r">\n  <drake:filter/>\n</robot>\n'
    assert [q.line for q in source_lines(expanded, source)] == [3, 0]
    assert [q.line for q in source_lines(expanded[:1], b'<robot name="r"/>')] == [0]  # only an include uses it


def test_a_missing_mesh_names_the_first_place_looked_and_the_hint_all_of_them():
    (finding,) = [f for f in _lint("missing_package_mesh.urdf") if f.rule == "G001"]
    first, _, rest = finding.message.partition("; looked in ")
    assert "package 'absent_support' not found" in first and " more places" in rest
    assert finding.hint.startswith("Fix the path") and finding.hint.count(";") >= 2
    assert len(finding.message) < len(finding.hint)


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_macros_finding_is_reported_once_for_every_robot_that_includes_it(jobs):
    from ar3cli.lint.engine import lint_paths

    options = LintOptions(select=["ALL"])
    results = lint_paths([DATA / "shared_macro"], options, use_cache=False, jobs=jobs)
    found = [f for r in results for f in r.findings if f.rule == "G008"]
    (finding,) = found
    assert finding.path.endswith("parts.xacro") and "Found through 3 linted files" in finding.hint
    assert "robot_b.urdf.xacro" in finding.hint and "robot_c.urdf.xacro" in finding.hint
    assert "found through" not in finding.message  # a baseline of the folder matches a run on one file


def test_merged_repeats_count_once_and_a_macro_called_twice_stays_two_findings(tmp_path):
    """Review: two calls of one broken macro in one robot became one finding 'found through 2 linted files'
    naming the robot itself; a severity override counted every dropped copy as 'made less severe'."""
    from ar3cli.findings import Severity as S
    from ar3cli.lint.engine import lint_paths

    xacro = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
    (tmp_path / "hand.xacro").write_text(
        f'<robot {xacro}>\n<xacro:macro name="hand" params="prefix">\n'
        f'<link name="${{prefix}}hand"><visual>\n<origin xyz="0 0"/>\n'
        '<geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>\n</xacro:macro>\n</robot>\n')
    for name in ("a", "b"):
        (tmp_path / f"robot_{name}.urdf.xacro").write_text(
            f'<robot name="{name}" {xacro}><xacro:include filename="hand.xacro"/>'
            '<xacro:hand prefix="l_"/><xacro:hand prefix="r_"/></robot>')
    options = LintOptions(select=["F007"], severity={"F007": S.WARNING})
    results = lint_paths([tmp_path], options, use_cache=False, jobs=1)
    by_file = {Path(r.path).name: r for r in results}
    own = by_file["robot_a.urdf.xacro"].findings
    assert len(own) == 2 and all("Found through 2 linted files" in f.hint for f in own)
    assert by_file["robot_b.urdf.xacro"].findings == []
    assert sum(r.lowered for r in results) == 2


def test_a_zero_size_collision_is_found_at_the_shape_and_is_an_error_for_mujoco():
    (info,) = [f for f in _lint("zero_size_collision.urdf") if f.rule == "G018"]
    assert info.severity is Severity.INFO  # PyBullet and ROS load it
    assert info.line == _line("zero_size_collision.urdf", '<sphere radius="0.00"/>')
    (error,) = [f for f in _lint("zero_size_collision.urdf", targets=("mujoco",)) if f.rule == "G018"]
    assert error.severity is Severity.ERROR and "MuJoCo refuses" in error.message


@pytest.mark.slow
def test_mujocos_refusal_of_a_zero_size_collision_is_not_restated():
    pytest.importorskip("mujoco", reason="MuJoCo is an optional extra")
    findings = _lint("zero_size_collision.urdf", select=("G018", "M001"), sim=True, engines=("mujoco",))
    assert _codes(findings) == ["G018"]


@pytest.mark.slow
def test_stand_in_boxes_for_collada_meshes_make_no_contact_finding():
    pytest.importorskip("mujoco", reason="MuJoCo is an optional extra")
    findings = _lint("stand_in/robot.urdf", select=("M002", "M003"), sim=True, engines=("mujoco",))
    assert _codes(findings) == ["M002", "M002"]  # each mesh's replacement is said; their boxes' overlap is not


@pytest.mark.slow
def test_a_torso_sliding_into_its_column_is_a_telescope():
    assert _lint("telescopic_lift.urdf", select=("P005",), sim=True) == []


@pytest.mark.slow
def test_the_packages_own_srdf_disables_its_pairs_and_the_hint_says_so(tmp_path):
    found = _by_file("srdf_package", sim=True)
    assert "P002" not in _codes(found["arm.urdf"])  # srdf/arm.srdf disables base-tip
    assert "P002" in _codes(found["other_arm.urdf"])  # no SRDF of its own
    shutil.copytree(DATA / "srdf_package", tmp_path / "pkg")
    (tmp_path / "pkg" / "srdf" / "arm.srdf").write_text(
        '<robot name="arm"><disable_collisions link1="base" link2="mid" reason="User"/></robot>')
    options = LintOptions(select=["P002"], sim=True)
    (finding,) = lint_file(tmp_path / "pkg" / "urdf" / "arm.urdf", options.rules(), options).findings
    assert "SRDF arm.srdf" in finding.hint and "--srdf" in finding.hint


def _pairs(findings) -> set[tuple[str, str]]:
    return {tuple(sorted(f.message.split("'")[1:4:2])) for f in findings}


@pytest.mark.slow
def test_contacts_a_robot_is_built_with_are_quiet_and_a_sunk_part_is_not():
    arm = _lint("ball_joint_arm.urdf", select=("P002", "M003"), sim=True, engines=("pybullet", "mujoco"))
    assert _pairs(arm) == {("forearm", "upper_arm")} and set(_codes(arm)) == {"P002", "M003"}
    hand = _lint("linkage_hand.urdf", select=("P002", "M003"), sim=True, engines=("pybullet", "mujoco"))
    assert _pairs(hand) == {("index", "thumb")}


@pytest.mark.slow
def test_mujocos_refusal_of_a_link_a_static_error_is_about_is_not_restated():
    pytest.importorskip("mujoco", reason="MuJoCo is an optional extra")
    restated = _lint("inertial_without_children.urdf", select=("S019", "M001"), sim=True, engines=("mujoco",))
    assert _codes(restated) == ["S019", "S019"]  # MuJoCo's "missing element: 'mass'" is the same <inertial>
    kept = _lint("planar_base.urdf", select=("I001", "I017", "M001"), sim=True, engines=("mujoco",))
    assert "M001" in _codes(kept)  # virtual1 is an info for PyBullet; MuJoCo's refusal of it is news


@pytest.mark.slow
def test_a_body_collided_as_many_small_spheres_is_not_a_placeholder(tmp_path):
    """P002 judged a placeholder collision by its largest shape alone: a 20 cm cube drawn, collided as
    spheres of 8 mm at its corners (each 4% of the drawing), hid a tip sunk 3 mm into one of them. The box
    around all of a link's collision shapes is what is compared with its drawing."""
    from ar3cli.lint.rules.base import LINK_INERTIAL, robot

    corners = "".join(f'<collision><origin xyz="{x} {y} {z}"/><geometry><sphere radius="0.004"/></geometry></collision>'
                      for x in (-0.096, 0.096) for y in (-0.096, 0.096) for z in (-0.096, 0.096))
    limit = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/>'
    text = robot(f"""
        <link name="base">{LINK_INERTIAL}<visual><geometry><box size="0.2 0.2 0.2"/></geometry></visual>{corners}</link>
        <link name="arm">{LINK_INERTIAL}<collision><geometry><sphere radius="0.01"/></geometry></collision></link>
        <link name="tip">{LINK_INERTIAL}<collision><geometry><sphere radius="0.004"/></geometry></collision></link>
        <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.5"/>{limit}</joint>
        <joint name="j2" type="revolute"><parent link="arm"/><child link="tip"/>
          <origin xyz="0.096 0.096 -0.399"/>{limit}</joint>""")
    (tmp_path / "r.urdf").write_text(text)
    options = LintOptions(select=["P002"], sim=True)
    findings = lint_file(tmp_path / "r.urdf", options.rules(), options).findings
    assert _pairs(findings) == {("base", "tip")}
