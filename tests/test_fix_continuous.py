"""ar3cli fix-continuous: fake limits removed, real limits from MoveIt's yaml, checked in PyBullet."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ar3cli.urdf.model import load_model
from tests.conftest import ASSETS
from tests.fixer_helpers import element_lines, lint_findings, only_within, write

WHEEL = """<robot name="wheel">
  <link name="base"/>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="wheel"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/>
  </joint>
  <link name="wheel">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="turn" type="revolute">
    <parent link="wheel"/><child link="arm"/>
    <axis xyz="1 0 0"/>
    <limit lower="-3.2" upper="3.2" effort="5" velocity="2"/>
  </joint>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""


def reached(path: Path, joint: str, target: float) -> float:
    """Position of ``joint`` after 10 s of POSITION_CONTROL towards ``target``."""
    from ar3cli.sim.session import Session

    with Session() as session:
        body = session.load(load_model(path))
        p = session.p
        index = body.link_index[load_model(path).joint(joint).child]
        p.setJointMotorControl2(body.id, index, p.POSITION_CONTROL, targetPosition=target, force=100,
                                physicsClientId=session.client)
        for _ in range(2400):
            p.stepSimulation(physicsClientId=session.client)
        return p.getJointState(body.id, index, physicsClientId=session.client)[0]


def test_removing_fake_limits_lets_a_position_target_through(cli, write_urdf):
    path = write_urdf(WHEEL)
    assert reached(path, "spin", 3.0) == pytest.approx(1.0, abs=1e-3)  # the fake limit clamps the target
    result = cli("fix-continuous", str(path), "--format", "json")
    assert result.code == 0, result.stderr
    doc = json.loads(result.stdout)["files"][0]
    assert [(c["field"], c["old"], c["new"]) for c in doc["changes"]] == [("limit lower", "-1", None),
                                                                           ("limit upper", "1", None)]
    assert doc["verification"]["verified"] is True
    assert {c["check"] for c in doc["verification"]["checks"]} == {"no position limit", "target beyond old limit"}
    assert path.read_text() == WHEEL.replace('<limit lower="-1" upper="1" effort="5"', '<limit effort="5"')
    assert reached(path, "spin", 3.0) == pytest.approx(3.0, abs=1e-3)
    again = cli("fix-continuous", str(path), "--check")
    assert again.code == 0 and "nothing to change" in again.stdout


def test_to_continuous_and_missing_effort(cli, write_urdf):
    text = WHEEL.replace('effort="5" velocity="2"/>\n  </joint>\n  <link name="wheel">',
                         'velocity="2"/>\n  </joint>\n  <link name="wheel">')
    path = write_urdf(text)
    result = cli("fix-continuous", str(path), "--to-continuous", "--effort", "7", "--format", "json")
    assert result.code == 0, result.stderr
    changes = json.loads(result.stdout)["files"][0]["changes"]
    assert {(c["element"], c["field"], c["new"]) for c in changes} >= {
        ("joint spin", "limit effort", "7"), ("joint turn", "type", "continuous")}
    assert next(c for c in changes if c["field"] == "limit effort")["source"].startswith("--effort (added")
    model = load_model(path)
    assert model.joint("turn").type == "continuous" and model.joint("turn").limit.lower is None
    assert model.joint("spin").limit.effort == 7.0
    assert cli("fix-continuous", str(path), "--to-continuous", "--check").code == 0


def test_fake_continuous_ar3_example(cli, tmp_path):
    source = (ASSETS / "examples" / "ar3_fake_continuous.urdf").read_text()
    path = write(tmp_path / "ar3.urdf", source)
    assert len(lint_findings(cli, path, "J006")) == 6  # continuous-with-range, one per joint
    diff = cli("fix-continuous", str(path), "--diff")
    assert diff.code == 0 and diff.stdout.count('-    <limit lower="-100" upper="100"') == 6
    assert path.read_text() == source
    assert cli("fix-continuous", str(path), "--check").code == 1
    result = cli("fix-continuous", str(path), "--format", "json")
    assert result.code == 0 and json.loads(result.stdout)["files"][0]["verification"]["verified"] is True
    fixed = path.read_text()
    limit_lines = [element_lines(source, rf'<joint name="joint_{i}"', "</joint>") for i in range(1, 7)]
    assert only_within(source, fixed, limit_lines)
    assert fixed == source.replace(' lower="-100" upper="100"', "")
    assert len(lint_findings(cli, tmp_path / "ar3.urdf", "J006")) == 0
    assert cli("fix-continuous", str(path), "--check").code == 0


@pytest.fixture
def real_ar3(shared_dir, tmp_path):
    real = shared_dir / "models" / "ar3_description"
    path = write(tmp_path / "ar3.urdf", (real / "urdf" / "ar3.urdf").read_text())
    return real, path


