"""Inertia rules (I): zero, near-singular and implausible tensors, fix-inertia's exact set of rules
and the --fix-hint that asks for a mass source only where it is needed.

Each case is a small robot written to tmp_path; tests/test_lint_pybullet_data.py keeps the real-robot
counts honest.
"""

from __future__ import annotations

from ar3cli.findings import Severity
from ar3cli.lint.rules import FAMILY_ORDER, REGISTRY, RULES, inertia
from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from tests.lint_helpers import findings, fixed_child, tensor, welded_to_arm
from tests.test_lint_rules import codes_for, write_fixture

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
    """urdfdom refuses it: S019 says so on a link that does not move (I006 on one that does), once."""
    path = write_fixture(tmp_path, fixed_child('<inertial><mass value="1"/></inertial>'))
    (finding,) = codes_for(path, "S019")
    assert finding.severity is Severity.ERROR and "no <inertia>" in finding.message
    assert codes_for(path, "I006") == [] and codes_for(path, "I008") == []


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
    text = robot('<link name="world"><visual><geometry><box size="1 1 1"/></geometry></visual></link>')
    assert codes_for(write_fixture(tmp_path, text), "I012") == []  # PyBullet gives a link named world 0 kg
    # jackal's root: a frame without geometry or <inertial>, which PyBullet still weighs 1 kg when it floats
    frame_root = robot(f"""<link name="base_link"/><link name="chassis">{LINK_INERTIAL}</link>
        <joint name="j" type="fixed"><parent link="base_link"/><child link="chassis"/></joint>""")
    (frame,) = codes_for(write_fixture(tmp_path, frame_root), "I012")
    assert "is a frame (no geometry)" in frame.message and "1 kg" in frame.message and "tiny <inertial>" in frame.hint
    assert codes_for(write_fixture(tmp_path, arm()), "I012") == []  # an arm turning on its mounting frame
    (finding,) = codes_for(write_fixture(tmp_path, REGISTRY["I012"].bad), "I012")
    assert "if this robot floats" in finding.message and "fix-inertia --links chassis" in finding.hint


# ---- metadata ------------------------------------------------------------------------------------------

def test_fix_inertia_fixes_exactly_the_rules_that_say_so():
    for rule in inertia.FIXED_BY_FIX_INERTIA:
        assert rule.fixed_by and rule.fixed_by.startswith("fix-inertia"), rule.code
    for rule in inertia.NOT_FIXED_BY_FIX_INERTIA:
        assert rule.fixed_by is None, rule.code
    assert inertia.FIXED_BY_FIX_INERTIA[-1].code == "I007"  # fix-inertia reads I007 as "nothing invalid": it must come last
    assert {r.code for r in RULES if r.fixed_by and r.fixed_by.startswith("fix-inertia")} == \
        {r.code for r in (*inertia.FIXED_BY_FIX_INERTIA, *inertia.RESCALED_BY_FIX_INERTIA)}


def test_metadata_reaches_the_docs_and_the_rule_object():
    from ar3cli.lint.rules.docs import generate

    text = generate()
    assert "**Fixed by.** `ar3cli fix-continuous --limits-from joint_limits.yaml`." in text
    assert "**Thresholds.** Smallest principal moment below MJ_MINVAL = 1e-15" in text
    assert "**References.** MuJoCo include/mujoco/mjtnum.h" in text
    assert REGISTRY["J006"].fixed_by == "fix-continuous"
    codes = [r.code for r in RULES]
    assert codes == sorted(codes, key=lambda c: (FAMILY_ORDER.index(c[0]), c))


# ---- --fix-hint asks for a mass source only where fix-inertia needs one (issue 30 item 13) ----------

def test_fix_hint_asks_no_density_for_frame_links(tmp_path):
    from ar3cli.lint.fix_hints import fix_commands

    frame_only = findings(write_fixture(tmp_path / "frame", welded_to_arm("")))
    assert [f.rule for f in frame_only if f.rule.startswith("I")] == ["I002"]
    assert fix_commands("robot.urdf", frame_only) == ["ar3cli fix-inertia robot.urdf  # I002"]
    part = findings(write_fixture(tmp_path / "part", welded_to_arm(
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>')))
    assert fix_commands("robot.urdf", [f for f in part if f.rule == "I002"]) == [
        "ar3cli fix-inertia robot.urdf --density KG_PER_M3  # I002"]


def test_root_welded_links_get_a_fix_inertia_command_that_works(tmp_path):
    """I012's hint said 'run ar3cli fix-inertia', which selects none of the welded links (they are not I002
    any more), and gave a chassis with geometry a tiny inertial (found in review)."""
    frames = robot(f"""<link name="base">{LINK_INERTIAL}</link><link name="cam"/><link name="imu"/>
        <joint name="a" type="fixed"><parent link="base"/><child link="cam"/></joint>
        <joint name="b" type="fixed"><parent link="base"/><child link="imu"/></joint>""")
    (finding,) = codes_for(write_fixture(tmp_path / "frames", frames), "I012")
    assert "for each to its base" in finding.message
    assert "ar3cli fix-inertia --links cam,imu (a tiny <inertial> for each frame)" in finding.hint
    one = robot(f"""<link name="base">{LINK_INERTIAL}</link><link name="cam"/>
        <joint name="a" type="fixed"><parent link="base"/><child link="cam"/></joint>""")
    (finding,) = codes_for(write_fixture(tmp_path / "one", one), "I012")
    assert "1 link welded to root link 'base' has no <inertial> ('cam')" in finding.message
    assert "1 kg and I = 1 for it to its base" in finding.message
    chassis = robot("""<link name="base_footprint"/>
        <link name="base"><collision><geometry><box size="0.5 0.3 0.1"/></geometry></collision></link>
        <link name="imu"/><joint name="a" type="fixed"><parent link="base_footprint"/><child link="base"/></joint>
        <joint name="b" type="fixed"><parent link="base"/><child link="imu"/></joint>""")
    (finding,) = codes_for(write_fixture(tmp_path / "chassis", chassis), "I012")
    assert "ar3cli fix-inertia --links base,imu --density KG_PER_M3" in finding.hint
    assert "give 'base_footprint' a tiny <inertial>" in finding.hint
