"""SARIF 2.1.0 output for lint findings (GitHub code scanning, VS Code SARIF viewer, ...)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ar3cli import RULES_DOC, __version__
from ar3cli.findings import Finding, Severity
from ar3cli.output.lint_report import rule_groups

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
LEVELS = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}


def artifact_uri(path: str) -> str:
    """A relative URI for paths below the current directory, else a file:// URI."""
    candidate = Path(path)
    if not candidate.is_absolute():
        return candidate.as_posix()
    try:
        relative = os.path.relpath(candidate)
    except ValueError:
        relative = ".."
    return Path(relative).as_posix() if not relative.startswith("..") else candidate.as_uri()


SUPPRESSION_KINDS = {"comment": "inSource", "config": "external", "baseline": "external"}
"""SARIF's ``suppression.kind`` of each thing that suppresses a finding (a comment in the file is
in source; the configuration and a baseline are outside it)."""


def _physical(finding: Finding) -> dict[str, Any]:
    location: dict[str, Any] = {"artifactLocation": {"uri": artifact_uri(finding.path)}}
    if finding.line:
        location["region"] = {"startLine": finding.line, "startColumn": max(finding.column, 1)}
    return location


def sarif_document(findings: list[Finding], rules, grouped: bool = True,
                   suppressed: list[tuple[Finding, str, str]] = ()) -> dict[str, Any]:
    """One SARIF log with one run: the tool's rule metadata and one result per rule and file (its
    other findings as ``relatedLocations``, errors first); ``grouped`` False: a result per finding.
    Each ``suppressed`` (finding, by, justification) is a result too, with its ``suppressions``, so
    code scanning shows it as dismissed instead of never seeing it."""
    index = {rule.code: i for i, rule in enumerate(rules)}
    driver = {
        "name": "ar3cli",
        "version": __version__,  # no informationUri / helpUri: ar3cli has no hosted address (RULES_DOC)
        "rules": [{
            "id": rule.code,
            "name": rule.name,
            "shortDescription": {"text": rule.title},
            "fullDescription": {"text": rule.why},
            "help": {"text": rule.fix, "markdown": f"{rule.fix}\n\nDocumentation: `ar3cli lint-urdf --explain "
                                                   f"{rule.code}`, or {RULES_DOC}#{rule.anchor} in ar3cli's source."},
            "defaultConfiguration": {"level": LEVELS[rule.severity]},
            "properties": {"family": rule.family},
        } for rule in rules],
    }
    results = []
    for group in rule_groups(findings, grouped):
        first = group.first
        text = first.message + (f" ({group.count} findings of {first.rule} in this file: the first here, the others "
                                "as related locations)" if group.count > 1 else "")
        result: dict[str, Any] = {
            "ruleId": first.rule,
            "level": LEVELS[first.severity],
            "message": {"text": text + (f" Fix: {first.hint}" if first.hint else "")},
            "locations": [{"physicalLocation": _physical(first)}],
        }
        if group.count > 1:
            result["relatedLocations"] = [{"id": number, "physicalLocation": _physical(finding),
                                           "message": {"text": finding.message}}
                                          for number, finding in enumerate(group.findings[1:], 1)]
        if first.rule in index:
            result["ruleIndex"] = index[first.rule]
        results.append(result)
    for finding, by, justification in suppressed:
        result = {"ruleId": finding.rule, "level": LEVELS[finding.severity],
                  "message": {"text": finding.message + (f" Fix: {finding.hint}" if finding.hint else "")},
                  "locations": [{"physicalLocation": _physical(finding)}],
                  "suppressions": [{"kind": SUPPRESSION_KINDS[by], "justification": justification}]}
        if finding.rule in index:
            result["ruleIndex"] = index[finding.rule]
        results.append(result)
    return {"$schema": SCHEMA, "version": "2.1.0", "runs": [{"tool": {"driver": driver}, "results": results}]}
