"""The robot-analysis layer (:mod:`ar3cli.analysis`): one load, answers computed once, an unsaved
buffer analysed like the file, the files a load depends on, reloading, resources, hover facts, the
home pose and the verdict. No browser; the report's page is tested in test_report_html.py."""

from __future__ import annotations

import json
import shutil
import threading
from pathlib import Path

import pytest

from ar3cli.analysis import facts, findings, verdict
from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.analysis.settings import AnalysisSettings
from ar3cli.errors import UserError
from ar3cli.lint.config import LintConfig
from tests.conftest import ASSETS, REPO, run_cli

AR3 = ASSETS / "ar3" / "ar3.urdf"
XACRO = REPO / "tests" / "data" / "xacro"
INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'


def _arm(finger_lower: str = "0.01", box: str = "0.1 0.1 0.1", mesh: str = "") -> str:
    """A base, an arm on a revolute joint and a finger whose range excludes 0; ``box`` is the arm's
    collision box, beside the base (0.3 m long, it reaches into the base's other child, the post)."""
    visual = f'<visual><geometry><mesh filename="{mesh}"/></geometry></visual>' if mesh else ""
    return f"""<?xml version="1.0"?>
<robot name="tiny">
  <link name="base">{INERTIAL}<collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="post">{INERTIAL}<collision><origin xyz="0.3 0 0"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm">{INERTIAL}{visual}<collision><origin xyz="0.15 0 0"/><geometry><box size="{box}"/></geometry></collision></link>
  <link name="finger">{INERTIAL}<collision><origin xyz="0 0 0.6"/><geometry><box size="0.02 0.02 0.02"/></geometry></collision></link>
  <joint name="fix" type="fixed"><parent link="base"/><child link="post"/></joint>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="50" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="arm"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit lower="{finger_lower}" upper="0.04" effort="5" velocity="1"/></joint>
</robot>
"""


@pytest.fixture
def tiny(tmp_path) -> Path:
    path = tmp_path / "tiny.urdf"
    path.write_text(_arm(), encoding="utf-8")
    return path


def test_static_findings_are_lint_urdf_s(tmp_path):
    """The same engine, rules, suppressions and JSON document as ``lint-urdf --format json``."""
    robot = tmp_path / "robot.urdf"
    robot.write_text(_arm().replace("<link name=\"finger\">", "<link name=\"finger\"><!-- ar3cli: ignore[I005] -->"),
                     encoding="utf-8")
    answer = findings.static_findings(RobotAnalysis.load(robot))
    done = run_cli("lint-urdf", "--no-config", "--no-cache", "--format", "json", str(robot), cwd=tmp_path)
    printed = json.loads(done.stdout)
    assert answer.document["findings"] == [{**f, "path": answer.result.path} for f in printed["findings"]]
    assert {k: v for k, v in answer.summary.items()} == printed["summary"]
    assert not answer.sim


def test_configuration_and_targets_apply(tiny):
    everything = findings.static_findings(RobotAnalysis.load(tiny)).findings
    assert everything, "the fixture has findings (no visual geometry)"
    ignored = {finding.rule for finding in everything}
    quiet = RobotAnalysis.load(tiny, AnalysisSettings(config=LintConfig(ignore=sorted(ignored))))
    assert findings.static_findings(quiet).findings == []
    mujoco = RobotAnalysis.load(tiny, AnalysisSettings(targets=("mujoco",)))
    assert mujoco.settings.lint_options(sim=False).targets == ("mujoco",)


def test_an_answer_is_computed_once_even_from_two_threads(tiny):
    analysis = RobotAnalysis.load(tiny)
    calls: list[int] = []
    started, release = threading.Event(), threading.Event()

    @question
    def slow(given: RobotAnalysis) -> object:
        calls.append(1)
        started.set()
        release.wait(30)
        return object()

    answers: list[object] = []
    first = threading.Thread(target=lambda: answers.append(slow(analysis)))
    first.start()
    started.wait(30)
    second = threading.Thread(target=lambda: answers.append(slow(analysis)))
    second.start()
    release.set()
    first.join(30)
    second.join(30)
    assert len(calls) == 1 and len(answers) == 2 and answers[0] is answers[1]
    assert slow(RobotAnalysis.load(tiny)) is not answers[0]  # a new load, a new answer


