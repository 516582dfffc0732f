"""SARIF 2.1.0 output for lint findings (GitHub code scanning, VS Code SARIF viewer, ...)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from ar3cli import __version__
from ar3cli.findings import Finding, Severity

SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"
RULES_URL = "https://github.com/ar3cli/ar3cli/blob/main/docs/rules.md"
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


def sarif_document(findings: list[Finding], rules, suppressed: list[tuple[Finding, str, str]] = ()) -> dict[str, Any]:
    """One SARIF log with one run: the tool's rule metadata and one result per finding; each
    ``suppressed`` (finding, by, justification) is a result too, with its ``suppressions``, so code
    scanning shows it as dismissed instead of never seeing it."""
    index = {rule.code: i for i, rule in enumerate(rules)}
    driver = {
        "name": "ar3cli",
        "version": __version__,
        "informationUri": RULES_URL,
        "rules": [{
            "id": rule.code,
            "name": rule.name,
            "shortDescription": {"text": rule.title},
            "fullDescription": {"text": rule.why},
            "help": {"text": rule.fix},
            "helpUri": f"{RULES_URL}#{rule.anchor}",
            "defaultConfiguration": {"level": LEVELS[rule.severity]},
            "properties": {"family": rule.family},
        } for rule in rules],
    }
    results = []
    for finding, by, justification in [*((finding, "", "") for finding in findings), *suppressed]:
        location: dict[str, Any] = {"artifactLocation": {"uri": artifact_uri(finding.path)}}
        if finding.line:
            location["region"] = {"startLine": finding.line, "startColumn": max(finding.column, 1)}
        result: dict[str, Any] = {
            "ruleId": finding.rule,
            "level": LEVELS[finding.severity],
            "message": {"text": finding.message + (f" Fix: {finding.hint}" if finding.hint else "")},
            "locations": [{"physicalLocation": location}],
        }
        if finding.rule in index:
            result["ruleIndex"] = index[finding.rule]
        if by:
            result["suppressions"] = [{"kind": SUPPRESSION_KINDS[by], "justification": justification}]
        results.append(result)
    return {"$schema": SCHEMA, "version": "2.1.0", "runs": [{"tool": {"driver": driver}, "results": results}]}
