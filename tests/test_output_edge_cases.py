"""Options and output on hostile or unusual input: finite floats, control characters in names,
tables that fit the width, a consistent lint summary, undeclared attribute prefixes, JUnit with
one failure per testcase (issues 22 and 30)."""

from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET

import pytest

from ar3cli.lint.rules.base import LINK_INERTIAL, arm, robot
from ar3cli.output.report import Table, plain_table, printable

NO_LIMIT = arm(joint_extra="")  # J001 error
TWO_ERRORS = robot(f"""
    <link name="base"/>
    <link name="a">{LINK_INERTIAL}</link>
    <link name="b">{LINK_INERTIAL}</link>
    <joint name="ja" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
    <joint name="jb" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
    """)


# ---- 1. every float option refuses nan and infinities ---------------------------------------------


def _float_options() -> list[tuple[str, object]]:
    """(command name, click parameter) for every float option of every command of the real app."""
    import typer

    from ar3cli.cli import application

    group = typer.main.get_command(application([]))
    found = []
    for name, command in group.commands.items():
        for param in command.params:
            if "float" in type(param.type).__name__.lower() or getattr(param.type, "name", "") == "float":
                found.append((name, param))
    return found


def test_every_float_option_uses_the_finite_float_type():
    from ar3cli.commands.options import FiniteFloat

    options = _float_options()
    assert len(options) >= 13  # fix-collision 1, fix-continuous 2, fix-joints 2, fix-inertia 2, fk-verify 2, ...
    assert [(name, param.opts) for name, param in options if not isinstance(param.type, FiniteFloat)] == []


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "NaN", "-Infinity"])
def test_every_float_option_refuses_nan_and_infinities(value, write_urdf, capsys):
    """Walks the app: each command's every float option, given ``value``, is one line and exit 2
    (parsing stops at the option, so no command body runs)."""
    from ar3cli.cli import main

    path = str(write_urdf(NO_LIMIT))
    for name, param in _float_options():
        option = max(param.opts, key=len)
        with pytest.raises(SystemExit) as exit_info:
            main([name, path, f"{option}={value}"])
        err = capsys.readouterr().err
        assert exit_info.value.code == 2, (name, option, err)
        assert err.count("\n") == 1 and err.startswith("ar3cli: error: ")
        assert f"'{option}': {value}: must be a finite number" in err, err


def test_densities_that_are_no_material_are_refused(cli, write_urdf):
    path = write_urdf(NO_LIMIT)
    for density in ("1e-320", "0", "-5", "1e300"):
        result = cli("fix-inertia", str(path), "--density", density, "--diff")
        assert result.code == 2 and result.stderr.count("\n") == 1 and "must be a density between" in result.stderr
    assert cli("fix-inertia", str(path), "--total-mass", "1e-320", "--diff").code == 2


# ---- 2. control characters in names ------------------------------------------------------------------


def test_printable_shows_controls_and_bidi_marks_and_keeps_the_rest():
    assert printable("plain ümlaut 日本") == "plain ümlaut 日本"
    assert printable("a\x1b[2Jb\rc\x9bd\u202ee\x7f\tf\ng") == "a\\x1b[2Jb\\x0dc\\x9bd\\u202ee\\x7f\tf\\x0ag"
    assert printable("bad\udcff\u2028") == "bad\\xff\\u2028"  # a file name's non-UTF-8 byte, a line separator


def test_control_characters_are_neutralised_in_text_github_markdown_and_kept_in_json(cli, tmp_path):
    name = "evil\x1b[2J\x1b[31m.urdf"
    hostile = NO_LIMIT.replace('name="j1"', 'name="j&#13;\u202eok\u009b"')
    assert hostile != NO_LIMIT
    (tmp_path / name).write_text(hostile, encoding="utf-8")
    for fmt in ("text", "github", "markdown"):
        result = cli("lint-urdf", name, "--no-cache", "--format", fmt, cwd=tmp_path)
        shown = result.stdout + result.stderr
        assert result.code == 1 and "evil\\x1b[2J" in shown.replace("\\\\", "\\"), fmt
        assert not any(char in shown for char in "\x1b\r\u202e\u009b"), fmt
    data = json.loads(cli("lint-urdf", name, "--no-cache", "--format", "json", cwd=tmp_path).stdout)
    assert data["findings"][0]["path"] == name and "j\r\u202eok\u009b" in data["findings"][0]["message"]


