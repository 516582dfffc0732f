"""One finding for one line of an included xacro file, however many linted files include it.

A macro file's defect is found once per robot that expands it: linting a folder of 12 robots that
include ``hand.xacro`` reported the same path, line and message 12 times (49 repeats in the quietness
corpus). :func:`merge_included` keeps the first and drops the repeats found through other linted files;
the kept one's hint counts and names them. Its message is left as it is, so a baseline written on a whole
folder still matches a run on one file of it (pre-commit, ``--changed-since``). Findings in the linted
file itself are never merged (two robots may well share a mistake), nor are repeats within one file (a
macro called twice with the same defect is two findings of that file).
"""

from __future__ import annotations

import dataclasses
from typing import Any

NAMED = 3
"""Other linted files the hint names (the rest are counted)."""


def merge_included(results: list[Any]) -> list[Any]:
    """``results`` (unsettled :class:`~ar3cli.lint.engine.LintResult`, in order) with each finding that points
    into an included file (its path is not the linted file's) kept in the first result that has it and dropped
    from the later ones, its hint naming them; the suppressed findings likewise, so that the counts a run
    reports (suppressed, made less severe) agree with what it shows. Results without such repeats come back
    as they are."""
    owner: dict[tuple, int] = {}  # finding identity -> the index of the first result that has it
    also: dict[tuple, list[str]] = {}
    for number, result in enumerate(results):
        for key in {_key(finding) for finding in _all_findings(result) if finding.path != result.path}:
            if key in owner:
                also[key].append(result.path)
            else:
                owner[key], also[key] = number, []
    if not any(also.values()):
        return results
    merged = []
    for number, result in enumerate(results):
        def kept(finding, number=number, result=result) -> bool:
            return finding.path == result.path or owner[_key(finding)] == number

        findings = [_named(finding, also[_key(finding)]) if finding.path != result.path else finding
                    for finding in result.findings if kept(finding)]
        suppressed = [item for item in result.suppressed if kept(item.finding)]
        merged.append(dataclasses.replace(result, findings=findings, suppressed=suppressed))
    return merged


def _all_findings(result: Any):
    yield from result.findings
    yield from (item.finding for item in result.suppressed)


def _key(finding: Any) -> tuple:
    return (finding.path, finding.line, finding.column, finding.rule, finding.message)


def _named(finding: Any, others: list[str]) -> Any:
    """``finding`` with a hint that says which other linted files include its file (unchanged when none)."""
    if not others:
        return finding
    listed = ", ".join(others[:NAMED]) + (", ..." if len(others) > NAMED else "")
    return dataclasses.replace(finding, hint=f"{finding.hint or ''} Found through {len(others) + 1} linted files "
                                             f"that include it; also: {listed}.".strip())