def test_limits_from_moveit_yaml_on_the_real_ar3(cli, real_ar3):
    import yaml

    from ar3cli.sim.session import Session

    real, path = real_ar3
    limits_file = real / "extra" / "ar3_moveit_config" / "config" / "joint_limits.yaml"
    package = f"ar3_description={real}"
    original = path.read_text()
    refused = cli("fix-continuous", str(path), "--limits-from", str(limits_file), "--package-path", package,
                  env={"COLUMNS": "1000"})  # the table a row a line: the reason whole
    assert refused.code == 1 and "pass --effort" in refused.stdout and path.read_text() == original
    result = cli("fix-continuous", str(path), "--limits-from", str(limits_file), "--effort", "10",
                 "--package-path", package, "--format", "json")
    assert result.code == 0, result.stderr
    assert json.loads(result.stdout)["files"][0]["verification"]["verified"] is True
    joints = [element_lines(original, rf'name="joint_{i}"', "</joint>") for i in range(1, 7)]
    assert only_within(original, path.read_text(), [(first - 1, last) for first, last in joints])
    before = {f["rule"] for f in lint_findings(cli, real / "urdf" / "ar3.urdf", "J", "--package-path", package)}
    after = {f["rule"] for f in lint_findings(cli, path, "J", "--package-path", package)}
    assert "J011" in before and not after & {"J001", "J002", "J006", "J007", "J008", "J011"}, (before, after)
    wanted = yaml.safe_load(limits_file.read_text())["joint_limits"]
    model = load_model(path, {"ar3_description": real})
    with Session() as session:
        body = session.load(model)
        records = {record.name: record for record in body.joints}
        for name, entry in wanted.items():
            info = session.p.getJointInfo(body.id, records[name].index, physicsClientId=session.client)
            assert model.joint(name).type == "revolute"
            assert info[8] == pytest.approx(entry["min_position"], abs=1e-12)
            assert info[9] == pytest.approx(entry["max_position"], abs=1e-12)
            assert info[10] == 10.0 and info[11] == entry["max_velocity"]
    again = cli("fix-continuous", str(path), "--limits-from", str(limits_file), "--check", "--package-path", package)
    assert again.code == 0, again.stdout


def test_limits_file_errors(cli, tmp_path, write_urdf):
    path = write_urdf(WHEEL)
    bad = tmp_path / "bad.yaml"
    bad.write_text("joint_limits:\n  spin: [unclosed\n")
    result = cli("fix-continuous", str(path), "--limits-from", str(bad))
    assert result.code == 2 and "not valid YAML" in result.stderr and "Traceback" not in result.stderr
    wrong = tmp_path / "wrong.yaml"
    wrong.write_text("limits: {}\n")
    assert cli("fix-continuous", str(path), "--limits-from", str(wrong)).code == 2
    unknown = tmp_path / "unknown.yaml"
    unknown.write_text("joint_limits:\n  ghost: {has_position_limits: true, min_position: -1, max_position: 1}\n"
                       "  spin: {has_position_limits: true, min_position: -0.5, max_position: 0.5}\n")
    result = cli("fix-continuous", str(path), "--limits-from", str(unknown), "--format", "json")
    assert result.code == 0, result.stderr
    doc = json.loads(result.stdout)["files"][0]
    assert any("'ghost' is not in" in note for note in doc["notes"])
    spin = load_model(path).joint("spin")
    assert spin.type == "revolute" and (spin.limit.lower, spin.limit.upper) == (-0.5, 0.5)
    assert spin.limit.effort == 5.0 and not math.isnan(spin.limit.velocity)
    xacro = cli("fix-continuous", str(ASSETS / "ar3" / "ar3.urdf.xacro"), "--check")  # a xacro source is read
    assert xacro.code == 0 and "nothing to change" in xacro.stdout, xacro.stderr
    before = path.read_bytes()
    for text, message in [("joint_limits:\n  spin: {has_position_limits: true, min_position: 2, max_position: 1}\n",
                           "is above max_position"),
                          ("joint_limits:\n  spin: {has_position_limits: true}\n", "no min_position/max_position")]:
        bad.write_text(text)
        result = cli("fix-continuous", str(path), "--limits-from", str(bad))
        assert result.code == 2 and message in result.stderr and path.read_bytes() == before


BARE = WHEEL.replace('<limit lower="-1" upper="1" effort="5" velocity="2"/>', '<limit lower="-100" upper="100"/>')


def test_fake_limits_without_effort_remove_the_whole_limit(cli, write_urdf):
    """The popular advice leaves `<limit lower upper/>`; stripping only lower/upper would leave `<limit/>`,
    which urdfdom refuses (no effort/velocity). A continuous joint needs no `<limit>`, so it goes."""
    path = write_urdf(BARE)
    result = cli("fix-continuous", str(path))
    assert result.code == 0, result.stderr
    assert "<limit" not in path.read_text().split('name="spin"')[1].split("</joint>")[0]
    assert path.read_text() == BARE.replace('    <limit lower="-100" upper="100"/>\n', "")  # every other byte stays
    assert not lint_findings(cli, path, "J006,J007")
    assert cli("fix-continuous", str(path), "--check").code == 0
    again = cli("fix-continuous", str(path), "--effort", "5", "--velocity", "2")  # now add real values
    assert again.code == 0 and load_model(path).joint("spin").limit.effort == 5.0
    assert load_model(path).joint("spin").limit.velocity == 2.0


