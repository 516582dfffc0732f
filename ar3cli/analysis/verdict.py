"""One verdict about a robot, built from every section: the lint findings (static and simulated),
the pictures' contacts at home, the collision matrix, the torque check, fk-verify and cross-check.

Each section gives a :class:`Check`: a status, one line that says why, and a count (the findings,
pairs or joints behind the status). A section that could not be computed is ``not checked`` with
its reason, never a pass. The :class:`Verdict` is the worst status of its checks (``fail`` over
``warning`` over ``pass``; ``not checked`` changes nothing but is said), its headline names every
check that did not pass, and its notes say what a reader must know to read the rest (the home pose
is not all zeros).

A check is a function ``(analysis) -> Check``; :data:`CHECKS` lists the report's, and
:func:`verdict` takes any tuple of them (a viewer adds its own, e.g. contacts at the current pose).
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ar3cli.analysis.robot import RobotAnalysis, question
from ar3cli.errors import UserError


class Status(str, enum.Enum):
    FAIL = "fail"
    WARNING = "warning"
    PASS = "pass"
    NOT_CHECKED = "not checked"

    @property
    def rank(self) -> int:
        """Worse is higher; not checked ranks with pass (it is said, not counted)."""
        return {"fail": 2, "warning": 1}.get(self.value, 0)


@dataclass(frozen=True)
class Check:
    """One section's verdict: ``key`` (the page's section id), ``title``, ``status``, ``line`` (one
    line that says why) and ``count`` (findings, pairs or joints behind the status; 0 for a pass)."""

    key: str
    title: str
    status: Status
    line: str
    count: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {"key": self.key, "title": self.title, "status": self.status.value, "line": self.line,
                "count": self.count}


@dataclass(frozen=True)
class Verdict:
    """The worst status of ``checks``, the headline that names the checks that did not pass, and notes."""

    checks: tuple[Check, ...]
    notes: tuple[str, ...] = field(default_factory=tuple)

    @property
    def status(self) -> Status:
        worst = max((check.status.rank for check in self.checks), default=0)
        return {2: Status.FAIL, 1: Status.WARNING}.get(worst, Status.PASS)

    @property
    def headline(self) -> str:
        """``FAIL: 1 check fails (fk), 2 warn (findings, collisions); 1 not checked (cross-check)``, or
        ``PASS: every check passed (6)``."""
        def names(status: Status) -> list[str]:
            return [check.title for check in self.checks if check.status is status]

        failing, warning, unchecked = names(Status.FAIL), names(Status.WARNING), names(Status.NOT_CHECKED)
        parts = []
        if failing:
            parts.append(f"{len(failing)} check{'s' if len(failing) != 1 else ''} "
                         f"fail{'s' if len(failing) == 1 else ''} ({', '.join(failing)})")
        if warning:
            parts.append(f"{len(warning)} warn{'s' if len(warning) == 1 else ''} ({', '.join(warning)})")
        passed = sum(check.status is Status.PASS for check in self.checks)
        text = "; ".join(parts) if parts else f"every check passed ({passed})"
        if unchecked:
            text += f"; {len(unchecked)} not checked ({', '.join(unchecked)})"
        return f"{self.status.value.upper()}: {text}"

    def to_dict(self) -> dict[str, Any]:
        return {"status": self.status.value, "headline": self.headline,
                "checks": [check.to_dict() for check in self.checks], "notes": list(self.notes)}


def _count(number: int, noun: str, plural: str | None = None) -> str:
    return f"{number} {noun if number == 1 else plural or noun + 's'}"


def lint_check(analysis: RobotAnalysis) -> Check:
    """The findings of lint-urdf --sim: fail from the configuration's fail-on, warning below it."""
    from ar3cli.analysis.findings import findings
    from ar3cli.findings import Severity

    answer = findings(analysis)
    summary, error = answer.summary, answer.result.error
    counts = ", ".join(_count(summary[level], level, "info" if level == "info" else None)
                       for level in ("error", "warning", "info") if summary[level]) or "no findings"
    codes = sorted({finding.rule for finding in answer.findings if finding.severity >= Severity.WARNING})
    line = counts + (f" ({', '.join(codes[:6])}{', ...' if len(codes) > 6 else ''})" if codes else "")
    if error:
        return Check("findings", "findings", Status.FAIL, f"the simulated checks did not finish: {error}; {line}",
                     summary["findings"])
    if not answer.result.loaded:
        return Check("findings", "findings", Status.FAIL, f"the file does not load: {line}", summary["findings"])
    if summary["findings_failing"]:
        status = Status.FAIL
    elif summary["warning"]:
        status = Status.WARNING
    else:
        status = Status.PASS
    return Check("findings", "findings", status, line, summary["findings"] if status is not Status.PASS else 0)


def pictures_check(analysis: RobotAnalysis) -> Check:
    """Links drawn red (in contact at home) and visuals that could not be drawn."""
    from ar3cli.analysis.pictures import pictures

    drawn = pictures(analysis)
    contacts = drawn.contacts_at_home()
    failed = [picture for picture in drawn.pictures if picture.error]
    left_out = {name for picture in drawn.pictures for name in picture.facts.get("visuals_not_drawn", [])}
    problems = []
    if contacts:
        problems.append(f"{_count(len(contacts), 'pair')} of links in contact at home (drawn red)")
    if left_out:
        problems.append(f"{_count(len(left_out), 'visual')} not drawn")
    if failed:
        problems.append(f"{_count(len(failed), 'picture')} not drawn")
    if not problems:
        return Check("renders", "pictures", Status.PASS, "no two non-adjacent links in contact at home")
    return Check("renders", "pictures", Status.WARNING, "; ".join(problems), len(contacts) + len(left_out) + len(failed))


