"""What ``ar3cli report``'s page shows, gathered from one analysis: every section's JSON document
(the same documents ``info --torques``, ``lint-urdf``, ``sample-collisions``, ``fk-verify`` and
``cross-check`` print with ``--format json`` for the same samples and seed), its summary lines, the
pictures and the findings. :mod:`ar3cli.output.html` renders it; nothing here writes HTML.

A section that cannot be computed (no collision geometry, a pybullet crash) is None in the data,
``data["skipped"][section]`` says why, and a line on stderr says so; the rest of the page stays.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeVar

from ar3cli.analysis.robot import RobotAnalysis
from ar3cli.errors import UserError

if TYPE_CHECKING:
    from ar3cli.findings import Finding

T = TypeVar("T")


@dataclass
class RobotReport:
    """The page's data island (``data``), each section's summary lines (``lines``), the findings
    shown (for their source lines and fix commands) and the pictures (``png`` bytes included)."""

    data: dict[str, Any]
    lines: dict[str, list[str]] = field(default_factory=dict)
    findings: list[Finding] = field(default_factory=list)
    pictures: list[dict[str, Any]] = field(default_factory=list)


def robot_report(analysis: RobotAnalysis) -> RobotReport:
    """Every section of the page; a robot that did not load raises its one-line error."""
    from ar3cli.analysis import collisions, cross_check, facts, findings, kinematics, pictures
    from ar3cli.info.presentation import report as info_report
    from ar3cli.info.presentation import summary_lines, torque_lines

    analysis.require_model()
    settings = analysis.settings
    skipped: dict[str, str] = {}
    data: dict[str, Any] = {"settings": {"samples": settings.samples, "seed": settings.seed,
                                         "described": f"{settings.samples} samples, seed {settings.seed}"},
                            "skipped": skipped, "cross_check": None}
    made = RobotReport(data)
    lint = findings.static_findings(analysis)
    data["lint"], made.findings = lint.document, lint.findings

    summary = facts.summary(analysis)
    torques = _attempt(lambda: facts.torques(analysis), "torques", skipped)
    data["info"] = info_report(summary, tree=False, torques=torques).data
    made.lines["info"] = summary_lines(summary)
    made.lines["torques"] = torque_lines(torques) if torques is not None else []

    drawn = pictures.pictures(analysis)
    made.lines["pictures"] = list(drawn.notes)
    data["renders"] = [picture.to_dict() for picture in drawn.pictures]
    made.pictures = [{**picture.to_dict(), **({"png": picture.png} if picture.png is not None else {})}
                     for picture in drawn.pictures]

    matrix = _attempt(lambda: collisions.collision_matrix(analysis), "collisions", skipped)
    data["collisions"], made.lines["collisions"] = (matrix.document, matrix.lines) if matrix else (None, [])
    fk = _attempt(lambda: kinematics.fk_verify(analysis), "fk", skipped)
    data["fk"], made.lines["fk"] = (fk.document, fk.lines) if fk else (None, [])
    cross = _attempt(lambda: cross_check.cross_check(analysis), "cross_check", skipped)
    if cross is not None:
        data["cross_check"] = {**cross.document, "passed": cross.agree, "lines": cross.lines}
        made.lines["cross_check"] = cross.lines
    return made


def _attempt(work: Callable[[], T], key: str, skipped: dict[str, str]) -> T | None:
    """One section's answer; its UserError (nothing to check, pybullet crashed) leaves it out with its reason."""
    from ar3cli.output.report import log

    try:
        return work()
    except UserError as exc:
        skipped[key] = exc.message
        log(f"report: {key} left out: {exc.message}")
        return None
