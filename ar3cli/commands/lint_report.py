"""The :class:`~ar3cli.output.lint_report.LintReport` of the linter's results: what lint-urdf
renders in its ``--format`` and ``report`` puts on its page (:func:`lint_document`). The output layer does not import the
linter, so the linter's parts (fixers per rule, grouping, the rules that ran) are handed in here."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from ar3cli.errors import EXIT_USAGE
from ar3cli.output.lint_report import LintReport

if TYPE_CHECKING:
    from ar3cli.commands.robot_options import RobotSource


def exit_code(summary: dict[str, Any], exit_zero: bool = False) -> int:
    """The exit code a lint run with ``summary`` ends with (2 when a file was not checked)."""
    return EXIT_USAGE if summary["files_not_checked"] else 1 if summary["findings_failing"] and not exit_zero else 0


def lint_report(results: list, summary: dict[str, Any], options: Any, grouped: bool = False, **extra: Any) -> LintReport:
    """The report of ``results`` (``lint.engine.lint_paths``) and ``summary`` (``summarize``) for
    ``options`` (``LintOptions``); ``grouped`` folds alike findings into one text row; ``extra``
    sets the remaining :class:`LintReport` fields (note, changed, fix_commands, exit_zero, wide)."""
    import functools

    from ar3cli.commands.finding_context import finding_context
    from ar3cli.lint.engine import group_findings
    from ar3cli.lint.fix_hints import fixed_by

    findings = [finding for result in results for finding in result.findings]
    data = {"files": [result.to_dict() for result in results],
            "findings": [{**finding.to_dict(), "fixed_by": fixed_by(finding.rule)} for finding in findings],
            "summary": summary,
            "suppressed": [{**item.finding.to_dict(), "suppressed_by": item.by}
                           for result in results for item in result.suppressed]}
    digests = {path: digest for result in results for path, digest in result.sources.items()}
    return LintReport(results, summary, data, options.rules, group=group_findings if grouped else None,
                      context=functools.partial(finding_context, digests=digests), **extra)


def lint_document(path: Path, source: RobotSource) -> tuple[dict, Any]:
    """``lint-urdf --format json PATH``'s document (the project's configuration applies, as there)
    and its :class:`LintReport` (findings, and the context a page shows with them), the file read as
    ``source`` says (its packages, xacro arguments, ``--xacro`` mode and ``--xacro-env``, as the
    rest of the page reads it)."""
    from ar3cli.commands.lint_options import linter_options
    from ar3cli.findings import Severity
    from ar3cli.lint.config import load_config
    from ar3cli.lint.engine import lint_paths, summarize

    config = load_config()
    packages, xacro_args = source.specs()
    options = linter_options(config, package_paths=packages, xacro_args=xacro_args, sources=True)
    results = lint_paths([path], options)
    summary = {**summarize(results, config.fail_on or Severity.ERROR), "config_file": options.config_file,
               "isolated": False}
    summary["exit_code"] = exit_code(summary)
    made = lint_report(results, summary, options)
    return made.data, made