def test_half_known_effort_velocity_is_reported_not_half_fixed(cli, write_urdf):
    path = write_urdf(BARE.replace('<limit lower="-100" upper="100"/>', '<limit lower="-100" upper="100" effort="3"/>'))
    before = path.read_bytes()
    result = cli("fix-continuous", str(path), "--format", "json")
    assert result.code == 1
    (skipped,) = json.loads(result.stdout)["files"][0]["skipped"]
    assert "pass --velocity" in skipped["reason"] and path.read_bytes() == before


def test_full_turn_written_with_eight_digits_of_pi(cli, write_urdf):
    path = write_urdf(WHEEL.replace('lower="-3.2" upper="3.2"', 'lower="-3.14159265" upper="3.14159265"'))
    assert cli("fix-continuous", str(path), "--to-continuous").code == 0
    assert load_model(path).joint("turn").type == "continuous"


def test_a_read_only_second_input_stops_the_run_before_any_write(cli, tmp_path):
    first, second = tmp_path / "a.urdf", tmp_path / "b.urdf"
    for path in (first, second):
        path.write_text(BARE)
    second.chmod(0o444)
    result = cli("fix-continuous", str(first), str(second), "--no-verify")
    assert result.code == 2 and "is read-only" in result.stderr
    assert first.read_text() == BARE  # all or nothing


UNLOADABLE = """<?xml version="1.0"?>
<robot name="no_load">
  <link name="base">
    <inertial><origin xyz="0 0 0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="wheel"/><axis xyz="0 0 1"/>
    <limit lower="-3.14" upper="3.14" effort="1" velocity="1"/>
  </joint>
  <link name="wheel">
    <inertial><mass value="0.5"/><inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
  </link>
</robot>
"""
"""A continuous joint with fake limits in a file pybullet refuses ("failed to parse link": base's
``<inertial>`` has no ``<mass>``)."""


def test_a_file_pybullet_cannot_load_is_never_called_verified(cli, tmp_path):
    """issue 30 item 12: the fix was written and "verified in PyBullet" printed above a "fail" row.
    The original does not load either, so the fix did not break loading: it is written, and the
    verdict says it was not verified (exit 1), in agreement with its rows."""
    path = tmp_path / "no_load.urdf"
    path.write_text(UNLOADABLE, encoding="utf-8")
    result = cli("fix-continuous", str(path))
    assert result.code == 1, result.stdout + result.stderr
    assert "verified in PyBullet" not in result.stdout and "checked in PyBullet: not verified" in result.stdout
    assert "PyBullet cannot load the original either: not verified" in result.stdout
    assert 'lower="-3.14"' not in path.read_text(encoding="utf-8")
    path.write_text(UNLOADABLE, encoding="utf-8")
    data = json.loads(cli("fix-continuous", str(path), "--format", "json").stdout)
    (file,) = data["files"]
    assert data["ok"] is False and file["written"] == str(path)
    verification = file["verification"]
    assert verification["status"] == "not verified" and verification["verified"] is False
    assert [(row["element"], row["status"]) for row in verification["checks"]] == [("(the file)", "fail"),
                                                                                 ("(the original)", "fail")]


def test_a_fix_that_fails_its_pybullet_check_is_not_written(tmp_path, capsys):
    """The verdict line agrees with the table, and a failed check keeps the original file."""
    from ar3cli.fix.driver import Change, Fixer, FixerArgs, FixPlan, check_row, run_fixer

    path = tmp_path / "robot.urdf"
    original = (ASSETS / "examples" / "ar3_fake_continuous.urdf").read_bytes()
    path.write_bytes(original)

    def plan(model, document, options):
        joint = next(j for j in model.joints if j.type == "continuous")
        element = joint.element.find("limit")
        document.remove_attribute(document.span(element), "lower")
        return FixPlan(changes=[Change(f"joint {joint.name}", joint.line, "limit lower", "x", None, "test")])

    def verifier(model, plan):
        return {"verified": False, "checks": [check_row("joint j", "limits", False, "made up for the test")]}

    code = run_fixer(Fixer("fix-continuous", plan, verifier), None, FixerArgs([path]), verify=True)
    out = capsys.readouterr().out
    assert code == 1 and path.read_bytes() == original
    assert "verified in PyBullet" not in out and "nothing written: the fixed file failed its check in PyBullet" in out
    assert not [p for p in tmp_path.iterdir() if p.name != "robot.urdf"]  # no temporary file left
