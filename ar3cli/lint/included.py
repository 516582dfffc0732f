"""One finding for one line of an included xacro file, however many linted files include it.

A macro file's defect is found once per robot that expands it: linting a folder of 12 robots that
include ``hand.xacro`` reported the same path, line and message 12 times (49 repeats in the quietness
corpus). :func:`merge_included` keeps the first and counts the others in its message; the hint names
them. Findings in the linted file itself are never merged: two robots may well share a mistake.
"""

from __future__ import annotations

import dataclasses
from typing import Any

NAMED = 3
"""Other linted files the hint names (the rest are counted)."""


def merge_included(results: list[Any]) -> list[Any]:
    """``results`` (:class:`~ar3cli.lint.engine.LintResult`, in order) with each finding that points into
    an included file (its path is not the linted file's) kept in the first result that has it and dropped
    from the others, its message saying how many linted files include it. Results without such repeats come
    back as they are."""
    first: dict[tuple, tuple[int, int]] = {}  # finding identity -> (result index, finding index)
    also: dict[tuple, list[str]] = {}
    kept: list[list] = []
    for number, result in enumerate(results):
        findings = []
        for finding in result.findings:
            if finding.path == result.path:
                findings.append(finding)
                continue
            key = (finding.path, finding.line, finding.column, finding.rule, finding.message)
            if key in first:
                also[key].append(result.path)
                continue
            first[key] = (number, len(findings))
            also[key] = []
            findings.append(finding)
        kept.append(findings)
    if not any(also.values()):
        return results
    for key, others in also.items():
        if others:
            number, index = first[key]
            finding = kept[number][index]
            listed = ", ".join(others[:NAMED]) + (", ..." if len(others) > NAMED else "")
            kept[number][index] = dataclasses.replace(
                finding, message=f"{finding.message} (found through {len(others) + 1} linted files that include it)",
                hint=f"{finding.hint} Also found through: {listed}.".strip())
    return [dataclasses.replace(result, findings=findings) for result, findings in zip(results, kept)]
