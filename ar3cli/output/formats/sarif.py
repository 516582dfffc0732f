"""``--format sarif``: lint findings as one SARIF 2.1.0 document (code scanning)."""

from __future__ import annotations

from ar3cli.output.formats import LINT, Format, register
from ar3cli.output.lint_report import LintReport, completed
from ar3cli.output.report import OutputFormat, Report


def lint_sarif(lint: LintReport) -> Report:
    """The SARIF document of the findings and the rules that ran."""
    from ar3cli.output.sarif import sarif_document

    return completed(lint, Report(data=sarif_document(lint.findings, lint.rules(), lint.group is not None), ok=lint.ok))


FORMAT = register(Format("sarif", "SARIF 2.1.0", {LINT: lint_sarif}, stream=OutputFormat.json, order=20))
