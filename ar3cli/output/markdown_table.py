"""Markdown for GitHub (``--format markdown``, the step summary, pull-request comments): tables with
every cell made inert, and lint findings one row per rule and file.

Names and messages go through :func:`~ar3cli.output.escape.markdown_text` (a link named
``![x](https://...)`` stays text, ``<inertial>`` is shown, not eaten as an HTML tag), paths and
locations through :func:`~ar3cli.output.escape.markdown_code` (a backtick in a file name cannot end
the code span). Tables show at most :data:`~ar3cli.output.lists.TABLE_ROWS` rows.
"""

from __future__ import annotations

from collections.abc import Sequence

from ar3cli.findings import Finding
from ar3cli.output.escape import markdown_code, markdown_text
from ar3cli.output.lint_report import RuleGroup, headline, rule_groups
from ar3cli.output.lists import capped, left_out
from ar3cli.output.report import Table, format_cell

DETAILS = 20
"""Findings a grouped row lists in full in its ``<details>``."""


def markdown_row(cells: Sequence[str]) -> str:
    """``| a | b |`` of cells already escaped."""
    return "| " + " | ".join(cells) + " |"


def table_markdown(table: Table, code_columns: Sequence[str] = (), heading: str = "###") -> list[str]:
    """The lines of ``table`` in Markdown: its title as a heading, a header, at most
    :data:`~ar3cli.output.lists.TABLE_ROWS` rows (``code_columns`` as code spans, numbers right
    aligned), then its caption and a line counting the rows left out."""
    out = [f"{heading} {markdown_text(table.title)}", ""] if table.title else []
    out += [markdown_row([markdown_text(column) for column in table.columns]),
            markdown_row(["---:" if column in table.numeric_columns else "---" for column in table.columns])]
    rows, left = capped(table.rows)
    code = [column in code_columns for column in table.columns]
    out += [markdown_row([markdown_code(format_cell(value)) if as_code and value not in (None, "")
                          else markdown_text(format_cell(value) if value is not None else "")
                          for value, as_code in zip(row, code)]) for row in rows]
    out += [line for line in (table.caption and markdown_text(table.caption), left and markdown_text(left_out(left)))
            if line]
    return [*out, ""]


def findings_markdown(findings: list[Finding], summary_line: str, grouped: bool = True) -> str:
    """lint-urdf's Markdown: one row per rule and file (errors first) with the count, the first
    message (long ones cut at their first ``;``) and every message in a ``<details>``; ``grouped``
    False: a row per finding. The verdict last."""
    lines = ["## ar3cli lint-urdf", ""]
    if findings:
        groups, left = capped(rule_groups(findings, grouped))
        lines += [markdown_row(["location", "rule", "severity", "message", "hint"]), "| --- | --- | --- | --- | --- |"]
        lines += [markdown_row([markdown_code(group.first.location), markdown_text(group.first.rule),
                                group.first.severity.value, _message(group), markdown_text(group.first.hint)])
                  for group in groups]
        if left:
            lines.append(markdown_text(left_out(left, "rows")))
        lines.append("")
    lines.append(markdown_text(summary_line))
    return "\n".join(lines) + "\n"


def _message(group: RuleGroup) -> str:
    """The message cell: the group's summary, and when there is more to read (more findings, or a
    message cut short) a ``<details>`` with every message (at most :data:`DETAILS`)."""
    text = markdown_text(group.summary())
    cut = any(headline(finding.message) != finding.message for finding in group.findings)
    if group.count == 1 and not cut:
        return text
    shown, left = capped(group.findings, DETAILS)
    items = [f"{markdown_code(f'{f.line}:{f.column or 1}' if f.line else f.path)} {markdown_text(f.message)}"
             for f in shown]
    if left:
        items.append(markdown_text(f"and {left:,} more"))
    label = f"at {group.places()}" if group.count > 1 else "the whole message"
    return f"{text}<details><summary>{markdown_text(label)}</summary>{'<br>'.join(items)}</details>"
