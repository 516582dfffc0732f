"""``--format json``: the report's JSON document alone on stdout (every report)."""

from __future__ import annotations

from ar3cli.output.formats import LINT, REPORT, Format, register
from ar3cli.output.lint_report import LintReport, completed
from ar3cli.output.report import OutputFormat, Report


def lint_json(lint: LintReport) -> Report:
    """The lint document: files, findings, summary (and ``changed_since``, ``fix_commands``)."""
    return completed(lint, Report(data=lint.data, ok=lint.ok), hints=True)


FORMAT = register(Format("json", "one JSON document on stdout", {REPORT: lambda report: report, LINT: lint_json},
                         stream=OutputFormat.json, order=10))
