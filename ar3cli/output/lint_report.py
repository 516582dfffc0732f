"""What every lint format renders: :class:`LintReport` (the ``lint`` kind of
:mod:`ar3cli.output.formats`), the verdict line, and the steps every lint format ends with.

The output layer does not import the linter: the command hands in the per-file results and the
few things only the linter knows (the rules that ran, how alike findings are grouped, an HTML
page's source lines) as values and functions.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ar3cli.findings import Finding, listed
from ar3cli.output.report import Report, log


@dataclass
class LintReport:
    """A lint run, before it is given a format.

    ``results`` are the linter's per-file results (``path``, ``findings``, ``error``, ``cached``,
    ``suppressed`` (each with its ``finding`` and what suppressed it, ``by``) and ``to_dict()``);
    ``data`` is the JSON document (``files``, ``findings`` with ``fixed_by``, ``summary``,
    ``suppressed``), which the json format prints and the html page embeds.
    """

    results: list[Any]
    summary: dict[str, Any]
    data: dict[str, Any]
    rules: Callable[[], list[Any]]
    """The rules that ran (SARIF's ``tool.driver.rules``)."""
    group: Callable[[list[Finding]], list[Any]] | None = None
    """Folds alike findings of the text table into one row (``--group``); None: a row each, and in
    the CI formats an annotation, row, result or test case each (see :func:`rule_groups`)."""
    context: Callable[[list[Finding]], dict[str, Any]] = lambda findings: {}
    """What the html page shows with each finding (source lines, fix commands)."""
    note: str | None = None
    """``--changed-since``'s line: the first text line, on stderr in the other formats."""
    changed: dict[str, Any] | None = None
    """``--changed-since``'s selection, added to the JSON (and SARIF) document."""
    fix_commands: list[str] | None = None
    """``--fix-hint``: the fixer command lines (text and json only)."""
    exit_zero: bool = False
    wide: bool = False
    findings: list[Finding] = field(init=False)

    def __post_init__(self) -> None:
        self.findings = [finding for result in self.results for finding in result.findings]

    @property
    def ok(self) -> bool:
        """No finding at or above the fail-on severity (a file not checked is exit 2 through
        ``Report.errors``, not 1)."""
        return not self.summary["findings_failing"]


def summary_line(summary: dict, cached: int = 0) -> str:
    """The verdict line; ``cached`` files answered from the result cache are said when there are any."""
    files = summary["files"]
    broken = summary["files_not_checked"]
    clean = summary["files_clean"]
    verdict = "FAILED" if summary["failed"] else "passed"
    unchecked = f"; {broken} not fully checked (pybullet crashed, or ran out of time or memory)" if broken else ""
    remembered = f"; {cached} unchanged since an earlier run (from the cache)" if cached else ""
    held = ""
    if summary.get("baselined") is not None:
        unused = summary.get("baseline_unused") or 0
        held = f"; {summary['baselined']} baselined" + (
            f" ({unused} more in the baseline no longer found: --write-baseline drops them)" if unused else "")
    return (f"{verdict}: {files} file{'s' if files != 1 else ''} checked, {summary['error']} errors, "
            f"{summary['warning']} warnings, {summary['info']} info; {clean} clean{held}{suppressed_clause(summary)}"
            f"{unchecked}{remembered} (fail-on: {summary['fail_on']}{'; --isolated' if summary.get('isolated') else ''})")


def suppressed_clause(summary: dict) -> str:
    """``; 7 suppressed (5 by pyproject.toml, 2 by comments in the files); 1 made less severe by
    pyproject.toml``: what the configuration and the files' own comments kept from the verdict
    (the baseline has its own clause), empty when nothing was."""
    counts = summary.get("suppressed") or {}
    config = config_name(summary.get("config_file"))
    parts = [f"{counts[by]} by {what}" for by, what in (("config", config), ("comment", "comments in the files"))
             if counts.get(by)]
    text = f"; {sum(counts.get(by, 0) for by in ('config', 'comment'))} suppressed ({', '.join(parts)})" if parts else ""
    lowered = summary.get("severity_lowered") or 0
    return text + (f"; {lowered} made less severe by {config}" if lowered else "")


def config_name(path: str | None) -> str:
    """The configuration file as a message names it: relative to the current folder when below it."""
    if not path:
        return "the configuration"
    import os

    relative = os.path.relpath(path)
    return path if relative.startswith("..") else relative


def completed(lint: LintReport, report: Report, *, text: bool = False, hints: bool = False) -> Report:
    """What every lint format ends with: the ``--changed-since`` selection and note (the first
    line of ``text`` output, else on stderr), ``--fix-hint``'s lines when the format shows
    ``hints``, ``--exit-zero``, ``--wide``, and one error per file that could not be checked."""
    if lint.changed is not None:
        report.data["changed_since"] = lint.changed
    if lint.note is not None:
        if text:
            report.lines.insert(0, lint.note)
        else:
            log(lint.note)
    if hints and lint.fix_commands is not None:
        report.data["fix_commands"] = lint.fix_commands
        report.lines += [f"to fix: {line}" for line in lint.fix_commands] or ["to fix: no finding has an ar3cli fixer"]
    report.ok = report.ok or lint.exit_zero
    report.wide = lint.wide
    report.errors = [*report.errors, *(result.error for result in lint.results if result.error)]
    return report


HEADLINE = 200
"""Characters of a message a CI format shows in its first line; the rest (G001's places looked in,
seven paths of ~900 characters) goes to the details."""
GROUP_PLACES = 5
"""Line numbers a grouped annotation, row or test case names."""


@dataclass(frozen=True)
class RuleGroup:
    """The findings of one rule in one file: what the CI formats show as one annotation (github),
    one row (markdown, the step summary), one result with related locations (sarif), one test case
    (junit). The text table groups by message shape instead (``LintReport.group``)."""

    findings: tuple[Finding, ...]

    @property
    def first(self) -> Finding:
        return self.findings[0]

    @property
    def count(self) -> int:
        return len(self.findings)

    @property
    def alike(self) -> bool:
        """Every finding has the first one's message."""
        return all(finding.message == self.first.message for finding in self.findings)

    def summary(self) -> str:
        """``headline``, or ``7x: headline (and 6 more like it)``."""
        text = headline(self.first.message)
        if self.count == 1:
            return text
        return f"{self.count}x: {text}" + ("" if self.alike else f" (and {self.count - 1:,} more like it)")

    def places(self, most: int = GROUP_PLACES) -> str:
        """``12:5, 14:5, 20:1 and 4 more`` (line:column of each finding that has a line)."""
        return listed((f"{f.line}:{f.column or 1}" for f in self.findings if f.line), most)


def headline(message: str, limit: int = HEADLINE) -> str:
    """``message`` up to its first ``"; "`` when it is longer than ``limit`` (that part fits), else cut
    at ``limit``; ``...`` says it was cut (the details and ``--format json`` hold all of it)."""
    if len(message) <= limit:
        return message
    cut = message.find("; ")
    if 0 < cut <= limit:
        return message[:cut] + "; ..."
    return message[:limit - 3].rstrip() + "..."


def rule_groups(findings: Sequence[Finding], grouped: bool = True) -> list[RuleGroup]:
    """The findings of each rule in each file as one :class:`RuleGroup` (with ``grouped`` False, a
    group per finding), errors first, then warnings, then info; in run order within a severity."""
    if not grouped:
        groups = [RuleGroup((finding,)) for finding in findings]
    else:
        members: dict[tuple, list[Finding]] = {}
        for finding in findings:
            members.setdefault((finding.path, finding.rule, finding.severity), []).append(finding)
        groups = [RuleGroup(tuple(alike)) for alike in members.values()]
    return sorted(groups, key=lambda group: -group.first.severity.rank)
