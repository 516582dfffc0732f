"""The self-collision matrix: sample-collisions' sampling and MoveIt classification of every link
pair (in a pybullet child), with the settings' samples and seed."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ar3cli.analysis.robot import RobotAnalysis, question

if TYPE_CHECKING:
    from ar3cli.collisions.run import MatrixRun


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
