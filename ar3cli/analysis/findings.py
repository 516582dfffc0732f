"""The lint findings of an analysed robot: lint-urdf's engine, rules and configuration on the one
model the analysis loaded (no second read of the file, an unsaved buffer included).

- :func:`static_findings`: the static rules, as ``lint-urdf PATH`` (milliseconds for most robots:
  what an editor runs on each change).
- :func:`findings`: the static and the PyBullet rules, as ``lint-urdf --sim PATH``; the P rules run
  in a forked child (a pybullet crash is the result's ``error``, the static findings stay).

Both apply the settings' configuration (select, ignore, per-file-ignores, severity, fail-on), its
``--target`` engines and the file's own suppressions (``ar3cli: ignore[...]`` comments), exactly as
the engine does for lint-urdf; a file that did not load is its F finding.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from ar3cli.analysis.robot import RobotAnalysis, question

if TYPE_CHECKING:
    from ar3cli.findings import Finding
    from ar3cli.lint.engine import LintResult


@dataclass(frozen=True)
class LintAnswer:
    """One file's lint: the engine's ``result``, its ``summary`` (lint-urdf's JSON ``summary``, with
    ``exit_code``) and ``document`` (``lint-urdf --format json``'s whole document)."""

    result: LintResult
    summary: dict[str, Any]
    document: dict[str, Any]
    sim: bool
    """Whether the PyBullet rules ran (``--sim``)."""

    @property
    def findings(self) -> list[Finding]:
        return self.result.findings


@question
def static_findings(analysis: RobotAnalysis) -> LintAnswer:
    """``lint-urdf PATH``: the static rules."""
    return _lint(analysis, sim=False)


@question
def findings(analysis: RobotAnalysis) -> LintAnswer:
    """``lint-urdf --sim PATH``: the static rules and the PyBullet rules (in a child)."""
    return _lint(analysis, sim=True)


def _lint(analysis: RobotAnalysis, sim: bool) -> LintAnswer:
    from ar3cli.lint.document import exit_code, lint_json
    from ar3cli.lint.engine import lint_model, load_failure, settle, summarize, unloaded_result

    options = analysis.settings.lint_options(sim)
    shown = analysis.shown_path
    if analysis.model is None:
        message = analysis.load_error.message if analysis.load_error else "not loaded"
        result = settle(unloaded_result(load_failure(analysis.path, shown, message), options), options)
    else:
        reuse = None
        if not sim:  # the earlier check's work: used once by the static rules, then let go
            reuse, analysis.lint_reuse = analysis.lint_reuse, None
        ran = lint_model(analysis.model, shown, options.rules(), options, reuse=reuse, keep=analysis.editing and not sim)
        if ran.carry is not None:
            analysis.lint_carry = ran.carry
        result = settle(ran, options)
    summary = {**summarize([result], analysis.settings.fail_on), "config_file": options.config_file, "isolated": False}
    summary["exit_code"] = exit_code(summary)
    return LintAnswer(result, summary, lint_json([result], summary), sim)