def test_an_error_is_an_answer_too(tiny):
    calls: list[int] = []

    @question
    def refused(given: RobotAnalysis) -> None:
        calls.append(1)
        raise UserError("nothing to check")

    analysis = RobotAnalysis.load(tiny)
    for _ in range(2):
        with pytest.raises(UserError, match="nothing to check"):
            refused(analysis)
    assert len(calls) == 1


def test_a_buffer_stands_in_for_the_file(tiny):
    """An unsaved edit is analysed, the file on disk is not read."""
    edited = _arm().replace(f'<link name="finger">{INERTIAL}', '<link name="finger">')
    analysis = RobotAnalysis.load(tiny, text=edited)
    assert analysis.source == edited.encode()
    rules = {finding.rule for finding in findings.static_findings(analysis).findings}
    on_disk = {finding.rule for finding in findings.static_findings(RobotAnalysis.load(tiny)).findings}
    assert "I001" in rules - on_disk


def test_a_xacro_buffer_is_expanded_with_its_includes(tmp_path):
    """The buffer replaces the top file; macros still come from the included file on disk, and the
    findings point at the buffer's lines."""
    shutil.copytree(XACRO, tmp_path / "xacro")
    top = tmp_path / "xacro" / "arm.urdf.xacro"
    text = top.read_text(encoding="utf-8").replace('<link name="wrist_link"/>', '<link name="hand_link"/>\n  '
                                                   '<link name="wrist_link"/>')
    analysis = RobotAnalysis.load(top, text=text)
    assert analysis.model is not None and analysis.model.link("hand_link") is not None
    assert analysis.model.link("shoulder_link") is not None  # from the macro file
    hand = [f for f in findings.static_findings(analysis).findings if "hand_link" in f.message]
    assert hand and hand[0].line == text.splitlines().index('  <link name="hand_link"/>') + 1
    assert RobotAnalysis.load(top).model.link("hand_link") is None


def test_a_file_that_does_not_load_is_its_finding(tiny):
    analysis = RobotAnalysis.load(tiny, text="<robot name='x'><link name='a'></robot>")
    assert analysis.model is None and "tiny.urdf:1" in analysis.load_error.message
    assert [f.rule for f in findings.static_findings(analysis).findings] == ["F002"]
    with pytest.raises(UserError):
        facts.summary(analysis)
    assert facts.link_facts(analysis, "a") is None
    result = verdict.verdict(analysis)
    assert result.status is verdict.Status.FAIL and result.notes[0].startswith("not loaded:")


def test_a_buffer_over_the_size_limit_is_refused(tiny, monkeypatch):
    import ar3cli.infra.safe_read as safe_read

    monkeypatch.setattr(safe_read, "MAX_FILE_BYTES", 1000)
    analysis = RobotAnalysis.load(tiny, text=_arm())
    assert analysis.model is None and "limit" in analysis.load_error.message


def test_changes_to_the_file_an_include_or_a_mesh_are_seen(tmp_path):
    shutil.copytree(XACRO, tmp_path / "xacro")
    top = tmp_path / "xacro" / "arm.urdf.xacro"
    macros = tmp_path / "xacro" / "macros" / "arm_segment.xacro"
    analysis = RobotAnalysis.load(top)
    assert analysis.changed() == []
    assert {top.resolve(), macros.resolve()} <= {path.resolve() for path in analysis.dependencies.paths}
    macros.write_text(macros.read_text().replace('value="0.5"', 'value="0.75"'), encoding="utf-8")
    assert [path.resolve() for path in analysis.changed()] == [macros.resolve()]
    again = analysis.reloaded()
    assert again.changed() == [] and again.model.link("shoulder_link").inertial.mass == 0.75
    assert analysis.model.link("shoulder_link").inertial.mass == 0.5  # a snapshot: the old one is unchanged

    robot = tmp_path / "mesh.urdf"
    robot.write_text(_arm(mesh="meshes/arm.stl"), encoding="utf-8")
    missing = RobotAnalysis.load(robot)
    assert missing.changed() == []
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "arm.stl").write_bytes(b"solid arm\nendsolid arm\n")
    assert (tmp_path / "meshes" / "arm.stl") in missing.changed()


