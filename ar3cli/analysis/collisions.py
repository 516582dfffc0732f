"""The self-collision matrix: sample-collisions' sampling and MoveIt classification of every link
pair (in a pybullet child), with the settings' samples and seed."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ar3cli.analysis.robot import RobotAnalysis, question

if TYPE_CHECKING:
    from pathlib import Path

    from ar3cli.collisions.run import MatrixRun
    from ar3cli.urdf.srdf_read import DisabledPairs


@dataclass(frozen=True)
class CollisionMatrix:
    """The run, ``sample-collisions --format json``'s document and its text summary lines."""

    run: MatrixRun
    document: dict[str, Any]
    lines: list[str]


@question
def collision_matrix(analysis: RobotAnalysis) -> CollisionMatrix:
    """``sample-collisions --samples N --seed S``; UserError when fewer than two links have collision geometry."""
    from ar3cli.collisions.matrix import ALWAYS_THRESHOLD
    from ar3cli.collisions.matrix_report import matrix_report
    from ar3cli.collisions.run import sample_matrix

    model = analysis.require_model()
    settings = analysis.settings
    run = sample_matrix(model, settings.samples, settings.seed, None, ALWAYS_THRESHOLD)
    made = matrix_report(model, run, "text")
    return CollisionMatrix(run, made.data, made.lines)


@question
def moveit_disabled_pairs(analysis: RobotAnalysis) -> tuple[DisabledPairs, Path | None]:
    """The link pairs MoveIt is told not to check (the settings' ``--srdf``, else the package's own SRDF, which
    comes back too): contact at home there is not a warning, as for lint-urdf's P002
    (:func:`~ar3cli.urdf.srdf_read.moveit_disabled`)."""
    from ar3cli.urdf.srdf_read import moveit_disabled

    return moveit_disabled(analysis.require_model(), analysis.settings.srdf_disabled)


def disabled_in_srdf(analysis: RobotAnalysis, pairs) -> tuple[list, str]:
    """``pairs`` ((link a, link b), ...) MoveIt is told not to check, and the words naming where that is said
    ('' when none is)."""
    disabled, srdf = moveit_disabled_pairs(analysis)
    found = [pair for pair in pairs if disabled.covers(*pair)]
    if not found:
        return [], ""
    return found, f"the package's SRDF {srdf.name}" if srdf is not None else "the --srdf SRDF"
