"""cross-check: PyBullet against MuJoCo (each in its own child), where the ``mujoco`` extra is installed."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ar3cli.analysis.robot import RobotAnalysis, question

INSTALL_HINT = "pip install 'ar3cli[mujoco]'"


@dataclass(frozen=True)
class CrossCheck:
    """``cross-check --format json``'s document, its verdict lines and whether the engines agree."""

    document: dict[str, Any]
    lines: list[str]
    agree: bool


def mujoco_installed() -> bool:
    import importlib.util

    return importlib.util.find_spec("mujoco") is not None


@question
def cross_check(analysis: RobotAnalysis) -> CrossCheck | None:
    """``cross-check --samples N --seed S``; None where MuJoCo is not installed (:data:`INSTALL_HINT`)."""
    if not mujoco_installed():
        return None
    from ar3cli.cross_check.run import cross_check as run_cross_check

    model = analysis.require_model()
    made = run_cross_check(model, analysis.path, analysis.settings.samples, analysis.settings.seed, announce=False)
    return CrossCheck(made.data, made.lines, made.ok)
