"""The diff as the output layer shows it: tables and JSON (:class:`~ar3cli.output.report.Report`),
Markdown for a pull-request comment or the step summary, and GitHub workflow annotations."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ar3cli.output.report import Report, Table
from ar3cli.robot_diff.records import RobotDiff, finite_or_none, show
from ar3cli.robot_diff.tolerance import Tolerance

CHANGE_COLUMNS = ["section", "element", "change", "old", "new", "amount", "at"]
KINEMATIC_COLUMNS = ["end effector", "home m", "home rad", "max m", "mean m", "max rad", "mean rad", "cause"]


def verdict(diffs: Sequence[RobotDiff]) -> str:
    changed = [diff for diff in diffs if diff.changed]
    if not changed:
        return f"no semantic change ({len(diffs)} robot file{'s' if len(diffs) != 1 else ''} compared)"
    count = sum(len(diff.changes) + len(diff.displacements) for diff in changed)
    return f"CHANGED: {count} change(s) in {len(changed)} of {len(diffs)} robot file(s)"


def _amount(amount: float | None, unit: str) -> str:
    amount = finite_or_none(amount)
    return "" if amount is None else f"{show(round(amount, 12))} {unit}".strip()


def _kinematic_row(moved) -> list[Any]:
    return [moved.link, moved.home_m, moved.home_rad, moved.max_m, moved.mean_m, moved.max_rad, moved.mean_rad,
            moved.cause]


def report(diffs: Sequence[RobotDiff], tolerance: Tolerance, samples: int, seed: int,
           errors: Sequence[str] = ()) -> Report:
    """Tables per robot (changes, end-effector displacement, findings) and the JSON document."""
    data = {"changed": any(diff.changed for diff in diffs), "tolerance": tolerance.to_dict(), "samples": samples,
            "seed": seed, "robots": [diff.to_dict() for diff in diffs], "errors": list(errors)}
    tables: list[Table] = []
    lines: list[str] = []
    for diff in diffs:
        title = f"{diff.old} -> {diff.new}"
        if diff.changes:
            tables.append(Table(f"{title}: changes", CHANGE_COLUMNS,
                                [[c.section, c.element, c.what, c.old, c.new, _amount(c.amount, c.unit),
                                  f"{c.file}:{c.line}" if c.line else c.file] for c in diff.changes],
                                nowrap_columns=("at",)))
        if diff.displacements:
            tables.append(Table(f"{title}: end effectors moved (home pose and {samples} samples, seed {seed})",
                                KINEMATIC_COLUMNS, [_kinematic_row(moved) for moved in diff.displacements],
                                numeric_columns=tuple(KINEMATIC_COLUMNS[1:7])))
        if diff.findings:
            tables.append(Table(f"{title}: lint findings", ["status", "rule", "severity", "message", "at"],
                                [[f.status, f.rule, f.severity, f.message, f"{f.file}:{f.line}" if f.line else f.file]
                                 for f in diff.findings], status_column="severity"))
        lines += [f"{title}: {note}" for note in diff.notes]
        if not diff.changed:
            lines.append(f"{title}: no semantic change")
    lines.append(verdict(diffs) + f" (tolerance {tolerance.length:g} m, {tolerance.angle:g} rad, "
                                  f"{tolerance.relative:g} relative; seed {seed})")
    return Report(data, tables, lines, ok=not data["changed"], errors=list(errors))


def _tables(diff: RobotDiff, samples: int, seed: int) -> list[tuple[str, Table]]:
    """The tables of one robot's diff for a Markdown page (the robot is in the heading), each with
    the line that introduces it (or none)."""
    tables = []
    if diff.changes:
        tables.append(("", Table("", CHANGE_COLUMNS, [[c.section, c.element, c.what, c.old, c.new,
                                                       _amount(c.amount, c.unit),
                                                       f"{c.file}:{c.line}" if c.line else c.file]
                                                      for c in diff.changes])))
    if diff.displacements:
        tables.append((f"End effectors moved (home pose and {samples} samples, seed {seed}):",
                       Table("", KINEMATIC_COLUMNS, [_kinematic_row(moved) for moved in diff.displacements])))
    if diff.findings:
        tables.append(("", Table("", ["lint", "rule", "severity", "message"],
                                 [[f.status, f.rule, f.severity, f.message] for f in diff.findings])))
    return tables


def markdown(diffs: Sequence[RobotDiff], samples: int, seed: int) -> str:
    """GitHub-flavoured Markdown: a heading per robot, its changes, moved end effectors and findings
    (every cell escaped by the output layer's Markdown tables)."""
    from ar3cli.output.escape import markdown_code, markdown_text
    from ar3cli.output.markdown_table import table_markdown

    out = ["## ar3cli diff", "", markdown_text(verdict(diffs)), ""]
    for diff in diffs:
        out += [f"### {markdown_code(diff.old)} → {markdown_code(diff.new)}", ""]
        if not diff.changed:
            out += ["No semantic change.", ""]
        for intro, table in _tables(diff, samples, seed):
            out += [markdown_text(intro), ""] if intro else []
            out += table_markdown(table, code_columns=("at",))
        out += [f"_{markdown_text(note)}_" for note in diff.notes]
    return "\n".join(out).rstrip("\n") + "\n"


def annotations(diffs: Sequence[RobotDiff]) -> str:
    """``::warning file=F,line=L,title=ar3cli diff::...`` per change and moved end effector, ``::notice``
    per lint finding that came or went (at most the output layer's annotations per run). Changes
    located only in a revision (``REV:path``) get no file."""
    from ar3cli.output.github_actions import capped_annotations, workflow_command

    def line(kind: str, file: str, number: int, title: str, message: str) -> str:
        return workflow_command(kind, message, file=file if file and ":" not in file else "", line=number, title=title)

    out = []
    for diff in diffs:
        out += [line("warning", c.file, c.line, f"ar3cli diff: {c.section}", c.summary) for c in diff.changes]
        out += [line("warning", m.file, m.line, "ar3cli diff: kinematics",
                     f"link '{m.link}' moved {show(m.home_m)} m, {show(m.home_rad)} rad at home (max {show(m.max_m)} m, "
                     f"{show(m.max_rad)} rad over the samples); cause: {m.cause}") for m in diff.displacements]
        out += [line("notice", f.file, f.line, f"ar3cli diff: lint {f.rule} {f.status}", f.message) for f in diff.findings]
    return capped_annotations(out, "changes")
