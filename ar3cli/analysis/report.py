"""What ``ar3cli report``'s page shows, gathered from one analysis: one verdict built from every
section (:mod:`ar3cli.analysis.verdict`), the home pose, every section's JSON document (the same
documents ``info --torques``, ``lint-urdf --sim``, ``sample-collisions``, ``fk-verify`` and
``cross-check`` print with ``--format json`` for the same samples and seed), its summary lines, the
pictures and the findings. :mod:`ar3cli.output.html` renders it; nothing here writes HTML.

A section that cannot be computed (no collision geometry, a pybullet crash) is None in the data,
``data["skipped"][section]`` says why, and its check in the verdict is ``not checked`` with that
reason; the rest of the page stays.
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
    sources: dict[str, str] = field(default_factory=dict)
    """The files whose lines the page may show with the findings, with the digest of the bytes linted
    (:attr:`~ar3cli.lint.engine.LintResult.sources`: never a file reached through a link out of the tree)."""
    pictures: list[dict[str, Any]] = field(default_factory=list)


def robot_report(analysis: RobotAnalysis) -> RobotReport:
    """Every section of the page; a robot that did not load raises its one-line error."""
    from ar3cli.analysis import collisions, cross_check, facts, findings, kinematics, pictures, verdict
    from ar3cli.info.presentation import report as info_report
    from ar3cli.info.presentation import summary_lines, torque_lines

    analysis.require_model()
    settings = analysis.settings
    skipped: dict[str, str] = {}
    data: dict[str, Any] = {"settings": {"samples": settings.samples, "seed": settings.seed,
                                         "described": f"{settings.samples} samples, seed {settings.seed}"},
                            "skipped": skipped, "cross_check": None}
    made = RobotReport(data)
    lint = findings.findings(analysis)
    data["lint"], made.findings, made.sources = lint.document, lint.findings, lint.result.sources
    home = _attempt(lambda: facts.home_pose(analysis), "home", skipped)
    data["home"] = home.to_dict() if home is not None else None

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
    data["collisions"] = matrix.document if matrix else None
    made.lines["collisions"] = _without_warnings(matrix.lines, len(matrix.run.warnings)) if matrix else []
    fk = _attempt(lambda: kinematics.fk_verify(analysis), "fk", skipped)
    data["fk"] = fk.document if fk else None
    made.lines["fk"] = fk_lines(analysis.require_model(), fk.document) if fk else []
    cross = _attempt(lambda: cross_check.cross_check(analysis), "cross_check", skipped)
    if cross is not None:
        data["cross_check"] = {**cross.document, "passed": cross.agree, "lines": cross.lines}
        made.lines["cross_check"] = cross.lines
    data["verdict"] = verdict.verdict(analysis).to_dict()  # every section above is answered: nothing runs twice
    return made


def _without_warnings(lines: list[str], warnings: int) -> list[str]:
    """sample-collisions' summary lines without its warning lines (its last ``warnings`` lines): the
    page shows the warnings grouped by kind from the JSON document (on G1, 60 lines of one kind)."""
    kept = lines[:len(lines) - warnings] if warnings else list(lines)
    return [line for line in kept if not line.startswith(("info: ", "warning: ", "error: "))]


FK_JOINTS_SHOWN = 8
"""Joint values the worst-link line names (the joints that move that link, from the root)."""


def fk_lines(model, document: dict[str, Any]) -> list[str]:
    """fk-verify's notes and its worst link with only the joints that move that link: fk-verify's own
    line names every joint (43 on G1), the JSON keeps them all (``fk.worst.configuration``)."""
    worst = document["worst"]
    configuration: dict[str, float] = worst["configuration"]
    chain = [joint.name for joint in model.joints_above(worst["link"]) if joint.name in configuration][::-1]
    shown = ", ".join(f"{name}={configuration[name]:.6g}" for name in chain[:FK_JOINTS_SHOWN])
    if len(chain) > FK_JOINTS_SHOWN:
        shown += f" and {len(chain) - FK_JOINTS_SHOWN} more"
    line = f"worst link: {worst['link']} (sample {worst['sample']}): " + (shown or "no moving joint above it")
    others = len(configuration) - len(chain)
    if others:
        line += f"; {others} other joint{'s are' if others != 1 else ' is'} not on its path to the root"
    return [f"note: {note}" for note in document.get("notes", [])] + [line]


def _attempt(work: Callable[[], T], key: str, skipped: dict[str, str]) -> T | None:
    """One section's answer; its UserError (nothing to check, pybullet crashed) leaves it out with its
    reason (the verdict says it too: that section is ``not checked``)."""
    try:
        return work()
    except UserError as exc:
        skipped[key] = exc.message
        return None
