"""``--format github``: GitHub Actions workflow annotations on stdout, and the Markdown form
appended to ``$GITHUB_STEP_SUMMARY`` when set (the reviewer sees it on the run's summary page)."""

from __future__ import annotations

from dataclasses import replace

from ar3cli.output.formats import ANNOTATIONS, LINT, Format, register
from ar3cli.output.lint_report import LintReport, RuleGroup, completed, headline, rule_groups, summary_line
from ar3cli.output.report import Report


def lint_github(lint: LintReport) -> Report:
    """One annotation per rule and file (errors first; per finding with ``--no-group``), at most
    :data:`~ar3cli.output.github_actions.ANNOTATIONS_PER_RUN`, then the verdict; the Markdown table
    to the step summary."""
    from ar3cli.output.github_actions import append_step_summary, capped_annotations
    from ar3cli.output.markdown_table import findings_markdown

    verdict = summary_line(lint.summary)
    grouped = lint.group is not None
    error = append_step_summary(findings_markdown(lint.findings, verdict, grouped))
    annotations = capped_annotations([group_annotation(group) for group in rule_groups(lint.findings, grouped)])
    report = Report(data=lint.data, text=annotations + verdict + "\n", ok=lint.ok, errors=[error] if error else [])
    return completed(lint, report)


def group_annotation(group: RuleGroup) -> str:
    """The annotation of one rule's findings in one file, at the first of them: the count and the
    first message (cut at its first ``;`` when long), the places, the fix; the whole messages are in
    the step summary."""
    from ar3cli.output.github_actions import COMMANDS, workflow_command

    first = group.first
    lines = [group.summary()]
    if group.count > 1:
        lines.append(f"at {group.places()}")
    if first.hint:
        lines.append(f"fix: {first.hint}")
    if group.count > 1 or headline(first.message) != first.message:
        lines.append("(every message in full: the step summary, or --format json)")
    title = first.rule if group.count == 1 else f"{first.rule} ({group.count:,} in this file)"
    return workflow_command(COMMANDS[first.severity], lines, file=first.path, line=first.line,
                            column=max(first.column, 1), title=title)


def annotated(report: Report) -> Report:
    """A report that has annotations and a Markdown form (``Report.annotations``, ``Report.markdown``)."""
    from ar3cli.output.github_actions import append_step_summary

    assert report.annotations is not None and report.markdown is not None
    failed = append_step_summary(report.markdown())
    return replace(report, text=report.annotations(), tables=[], lines=[],
                   errors=[*report.errors, *([failed] if failed else [])])


FORMAT = register(Format("github", "workflow annotations; the Markdown is appended to $GITHUB_STEP_SUMMARY",
                         {LINT: lint_github, ANNOTATIONS: annotated}, order=30))