def test_error_lines_show_control_characters_in_file_names(cli, tmp_path):
    for command in (["info"], ["fk-verify"], ["lint-urdf", "--format", "json"]):
        result = cli(*command, "missing\x1b[2J\x07.urdf", cwd=tmp_path)
        assert result.code == 2 and "missing\\x1b[2J\\x07.urdf" in result.stderr, command
        assert "\x1b" not in result.stderr and "\x07" not in result.stderr, command


# ---- 3. tables fit the width ---------------------------------------------------------------------------

WIDE = Table(title="t.urdf", columns=["location", "code", "severity", "message", "hint"],
             rows=[["t.urdf:3:5", "I001", "error", "link 'a' moves but has no <inertial>: PyBullet uses 1 kg " * 3,
                    "Add an <inertial> with the real mass, COM and tensor (ar3cli fix-inertia can compute one)."]],
             status_column="severity", nowrap_columns=("location",))


def test_plain_table_fits_a_width_and_wraps_the_long_cells():
    text = plain_table(WIDE, 80)
    lines = text.splitlines()
    assert max(map(len, lines)) <= 80 and len(lines) > 6
    assert "| t.urdf:3:5 | I001 | error    |" in text  # what grep looks for stays on the row's first line
    assert "PyBullet" in text and "fix-inertia" in text
    assert len(plain_table(WIDE).splitlines()) == 6  # no width: one line per row
    blocks = plain_table(WIDE, 40)  # too narrow for columns: one block per row
    assert max(map(len, blocks.splitlines())) <= 40 and "t.urdf:3:5  I001  error" in blocks


def test_lint_text_honours_columns_and_wide(cli, tmp_path):
    (tmp_path / "bad.urdf").write_text(TWO_ERRORS)
    fitted = cli("lint-urdf", "bad.urdf", "--no-cache", cwd=tmp_path, env={"COLUMNS": "80"})
    table = [line for line in fitted.stdout.splitlines() if line.startswith(("|", "+"))]
    assert fitted.code == 1 and table and max(map(len, table)) <= 80
    wide = cli("lint-urdf", "bad.urdf", "--no-cache", "--wide", cwd=tmp_path, env={"COLUMNS": "80"})
    rows = [line for line in wide.stdout.splitlines() if line.startswith("| bad.urdf:")]
    assert len(rows) == 2 and max(map(len, rows)) > 80  # one line per finding, however wide
    piped = cli("lint-urdf", "bad.urdf", "--no-cache", cwd=tmp_path, env={"COLUMNS": ""})
    concise = piped.stdout.splitlines()  # piped without COLUMNS: a line per finding, as ruff's concise output
    assert [line for line in concise if line.startswith("bad.urdf:")] == [
        line for line in concise if re.fullmatch(r"bad\.urdf:\d+:\d+: [A-Z]\d{3} \[(error|warning|info)\] .+", line)]
    assert len([line for line in concise if line.startswith("bad.urdf:")]) == 2 and concise[-1].startswith("FAILED")


# ---- 4. the lint summary agrees with itself and with the exit code -------------------------------------


def test_summary_fields_agree_with_the_counts_and_the_exit_code(cli, tmp_path):
    (tmp_path / "bad.urdf").write_text(TWO_ERRORS)
    (tmp_path / "good.urdf").write_text(arm())
    result = cli("lint-urdf", ".", "--no-cache", "--format", "json", cwd=tmp_path)
    summary = json.loads(result.stdout)["summary"]
    assert summary["error"] >= 2 and summary["files_with_errors"] == 1 and summary["files_not_checked"] == 0
    assert summary["failed"] is True and summary["findings_failing"] >= 2
    assert summary["exit_code"] == result.code == 1
    zero = cli("lint-urdf", ".", "--no-cache", "--format", "json", "--exit-zero", cwd=tmp_path)
    assert json.loads(zero.stdout)["summary"]["exit_code"] == zero.code == 0


INFO_AND_WARNING = '<robot name="r"><link name="base"><visual><geometry><box size="1 1 1"/></geometry></visual></link></robot>'
"""G008 (warning) and I012 (info), nothing at or above the default --fail-on."""


