"""``--format sarif``: lint findings as one SARIF 2.1.0 document (code scanning)."""

from __future__ import annotations

from ar3cli.output.formats import LINT, Format, register
from ar3cli.output.lint_report import LintReport, completed
from ar3cli.output.report import OutputFormat, Report


def lint_sarif(lint: LintReport) -> Report:
    """The SARIF document of the findings and the rules that ran."""
    from ar3cli.output.lint_report import config_name
    from ar3cli.output.sarif import sarif_document

    why = {"comment": "an ar3cli: ignore comment in the file",
           "config": f"{config_name(lint.summary.get('config_file'))} [tool.ar3cli.lint]",
           "baseline": f"the baseline {lint.summary.get('baseline') or ''}".rstrip()}
    suppressed = [(item.finding, item.by, why[item.by]) for result in lint.results
                  for item in getattr(result, "suppressed", ())]
    return completed(lint, Report(data=sarif_document(lint.findings, lint.rules(), lint.group is not None, suppressed),
                                  ok=lint.ok))


FORMAT = register(Format("sarif", "SARIF 2.1.0", {LINT: lint_sarif}, stream=OutputFormat.json, order=20))
