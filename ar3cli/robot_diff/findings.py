"""Lint findings new in NEW and fixed since OLD. The command lints both models (this package may
not import the linter) and hands the findings here; they are matched by rule code and the element
the message names (``link 'x'``, ``joint 'y'``, through the renames), never by line, so moving or
reformatting text changes nothing. A message that names no element is matched by its wording with
numbers left out. Several findings with the same key are counted: two in OLD and three in NEW is one new."""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Callable, Sequence

from ar3cli.findings import Finding
from ar3cli.robot_diff.match import Matching
from ar3cli.robot_diff.records import FindingChange

ELEMENT = re.compile(r"\b(link|joint) '([^']*)'")
NUMBER = re.compile(r"[-+]?\d[\d.eE+-]*")


def finding_key(finding: Finding, rename: Callable[[str, str], str] = lambda kind, name: name) -> tuple[str, str]:
    named = ELEMENT.search(finding.message)
    if named:
        return finding.rule, f"{named.group(1)} '{rename(named.group(1), named.group(2))}'"
    return finding.rule, NUMBER.sub("#", finding.message)


def compare_findings(old: Sequence[Finding], new: Sequence[Finding], matching: Matching,
                     show: Callable[[str], str] = str) -> list[FindingChange]:
    """The new findings (in NEW's order), then the fixed ones (in OLD's order); ``show`` relabels OLD's paths."""
    def rename(kind: str, name: str) -> str:
        return (matching.links if kind == "link" else matching.joints).get(name, name)

    old_keys = Counter(finding_key(finding, rename) for finding in old)
    new_keys = Counter(finding_key(finding) for finding in new)
    result: list[FindingChange] = []
    for findings, keys, others, status, relabel in ((new, new_keys, old_keys, "new", str),
                                                      (old, old_keys, new_keys, "fixed", show)):
        surplus = keys - others
        for finding in findings:
            key = finding_key(finding, rename) if status == "fixed" else finding_key(finding)
            if surplus[key] > 0:
                surplus[key] -= 1
                result.append(FindingChange(status, finding.rule, finding.severity.value, finding.message,
                                            relabel(finding.path), finding.line))
    return result
