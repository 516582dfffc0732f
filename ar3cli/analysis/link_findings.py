"""Which link each lint finding is about, so a viewer can colour the link and list the finding when
the link is clicked.

A finding names a file and a line (for a xacro, the file and line the element was written at). A
line belongs to a link when the ``<link>`` element or anything inside it is located there, and to a
joint's child link when the ``<joint>`` or anything inside it is (a joint's axis, limits and origin
are about the link it moves), located exactly as lint locates the element of a finding
(:class:`ar3cli.lint.engine.Locator`). A line that belongs to several links (a one-line file, a
xacro macro that writes several links) or to none (the ``<robot>`` line, a file-level finding) places
its finding on no link: it is listed, never drawn on a guess.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ar3cli.analysis.robot import RobotAnalysis, question

if TYPE_CHECKING:
    from ar3cli.findings import Finding, Severity

Place = tuple[str, int]
"""(the path a finding shows, line)."""


@dataclass(frozen=True)
class LinkFindings:
    """The findings of one lint, each on the link it is about or among the ``unplaced``."""

    by_link: dict[str, list[Finding]] = field(default_factory=dict)
    unplaced: list[Finding] = field(default_factory=list)

    def worst(self, link: str) -> Severity | None:
        """The highest severity among the link's findings, None when it has none."""
        found = self.by_link.get(link)
        return max((finding.severity for finding in found), key=lambda severity: severity.rank) if found else None


def place_findings(analysis: RobotAnalysis, findings: Iterable[Finding]) -> LinkFindings:
    """``findings`` (of this analysis's lint) by the link each is about."""
    owners = line_owners(analysis) if analysis.model is not None else {}
    by_link: dict[str, list[Finding]] = {}
    unplaced: list[Finding] = []
    for finding in findings:
        links = owners.get((finding.path, finding.line), ())
        if len(links) == 1:
            by_link.setdefault(next(iter(links)), []).append(finding)
        else:
            unplaced.append(finding)
    return LinkFindings(by_link, unplaced)


@question
def line_owners(analysis: RobotAnalysis) -> dict[Place, frozenset[str]]:
    """(path, line) -> the links whose elements (their own, or their parent joint's) are located there."""
    from ar3cli.lint.engine import Locator
    from ar3cli.lint.rules.base import Hit

    model = analysis.require_model()
    locator = Locator(model, analysis.shown_path)
    owners: dict[Place, set[str]] = {}
    owned = [(link.element, link.name) for link in model.links]
    owned += [(joint.element, joint.child) for joint in model.joints if joint.child is not None]
    for top, link in owned:
        for element in top.iter():
            if isinstance(element.tag, str):
                path, line, _ = locator.locate(Hit("", element=element))
                if line:
                    owners.setdefault((path, line), set()).add(link)
    return {place: frozenset(links) for place, links in owners.items()}
