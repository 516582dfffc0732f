"""The :class:`~ar3cli.output.lint_report.LintReport` of the linter's results: what lint-urdf
renders in its ``--format``. The output layer does not import the linter, so the linter's parts
(fixers per rule, grouping, the rules that ran) are handed in here."""

from __future__ import annotations

from typing import Any

from ar3cli.lint.document import exit_code as exit_code  # lint-urdf's exit code, imported from here
from ar3cli.output.lint_report import LintReport


def lint_report(results: list, summary: dict[str, Any], options: Any, grouped: bool = False, **extra: Any) -> LintReport:
    """The report of ``results`` (``lint.engine.lint_paths``) and ``summary`` (``summarize``) for
    ``options`` (``LintOptions``); ``grouped`` folds alike findings into one text row; ``extra``
    sets the remaining :class:`LintReport` fields (note, changed, fix_commands, exit_zero, wide).
    An HTML page shows the cited lines only of the files each result recorded with the digest of
    the bytes linted (``LintResult.sources``)."""
    import functools

    from ar3cli.commands.finding_context import finding_context
    from ar3cli.lint.document import lint_json
    from ar3cli.lint.engine import group_findings

    digests = {path: digest for result in results for path, digest in result.sources.items()}
    return LintReport(results, summary, lint_json(results, summary), options.rules,
                      group=group_findings if grouped else None,
                      context=functools.partial(finding_context, digests=digests), **extra)
