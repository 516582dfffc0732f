"""``--format github``: GitHub Actions workflow annotations on stdout, and the Markdown form
appended to ``$GITHUB_STEP_SUMMARY`` when set (the reviewer sees it on the run's summary page)."""

from __future__ import annotations

from dataclasses import replace

from ar3cli.output.formats import ANNOTATIONS, LINT, Format, register
from ar3cli.output.lint_report import LintReport, completed, summary_line
from ar3cli.output.report import Report


def lint_github(lint: LintReport) -> Report:
    """One annotation per finding, then the verdict."""
    from ar3cli.output.github_actions import annotation, append_step_summary
    from ar3cli.output.markdown_table import markdown_table

    verdict = summary_line(lint.summary)
    error = append_step_summary(markdown_table(lint.findings, verdict))
    annotations = "".join(annotation(finding) + "\n" for finding in lint.findings)
    report = Report(data=lint.data, text=annotations + verdict + "\n", ok=lint.ok, errors=[error] if error else [])
    return completed(lint, report)


def annotated(report: Report) -> Report:
    """A report that has annotations and a Markdown form (``Report.annotations``, ``Report.markdown``)."""
    from ar3cli.output.github_actions import append_step_summary

    assert report.annotations is not None and report.markdown is not None
    failed = append_step_summary(report.markdown())
    return replace(report, text=report.annotations(), tables=[], lines=[],
                   errors=[*report.errors, *([failed] if failed else [])])


FORMAT = register(Format("github", "workflow annotations; the Markdown is appended to $GITHUB_STEP_SUMMARY",
                         {LINT: lint_github, ANNOTATIONS: annotated}, order=30))
