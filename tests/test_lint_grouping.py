"""Grouping in lint-urdf's text output: 5 or more alike findings of one rule in one file become one
row or line (count, first locations, the first message); --group/--no-group; JSON keeps every
finding, the CI formats (github, markdown, sarif, junit) show one annotation, row, result or test
case per rule and file (issue 36, item 2)."""

from __future__ import annotations

import json

from ar3cli.findings import Finding, Severity
from ar3cli.lint.engine import FindingGroup, group_findings, message_shape

LINK_INERTIAL = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
                 '</inertial>')


def chain(joints: int) -> str:
    """A chain of ``joints`` revolute joints without <limit> (J001 on each: alike but for the name)."""
    links = "".join(f'  <link name="l{i}">{LINK_INERTIAL}</link>\n' for i in range(joints + 1))
    moving = "".join(f'  <joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                     f'<axis xyz="0 0 1"/></joint>\n' for i in range(joints))
    return f'<?xml version="1.0"?>\n<robot name="r">\n{links}{moving}</robot>\n'


def finding(rule: str, message: str, line: int, path: str = "a.urdf", severity: Severity = Severity.ERROR) -> Finding:
    return Finding(rule, severity, message, path, line, 3, "fix it")


def test_message_shape_ignores_names_paths_and_numbers():
    assert message_shape("link 'a' mesh package:///x/a.STL names no package") == \
        message_shape("link 'b_2' mesh package:///y/z/b.dae names no package")
    assert message_shape("revolute joint 'j' limits (-9.42, 9.42) exceed ±2π rad") == \
        message_shape("revolute joint 'k' limits (-180, 180) exceed ±2π rad")
    assert message_shape("link 'a' is a frame (no geometry) on fixed joint 'j'") != \
        message_shape("link 'a' has geometry on fixed joint 'j'")


def test_five_alike_findings_become_one_group_where_the_first_was():
    names = "abcdef"
    rows = group_findings([finding("J001", "joint 'a' has no <limit>", 5), finding("S001", "no name", 6),
                           *(finding("J001", f"joint '{name}' has no <limit>", 7 + 2 * i)
                             for i, name in enumerate(names[1:]))])
    assert [type(row) for row in rows] == [FindingGroup, Finding]
    group = rows[0]
    assert len(group.findings) == 6
    assert group.message == "6x: joint 'a' has no <limit> (and 5 more like it); at 5:3, 7:3, 9:3, ..."


def test_identical_messages_are_not_called_alike_and_small_groups_stay():
    rows = group_findings([finding("S008", "same", line) for line in (1, 2, 3, 4, 5)])
    assert rows[0].message == "5x: same; at 1:3, 2:3, 3:3, ..."
    four = [finding("J001", f"joint '{name}' has no <limit>", line) for name, line in zip("abcd", (5, 7, 9, 11))]
    assert group_findings(four) == four  # a few stay one per row: each is worth reading


def test_other_files_severities_and_shapes_are_not_mixed():
    findings = [finding("J001", "joint 'a' x", 1, "a.urdf"), finding("J001", "joint 'b' x", 2, "a.urdf"),
                finding("J001", "joint 'c' x", 3, "b.xacro"), finding("J001", "joint 'd' x", 4, "a.urdf", Severity.WARNING),
                finding("J001", "joint 'e' y", 5, "a.urdf")]
    assert group_findings(findings) == findings


def test_cli_group_and_no_group(cli, write_urdf):
    path = str(write_urdf(chain(5)))
    grouped = cli("lint-urdf", path, "--group", "--no-cache")
    assert grouped.code == 1
    rows = [line for line in grouped.stdout.splitlines() if " J001 [error] " in line]  # piped: a line per row
    assert len(rows) == 1 and "5x: revolute joint 'j0' has no <limit> (and 4 more like it); at " in rows[0]
    assert "FAILED: 1 file checked, 5 errors" in grouped.stdout  # the summary counts every finding
    every = cli("lint-urdf", path, "--no-group")
    assert every.stdout.count(" J001 [error] ") == 5
    assert cli("lint-urdf", path, "--no-group", "--wide").stdout.count("| J001 |") == 5
    assert cli("lint-urdf", path, "--no-cache").stdout == grouped.stdout  # grouped by default, terminal or not


def test_json_keeps_every_finding_and_ci_formats_group_by_rule_and_file(cli, write_urdf):
    path = str(write_urdf(chain(4)))
    document = json.loads(cli("lint-urdf", path, "--group", "--format", "json").stdout)
    assert len(document["findings"]) == 4 and document["summary"]["findings"] == 4
    sarif = json.loads(cli("lint-urdf", path, "--group", "--format", "sarif").stdout)
    (result,) = sarif["runs"][0]["results"]
    assert len(result["relatedLocations"]) == 3 and "4 findings of J001" in result["message"]["text"]
    assert cli("lint-urdf", path, "--group", "--format", "github").stdout.count("title=J001") == 1
    assert cli("lint-urdf", path, "--group", "--format", "markdown").stdout.count("| J001 |") == 1
    every = cli("lint-urdf", path, "--no-group", "--format", "github").stdout
    assert every.count("title=J001") == 4
    import xml.etree.ElementTree as ET

    (case,) = ET.fromstring(cli("lint-urdf", path, "--format", "junit").stdout).iter("testcase")
    failure = case.find("failure")
    assert failure.get("message").endswith("(4 findings)") and failure.text.count(" error J001: ") == 4


def test_ci_groups_are_one_per_rule_and_file_errors_first_and_long_messages_cut():
    from ar3cli.output.lint_report import headline, rule_groups

    findings = [finding("I002", "link 'x' is a frame", 3, severity=Severity.WARNING),
                finding("G001", "link 'a' mesh m.stl: not found; looked in " + ", ".join(["/far/away"] * 40), 5),
                finding("G001", "link 'b' mesh n.stl: not found", 9), finding("G001", "elsewhere", 2, "b.urdf")]
    groups = rule_groups(findings)
    assert [(group.first.rule, group.first.path, group.count) for group in groups] == [
        ("G001", "a.urdf", 2), ("G001", "b.urdf", 1), ("I002", "a.urdf", 1)]
    assert groups[0].summary() == "2x: link 'a' mesh m.stl: not found; ... (and 1 more like it)"
    assert groups[0].places() == "5:3, 9:3" and headline("short") == "short"
    assert [group.count for group in rule_groups(findings, grouped=False)] == [1, 1, 1, 1]