def test_a_failed_reload_keeps_watching_the_last_good_files(tmp_path):
    shutil.copytree(XACRO, tmp_path / "xacro")
    top = tmp_path / "xacro" / "arm.urdf.xacro"
    macros = tmp_path / "xacro" / "macros" / "arm_segment.xacro"
    good = RobotAnalysis.load(top)
    original = macros.read_text()
    macros.write_text(original.replace("</xacro:macro>", "", 1), encoding="utf-8")
    broken = good.reloaded()
    assert broken.model is None and "xacro" in broken.load_error.message
    assert broken.changed() == []
    macros.write_text(original, encoding="utf-8")
    assert [path.resolve() for path in broken.changed()] == [macros.resolve()]
    assert broken.reloaded().model is not None


def test_a_buffer_does_not_watch_its_own_file(tiny):
    analysis = RobotAnalysis.load(tiny, text=_arm(box="0.1 0.1 0.2"))
    tiny.write_text(_arm(box="0.1 0.1 0.3"), encoding="utf-8")
    assert analysis.changed() == []


def test_resources_are_closed_with_the_analysis(tiny):
    closed: list[str] = []

    class Child:
        def __init__(self, name: str) -> None:
            self.name = name

        def close(self) -> None:
            closed.append(self.name)

    with RobotAnalysis.load(tiny) as analysis:
        first = analysis.keep("child", lambda: Child("a"))
        assert analysis.keep("child", lambda: Child("b")) is first
        analysis.keep("other", lambda: Child("c"))
    assert closed == ["c", "a"]
    with pytest.raises(RuntimeError, match="closed"):
        analysis.keep("late", lambda: Child("d"))


def test_hover_facts_of_a_link_and_a_joint():
    analysis = RobotAnalysis.load(AR3)
    link = facts.link_facts(analysis, "link_2")
    assert link is not None and link.parent.name == "joint_2" and link.children[0].name == "joint_3"
    assert link.lines()[0].startswith("link link_2: ") and link.lines()[0].endswith(" kg")
    assert "parent: link_1 via joint_2: revolute" in link.lines()[1]
    joint = facts.joint_facts(analysis, "joint_2")
    assert joint.info.parent == "link_1" and joint.info.child == "link_2"
    assert joint.lines()[0].startswith("joint joint_2: revolute, axis ")
    assert json.dumps(link.to_dict()) and json.dumps(joint.to_dict())
    assert facts.link_facts(analysis, "no_such_link") is None and facts.joint_facts(analysis, "nope") is None


def test_the_home_pose_says_which_joints_are_not_at_zero(tiny):
    pose = facts.home_pose(RobotAnalysis.load(tiny))
    assert pose.values == {"shoulder": 0.0, "slide": pytest.approx(0.025)}
    assert pose.away_from_zero == {"slide": "0 is outside [0.01, 0.04]"}
    assert pose.line() == "home pose is not all zeros: slide = 0.025 (0 is outside [0.01, 0.04])"
    assert facts.home_pose(RobotAnalysis.load(AR3)).all_zero


def test_the_home_pose_is_the_one_pybullet_commands_use(tiny, pybullet_data_dir):
    """:func:`ar3cli.urdf.home.home_pose` (no pybullet) against sim.sampling.home_positions (a loaded body)."""
    from ar3cli.sim.sampling import home_positions
    from ar3cli.sim.session import Session, run_pybullet
    from ar3cli.urdf.home import home_pose

    robots = [tiny, AR3, pybullet_data_dir / "franka_panda" / "panda.urdf"]
    for robot in robots:
        model = RobotAnalysis.load(robot).require_model()

        def in_child(model=model):
            with Session() as session:
                return home_positions(session.load(model, fixed_base=True))

        assert home_pose(model) == pytest.approx(run_pybullet(in_child, model)), robot


