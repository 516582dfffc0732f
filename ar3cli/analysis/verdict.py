"""One verdict about a robot, built from every section: the lint findings (static and simulated),
the pictures' contacts at home, the collision matrix, the torque check, fk-verify and cross-check.

Each section gives a :class:`Check`: a status, one line that says why, and a count (the findings,
pairs or joints behind the status). A section that could not be computed is ``not checked`` with
its reason, never a pass. The :class:`Verdict` is the worst status of its checks (``fail`` over
``warning`` over ``pass``; ``not checked`` changes nothing but is said), its headline names every
check that did not pass, and its notes say what a reader must know to read the rest (the home pose
is not all zeros).

A check is a function ``(analysis) -> Outcome`` decorated with ``@check(key, title)`` (which makes
it return a :class:`Check`, ``not checked`` when the section raises its UserError); :data:`CHECKS`
lists the report's, and :func:`verdict` takes any tuple of them (a viewer adds its own, e.g. contacts
at the current pose, without editing this module).
"""

from __future__ import annotations

import enum
import functools
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

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
        """``FAIL: 1 check fails (FK verification); 2 checks warn (findings, self-collision matrix); 1 not
        checked (cross-check)``, or ``PASS: every check passed (6)``."""
        def names(status: Status) -> list[str]:
            return [check.title for check in self.checks if check.status is status]

        failing, warning, unchecked = names(Status.FAIL), names(Status.WARNING), names(Status.NOT_CHECKED)
        parts = []
        if failing:
            parts.append(f"{_count(len(failing), 'check')} fail{'s' if len(failing) == 1 else ''} ({', '.join(failing)})")
        if warning:
            parts.append(f"{_count(len(warning), 'check')} warn{'s' if len(warning) == 1 else ''} ({', '.join(warning)})")
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


class Outcome(NamedTuple):
    """What a check function returns: its status, one line that says why, and the count."""

    status: Status
    line: str
    count: int = 0


CheckFunction = Callable[[RobotAnalysis], Check]


def check(key: str, title: str) -> Callable[[Callable[[RobotAnalysis], Outcome]], CheckFunction]:
    """Make ``function(analysis) -> Outcome`` a check of section ``key`` (the page's section id)
    called ``title``: it returns a :class:`Check`, ``not checked`` with the reason when the section
    cannot be computed (its UserError). A viewer's or an editor's own check is one such function."""
    def decorate(function: Callable[[RobotAnalysis], Outcome]) -> CheckFunction:
        @functools.wraps(function)
        def checked(analysis: RobotAnalysis) -> Check:
            try:
                outcome = function(analysis)
            except UserError as exc:
                return Check(key, title, Status.NOT_CHECKED, without_path(exc.message, analysis.path))
            return Check(key, title, outcome.status, outcome.line, outcome.count if outcome.status is not
                         Status.PASS else 0)

        checked.key, checked.title = key, title  # type: ignore[attr-defined]
        return checked

    return decorate


def without_path(message: str, path: Path) -> str:
    """A one-line error without the robot file's path in front (the page and the verdict are about
    that file): ``PATH:12: reason`` -> ``line 12: reason``, ``PATH: reason`` -> ``reason``."""
    prefix = os.fspath(path) + ":"
    if not message.startswith(prefix):
        return message
    rest = message[len(prefix):]
    line, colon, tail = rest.partition(": ")
    return f"line {line}: {tail}" if colon and line.isdigit() else rest.lstrip()


@check("findings", "findings")
def lint_check(analysis: RobotAnalysis) -> Outcome:
    """The findings of lint-urdf --sim: fail from the configuration's fail-on, warning below it; a
    file that does not load, or whose simulated checks crashed, fails."""
    from ar3cli.analysis.findings import findings
    from ar3cli.findings import Severity

    answer = findings(analysis)
    summary, error = answer.summary, answer.result.error
    counts = ", ".join(_count(summary[level], level, "info" if level == "info" else None)
                       for level in ("error", "warning", "info") if summary[level]) or "no findings"
    codes = sorted({finding.rule for finding in answer.findings if finding.severity >= Severity.WARNING})
    line = counts + (f" ({', '.join(codes[:6])}{', ...' if len(codes) > 6 else ''})" if codes else "")
    if error:
        return Outcome(Status.FAIL, f"the simulated checks did not finish: {error}; {line}", summary["findings"])
    if not answer.result.loaded:
        return Outcome(Status.FAIL, f"the file does not load: {line}", summary["findings"])
    if summary["findings_failing"]:
        return Outcome(Status.FAIL, line, summary["findings"])
    return Outcome(Status.WARNING if summary["warning"] else Status.PASS, line, summary["findings"])


@check("renders", "pictures")
def pictures_check(analysis: RobotAnalysis) -> Outcome:
    """Links drawn red (in contact at home) and visuals or pictures that could not be drawn."""
    from ar3cli.analysis.collisions import disabled_in_srdf
    from ar3cli.analysis.pictures import pictures

    drawn = pictures(analysis)
    contacts = drawn.contacts_at_home()
    allowed, source = disabled_in_srdf(analysis, list(contacts))
    contacts = {pair: depth for pair, depth in contacts.items() if pair not in allowed}
    failed = [picture for picture in drawn.pictures if picture.error]
    left_out = {name for picture in drawn.pictures for name in picture.facts.get("visuals_not_drawn", [])}
    problems = []
    if contacts:
        problems.append(f"{_count(len(contacts), 'pair')} of links in contact at home (drawn red)")
    if left_out:
        problems.append(f"{_count(len(left_out), 'visual')} not drawn")
    if failed:
        problems.append(f"{_count(len(failed), 'picture')} not drawn")
    if failed and len(failed) == len(drawn.pictures):
        return Outcome(Status.NOT_CHECKED, without_path(str(failed[0].error), analysis.path))
    also = f"; {_count(len(allowed), 'pair')} in contact that {source} disables (drawn red)" if allowed else ""
    if not problems:
        return Outcome(Status.PASS, "no two non-adjacent links in contact at home" + also)
    return Outcome(Status.WARNING, "; ".join(problems) + also, len(contacts) + len(left_out) + len(failed))


