"""``--format junit``: lint findings as a JUnit XML test report (one test case per file)."""

from __future__ import annotations

from ar3cli.findings import Severity
from ar3cli.output.formats import LINT, Format, register
from ar3cli.output.lint_report import LintReport, completed, summary_line
from ar3cli.output.report import Report


def lint_junit(lint: LintReport) -> Report:
    """The JUnit document on stdout, the verdict on stderr."""
    from ar3cli.output.junit import junit_document

    document = junit_document([(r.path, r.findings, r.error) for r in lint.results], Severity(lint.summary["fail_on"]),
                              lint.group is not None)
    return completed(lint, Report(data=lint.data, text=document, lines=[summary_line(lint.summary)], ok=lint.ok))


FORMAT = register(Format("junit", "JUnit XML test report", {LINT: lint_junit}, order=50))