def test_the_verdict_is_built_from_every_section(tmp_path):
    """A robot whose arm box reaches into the post at home: pictures and collision matrix warn, the
    simulated lint finds P002; FK passes; the note says the home pose is not all zeros."""
    robot = tmp_path / "touching.urdf"
    robot.write_text(_arm(box="0.3 0.1 0.1"), encoding="utf-8")
    analysis = RobotAnalysis.load(robot, AnalysisSettings(samples=20, seed=1))
    result = verdict.verdict(analysis)
    checks = {check.key: check for check in result.checks}
    assert "P002" in {f.rule for f in findings.findings(analysis).findings}
    assert checks["renders"].status is verdict.Status.WARNING and checks["renders"].count == 1
    assert checks["collisions"].status is verdict.Status.WARNING
    assert checks["collisions"].line.startswith("1 pair in contact at home; of 6 pairs: 3 adjacent, 1 default")
    assert checks["fk"].status is verdict.Status.PASS
    assert result.status is not verdict.Status.PASS
    assert result.headline.startswith(result.status.value.upper() + ": ")
    assert any(note.startswith("home pose is not all zeros") for note in result.notes)
    assert json.loads(json.dumps(result.to_dict()))["checks"][0]["key"] == "findings"


def test_a_contact_the_packages_srdf_disables_is_not_a_warning(tmp_path):
    """As lint's P002: the pair the SRDF beside the robot disables (the Panda's three in example-robot-data)
    is drawn red and named, but neither the pictures nor the collision matrix warn about it."""
    robot = tmp_path / "touching.urdf"
    robot.write_text(_arm(box="0.3 0.1 0.1"), encoding="utf-8")
    (p002,) = [f for f in findings.findings(RobotAnalysis.load(robot)).findings if f.rule == "P002"]
    a, b = p002.message.split("'")[1:4:2]
    (tmp_path / "touching.srdf").write_text(
        f'<robot name="touching"><disable_collisions link1="{a}" link2="{b}" reason="Default"/></robot>')
    analysis = RobotAnalysis.load(robot, AnalysisSettings(samples=20, seed=1))
    checks = {check.key: check for check in verdict.verdict(analysis).checks}
    assert "P002" not in {f.rule for f in findings.findings(analysis).findings}
    assert checks["renders"].status is verdict.Status.PASS
    assert checks["renders"].line.endswith("1 pair in contact that the package's SRDF touching.srdf disables (drawn red)")
    assert checks["collisions"].status is verdict.Status.PASS
    assert "1 pair in contact at home that the package's SRDF touching.srdf disables" in checks["collisions"].line


def test_xacro_findings_keep_their_lines_however_many_files_were_expanded_since(tmp_path):
    """An editor opens many xacro files and lints them later: each model keeps its elements' origins
    (only the last four expansions used to be known, then findings fell back to expanded-URDF lines)."""
    shutil.copytree(XACRO, tmp_path / "xacro")
    top = tmp_path / "xacro" / "arm.urdf.xacro"
    first = RobotAnalysis.load(top)
    others = [RobotAnalysis.load(top, text=top.read_text().replace("xacro_arm", f"arm_{n}")) for n in range(6)]
    lines = {(f.path, f.line) for f in findings.static_findings(first).findings}
    assert any(path.endswith("macros/arm_segment.xacro") for path, _ in lines)
    assert lines == {(f.path, f.line) for f in findings.static_findings(others[0]).findings}


def test_a_check_that_cannot_run_is_not_checked_with_its_reason(tmp_path):
    """A robot without geometry: no picture, no collision matrix; those checks say why (without the
    file's path in front), and nothing counts as passed."""
    robot = tmp_path / "bare.urdf"
    robot.write_text(f'<robot name="bare"><link name="a">{INERTIAL}</link></robot>', encoding="utf-8")
    checks = {check.key: check for check in verdict.verdict(RobotAnalysis.load(robot)).checks}
    for key in ("renders", "collisions"):
        assert checks[key].status is verdict.Status.NOT_CHECKED, key
        assert not checks[key].line.startswith(str(robot)), checks[key].line
    assert "no link has <collision>" in checks["collisions"].line
    assert verdict.without_path(f"{robot}:12: bad", robot) == "line 12: bad"
