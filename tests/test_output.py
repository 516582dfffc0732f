"""The output layer: plain tables off a terminal, blocks on a narrow one, JSON alone on stdout."""

from __future__ import annotations

import io

from rich.console import Console

from ar3cli.output.report import Report, Table, plain_table, render_table

TABLE = Table(title="t.urdf", columns=["location", "code", "severity", "message"],
              rows=[["t.urdf:3:5", "I001", "error", "link 'a' moves but has no <inertial>: PyBullet uses 1 kg"]],
              status_column="severity", nowrap_columns=("location",))


def test_plain_table_is_one_line_per_row():
    text = plain_table(TABLE)
    lines = text.splitlines()
    assert lines[0] == "t.urdf" and len(lines) == 6
    assert "| t.urdf:3:5 | I001 | error    | link 'a' moves but has no <inertial>: PyBullet uses 1 kg |" in lines


def test_narrow_terminal_prints_blocks_and_wide_prints_a_table():
    narrow = io.StringIO()
    render_table(TABLE, Console(file=narrow, width=70, force_terminal=True, color_system=None))
    assert "t.urdf:3:5  I001  error" in narrow.getvalue()
    assert "    message: link 'a' moves" in narrow.getvalue()
    wide = io.StringIO()
    render_table(TABLE, Console(file=wide, width=160, force_terminal=True, color_system=None))
    assert "│ t.urdf:3:5 │ I001 │ error    │" in wide.getvalue()


def test_report_text_payload_goes_to_stdout_and_tables_to_stderr(capsys):
    from ar3cli.output.report import render_report

    render_report(Report(data={"a": 1}, tables=[TABLE], lines=["summary"], text="--- a/x\n+++ b/x\n"), "text")
    captured = capsys.readouterr()
    assert captured.out == "--- a/x\n+++ b/x\n"
    assert "I001" in captured.err and "summary" in captured.err
    render_report(Report(data={"a": 1}, tables=[TABLE], text="ignored"), "json")
    assert capsys.readouterr().out == '{\n  "a": 1\n}\n'
