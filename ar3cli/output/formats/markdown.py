"""``--format markdown``: a Markdown document on stdout (a pull-request comment, a job summary)."""

from __future__ import annotations

from dataclasses import replace

from ar3cli.output.formats import LINT, MARKDOWN, Format, register
from ar3cli.output.lint_report import LintReport, completed, summary_line
from ar3cli.output.report import Report


def lint_markdown(lint: LintReport) -> Report:
    """The findings as a Markdown table (a row per rule and file, errors first), then the verdict."""
    from ar3cli.output.markdown_table import findings_markdown

    text = findings_markdown(lint.findings, summary_line(lint.summary), lint.group is not None)
    return completed(lint, Report(data=lint.data, text=text, ok=lint.ok))


def markdown(report: Report) -> Report:
    """A report with a Markdown form (``Report.markdown``): that text alone on stdout."""
    assert report.markdown is not None
    return replace(report, text=report.markdown(), tables=[], lines=[])


FORMAT = register(Format("markdown", "for a pull-request comment", {LINT: lint_markdown, MARKDOWN: markdown},
                         order=40))
