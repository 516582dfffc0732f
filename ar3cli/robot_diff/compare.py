"""Compare two loaded robot models: match their elements, then ask each section (structure and
joints, end-effector kinematics, dynamics, limits, geometry, lint findings) for its changes."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ar3cli.findings import Finding
from ar3cli.robot_diff.dynamics import dynamics_changes
from ar3cli.robot_diff.findings import compare_findings
from ar3cli.robot_diff.geometry import geometry_changes
from ar3cli.robot_diff.kinematics import ForwardKinematics, displacements
from ar3cli.robot_diff.limits import limit_changes
from ar3cli.robot_diff.locate import Locator
from ar3cli.robot_diff.match import match
from ar3cli.robot_diff.pair import Pair
from ar3cli.robot_diff.records import SECTIONS, RobotDiff
from ar3cli.robot_diff.structure import structure_changes
from ar3cli.robot_diff.tolerance import Tolerance
from ar3cli.urdf.model import Model


def compare_models(old: Model, new: Model, old_label: str, new_label: str, *, fk: ForwardKinematics,
                   tolerance: Tolerance, samples: int, seed: int,
                   findings: tuple[Sequence[Finding], Sequence[Finding]] | None = None,
                   show_old: Callable[[str], str] = str, show_new: Callable[[str], str] = str) -> RobotDiff:
    """Everything NEW changes about OLD's robot, beyond ``tolerance``.

    ``fk`` is :mod:`ar3cli.kinematics.fk`; ``findings`` the lint findings of OLD and NEW (None: not
    compared); ``show_old``/``show_new`` turn a real path into the label the user knows.
    """
    pair = Pair(old, new, match(old, new), tolerance, Locator(new, new_label, show_new), Locator(old, old_label, show_old))
    result = RobotDiff(old_label, new_label)
    moved, (old_home, new_home), notes = displacements(pair, fk, samples, seed)
    result.displacements, result.notes = moved, notes
    dynamics, result.totals = dynamics_changes(pair, old_home, new_home)
    changes = [*structure_changes(pair), *dynamics, *limit_changes(pair), *geometry_changes(pair)]
    result.changes = sorted(changes, key=lambda change: SECTIONS.index(change.section))
    if findings is not None:
        result.findings = compare_findings(findings[0], findings[1], pair.matching, show_old)
    return result
