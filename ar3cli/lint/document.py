"""lint-urdf's JSON document and exit code, from the engine's results: what ``lint-urdf --format
json`` prints, what the HTML pages embed, and what :mod:`ar3cli.analysis` answers, built in one place
so the three stay equal."""

from __future__ import annotations

from typing import Any

from ar3cli.errors import EXIT_USAGE


def exit_code(summary: dict[str, Any], exit_zero: bool = False) -> int:
    """The exit code a lint run with ``summary`` ends with (2 when a file was not checked)."""
    return EXIT_USAGE if summary["files_not_checked"] else 1 if summary["findings_failing"] and not exit_zero else 0


def lint_json(results: list, summary: dict[str, Any]) -> dict[str, Any]:
    """``{"files", "findings" (each with the command that fixes it, ``fixed_by``), "summary",
    "suppressed" (each finding not reported, with what suppressed it: ``suppressed_by``)}`` of
    ``results`` (:class:`~ar3cli.lint.engine.LintResult`) and their ``summary``."""
    from ar3cli.lint.fix_hints import fixed_by

    findings = [finding for result in results for finding in result.findings]
    return {"files": [result.to_dict() for result in results],
            "findings": [{**finding.to_dict(), "fixed_by": fixed_by(finding.rule)} for finding in findings],
            "summary": summary,
            "suppressed": [{**item.finding.to_dict(), "suppressed_by": item.by}
                           for result in results for item in result.suppressed]}