def collisions_check(analysis: RobotAnalysis) -> Check:
    """The collision matrix's warnings (contact at home, pairs PyBullet checks although they always
    touch, links without collision geometry); its info (contact only at a joint limit) is counted, not failed."""
    from ar3cli.analysis.collisions import collision_matrix
    from ar3cli.findings import Severity

    matrix = collision_matrix(analysis)
    warnings = [finding for finding in matrix.run.warnings if finding.severity >= Severity.WARNING]
    infos = len(matrix.run.warnings) - len(warnings)
    kinds: dict[str, int] = {}
    for finding in warnings:
        kinds[finding.rule] = kinds.get(finding.rule, 0) + 1
    words = {"contact-at-home": "in contact at home",
             "pybullet-default-self-collision": "always in contact, yet checked by PyBullet's self-collision flag"}
    parts = [f"{_count(count, 'pair')} {words[rule]}" for rule, count in kinds.items() if rule in words]
    parts += [finding.message.split(":")[0] for finding in warnings if finding.rule not in words]
    if infos:
        parts.append(f"{_count(infos, 'pair')} touching only at a joint limit (info)")
    counts = matrix.document.get("categories", {})
    tally = ", ".join(f"{counts[name]} {name}" for name in ("default", "always", "sometimes", "never") if counts.get(name))
    line = "; ".join(parts or ["no pair in contact at home"])
    line += f"; of {_count(len(matrix.run.results), 'pair')}: {tally}" if tally else ""
    return Check("collisions", "self-collision", Status.WARNING if warnings else Status.PASS, line, len(warnings))


def torques_check(analysis: RobotAnalysis) -> Check:
    """Joints too weak to hold the robot up at some sampled configuration."""
    from ar3cli.analysis.facts import torques

    check = torques(analysis)
    weak, missing = check.too_weak, check.without_effort
    if not check.joints:
        return Check("torques", "torque margins", Status.PASS, "no actuated joint")
    line = f"{len(check.joints) - len(weak) - len(missing)} of {_count(len(check.joints), 'joint')} hold the robot up"
    if weak:
        line += f"; too weak: {', '.join(joint.name for joint in weak[:5])}{', ...' if len(weak) > 5 else ''}"
    if missing:
        line += f"; {len(missing)} declare no effort"
    return Check("torques", "torque margins", Status.WARNING if weak else Status.PASS, line, len(weak))


def fk_check(analysis: RobotAnalysis) -> Check:
    from ar3cli.analysis.kinematics import fk_verify

    result = fk_verify(analysis)
    document = result.document
    line = (f"max position error {document['max_position_error_m']:.3g} m, max orientation error "
            f"{document['max_orientation_error_rad']:.3g} rad over {document['samples']} samples")
    failing = sum(not link.get("passed") for link in document.get("links", []))
    if result.passed:
        return Check("fk", "FK", Status.PASS, line)
    return Check("fk", "FK", Status.FAIL, f"{_count(failing, 'link')} beyond tolerance (worst "
                                          f"{document['worst']['link']}); {line}", failing)


def cross_check_check(analysis: RobotAnalysis) -> Check:
    from ar3cli.analysis.cross_check import INSTALL_HINT, cross_check

    result = cross_check(analysis)
    if result is None:
        return Check("cross-check", "cross-check", Status.NOT_CHECKED, f"MuJoCo is not installed ({INSTALL_HINT})")
    line = result.lines[-1] if result.lines else ("agree" if result.agree else "disagree")
    if result.agree:
        return Check("cross-check", "cross-check", Status.PASS, line)
    return Check("cross-check", "cross-check", Status.FAIL, line, int(result.document.get("disagreements", 0)))


CHECKS: tuple[Callable[[RobotAnalysis], Check], ...] = (
    lint_check, pictures_check, collisions_check, torques_check, fk_check, cross_check_check)
"""The report's checks, in the page's order."""
TITLES = {lint_check: ("findings", "findings"), pictures_check: ("renders", "pictures"),
          collisions_check: ("collisions", "self-collision"), torques_check: ("torques", "torque margins"),
          fk_check: ("fk", "FK"), cross_check_check: ("cross-check", "cross-check")}
"""(key, title) of each check, for the ``not checked`` entry when it raises."""


def run_check(analysis: RobotAnalysis, check: Callable[[RobotAnalysis], Check]) -> Check:
    """``check(analysis)``, or ``not checked`` with the reason it could not be computed."""
    try:
        return check(analysis)
    except UserError as exc:
        key, title = TITLES.get(check, (check.__name__.removesuffix("_check"),) * 2)
        return Check(key, title, Status.NOT_CHECKED, exc.message)


@question
def verdict(analysis: RobotAnalysis, checks: tuple[Callable[[RobotAnalysis], Check], ...] = CHECKS) -> Verdict:
    """Every check of ``checks`` and the notes: why the file does not load, or the home pose when it is not all zeros."""
    from ar3cli.analysis.facts import home_pose

    notes: list[str] = []
    if analysis.model is None:
        notes.append(f"not loaded: {analysis.load_error.message if analysis.load_error else 'unknown reason'}")
    else:
        try:
            pose = home_pose(analysis)
        except UserError as exc:
            notes.append(f"home pose: {exc.message}")
        else:
            if not pose.all_zero:
                notes.append(pose.line())
    return Verdict(tuple(run_check(analysis, check) for check in checks), tuple(notes))
