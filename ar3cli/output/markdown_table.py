"""Findings as a GitHub-flavoured Markdown table (``--format markdown``, the step summary, pull-request
comments), with cells made safe.

Text goes through :func:`~ar3cli.output.report.printable` first: a bidi override must not reorder a
reviewer's page, and ``<inertial>`` must be shown, not eaten as an HTML tag.
"""

from __future__ import annotations

from ar3cli.findings import Finding
from ar3cli.output.report import printable


def markdown_cell(text: str) -> str:
    """Text safe inside a table cell: pipes escaped, and ``<inertial>`` shown, not eaten as an HTML tag."""
    text = printable(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return text.replace("\\", "\\\\").replace("|", "\\|").replace("\r", " ").replace("\n", " ")


def markdown_table(findings: list[Finding], summary_line: str) -> str:
    """A findings table in GitHub-flavoured Markdown, ending with the summary line."""
    lines = ["## ar3cli lint-urdf", ""]
    if findings:
        lines += ["| location | rule | severity | message | hint |", "| --- | --- | --- | --- | --- |"]
        lines += [f"| `{markdown_cell(f.location)}` | {f.rule} | {f.severity.value} | {markdown_cell(f.message)} | "
                  f"{markdown_cell(f.hint)} |" for f in findings]
        lines.append("")
    lines.append(printable(summary_line))
    return "\n".join(lines) + "\n"
