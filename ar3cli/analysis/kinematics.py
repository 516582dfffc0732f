"""fk-verify: PyBullet's link frames against the URDF's own forward kinematics (in a pybullet
child), with the settings' samples and seed and fk-verify's default tolerances."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ar3cli.analysis.robot import RobotAnalysis, question


@dataclass(frozen=True)
class FkCheck:
    """``fk-verify --format json``'s document (``passed``, the worst link, every link's errors) and
    its verdict lines."""

    document: dict[str, Any]
    lines: list[str]

    @property
    def passed(self) -> bool:
        return bool(self.document.get("passed"))


@question
def fk_verify(analysis: RobotAnalysis) -> FkCheck:
    """``fk-verify --samples N --seed S``."""
    from ar3cli.kinematics.verify import DEFAULT_TOLERANCE_M, DEFAULT_TOLERANCE_RAD, Tolerance, fk_report, measure

    model = analysis.require_model()
    samples, seed = analysis.settings.samples, analysis.settings.seed
    drawn, comparison = measure(model, samples, seed, announce=False)
    made = fk_report(model, analysis.path, samples, seed, Tolerance(DEFAULT_TOLERANCE_M, DEFAULT_TOLERANCE_RAD,
                                                                     scaled=True), drawn, comparison, None)
    return FkCheck(made.data, made.lines)