def test_clean_means_nothing_at_or_above_fail_on_in_the_summary_json_and_scan(cli, tmp_path):
    """Issue 36 item 4: lint --sim's P003 (info) on the bundled AR3 made the summary say "1 info; 0 clean"
    and scan-report --keep clean keep nothing."""
    (tmp_path / "bad.urdf").write_text(TWO_ERRORS)
    (tmp_path / "info.urdf").write_text(INFO_AND_WARNING)
    text = cli("lint-urdf", ".", "--no-cache", cwd=tmp_path).stdout
    assert "1 warnings, 1 info; 1 clean (fail-on: error)" in text
    summary = json.loads(cli("lint-urdf", ".", "--no-cache", "--format", "json", cwd=tmp_path).stdout)["summary"]
    assert summary["files_clean"] == 1
    strict = json.loads(cli("lint-urdf", ".", "--no-cache", "--format", "json", "--fail-on", "warning",
                            cwd=tmp_path).stdout)["summary"]
    assert strict["files_clean"] == 0
    assert cli("scan", ".", "--store", "s.sqlite", cwd=tmp_path).code == 0
    report = json.loads(cli("scan-report", "s.sqlite", "--keep", "clean", "--format", "json", cwd=tmp_path).stdout)
    assert report["statuses"]["clean"] == 1 and report["statuses"]["findings"] == 1
    assert [path.rsplit("/", 1)[-1] for path in report["keep"]["paths"]] == ["info.urdf"]
    assert [row["path"].rsplit("/", 1)[-1] for row in report["worst"]] == ["bad.urdf", "info.urdf"]


def test_a_file_not_checked_fails_the_summary():
    from ar3cli.findings import Severity
    from ar3cli.lint.engine import LintResult, summarize

    summary = summarize([LintResult("a.urdf", True, [], error="pybullet crashed")], Severity.ERROR)
    assert summary["failed"] is True and summary["files_not_checked"] == 1
    assert summary["files_with_errors"] == 0 == summary["error"] and summary["files_clean"] == 0


# ---- 5. an undeclared prefix on an attribute ------------------------------------------------------------

DRAKE_ATTRIBUTE = f"""<?xml version="1.0"?>
<robot name="r">
  <!-- a comment with a:b="c" is not an attribute -->
  <link name="base">{LINK_INERTIAL}<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="arm">{LINK_INERTIAL}</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="0" velocity="1"
           drake:acceleration="2.5"/></joint>
</robot>
"""


def test_an_undeclared_attribute_prefix_is_a_warning_and_the_rest_is_linted(cli, write_urdf):
    path = write_urdf(DRAKE_ATTRIBUTE)
    data = json.loads(cli("lint-urdf", str(path), "--no-cache", "--format", "json").stdout)
    rules = {f["rule"]: f for f in data["findings"]}
    assert "F002" not in rules and rules["F005"]["line"] == 8 and "drake" in rules["F005"]["message"]
    assert "J008" in rules  # effort="0": the rest of the file was linted
    assert len([f for f in data["findings"] if f["rule"] == "F005"]) == 1  # the comment is not a use
    info = cli("info", str(path), "--format", "json")
    assert info.code == 0, info.stderr
    assert cli("fk-verify", str(path), "-n", "2").code == 0
    assert path.read_text() == DRAKE_ATTRIBUTE


# ---- 6. JUnit: one failure per testcase --------------------------------------------------------------------


def test_junit_has_one_testcase_per_failing_finding_and_one_failure_at_most(cli, tmp_path):
    (tmp_path / "bad.urdf").write_text(TWO_ERRORS)
    (tmp_path / "good.urdf").write_text(arm())
    result = cli("lint-urdf", ".", "--no-cache", "--format", "junit", "--no-group", cwd=tmp_path)
    root = ET.fromstring(result.stdout)
    for case in root.iter("testcase"):  # the common JUnit schema's rule
        assert len(case.findall("failure")) + len(case.findall("error")) <= 1
    bad = root.find("testsuite[@name='bad.urdf']")
    failures = [case.find("failure") for case in bad.findall("testcase")]
    assert len(failures) >= 2 and all(failure is not None for failure in failures)
    assert bad.get("tests") == bad.get("failures") == str(len(failures))
    (clean,) = root.find("testsuite[@name='good.urdf']").findall("testcase")
    assert clean.get("name") == "good.urdf" and clean.find("failure") is None
    assert int(root.get("tests")) == len(list(root.iter("testcase")))
    assert int(root.get("failures")) == len(list(root.iter("failure")))
