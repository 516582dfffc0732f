"""``--format html``: lint findings as one self-contained HTML page (source lines, fix commands)."""

from __future__ import annotations

from ar3cli.output.formats import LINT, Format, register
from ar3cli.output.lint_report import LintReport, completed, summary_line
from ar3cli.output.report import Report


def lint_html(lint: LintReport) -> Report:
    """The page on stdout, the verdict on stderr."""
    from ar3cli.output.html import lint_page

    verdict = summary_line(lint.summary)
    page = lint_page(lint.data, {"verdict": verdict, **lint.context(lint.findings)})
    return completed(lint, Report(data=lint.data, text=page, lines=[verdict], ok=lint.ok))


FORMAT = register(Format("html", "one self-contained HTML page", {LINT: lint_html}, order=60))