MATRIX_WORDS = {"contact-at-home": "in contact at home",
                "pybullet-default-self-collision": "always in contact, yet checked by PyBullet's self-collision flag"}


@check("collisions", "self-collision matrix")
def collisions_check(analysis: RobotAnalysis) -> Outcome:
    """The collision matrix's warnings (contact at home, pairs PyBullet checks although they always
    touch, links without collision geometry); its info (contact only at a joint limit) is counted, not failed."""
    from ar3cli.analysis.collisions import collision_matrix, disabled_in_srdf
    from ar3cli.collisions.matrix import contact_at_home
    from ar3cli.findings import Severity

    matrix = collision_matrix(analysis)
    at_home = [(result.link_a, result.link_b) for result in matrix.run.results
               if result.at_home and result.category != "adjacent"]
    allowed, source = disabled_in_srdf(analysis, at_home)
    disabled = {contact_at_home(*pair) for pair in allowed}
    warnings = [finding for finding in matrix.run.warnings if finding.severity >= Severity.WARNING
                and not (finding.rule == "contact-at-home" and finding.message in disabled)]
    infos = len([finding for finding in matrix.run.warnings if finding.severity < Severity.WARNING])
    kinds: dict[str, int] = {}
    for finding in warnings:
        kinds[finding.rule] = kinds.get(finding.rule, 0) + 1
    parts = [f"{_count(count, 'pair')} {MATRIX_WORDS[rule]}" for rule, count in kinds.items() if rule in MATRIX_WORDS]
    parts += [finding.message.split(":")[0] for finding in warnings if finding.rule not in MATRIX_WORDS]
    if allowed:
        parts.append(f"{_count(len(allowed), 'pair')} in contact at home that {source} disables")
    if infos:
        parts.append(f"{_count(infos, 'pair')} touching only at a joint limit (info)")
    counts = matrix.document.get("categories", {})
    tally = ", ".join(f"{count} {name}" for name, count in counts.items() if count)
    line = "; ".join(parts or ["no pair in contact at home"])
    line += f"; of {_count(len(matrix.run.results), 'pair')}: {tally}" if tally else ""
    return Outcome(Status.WARNING if warnings else Status.PASS, line, len(warnings))


@check("torques", "torque margins")
def torques_check(analysis: RobotAnalysis) -> Outcome:
    """Joints too weak to hold the robot up at some sampled configuration."""
    from ar3cli.analysis.facts import torques

    result = torques(analysis)
    weak, missing = result.too_weak, result.without_effort
    if not result.joints:
        return Outcome(Status.PASS, "no actuated joint")
    line = f"{len(result.joints) - len(weak) - len(missing)} of {_count(len(result.joints), 'joint')} hold the robot up"
    if weak:
        line += f"; too weak: {', '.join(joint.name for joint in weak[:5])}{', ...' if len(weak) > 5 else ''}"
    if missing:
        line += f"; {len(missing)} declare no effort"
    return Outcome(Status.WARNING if weak else Status.PASS, line, len(weak))


@check("fk", "FK verification")
def fk_check(analysis: RobotAnalysis) -> Outcome:
    """PyBullet's link frames against the URDF's forward kinematics."""
    from ar3cli.analysis.kinematics import fk_verify

    result = fk_verify(analysis)
    document = result.document
    line = (f"max position error {document['max_position_error_m']:.3g} m, max orientation error "
            f"{document['max_orientation_error_rad']:.3g} rad over {document['samples']} samples")
    if result.passed:
        return Outcome(Status.PASS, line)
    failing = sum(not link.get("passed") for link in document.get("links", []))
    return Outcome(Status.FAIL, f"{_count(failing, 'link')} beyond tolerance (worst {document['worst']['link']}); "
                                f"{line}", failing)


@check("cross-check", "cross-check")
def cross_check_check(analysis: RobotAnalysis) -> Outcome:
    """PyBullet against MuJoCo; not checked without the extra."""
    from ar3cli.analysis.cross_check import INSTALL_HINT, cross_check

    result = cross_check(analysis)
    if result is None:
        return Outcome(Status.NOT_CHECKED, f"MuJoCo is not installed ({INSTALL_HINT})")
    line = result.lines[-1] if result.lines else ("agree" if result.agree else "disagree")
    return Outcome(Status.PASS if result.agree else Status.FAIL, line, int(result.document.get("disagreements", 0)))


CHECKS: tuple[CheckFunction, ...] = (lint_check, pictures_check, collisions_check, torques_check, fk_check,
                                     cross_check_check)
"""The report's checks, in the page's order."""


@question
def verdict(analysis: RobotAnalysis, checks: tuple[CheckFunction, ...] = CHECKS) -> Verdict:
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
    return Verdict(tuple(check(analysis) for check in checks), tuple(notes))
