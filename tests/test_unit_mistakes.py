"""Unit and reference mistakes injected into real robots are found at the element that holds it (issue 35).

Every class of tests/unit_injection.py is injected, one robot at a time, into ten real robots:
pybullet_data's (installed with pybullet) and, where pybullet_data has too few with the element the
mistake needs (joints sharing one speed), small fixtures derived from example-robot-data in
tests/data/units (README.md there). The same robots, unmodified, get none of these findings.
``python benchmarks/inject_units.py`` runs the injections on every robot of example-robot-data and
pybullet_data.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from ar3cli.lint.engine import LintOptions, lint_file
from ar3cli.urdf.model import load_model
from tests.unit_injection import KINDS, found_at_its_element, inject

UNITS = Path(__file__).parent / "data" / "units"
PYBULLET_ROBOTS = ("kuka_iiwa/model.urdf", "franka_panda/panda.urdf", "r2d2.urdf", "xarm/xarm6_with_gripper.urdf",
                   "a1/a1.urdf", "aliengo/aliengo.urdf", "laikago/laikago_toes.urdf", "mini_cheetah/mini_cheetah.urdf",
                   "quadruped/minitaur.urdf", "racecar/racecar.urdf", "husky/husky.urdf", "quadruped/spirit40.urdf",
                   "quadruped/vision60.urdf", "bicycle/bike.urdf", "humanoid/humanoid.urdf", "pr2_gripper.urdf",
                   "quadruped/microtaur/microtaur.urdf", "TwoJointRobot_wo_fixedJoints.urdf", "duck_vhacd.urdf")
"""One file per robot (pybullet_data's variants of one robot, kuka_iiwa/model_*.urdf, count once)."""
DERIVED = ("ur5.urdf", "talos_left_arm.urdf", "z1.urdf", "allegro_right_hand.urdf", "so101.urdf")
PER_CLASS = 10


def _robots() -> list[Path]:
    import pybullet_data

    root = Path(pybullet_data.getDataPath())
    return [root / name for name in PYBULLET_ROBOTS] + [UNITS / name for name in DERIVED]


@pytest.mark.parametrize("kind", KINDS)
def test_each_mistake_injected_into_ten_real_robots_is_found_at_its_element(kind):
    injected, missed = 0, []
    for path in _robots():
        injection = inject(kind, load_model(path))
        if injection is None:
            continue
        injected += 1
        found, what = found_at_its_element(path, injection)
        if not found:
            missed.append(f"{path.name}: {what}")
        if injected == PER_CLASS:
            break
    assert injected == PER_CLASS, f"only {injected} robots have a place for a {kind} mistake"
    assert missed == [], missed


UNIT_RULES = ("J015", "J016", "J017", "I016", "G017", "T009")


def test_the_real_robots_unmodified_have_no_unit_finding():
    options = LintOptions(select=[*UNIT_RULES, "I013", "I007", "G006"])
    for path in _robots():
        for finding in lint_file(path, options.rules(), options).findings:
            assert finding.rule not in UNIT_RULES and "looks" not in finding.message, (path.name, finding.message)


def test_fix_joints_converts_degrees_it_has_evidence_for(cli, tmp_path):
    path = tmp_path / "ur5.urdf"
    text = (UNITS / "ur5.urdf").read_text()
    text = text.replace('<origin rpy="0.0 1.57079632679 0.0" xyz="0.0 0.13585 0.0"/>',
                        '<origin rpy="0 90 0" xyz="0.0 0.13585 0.0"/>', 1)
    text = text.replace('lower="-3.14159265359" upper="3.14159265359" velocity="3.15"/>',
                        'lower="-3.14159265359" upper="3.14159265359" velocity="180"/>', 1)
    path.write_text(text)
    assert {f.rule for f in _lint(path, ("J015", "J016"))} == {"J015", "J016"}
    result = cli("fix-joints", str(path), "--no-verify")
    assert result.code == 0, result.stderr
    fixed = path.read_text()
    assert 'rpy="0 1.570796327 0"' in fixed and 'velocity="3.141592654"' in fixed
    assert _lint(path, ("J015", "J016")) == []


def test_fix_inertia_rescales_a_mass_in_grams_and_a_tensor_in_kg_mm2(cli, tmp_path):
    shutil.copy(UNITS / "arm_with_boxes.urdf", tmp_path / "arm.urdf")
    path = tmp_path / "arm.urdf"
    text = path.read_text()
    text = text.replace('<mass value="1.2"/>', '<mass value="1200"/>')
    text = text.replace('ixx="0.0041" ixy="0" ixz="0" iyy="0.0041" iyz="0" izz="0.0008"',
                        'ixx="4100" ixy="0" ixz="0" iyy="4100" iyz="0" izz="800"')
    path.write_text(text)
    before = {f.rule: f.message for f in _lint(path, ("I013", "I007"))}
    assert "looks like grams (1.2 kg?" in before["I013"] and "looks like kg·mm²" in before["I007"]
    result = cli("fix-inertia", str(path))
    assert result.code == 0, result.stderr
    fixed = path.read_text()
    assert '<mass value="1.2"/>' in fixed and 'ixx="0.0041"' in fixed and 'izz="0.0008"' in fixed
    assert _lint(path, ("I013", "I007")) == []


def _lint(path: Path, codes) -> list:
    options = LintOptions(select=list(codes))
    return lint_file(path, options.rules(), options).findings


def test_fix_inertia_names_the_densities_it_does_not_touch(cli, tmp_path):
    """I013 names fix-inertia for a mass in grams only: a density no material has that is not grams
    (200 kg in an 8x8x30 cm box, 1e5 kg/m³, and still 104 kg/m³ read as grams, far from the arm's other
    links) is left alone, and said so (the real-robot sweep's tiago arm_tool_link, pybullet_data's chest)."""
    path = tmp_path / "arm.urdf"
    path.write_text((UNITS / "arm_with_boxes.urdf").read_text().replace('<mass value="2.0"/>', '<mass value="200"/>'))
    (finding,) = _lint(path, ("I013",))
    assert "denser than any material" in finding.message and "grams" not in finding.message
    before = path.read_bytes()
    result = cli("fix-inertia", str(path))
    assert result.code in (0, 1), result.stderr
    assert "density no material has alone (I013, not a mass in grams): upper" in result.stdout + result.stderr
    assert path.read_bytes() == before
    given = cli("fix-inertia", str(path), "--mass", "upper=2")  # a --mass for a link no other rule selects
    assert "density no material has alone (I013, not a mass in grams): upper" in given.stdout + given.stderr
    assert path.read_bytes() == before
    # selected by another rule (a tensor that breaks the triangle inequality): recomputed around its own mass,
    # so its density is still no material's, and the note still says so (the sweep's TIAGo tool links)
    path.write_text(before.decode().replace('izz="0.0021"', 'izz="0.05"'))
    recomputed = cli("fix-inertia", str(path))
    assert "density no material has alone (I013, not a mass in grams): upper" in recomputed.stdout + recomputed.stderr


def test_density_is_judged_on_the_collision_alone_when_a_link_has_no_visual(tmp_path):
    text = (UNITS / "arm_with_boxes.urdf").read_text().replace('<mass value="2.0"/>', '<mass value="200"/>')
    without_visual = text.replace('<visual><origin xyz="0 0 0.15"/><geometry><box size="0.08 0.08 0.3"/></geometry>'
                                  '</visual>', "")
    assert without_visual != text
    path = tmp_path / "arm.urdf"
    path.write_text(without_visual)
    assert [f.message.split(" is ")[0] for f in _lint(path, ("I013",))] == ["link 'upper'"]
