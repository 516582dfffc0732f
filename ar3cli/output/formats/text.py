"""``--format text``: tables for people (every report); lint findings one table per file on a
terminal, one line per finding elsewhere."""

from __future__ import annotations

import sys

from ar3cli.findings import Finding
from ar3cli.output.formats import LINT, REPORT, Format, register
from ar3cli.output.lint_report import LintReport, completed, summary_line
from ar3cli.output.lists import capped, left_out
from ar3cli.output.report import Report, Table, piped


def lint_text(lint: LintReport) -> Report:
    """One table per file with findings (alike findings folded into one row when ``lint.group``),
    then the verdict; piped without ``COLUMNS`` (pre-commit, a CI log, grep) and without ``--wide``,
    one line per finding instead (:func:`concise_lines`); with ``--changed-since`` and nothing to
    check, only its note."""
    if lint.note is not None and not lint.results:
        return completed(lint, Report(data={}), text=True, hints=True)
    cached = sum(result.cached for result in lint.results)
    verdict = summary_line(lint.summary, cached)
    if not lint.wide and piped(sys.stdout):
        lines = [line for result in lint.results for line in concise_lines(result.findings, lint)]
        return completed(lint, Report(data=lint.data, lines=[*lines, verdict], ok=lint.ok), text=True, hints=True)
    tables = [Table(title=result.path, columns=["location", "code", "severity", "message", "hint"],
                    rows=_rows(result.findings, lint), status_column="severity", nowrap_columns=("location",))
              for result in lint.results if result.findings]
    report = Report(data=lint.data, tables=tables, lines=[verdict], ok=lint.ok)
    return completed(lint, report, text=True, hints=True)


def concise_lines(findings: list[Finding], lint: LintReport) -> list[str]:
    """``path:line:col: CODE [severity] message``, a line per finding or group of alike findings (as
    ruff's concise output; editors and terminals make the location a link, grep finds the code), at
    most :data:`~ar3cli.output.lists.TABLE_ROWS` a file, as its table."""
    rows, left = capped(_rows(findings, lint))
    lines = [f"{location}: {code} [{severity}] {message}" for location, code, severity, message, _ in rows]
    return lines + ([f"{findings[0].path}: {left_out(left)}"] if left else [])


def _rows(findings: list[Finding], lint: LintReport) -> list[list]:
    """Table rows: one per finding, or per group of alike findings (``first`` and ``message``)."""
    rows = []
    for row in lint.group(findings) if lint.group else findings:
        first = row if isinstance(row, Finding) else row.first
        rows.append([first.location, first.rule, first.severity.value, row.message, first.hint])
    return rows


FORMAT = register(Format("text", "tables for people", {REPORT: lambda report: report, LINT: lint_text}, order=0))
