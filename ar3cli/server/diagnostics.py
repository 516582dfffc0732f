"""A lint finding as an LSP diagnostic: its range, severity, rule code linked to its documentation.

The message is the finding's, then its hint on a second line (what lint-urdf prints in its ``hint``
column). Names in it come from the robot file: control characters are written out
(:func:`~ar3cli.output.report.printable`), as every other output does, so a file cannot make an
editor's message panel misbehave. ``data`` carries the finding's own location (1-based line and
column in its file) so a code action can find the element again.
"""

from __future__ import annotations

from lsprotocol import types

from ar3cli.findings import Finding, Severity
from ar3cli.server.ranges import LineIndex, finding_span

SOURCE = "ar3cli"
"""The ``source`` of every diagnostic (editors show it next to the code)."""
SEVERITY = {Severity.ERROR: types.DiagnosticSeverity.Error, Severity.WARNING: types.DiagnosticSeverity.Warning,
            Severity.INFO: types.DiagnosticSeverity.Information}


def rule_url(code: str) -> str | None:
    """The rule's section of docs/rules.md as installed with ar3cli (a ``file:`` URI an editor opens
    offline); None for a code without a rule or where the file is missing (ar3cli has no hosted address)."""
    from ar3cli.infra.assets import rules_doc
    from ar3cli.lint.rules import REGISTRY

    rule, doc = REGISTRY.get(code), rules_doc()
    return f"{doc.as_uri()}#{rule.anchor}" if rule is not None and doc is not None else None


def _description(code: str) -> types.CodeDescription | None:
    url = rule_url(code)
    return types.CodeDescription(href=url) if url else None


def to_range(index: LineIndex, start: int, end: int) -> types.Range:
    (start_line, start_character), (end_line, end_character) = index.position(start), index.position(end)
    return types.Range(types.Position(start_line, start_character), types.Position(end_line, end_character))


def diagnostic(finding: Finding, index: LineIndex) -> types.Diagnostic:
    """``finding`` as a diagnostic on the text ``index`` indexes (the text the finding was made from)."""
    from ar3cli.output.report import printable

    start, end = finding_span(index, finding.line, finding.column, finding.message)
    message = "\n".join(printable(line) for line in (finding.message, finding.hint) if line)
    return types.Diagnostic(
        range=to_range(index, start, end), message=message, severity=SEVERITY[finding.severity],
        code=finding.rule, code_description=_description(finding.rule), source=SOURCE,
        data={"rule": finding.rule, "line": finding.line, "column": finding.column})


def problem(message: str, index: LineIndex | None = None) -> types.Diagnostic:
    """A diagnostic on the first line for what is not a finding: the check itself failed (a bug in
    ar3cli, a pybullet crash under ``sim``). It says so, in one line, with no rule code."""
    from ar3cli.output.report import printable

    end = len(index.line_text(0)) if index is not None else 0
    return types.Diagnostic(range=types.Range(types.Position(0, 0), types.Position(0, end)),
                            message=printable(message), severity=types.DiagnosticSeverity.Error, source=SOURCE)


def key(item: types.Diagnostic) -> tuple:
    """What makes two diagnostics the same (two open files that include a third report its findings alike)."""
    start, end = item.range.start, item.range.end
    return (start.line, start.character, end.line, end.character, item.code, item.message)
